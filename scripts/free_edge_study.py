"""Free edges under refinement: do free-edge displacements converge like interior ones?

Issue 17, item 4: a free-edge displacement of the pulled open cylinder (Sze, Liu & Lo 2004, test 3.5)
was reported to drift away from the reference under refinement while the loaded point converged.
This study measures, on the same meshes:

(a) linear problems with free edges and a known answer
    * ``anticlastic``: a plate strip bent by uniform end moments, nu = 0.3.  Kirchhoff's exact
      solution is the pure-bending state M_x = M, M_y = M_xy = 0 (it meets every free-edge condition),
      w = (k_x x^2 + k_y y^2)/2 with k_x = 12 M / (E t^3), k_y = -nu k_x (Timoshenko &
      Woinowsky-Krieger, Theory of Plates and Shells, 2nd ed., Sec. 10, "pure bending of plates"):
      the free corner rises above the mid-tip by -nu k_x b^2/8.  Quadratic: a Loop space with a correct
      free boundary reproduces it exactly, so the error is round-off at every mesh.
    * ``cantilever``: a strip clamped at one end under an end shear, nu = 0: plate = Euler-Bernoulli
      beam exactly, w_tip = P L^3 / (3 E I) at the mid-tip AND at the free corner (cubic: exact again).
    * ``open_cylinder_linear``: the pulled (or pinched) open cylinder of Sze's test 3.5 at P = 100, linear:
      the classic "pinched cylinder with free ends" (Takemoto & Cook 1973; Cook, Concepts and
      Applications of FEA, 2nd ed. 1981, pp. 284-287: 0.1139 under the load, a shear-deformable
      reference).  Points A (load, mid-length), B (mid-length, 90 degrees from A), C (free edge,
      90 degrees from A), D (free edge above A).  Observed order and Richardson-extrapolated value of
      each (meshes halve exactly: n_theta x n_z = 12x8 ... 96x64 on the 1/8 model).
(b) the pulled open cylinder, finite deformation (benchmarks/nonlinear/pullout_cylinder.toml, displacement
    control through the snap), A, B, C at P/P_max = 0.5 and 1 against Sze's S4R 24x36 table, with the
    Richardson estimate; and the small-load check that the nonlinear path leaves the linear solution
    at O(load) in the normalised response (u_nl / lambda - u_lin = O(lambda)).

Writes ``free_edge_study.json``, ``free_edge_study.csv`` and ``free_edge_study.png`` to ``--out``
and prints Markdown tables.  About 2-3 minutes on two cores (``--fast``: about 40 s, no 48x32
nonlinear mesh and no 96x64 linear mesh).

    python scripts/free_edge_study.py [--out out/free_edge_study] [--fast]
"""
from __future__ import annotations

import argparse
import json
import re
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent / "gallery"))
import _common as C  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
PULLOUT = ROOT / "benchmarks" / "nonlinear" / "pullout_cylinder.toml"
#: Sze's test 3.5 data (MBDyn tests/plates/sze2004/sze.tex)
R, L, T, E, NU = 4.953, 10.35, 0.094, 10.5e6, 0.3125
#: the four points of the 1/8 model (z = 0 mid-length, z = L/2 free edge); outward radial unit vectors
POINTS = {"A": ((R, 0.0, 0.0), (1.0, 0.0, 0.0)), "B": ((0.0, R, 0.0), (0.0, 1.0, 0.0)),
          "C": ((0.0, R, L / 2), (0.0, 1.0, 0.0)), "D": ((R, 0.0, L / 2), (1.0, 0.0, 0.0))}
FREE_EDGE = ("C", "D")
LINEAR_SIZES = (4, 8, 16, 32)          # k: n_theta = 3k, n_z = 2k (square cells)
NONLINEAR_SIZES = (4, 8, 16)
PLATE_SIZES = (1, 2, 4)


def richardson(values, ratio: float = 2.0) -> dict:
    """Observed order p and extrapolated value from the last three of a sequence of meshes whose size
    shrinks by ``ratio`` each time: p = log(|f1 - f2| / |f2 - f3|) / log(ratio),
    f_inf = f3 + (f3 - f2) / (ratio^p - 1); no extrapolated value (NaN) when the differences change
    sign or do not shrink (p <= 0.5: the meshes are not in the asymptotic range)."""
    f1, f2, f3 = (float(v) for v in values[-3:])
    d1, d2 = f1 - f2, f2 - f3
    if d2 == 0.0 or d1 * d2 <= 0.0:
        return {"order": float("nan"), "extrapolated": float("nan")}
    p = float(np.log(abs(d1 / d2)) / np.log(ratio))
    if p <= 0.5:                                   # differences not shrinking: not asymptotic
        return {"order": p, "extrapolated": float("nan")}
    return {"order": p, "extrapolated": f3 + (f3 - f2) / (ratio ** p - 1.0)}


