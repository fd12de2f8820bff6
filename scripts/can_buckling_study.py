"""Does the ideal soda can buckle (snap) under the pins, and is it imperfection sensitive?

The paper (Tian & Jia 2010, Table I, last row) measured 1.42 mm maximum displacement for an empty
soda can squeezed by two pins at 0.76 N per finger; graspdef's ideal closed can
(``scenes/soda_can/ideal_can_pinched.toml``: mid-surface radius 33.85 mm, 101.8 mm between rigid
lids, 0.1 mm AA3004 wall, E 69 GPa, nu 0.33, pinched at mid-height) gives 0.101 mm linear, 0.121 mm
nonlinear (SVK).  This study follows the nonlinear (SVK) load path by arc length (graspdef's
Crisfield continuation, ``PathOptions(method="arc_length")``) past its first limit point, for the
perfect can and for cans with a geometric imperfection: an inward dimple at each load point,

    w0(s, zeta) = -A exp(-(s^2 + zeta^2) / l^2),   l = 2 sqrt(R t) = 3.68 mm,

s = R theta the arc length from the load point around the can, zeta = z - L/2 (radial inward
offset of the control vertices; the dimple's depth on the limit surface is measured and printed).
A = 0 (perfect), 0.5 t, 1 t and 3 t by default.

Model: the 1/8 can (theta in [0, 90 deg], z from the lid to mid-height), symmetry planes y = 0,
x = 0 and z = L/2, the lid a rigid diaphragm (as in the problem file); the point load F/4 at the
corner (R, 0, L/2) (the load point lies on two symmetry planes); the load factor is the force per
finger F [N].  A uniform n x n mesh of the 1/8 model (default 96 x 96: 9,409 vertices, 9,799
control points with the ghost layer, cells 0.55 x 0.53 mm, about 3.3 cells per sqrt(R t) = 1.84 mm,
the width of a point load's dimple;
``--fast``: 32 x 32, 1.7 x 1.6 mm cells, the full 8.3k model's resolution, about one cell per
sqrt(R t): too coarse to resolve the dimple's shape, yet within 3 % of 96 x 96 for the perfect can
(measured: 0.120 / 0.122 / 0.123 mm at 0.76 N, 1.42 mm at 3.651 / 3.657 / 3.656 N on 32 / 64 / 96)).
The symmetric model sees only symmetric modes: a bifurcation into a mode that breaks one of the three
symmetries is not detected here (``--full-check`` follows the whole can, every mode counted).

For each case: the path (force per finger, the load point's inward displacement -- what is compared
with the paper's maximum displacement; the point B at 90 degrees moves < 0.06 mm to 6 N --, the
number of negative eigenvalues of the tangent on the constraint null space), the limit points, the
displacement at 0.76 N (first crossing) and the force at which the displacement first reaches
1.42 mm (interpolated between path points), or that it does not within the path followed.

Writes ``can_buckling.json``, ``can_buckling.csv`` (every path point) and ``can_buckling.png`` to
``--out`` (default out/can_buckling) and prints a Markdown table.

    PYTHONPATH=. python scripts/can_buckling_study.py [--fast] [--n 96] [--amplitudes 0,0.5,1,3]
        [--dimple-l-mm 3.68] [--max-force 6] [--max-disp-mm 3] [--steps 24] [--full-check]

Measured 2026-11-26 (two shared cores): default run 18 min (4 cases of 9.8k control vertices,
3-6 min each), --full-check adds 4 min (8.6k), --fast 2.3 min.  Results in docs/grasp.md ("Soda can").
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
#: the ideal can (scenes/soda_can/ideal_can_pinched.toml), SI
R, L, T, E, NU = 33.85e-3, 101.8e-3, 0.1e-3, 69e9, 0.33
F_PAPER, D_PAPER = 0.76, 1.42e-3          # Tian & Jia 2010, Table I: N per finger, m
DIMPLE_L = 2.0 * math.sqrt(R * T)          # [m] e-folding radius of the imperfection


def build(n: int, amplitude: float, width: float = DIMPLE_L):
    """The 1/8 can on an n x n mesh with an inward dimple of depth ``amplitude`` [m] at the load
    point (e-folding radius ``width`` [m]); the point load is F/4 = 0.25 N (load factor 1 = 1 N per finger)."""
    from graspdef.geometry import primitives as prim
    from graspdef.problem.loads import PointLoad
    from graspdef.problem.problem import Problem, locate
    from graspdef.problem.supports import EdgeSupport
    from graspdef.shell.hyperelastic import make_material
    from graspdef.shell.model import Shell

    m = prim.cylinder(R, L / 2, n, n, 0.0, math.pi / 2)
    v = m.vertices.copy()
    theta = np.arctan2(v[:, 1], v[:, 0])
    s, zeta = R * theta, v[:, 2] - L / 2
    w0 = -amplitude * np.exp(-(s ** 2 + zeta ** 2) / width ** 2)       # radial, outward positive
    v[:, 0] += w0 * np.cos(theta)
    v[:, 1] += w0 * np.sin(theta)
    shell = Shell(v, m.faces, make_material("linear_elastic", {"E": E, "nu": NU}), T)
    tol = 1e-9
    supports = [
        EdgeSupport("diaphragm", lambda p: np.abs(p[:, 2]) < tol, (0.0, 0.0, 1.0), "lid"),
        EdgeSupport("symmetry", lambda p: np.abs(p[:, 2] - L / 2) < tol, (0.0, 0.0, 1.0), "mid"),
        EdgeSupport("symmetry", lambda p: np.abs(p[:, 1]) < tol, (0.0, 1.0, 0.0), "xz"),
        EdgeSupport("symmetry", lambda p: np.abs(p[:, 0]) < tol, (1.0, 0.0, 0.0), "yz"),
    ]
    ev = shell.evaluator
    a = locate(shell, ev, np.array([R - amplitude, 0.0, L / 2]), "A", tol=0.2 * R)[0]
    b = locate(shell, ev, np.array([0.0, R, L / 2]), "B", tol=0.2 * R)[0]
    # one collocation point per supported edge (the recorded results).  With two, the 96 x 96
    # model's KKT matrix once counted one negative pivot too many: PARDISO's improved matching
    # on the re-based support rows, not the model (graspdef.solve.sparse._PARDISO_ROBUST; it now
    # solves, tests/solve/test_kkt_robust.py)
    pr = Problem(shell, [PointLoad(a.face, a.bary, (-0.25, 0.0, 0.0))], supports, {"A": a, "B": b},
                 n_collocation=1)
    # the dimple's depth on the limit surface: the load point's radius against the unperturbed B's
    xa = _point(pr, "A", np.zeros((shell.n_control, 3)))
    xb = _point(pr, "B", np.zeros((shell.n_control, 3)))
    depth = float(np.hypot(xb[0], xb[1]) - np.hypot(xa[0], xa[1]))
    return pr, depth


def _point(pr, name, u):
    sp = pr.probes[name]
    st, w = pr.evaluator.values(sp.face, np.asarray(sp.bary))
    return w @ (pr.shell.rest_positions[st] + u[st])


def run_case(n: int, amplitude: float, max_force: float, max_disp: float, steps: int = 24, width: float = DIMPLE_L,
             progress=print) -> dict:
    from graspdef.solve.linear import solve_linear
    from graspdef.solve.nonlinear import PathOptions, solve_nonlinear

    t0 = time.perf_counter()
    pr, depth = build(n, amplitude, width)
    lin_sol = solve_linear(pr)
    sp = pr.probes["A"]
    st, w = pr.evaluator.values(sp.face, np.asarray(sp.bary))
    lin = float(-(w @ lin_sol.u.reshape(-1, 3)[st])[0])          # inward per N per finger
    opts = PathOptions(method="arc_length", max_load=max_force, steps=steps, targets=(F_PAPER,),
                       max_probe_displacement=max_disp, max_steps=400)

    def prog(info):
        progress(f"  A={amplitude * 1e3:.3f} mm  step {info['step']:3d}  F = {info['load_factor']:.5f} N  "
                 f"its {info['iterations']:2d}  stable {info['stable']}  {info['seconds']:.0f} s", flush=True)

    sol = solve_nonlinear(pr, opts, progress=prog, allow_partial=True)
    pts = []
    for p in sol.path:
        ua = np.asarray(p.probes["A"])
        ub = np.asarray(p.probes["B"])
        pts.append({"force_N": p.load_factor, "disp_A_m": float(-ua[0]), "abs_disp_A_m": float(np.linalg.norm(ua)),
                    "disp_B_m": float(ub[1]),
                    "negative_eigenvalues": p.instability, "kind": p.kind})
    f = np.array([q["force_N"] for q in pts])
    d = np.array([q["disp_A_m"] for q in pts])
    out = {"amplitude_m": amplitude, "amplitude_over_t": amplitude / T, "dimple_width_m": width, "dimple_depth_limit_surface_m": depth,
           "n": n, "n_control": int(pr.shell.n_control), "linear_m_per_N": lin,
           "completed": bool(sol.completed), "stop_reason": sol.stop_reason,
           "seconds": time.perf_counter() - t0, "n_factorisations": int(sol.n_factorisations),
           "critical_points": [{k: v for k, v in cp.items() if k != "probes"} | {"disp_A_m": float(-cp["probes"]["A"][0])}
                               for cp in sol.critical_points],
           "path": pts}
    out["disp_at_paper_force_m"] = _first_crossing(f, d, F_PAPER)
    out["force_at_paper_disp_N"] = _first_crossing(d, f, D_PAPER)
    lp = [cp for cp in out["critical_points"] if cp["kind"] == "limit point"]
    out["first_limit_point"] = lp[0] if lp else None
    out["max_force_followed_N"] = float(f.max())
    out["max_disp_followed_m"] = float(d.max())
    return out


def _first_crossing(x, y, x0):
    """y where x first reaches x0 along the path (linear between points), None if it never does."""
    for i in range(1, len(x)):
        if (x[i - 1] - x0) * (x[i] - x0) <= 0 and x[i] != x[i - 1]:
            return float(y[i - 1] + (x0 - x[i - 1]) / (x[i] - x[i - 1]) * (y[i] - y[i - 1]))
    return None


def table(results) -> str:
    rows = ["| imperfection A (dimple depth on the surface) | linear at 0.76 N | nonlinear at 0.76 N | first change of stability: kind, F, displacement, negative eigenvalues before → after | force at 1.42 mm | followed to | control vertices, time |",
            "|---|---|---|---|---|---|---|"]
    for r in results:
        cps = r["critical_points"]
        lp = cps[0] if cps else None
        lps = (f"{lp['kind']}, {lp['load_factor']:.3f} N, {lp['disp_A_m'] * 1e3:.3f} mm, "
               f"{lp['instability_before']} → {lp['instability_after']}" if lp else "none (stable throughout)")
        fd = r["force_at_paper_disp_N"]
        d76 = r["disp_at_paper_force_m"]
        lin = "—" if r["linear_m_per_N"] is None else f"{r['linear_m_per_N'] * F_PAPER * 1e3:.3f} mm"
        rows.append(f"| {r['amplitude_over_t']:g} t = {r['amplitude_m'] * 1e3:.2f} mm ({r['dimple_depth_limit_surface_m'] * 1e3:.3f} mm) "
                    f"| {lin} "
                    f"| {'—' if d76 is None else f'{d76 * 1e3:.3f} mm'} | {lps} "
                    f"| {'not reached' if fd is None else f'{fd:.3f} N'} "
                    f"| {r['max_force_followed_N']:.3f} N max, {r['max_disp_followed_m'] * 1e3:.2f} mm"
                    f"{'' if r['completed'] else ' (stopped: ' + str(r['stop_reason'])[:60] + ')'} "
                    f"| {r['n_control']}, {r['seconds']:.0f} s |")
    return "\n".join(rows)


def full_check(n_theta: int, max_force: float, max_disp: float, steps: int = 24, progress=print) -> dict:
    """The perfect can as the whole cylinder (no symmetry planes), from the problem file
    scenes/soda_can/ideal_can_pinched.toml at n_theta x n_theta/2 cells, by arc length (load factor 1
    = 0.76 N per finger in that file); its negative eigenvalues include the modes that break the
    1/8 model's symmetries."""
    import tempfile

    from graspdef.problem.config import load_problem
    from graspdef.solve.nonlinear import PathOptions, solve_nonlinear

    text = (ROOT / "scenes" / "soda_can" / "ideal_can_pinched.toml").read_text()
    text = text.replace("n_theta = 256", f"n_theta = {n_theta}").replace("n_z = 128", f"n_z = {n_theta // 2}")
    # one collocation point per edge: the closed diaphragm rings' rows are nearly dependent with two
    text += '\n[solver]\ntype = "nonlinear"\nmethod = "arc_length"\ncollocation = 1\n'
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "ideal_can_pinched.toml"
        p.write_text(text)
        spec = load_problem(p)
    pr = spec.problem
    scale = F_PAPER                                     # the file's load factor 1 = 0.76 N per finger
    opts = PathOptions(method="arc_length", max_load=max_force / scale, steps=steps, targets=(1.0,),
                       max_probe_displacement=max_disp, max_steps=400)

    def prog(info):
        progress(f"  full model  step {info['step']:3d}  F = {info['load_factor'] * scale:.5f} N  "
                 f"its {info['iterations']:2d}  stable {info['stable']}  {info['seconds']:.0f} s", flush=True)

    sol = solve_nonlinear(pr, opts, progress=prog, allow_partial=True)
    pts = [{"force_N": p.load_factor * scale, "disp_A_m": float(-np.asarray(p.probes["A"])[0]),
            "disp_B_m": float("nan"), "negative_eigenvalues": p.instability, "kind": p.kind} for p in sol.path]
    f = np.array([q["force_N"] for q in pts])
    d = np.array([q["disp_A_m"] for q in pts])
    cps = [{k: v for k, v in cp.items() if k != "probes"} | {"disp_A_m": float(-cp["probes"]["A"][0]),
                                                             "load_factor": cp["load_factor"] * scale}
           for cp in sol.critical_points]
    lp = [cp for cp in cps if cp["kind"] == "limit point"]
    lin = None
    return {"amplitude_m": 0.0, "amplitude_over_t": 0.0, "dimple_depth_limit_surface_m": 0.0, "n": n_theta,
            "n_control": int(pr.shell.n_control), "linear_m_per_N": lin, "completed": bool(sol.completed),
            "stop_reason": sol.stop_reason, "seconds": time.perf_counter() - t0,
            "n_factorisations": int(sol.n_factorisations), "critical_points": cps, "path": pts,
            "disp_at_paper_force_m": _first_crossing(f, d, F_PAPER), "force_at_paper_disp_N": _first_crossing(d, f, D_PAPER),
            "first_limit_point": lp[0] if lp else None, "max_force_followed_N": float(f.max()),
            "max_disp_followed_m": float(d.max()), "model": f"full can, {n_theta} x {n_theta // 2} cells"}


