"""Snap-through of a clamped shallow spherical cap under uniform external pressure: the 3-D
Loop-subdivision solver against the axisymmetric solver (graspdef.axisym, the thesis's shooting
method with arc-length continuation) -- the reference of benchmarks/nonlinear/shallow_cap_snap.toml.

    python scripts/shallow_cap_study.py [--fast] [--out out/shallow_cap] [--replot]

The cap (see the benchmark file): R/t = 100, rise parameter lambda = 2 (3 (1 - nu^2))^(1/4)
sqrt(H/t) = 4 (nu = 1/2: H = t lambda^2 / 6), clamped edge, incompressible Mooney-Rivlin
(C2/C1 = 0.1), a dead pressure along the rest normal scaled by p_cl = 2 E t^2 / (R^2 sqrt(3 (1 -
nu^2))) = 4 mu t^2 / R^2 (mu = 2 (C1 + C2)).  At lambda = 4 the cap snaps axisymmetrically: the
first change of stability on its path is the limit point.

Axisymmetric side: nodes at equal polar angles from the apex to the clamped edge (r, z and phi
held), each segment loaded by the pressure's components along its mid-angle's rest normal (QH,
QV per unit undeformed area: the direction error is O(dphi^2), 2e-5 with 32 pieces of the 13.3 deg
half-angle), arc length to past the limit point.  Run twice: with the thesis's thickness model
(graspdef.axisym as is) and with the 3-D solver's (``axisym_material("3d")`` of
scripts/crosscheck_axisym_3d.py): the second compares the two *solvers*, the first includes the
O(t/R) difference between the two shell theories (docs/crosscheck.md).

3-D side: the benchmark file at three meshes (the disk's octagon refined 2, 3, 4 times: 97, 353
and 1,345 control vertices), arc length; the limit point located by the path (bisection of the
arc length to 2^-12 of the step).

Writes ``shallow_cap.json`` and ``shallow_cap.png`` (load factor against apex deflection; the
limit points) to --out and prints the table.
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import re
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
BENCH = ROOT / "benchmarks" / "nonlinear" / "shallow_cap_snap.toml"
GAMMA = 0.1
R_OVER_T = 100.0
LAMBDA = 4.0
#: 3-D meshes: (edge_length, refinements) of the benchmark's geometry -> 97, 353, 1,345 control vertices
MESHES = ((5.8, 2), (2.9, 3), (1.45, 4))


def cap_dimensions(t: float = 1.0):
    """(R, H, phi0, p_cl) of the cap for C1 = 1: sphere radius, rise, half-angle [rad], and the
    classical pressure 4 mu t^2 / R^2."""
    R = R_OVER_T * t
    H = t * LAMBDA ** 2 / 6.0
    phi0 = float(np.arccos(1.0 - H / R))
    mu = 2.0 * (1.0 + GAMMA)
    return R, H, phi0, 4.0 * mu * t * t / R ** 2


def axisym_material(energy: str):
    """The thesis's Mooney-Rivlin material, or with the 3-D solver's thickness model ("3d", the
    diagnostic class of scripts/crosscheck_axisym_3d.py)."""
    if energy == "thesis":
        from graspdef.axisym import AxisymMaterial
        return AxisymMaterial("mooney_rivlin", C1=1.0, gamma=GAMMA)
    spec = importlib.util.spec_from_file_location("crosscheck_axisym_3d", ROOT / "scripts" / "crosscheck_axisym_3d.py")
    cc = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(cc)
    return cc.axisym_material("3d")


def axisym_cap(energy: str = "3d", pieces: int = 32, max_piece: float = 0.5) -> dict:
    """The axisymmetric cap's path to past its limit point: the limit load factor (the path's
    bracketed limit point) and the apex deflection there (the parabola through the path's largest
    load factor and its neighbours), the path itself, the time."""
    from graspdef.axisym import solve_path
    from graspdef.axisym.assembly import DistributedLoad, Model, Node, Segment

    t = 1.0
    R, H, phi0, p_cl = cap_dimensions(t)
    angles = np.linspace(0.0, phi0, pieces + 1)
    nodes = [Node(R * np.sin(a), R * np.cos(a), -a) for a in angles]
    nodes[-1].fix = (True, True, True)                          # clamped
    segs = [Segment(k, k + 1, kappa=-1.0 / R) for k in range(pieces)]
    mid = 0.5 * (angles[:-1] + angles[1:])
    loads = [DistributedLoad(QH=-p_cl * np.sin(a), QV=-p_cl * np.cos(a), segments=[k]) for k, a in enumerate(mid)]
    model = Model(axisym_material(energy), t, nodes, segs, [], loads, max_piece=max_piece, rk_steps=2,
                  name="shallow_cap")
    t0 = time.perf_counter()
    path = solve_path(model, ds=0.05, max_steps=300, unload_fraction=0.9)
    seconds = time.perf_counter() - t0
    if not path.limits:
        raise RuntimeError(f"the axisymmetric cap's path found no limit point ({path.stopped_by})")
    w = -(path.node(0)[:, 1] * t - R)                          # apex deflection (down positive)
    lam = path.lam
    k = int(np.argmax(lam))
    c = np.polyfit(w[k - 1:k + 2] - w[k], lam[k - 1:k + 2], 2)
    dw = -c[1] / (2.0 * c[0])
    return {"energy": energy, "pieces": pieces, "max_piece": max_piece, "limit_load": float(path.limits[0]["lam"]),
            "deflection_at_limit": float(w[k] + dw), "seconds": seconds,
            "load_factors": lam.tolist(), "apex_deflection": w.tolist()}


def cap_file(folder: Path, edge_length: float, refinements: int) -> Path:
    """The benchmark file with another mesh (its geometry's edge_length and refinements), written
    to ``folder``."""
    text = re.sub(r"(?m)^edge_length = \S+", f"edge_length = {edge_length}", BENCH.read_text())
    text = re.sub(r"(?m)^refinements = \S+", f"refinements = {refinements}", text)
    path = Path(folder) / BENCH.name
    path.write_text(text)
    return path


def shell3d_cap(edge_length: float, refinements: int) -> dict:
    """The benchmark file's cap at another mesh: its first located limit point and path."""
    from graspdef.problem.config import load_problem
    from graspdef.solve.nonlinear import path_options, solve_nonlinear

    with tempfile.TemporaryDirectory() as d:
        spec = load_problem(cap_file(Path(d), edge_length, refinements))
    t0 = time.perf_counter()
    sol = solve_nonlinear(spec.problem, path_options(spec.solver), backend=spec.backend)
    seconds = time.perf_counter() - t0
    pts = [p for p in sol.path if p.kind != "refine"]
    cps = [c for c in sol.critical_points if c["kind"].startswith("limit point")]
    first = sol.critical_points[0] if sol.critical_points else None
    return {"n_control": int(spec.problem.shell.mesh.n_real), "seconds": seconds,
            "first_critical": None if first is None else {k: first[k] for k in ("kind", "load_factor",
                                                                                  "instability_before", "instability_after")},
            "limit_load": cps[0]["load_factor"] if cps else None,
            "deflection_at_limit": -cps[0]["probes"]["apex"][2] if cps else None,
            "factorisations": int(sol.n_factorisations),
            "load_factors": [p.load_factor for p in pts], "apex_deflection": [-p.probes["apex"][2] for p in pts]}


def run(fast: bool) -> dict:
    res = {"R_over_t": R_OVER_T, "lambda": LAMBDA, "gamma": GAMMA}
    res["axisym"] = [axisym_cap("3d"), axisym_cap("thesis")]
    if not fast:
        res["axisym"].append(axisym_cap("3d", pieces=64, max_piece=0.25))
    ref = res["axisym"][0]["limit_load"]
    res["shell3d"] = [shell3d_cap(*m) for m in (MESHES[:2] if fast else MESHES)]
    print(f"\nclamped shallow cap, R/t = {R_OVER_T:g}, lambda = {LAMBDA:g}, Mooney-Rivlin C2/C1 = {GAMMA:g}")
    print("| solver | mesh | limit load p/p_cl | vs axisym (3-D model) | apex deflection / t | time [s] |")
    print("|---|---|---|---|---|---|")
    for a in res["axisym"]:
        print(f"| axisym, {a['energy']} thickness model | {a['pieces']} pieces, {a['max_piece']} t | "
              f"{a['limit_load']:.6f} | {100 * (a['limit_load'] / ref - 1):+.3f} % | {a['deflection_at_limit']:.4f} | "
              f"{a['seconds']:.1f} |")
    for s in res["shell3d"]:
        print(f"| 3-D Loop | {s['n_control']} control vertices | {s['limit_load']:.6f} | "
              f"{100 * (s['limit_load'] / ref - 1):+.3f} % | {s['deflection_at_limit']:.4f} | {s['seconds']:.1f} |")
        print(f"|   first change of stability | | {s['first_critical']} | | | |")
    return res


def plot(res, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.0, 5.0))
    for a, style in zip(res["axisym"], ("k-", "k:")):
        ax.plot(a["apex_deflection"], a["load_factors"], style, label=f"axisym, {a['energy']} thickness model")
        ax.plot([a["deflection_at_limit"]], [a["limit_load"]], "ko", mfc="none")
    for s, c in zip(res["shell3d"], ("tab:orange", "tab:blue", "tab:green")):
        ax.plot(s["apex_deflection"], s["load_factors"], "--s", color=c, ms=3, mfc="none",
                label=f"3-D, {s['n_control']} control vertices")
        if s["limit_load"] is not None:
            ax.plot([s["deflection_at_limit"]], [s["limit_load"]], "x", color=c, ms=9)
    ax.set_xlabel("apex deflection / t")
    ax.set_ylabel("p / p_cl")
    ax.set_title(f"clamped shallow cap, R/t = {res['R_over_t']:g}, lambda = {res['lambda']:g}: snap-through")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    from _study import write_results      # scripts/_study.py (run as a script: scripts/ is on the path)

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/shallow_cap")
    ap.add_argument("--fast", action="store_true", help="two 3-D meshes, no fine axisymmetric run (~1 min)")
    ap.add_argument("--replot", action="store_true", help="only redraw the PNG from --out/shallow_cap.json")
    a = ap.parse_args()
    out = Path(a.out)
    if a.replot:
        plot(json.loads((out / "shallow_cap.json").read_text()), out / "shallow_cap.png")
        return
    t0 = time.perf_counter()
    res = run(a.fast)
    res["total_seconds"] = time.perf_counter() - t0
    write_results(out, "shallow_cap", res, plot)


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