def pullout_spec(k: int):
    """benchmarks/nonlinear/pullout_cylinder.toml on a 3k x 2k mesh of the 1/8 model."""
    from graspdef.problem.config import load_problem

    text = PULLOUT.read_text()
    text = re.sub(r"(?m)^n_theta = \d+", f"n_theta = {3 * k}", text)
    text = re.sub(r"(?m)^n_z = \d+", f"n_z = {2 * k}", text)
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / PULLOUT.name
        p.write_text(text)
        return load_problem(p)


def _radial(problem, u: np.ndarray) -> dict:
    out = {}
    for name, (x, e) in POINTS.items():
        sp = problem.probes[name]
        st, w = problem.evaluator.values(sp.face, np.asarray(sp.bary))
        out[name] = float((w @ u[st]) @ np.asarray(e))
    return out


def open_cylinder_linear(k: int, P: float = 100.0) -> tuple[int, dict]:
    """Linear radial displacements at A, B, C, D under the pair of pulling forces P (P/4 on the
    1/8 model), the pull-out file's shell and symmetry supports."""
    from graspdef.problem.loads import PointLoad
    from graspdef.problem.problem import Problem
    from graspdef.problem.supports import PointSupport
    from graspdef.solve.linear import solve_linear

    spec = pullout_spec(k)
    pr0 = spec.problem
    a = pr0.probes["A"]
    pr = Problem(pr0.shell, [PointLoad(a.face, a.bary, (P / 4, 0.0, 0.0))],
                 [s for s in pr0.supports if not isinstance(s, PointSupport)], dict(pr0.probes))
    sol = solve_linear(pr)
    return pr.shell.mesh.n_real, _radial(pr, sol.u)


def plate_patch_tests(n: int) -> dict:
    """Relative errors of the two exact free-edge plate solutions (see the module docstring) on a
    10n x 2n mesh."""
    from graspdef.geometry import primitives as prim
    from graspdef.problem.loads import EdgeLoad
    from graspdef.problem.potentials import EdgeMoment
    from graspdef.problem.problem import Problem
    from graspdef.problem.supports import EdgeSupport, PointSupport
    from graspdef.shell.hyperelastic import make_material
    from graspdef.shell.model import Shell
    from graspdef.solve.linear import solve_linear

    Ep, t, Lp = 1.2e6, 0.1, 10.0

    def w(pr, sol, x):
        p = pr.locate(x)
        st, wt = pr.evaluator.values(p.face, np.asarray(p.bary))
        return float((wt @ sol.u[st])[2])

    # anticlastic bending: half-strip x in [0, L] (symmetry at x = 0), free sides y = +-b/2, moment M at x = L
    b, nu, M = 2.0, 0.3, 1.0
    m = prim.rectangle(Lp, b, 10 * n, 2 * n, (Lp / 2, 0.0))
    sh = Shell(m.vertices, m.faces, make_material("linear_elastic", {"E": Ep, "nu": nu}), t)
    pr = Problem(sh, [EdgeMoment(lambda p: np.abs(p[:, 0] - Lp) < 1e-9, M, (0.0, 1.0, 0.0), "tip")],
                 [EdgeSupport("symmetry", lambda p: np.abs(p[:, 0]) < 1e-9, (1.0, 0.0, 0.0), "x0")])
    for i, (y, d) in enumerate([(0.0, (0.0, 1.0, 0.0)), (b / 2, (0.0, 0.0, 1.0)), (-b / 2, (0.0, 0.0, 1.0))]):
        a = pr.locate((0.0, y, 0.0))
        pr.supports.append(PointSupport(a.face, a.bary, (d,), f"hold{i}"))
    sol = solve_linear(pr)
    kx = 12.0 * M / (Ep * t ** 3)
    w0 = w(pr, sol, (0.0, 0.0, 0.0))
    mid = w(pr, sol, (Lp, 0.0, 0.0)) - w0
    rise = w(pr, sol, (Lp, b / 2, 0.0)) - w0 - mid
    # the sign of w follows the couple's sense; compare magnitudes and the ratio's sign
    anti_mid = abs(mid) / (kx * Lp ** 2 / 2) - 1.0
    anti_rise = (rise / mid) / (-nu * b ** 2 / (4 * Lp ** 2)) - 1.0
    # cantilever under end shear, nu = 0
    bc, P = 1.0, 1e-3
    m = prim.rectangle(Lp, bc, 10 * n, 2 * n, (Lp / 2, bc / 2))
    sh = Shell(m.vertices, m.faces, make_material("linear_elastic", {"E": Ep, "nu": 0.0}), t)
    pr = Problem(sh, [EdgeLoad(lambda p: np.abs(p[:, 0] - Lp) < 1e-9, (0.0, 0.0, P / bc), "tip")],
                 [EdgeSupport("clamped", lambda p: np.abs(p[:, 0]) < 1e-9, None, "root")])
    sol = solve_linear(pr)
    exact = P * Lp ** 3 / (3 * Ep * bc * t ** 3 / 12)
    return {"n_control": sh.mesh.n_real, "anticlastic_mid": anti_mid, "anticlastic_corner_rise": anti_rise,
            "cantilever_mid_tip": w(pr, sol, (Lp, bc / 2, 0.0)) / exact - 1.0,
            "cantilever_corner": w(pr, sol, (Lp, 0.0, 0.0)) / exact - 1.0}


