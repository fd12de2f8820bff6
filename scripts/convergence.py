"""Convergence of the linear Loop-subdivision shell: error vs number of control vertices.

Two studies, each up to >= 50,000 control vertices (Tian & Jia's solver stopped at 2,500):

* square plate, simply supported, uniform load (the Tian & Jia plate: L = 100, h = 1, nu = 0.3,
  q/E = 1e-7): centre deflection vs 0.0040623527 q L^4 / D = 0.44361 (Navier series);
* pinched cylinder with rigid diaphragms, full model (R = 300, L = 600, t = 3, E = 3e6,
  nu = 0.3, F = 1): radial displacement under the load vs 1.8248e-5 (MacNeal & Harder 1985).

Writes ``convergence.json``, ``convergence.csv`` and ``convergence.png`` to ``--out`` and prints
a Markdown table with the observed order of the error in h ~ n_control^(-1/2).

    python scripts/convergence.py [--out out/convergence] [--fast]
"""
from __future__ import annotations

import argparse
import csv
import json
import time
from pathlib import Path

import numpy as np

from graspdef.geometry import cylinder, rectangle
from graspdef.problem.loads import PointLoad, Pressure
from graspdef.problem.problem import Problem, locate
from graspdef.problem.supports import EdgeSupport, PointSupport
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell
from graspdef.solve.linear import solve_linear

PLATE_REF = 0.0040623527 * 0.1 * 100.0 ** 4 / (1e6 / (12 * (1 - 0.09)))
CYL_REF = 1.8248e-5


def plate(n: int) -> tuple[int, float]:
    m = rectangle(100.0, 100.0, n, n)
    sh = Shell(m.vertices, m.faces, LinearElastic(1e6, 0.3), 1.0)
    edges = lambda p: (np.abs(np.abs(p[:, 0]) - 50) < 1e-6) | (np.abs(np.abs(p[:, 1]) - 50) < 1e-6)
    sup = [EdgeSupport("simply_supported", edges)]
    c, _ = locate(sh, Problem(sh, [], sup).evaluator, [0.0, 0.0, 0.0], "centre")
    sol = solve_linear(Problem(sh, [Pressure(0.1)], sup, {"c": c}))
    return m.n_vertices, float(sol.probe("c")[2])


def pinched_cylinder_problem(n_z: int) -> Problem:
    """Full-model pinched cylinder with 2 n_z x n_z cells; probe "A" under the inward load at +x."""
    R, L = 300.0, 600.0
    m = cylinder(R, L, 2 * n_z, n_z)
    sh = Shell(m.vertices, m.faces, LinearElastic(3e6, 0.3), 3.0)
    ends = lambda p: (np.abs(p[:, 2]) < 1e-6) | (np.abs(p[:, 2] - L) < 1e-6)
    sup = [EdgeSupport("diaphragm", ends, normal=(0, 0, 1))]
    A, _ = locate(sh, None, [R, 0, L / 2], "A")
    B, _ = locate(sh, None, [-R, 0, L / 2], "B")
    C, _ = locate(sh, None, [0, R, L / 2], "C")
    return Problem(sh, [PointLoad(A.face, A.bary, (-1.0, 0, 0)), PointLoad(B.face, B.bary, (1.0, 0, 0))],
                   sup + [PointSupport(C.face, C.bary, ((0, 0, 1),))], {"A": A})


def pinched_cylinder(n_z: int) -> tuple[int, float]:
    pr = pinched_cylinder_problem(n_z)
    sol = solve_linear(pr)
    return pr.shell.mesh.n_real, float(-sol.probe("A")[0])


STUDIES = {
    "plate_ss_uniform": (plate, PLATE_REF, [4, 8, 16, 32, 64, 128, 224], [4, 8, 16]),
    "pinched_cylinder": (pinched_cylinder, CYL_REF, [16, 24, 32, 48, 64, 96, 128, 160], [16, 24, 32]),
}


def order(rows: list[dict]) -> float:
    """Least-squares slope of log|error| against log h, h = n_control^(-1/2)."""
    n = np.array([r["n_control"] for r in rows], float)
    e = np.array([abs(r["rel_error"]) for r in rows])
    return float(np.polyfit(np.log(n ** -0.5), np.log(e), 1)[0])


def run(fast: bool = False, progress=print) -> dict:
    results = {}
    for name, (fn, ref, sizes, fast_sizes) in STUDIES.items():
        rows = []
        for s in (fast_sizes if fast else sizes):
            t0 = time.perf_counter()
            n, value = fn(s)
            dt = time.perf_counter() - t0
            rows.append({"study": name, "resolution": s, "n_control": n, "value": value,
                         "reference": ref, "rel_error": (value - ref) / ref, "seconds": dt})
            progress(f"{name:18s} n_control={n:7d}  value={value:.6g}  error={100 * (value - ref) / ref:+.4f} %  {dt:.1f} s")
        results[name] = rows
    return results


def main(fast: bool = False, out: str = "out/convergence") -> dict:
    res = run(fast)
    o = Path(out)
    o.mkdir(parents=True, exist_ok=True)
    (o / "convergence.json").write_text(json.dumps(res, indent=2) + "\n")
    with open(o / "convergence.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(next(iter(res.values()))[0]))
        w.writeheader()
        for rows in res.values():
            w.writerows(rows)
    print("| study | control vertices | value | reference | error |")
    print("|---|---|---|---|---|")
    for name, rows in res.items():
        for r in rows:
            print(f"| {name} | {r['n_control']} | {r['value']:.6g} | {r['reference']:.6g} | {100 * r['rel_error']:+.4f} % |")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4.2))
        for name, rows in res.items():
            n = [r["n_control"] for r in rows]
            e = [abs(r["rel_error"]) for r in rows]
            ax.loglog(n, e, "o-", label=name.replace("_", " "))
        ax.set_xlabel("control vertices")
        ax.set_ylabel("|relative error|")
        ax.set_title("graspdef linear shell: convergence")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(o / "convergence.png", dpi=120)
    except ImportError:
        print("matplotlib not installed: no plot")
    return res


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/convergence")
    ap.add_argument("--fast", action="store_true", help="small meshes only")
    a = ap.parse_args()
    main(a.fast, a.out)