def figure(results, path: Path, full=None) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for r in results:
        d = np.array([p["disp_A_m"] for p in r["path"]]) * 1e3
        f = np.array([p["force_N"] for p in r["path"]])
        unstable = np.array([(p["negative_eigenvalues"] or 0) > 0 for p in r["path"]])
        line, = ax.plot(d, f, "-", label=f"A = {r['amplitude_over_t']:g} t")
        ax.plot(d[unstable], f[unstable], "x", color=line.get_color(), ms=4)
    if full is not None:
        ax.plot([p["disp_A_m"] * 1e3 for p in full["path"]], [p["force_N"] for p in full["path"]], "k.",
                ms=4, label=f"A = 0, full can ({full['model'].split(', ')[1]})")
    ax.plot([D_PAPER * 1e3], [F_PAPER], "k*", ms=12, label="paper: 1.42 mm at 0.76 N")
    ax.axhline(F_PAPER, color="0.6", lw=0.8)
    ax.axvline(D_PAPER * 1e3, color="0.6", lw=0.8)
    ax.set_xlabel("load-point displacement (inward, per finger) [mm]")
    ax.set_ylabel("force per finger [N]")
    ax.set_title("ideal can, SVK, arc length; x: unstable"
                 + (f" (1/8 model, {results[0]['n']}² cells)" if results else ""))
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fast", action="store_true", help="32 x 32 cells (too coarse for the dimple)")
    ap.add_argument("--n", type=int, default=None, help="cells per side of the 1/8 model (default 96)")
    ap.add_argument("--amplitudes", default="0,0.5,1,3", help="dimple depths in wall thicknesses")
    ap.add_argument("--max-force", type=float, default=6.0, help="[N per finger] end of the path")
    ap.add_argument("--max-disp-mm", type=float, default=3.0, help="[mm] the path also ends here")
    ap.add_argument("--dimple-l-mm", type=float, default=DIMPLE_L * 1e3,
                    help=f"[mm] e-folding radius of the dimple (default 2 sqrt(R t) = {DIMPLE_L * 1e3:.2f} mm)")
    ap.add_argument("--steps", type=int, default=24,
                    help="initial arc length = the tangent's length over max_force / steps (it adapts, up to 8x)")
    ap.add_argument("--full-check", action="store_true",
                    help="also the full perfect can (scenes/soda_can/ideal_can_pinched.toml at 128 x 64, or 64 x 32 "
                         "with --fast; no symmetry planes: every mode's stability) by arc length")
    ap.add_argument("--out", default=str(ROOT / "out" / "can_buckling"))
    a = ap.parse_args()

    from graspdef import runtime

    runtime.configure()
    n = a.n or (32 if a.fast else 96)
    results = []
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    for amp in [float(x) * T for x in a.amplitudes.split(",") if x.strip()]:   # "": the full check only
        r = run_case(n, amp, a.max_force, a.max_disp_mm * 1e-3, a.steps, a.dimple_l_mm * 1e-3)
        results.append(r)
        print(table([r]).splitlines()[-1], flush=True)
        (out / "can_buckling.json").write_text(json.dumps(
            {"units": {"force": "N per finger", "displacement": "m", "amplitude": "m"},
             "model": f"1/8 ideal can, {n} x {n} cells, SVK, arc length; dimple l = {a.dimple_l_mm * 1e-3:.4g} m",
             "paper": {"force_N": F_PAPER, "max_displacement_m": D_PAPER}, "results": results}, indent=1) + "\n")
    with open(out / "can_buckling.csv", "w", newline="") as fh:
        wr = csv.writer(fh)
        wr.writerow(["amplitude_m", "force_N_per_finger", "disp_load_point_m", "disp_B_m", "negative_eigenvalues", "kind"])
        for r in results:
            for p in r["path"]:
                wr.writerow([r["amplitude_m"], p["force_N"], p["disp_A_m"], p["disp_B_m"], p["negative_eigenvalues"], p["kind"]])
    full = None
    if a.full_check:
        full = full_check(64 if a.fast else 128, a.max_force, a.max_disp_mm * 1e-3, a.steps)
        (out / "can_buckling_full.json").write_text(json.dumps(full, indent=1) + "\n")
    figure(results, out / "can_buckling.png", full)
    print()
    print(table(results))
    if full is not None:
        print(table([full]).splitlines()[-1].replace("| 0 t", f"| {full['model']}: 0 t"))
    print(f"\nwrote {out / 'can_buckling.json'}, .csv, .png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