def anticlastic_slaved_ghosts(n: int = 1) -> dict:
    """The anticlastic plate of :func:`plate_patch_tests` with the ghost control points slaved to
    their rest extrapolation (u_ghost = u_a + u_b - u_c, the extension map), i.e. a free edge that the
    ghost layer constrains -- the defect the patch test is there to catch.  Dense KKT solve (small
    mesh).  Returns the relative errors of the mid-tip deflection and of the corner rise."""
    import scipy.sparse as sp

    from graspdef.geometry import primitives as prim
    from graspdef.problem.potentials import EdgeMoment
    from graspdef.problem.problem import Problem
    from graspdef.problem.supports import EdgeSupport, PointSupport
    from graspdef.shell.hyperelastic import make_material
    from graspdef.shell.model import Shell
    from graspdef.solve.linear import rest_stiffness

    Ep, t, Lp, b, nu, M = 1.2e6, 0.1, 10.0, 2.0, 0.3, 1.0
    m = prim.rectangle(Lp, b, 10 * n, 2 * n, (Lp / 2, 0.0))
    sh = Shell(m.vertices, m.faces, make_material("linear_elastic", {"E": Ep, "nu": nu}), t)
    pr = Problem(sh, [EdgeMoment(lambda p: np.abs(p[:, 0] - Lp) < 1e-9, M, (0.0, 1.0, 0.0), "tip")],
                 [EdgeSupport("symmetry", lambda p: np.abs(p[:, 0]) < 1e-9, (1.0, 0.0, 0.0), "x0")])
    for i, (y, d) in enumerate([(0.0, (0.0, 1.0, 0.0)), (b / 2, (0.0, 0.0, 1.0)), (-b / 2, (0.0, 0.0, 1.0))]):
        a = pr.locate((0.0, y, 0.0))
        pr.supports.append(PointSupport(a.face, a.bary, (d,), f"hold{i}"))
    T = sp.kron(sh.mesh.extension_map, sp.identity(3)).toarray()
    K = T.T @ rest_stiffness(pr).toarray() @ T
    Cm = pr.constraints()[0].toarray() @ T
    A = np.block([[K, Cm.T], [Cm, np.zeros((len(Cm), len(Cm)))]])
    x = np.linalg.lstsq(A, np.concatenate([T.T @ pr.load_vector(), np.zeros(len(Cm))]), rcond=None)[0]
    u = (T @ x[: K.shape[0]]).reshape(-1, 3)

    def w(X):
        p = pr.locate(X)
        st, wt = pr.evaluator.values(p.face, np.asarray(p.bary))
        return float((wt @ u[st])[2])

    kx = 12.0 * M / (Ep * t ** 3)
    w0 = w((0.0, 0.0, 0.0))
    mid = w((Lp, 0.0, 0.0)) - w0
    rise = w((Lp, b / 2, 0.0)) - w0 - mid
    return {"anticlastic_mid": abs(mid) / (kx * Lp ** 2 / 2) - 1.0,
            "anticlastic_corner_rise": (rise / mid) / (-nu * b ** 2 / (4 * Lp ** 2)) - 1.0}


def pullout_nonlinear(k: int) -> dict:
    """The displacement-controlled pull-out path on a 3k x 2k mesh compared with Sze's table."""
    from graspdef.bench import run_nonlinear_benchmark

    text = PULLOUT.read_text()
    text = re.sub(r"(?m)^n_theta = \d+", f"n_theta = {3 * k}", text)
    text = re.sub(r"(?m)^n_z = \d+", f"n_z = {2 * k}", text)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / PULLOUT.name
        p.write_text(text)
        recs = run_nonlinear_benchmark(p)
    out = {"k": k, "n_control": recs[0]["n_control"], "seconds": time.perf_counter() - t0, "levels": {},
           "kl_levels": {}}
    for r in recs:
        # the file judges against nligaStruct's Kirchhoff-Love curve ("kl_levels") and reports Sze's
        # S4R table as its context ("levels", the tables below)
        name = r["name"].split(" ", 1)[1]
        key = "levels" if name.startswith("context: ") else "kl_levels"
        expr, level = name.removeprefix("context: ").split(" @ ")
        out[key].setdefault(level, {})[expr] = {"value": r["value"], "reference": r["reference"]}
    return out


def small_load_check(k: int = 4, lams=(0.002, 0.004)) -> dict:
    """The nonlinear path against the linear solution near rest: with A pulled out by lambda d,
    e(lambda) = |u_nl(lambda) / lambda - u_lin| / |u_lin| at each point must be O(lambda)
    (e(2 lambda) / e(lambda) -> 2; a free-edge term that differed between the two would give O(1)).
    A is the prescribed displacement itself (e = round-off there)."""
    from graspdef.solve.linear import solve_linear
    from graspdef.solve.nonlinear import path_options, solve_nonlinear

    spec = pullout_spec(k)
    pr = spec.problem
    lin = _radial(pr, solve_linear(pr).u)
    opts = replace(path_options(spec.solver), max_load=max(lams), targets=tuple(sorted(lams)), steps=4)
    sol = solve_nonlinear(pr, opts)
    out = {}
    for lam in lams:
        nl = _radial(pr, sol.at(lam).u)
        out[f"{lam:g}"] = {n: abs(nl[n] / lam - lin[n]) / abs(lin[n]) for n in POINTS}
    a, b = (out[f"{lam:g}"] for lam in lams)
    # not at A: its e is round-off, which may be exactly zero (it was, in a process where PARDISO
    # ran on another OpenMP runtime: graspdef.runtime, MKL's threading layer)
    out["ratio"] = {n: b[n] / a[n] for n in POINTS if n != "A"}
    return out


def run(fast: bool = False, progress=print) -> dict:
    res: dict = {"plate": [], "open_cylinder_linear": [], "pullout": []}
    for n in PLATE_SIZES:
        r = plate_patch_tests(n)
        res["plate"].append(r)
        progress(f"plate patch tests n_control={r['n_control']}: " + ", ".join(
            f"{k} {v:+.1e}" for k, v in r.items() if k != "n_control"))
    res["plate_slaved_ghosts"] = anticlastic_slaved_ghosts()
    progress("anticlastic plate with ghosts slaved to the extrapolation (a constrained free edge): "
             + ", ".join(f"{k} {v:+.3f}" for k, v in res["plate_slaved_ghosts"].items()))
    for k in LINEAR_SIZES[:-1] if fast else LINEAR_SIZES:
        t0 = time.perf_counter()
        n, vals = open_cylinder_linear(k)
        res["open_cylinder_linear"].append({"k": k, "n_control": n, "seconds": time.perf_counter() - t0, **vals})
        progress(f"open cylinder linear {3 * k}x{2 * k} ({n} vertices): "
                 + ", ".join(f"{p} {v:+.6f}" for p, v in vals.items()))
    rows = res["open_cylinder_linear"]
    res["open_cylinder_linear_richardson"] = {p: richardson([r[p] for r in rows]) for p in POINTS}
    for k in NONLINEAR_SIZES[:-1] if fast else NONLINEAR_SIZES:
        r = pullout_nonlinear(k)
        res["pullout"].append(r)
        at1 = r["levels"]["1"]
        progress(f"pull-out nonlinear {3 * k}x{2 * k} ({r['n_control']} vertices, {r['seconds']:.0f} s): P = P_max: "
                 + ", ".join(f"{e} {v['value']:.4f} ({100 * (v['value'] / v['reference'] - 1):+.2f} %)"
                             for e, v in at1.items()))
    if len(res["pullout"]) >= 3:
        res["pullout_richardson"] = {
            level: {e: richardson([r["levels"][level][e]["value"] for r in res["pullout"]])
                    for e in res["pullout"][0]["levels"][level]}
            for level in ("0.5", "1")}
    res["small_load"] = small_load_check()
    progress("small load: e(2 lam)/e(lam) = " + ", ".join(f"{p} {res['small_load']['ratio'][p]:.3f}" for p in "BCD"))
    return res


def main(fast: bool = False, out: str = "out/free_edge_study") -> dict:
    res = run(fast)
    o = Path(out)
    o.mkdir(parents=True, exist_ok=True)
    (o / "free_edge_study.json").write_text(json.dumps(res, indent=2) + "\n")
    csv_rows = [{"study": "open_cylinder_linear", **r} for r in res["open_cylinder_linear"]]
    csv_rows += [{"study": "pullout", "k": r["k"], "n_control": r["n_control"], "level": lv, "quantity": e,
                  "value": v["value"], "reference": v["reference"]}
                 for r in res["pullout"] for lv, d in r["levels"].items() for e, v in d.items()]
    C.write_csv(o / "free_edge_study.csv", csv_rows)

    print("\n| plate patch test | " + " | ".join(str(r["n_control"]) for r in res["plate"]) + " |")
    print("|---|" + "---|" * len(res["plate"]))
    for key in ("anticlastic_mid", "anticlastic_corner_rise", "cantilever_mid_tip", "cantilever_corner"):
        print(f"| {key} | " + " | ".join(f"{r[key]:+.1e}" for r in res["plate"]) + " |")
    print("\n| open cylinder, linear, P = 100 | " + " | ".join(p for p in POINTS) + " |")
    print("|---|" + "---|" * len(POINTS))
    for r in res["open_cylinder_linear"]:
        print(f"| {3 * r['k']}x{2 * r['k']} ({r['n_control']}) | " + " | ".join(f"{r[p]:+.6f}" for p in POINTS) + " |")
    rich = res["open_cylinder_linear_richardson"]
    print("| Richardson | " + " | ".join(f"{rich[p]['extrapolated']:+.6f}" for p in POINTS) + " |")
    print("| observed order | " + " | ".join(f"{rich[p]['order']:.2f}" for p in POINTS) + " |")
    for level in ("0.5", "1"):
        exprs = list(res["pullout"][0]["levels"][level])
        print(f"\n| pull-out, nonlinear, P/P_max = {level} | " + " | ".join(exprs) + " |")
        print("|---|" + "---|" * len(exprs))
        print("| Sze S4R 24x36 | " + " | ".join(f"{res['pullout'][0]['levels'][level][e]['reference']:.4f}" for e in exprs) + " |")
        for r in res["pullout"]:
            d = r["levels"][level]
            print(f"| {3 * r['k']}x{2 * r['k']} ({r['n_control']}) | " + " | ".join(
                f"{d[e]['value']:.4f} ({100 * (d[e]['value'] / d[e]['reference'] - 1):+.2f} %)" for e in exprs) + " |")
        if "pullout_richardson" in res:
            rr = res["pullout_richardson"][level]
            ref = res["pullout"][0]["levels"][level]
            print("| Richardson | " + " | ".join(
                f"{rr[e]['extrapolated']:.4f} ({100 * (rr[e]['extrapolated'] / ref[e]['reference'] - 1):+.2f} %), "
                f"p = {rr[e]['order']:.2f}" for e in exprs) + " |")

    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    rows = res["open_cylinder_linear"]
    for p in POINTS:
        ref = rich[p]["extrapolated"]
        axes[0].loglog([r["n_control"] for r in rows], [abs(r[p] / ref - 1) for r in rows], "o-" if p not in FREE_EDGE else "s--",
                       label=f"{p}{' (free edge)' if p in FREE_EDGE else ''}")
    axes[0].set_title("open cylinder, linear: error vs Richardson value")
    for level, mk in (("1", "o-"), ("0.5", "s--")):
        exprs = list(res["pullout"][0]["levels"][level])
        for e in exprs:
            axes[1].semilogx([r["n_control"] for r in res["pullout"]],
                             [100 * (r["levels"][level][e]["value"] / r["levels"][level][e]["reference"] - 1)
                              for r in res["pullout"]], mk, label=f"{e} @ {level}")
    axes[1].axhline(0.0, color="k", lw=0.5)
    axes[1].set_ylabel("difference from Sze's S4R [%]")
    axes[1].set_xlabel("control vertices")
    axes[1].set_title("pull-out, nonlinear (C: free edge)")
    axes[0].set_xlabel("control vertices")
    axes[0].set_ylabel("|relative error|")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(o / "free_edge_study.png", dpi=120)
    return res


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/free_edge_study")
    ap.add_argument("--fast", action="store_true", help="fewer meshes")
    a = ap.parse_args()
    main(a.fast, a.out)
