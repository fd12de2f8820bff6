"""The paper's soda can as *half* a can, pinched by the pins at its open end.

Tian & Jia 2010 model "half of a soda can" (section IX: "We also use both linear and nonlinear
elasticity theories to model the deformation of half of a soda can"), and their Fig. 12, "The Soda
Can Setup", labels an **Open End** beside the pins.  Table I's last row: 0.76 N per finger ->
1.42 mm measured maximum displacement.  graspdef's closed can (rigid lids, pinched at mid-height)
needs 3.66 N for 1.42 mm, and the half can pinched at mid-height or 3 mm below its cut edge 6-18x
too little displacement (docs/grasp.md, "Soda can"; scripts/can_buckling_study.py).  This study
puts the pins *on* the open edge, where the wall has no ring to stiffen it, and follows the
finite-deformation (SVK) path.

Model: a cylinder of mid-surface radius R = 32.95 mm (a 66 mm can) and height L = 61 mm (half of a
122 mm can), wall t (default 0.1 mm; the source's range 90-110 um: scenes/soda_can/object.toml),
AA3004 E = 69 GPa, nu = 0.33; the end that keeps the can's bottom (or lid) clamped, the cut end
free; the two pins as opposite point loads on the free edge (or ``--below`` mm under it), along the
diameter.  The quarter model (symmetry planes y = 0 and x = 0; the load point lies on y = 0, so it
carries F/2), n_theta x n_z cells of the quarter (default 64 x 96: 0.81 x 0.64 mm, 2.3 x 2.9 cells per
sqrt(R t) = 1.8 mm); load factor = force per finger [N]; SVK by arc length (graspdef's Crisfield
continuation), each point's stability from the tangent's negative eigenvalues on the constraint null
space.  The load point's inward displacement is compared with the paper's maximum displacement (it
is the largest displacement on the can).

Cases (each a row of the table): the mesh (``--meshes``), the wall thickness (``--thicknesses``),
the pin's distance below the edge (``--below``), the height (``--heights``) and the bottom's support
(``--bottoms``: clamped | simply_supported).  Writes ``can_half.json`` and ``can_half.png`` to
``--out`` (default out/can_half) and prints a Markdown table: linear and nonlinear displacement at
0.76 N, the force at which the load point reaches 1.42 mm, the first change of stability.

    PYTHONPATH=. python scripts/can_half_study.py [--fast] [--max-force 2.5] [--max-disp-mm 3] [--fit]

``--fit``: instead, the wall thickness at which the pins on the open edge give 1.42 mm at 0.76 N (secant
iterations on the base mesh; writes ``can_half_fit.json``) -- a fit to the one measurement, not a prediction.

Nothing here is fitted: every parameter is the source's or the paper's, and the cases show how far
the unknowns of the set-up (where the pins sit, the wall's thickness, the height of the half, the
bottom) move the result.
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
#: half of a 66 x 122 mm can (SI): mid-surface radius, height, wall; AA3004 (scenes/soda_can/object.toml)
R, L, T, E, NU = 32.95e-3, 61e-3, 0.1e-3, 69e9, 0.33
F_PAPER, D_PAPER = 0.76, 1.42e-3          # Tian & Jia 2010, Table I, last row: N per finger, m


def build(n_theta: int, n_z: int, t: float = T, below: float = 0.0, height: float = L, bottom: str = "clamped"):
    """The quarter half-can (theta in [0, 90 deg], z in [0, height]) with its bottom (z = 0)
    ``bottom`` supported, symmetry planes y = 0 and x = 0, and the point load F/2 (load factor 1 =
    1 N per finger) at (R, 0, height - below) along -x; probe "A" there."""
    from graspdef.geometry import primitives as prim
    from graspdef.problem.loads import PointLoad
    from graspdef.problem.problem import Problem, locate
    from graspdef.problem.supports import EdgeSupport
    from graspdef.shell.hyperelastic import make_material
    from graspdef.shell.model import Shell

    m = prim.cylinder(R, height, n_theta, n_z, 0.0, math.pi / 2)
    shell = Shell(m.vertices, m.faces, make_material("linear_elastic", {"E": E, "nu": NU}), t)
    tol = 1e-9
    supports = [
        EdgeSupport(bottom, lambda p: np.abs(p[:, 2]) < tol, None, "bottom"),
        EdgeSupport("symmetry", lambda p: np.abs(p[:, 1]) < tol, (0.0, 1.0, 0.0), "xz"),
        EdgeSupport("symmetry", lambda p: np.abs(p[:, 0]) < tol, (1.0, 0.0, 0.0), "yz"),
    ]
    a = locate(shell, shell.evaluator, np.array([R, 0.0, height - below]), "A", tol=0.2 * R)[0]
    return Problem(shell, [PointLoad(a.face, a.bary, (-0.5, 0.0, 0.0))], supports, {"A": a})


def _first_crossing(x, y, x0):
    """y where x first reaches x0 along the path (linear between points), None if it never does."""
    for i in range(1, len(x)):
        if (x[i - 1] - x0) * (x[i] - x0) <= 0 and x[i] != x[i - 1]:
            return float(y[i - 1] + (x0 - x[i - 1]) / (x[i] - x[i - 1]) * (y[i] - y[i - 1]))
    return None


def run_case(n_theta: int, n_z: int, t: float = T, below: float = 0.0, height: float = L, bottom: str = "clamped",
             max_force: float = 2.5, max_disp: float = 3e-3, steps: int = 24, progress=print) -> dict:
    """One case: the linear displacement, the SVK path by arc length and its readings (SI)."""
    from graspdef.solve.linear import solve_linear
    from graspdef.solve.nonlinear import PathOptions, solve_nonlinear

    t0 = time.perf_counter()
    pr = build(n_theta, n_z, t, below, height, bottom)
    lin = float(-solve_linear(pr).probe("A")[0])                            # inward, per N per finger
    opts = PathOptions(method="arc_length", max_load=max_force, steps=steps, targets=(F_PAPER,),
                       max_probe_displacement=max_disp, max_steps=400)
    label = f"t {t * 1e6:.0f} um, {below * 1e3:g} mm below, L {height * 1e3:g} mm, {bottom}, {n_theta}x{n_z}"

    def prog(info):
        progress(f"  {label}  step {info['step']:3d}  F = {info['load_factor']:.5f} N  its {info['iterations']:2d}  "
                 f"stable {info['stable']}  {info['seconds']:.0f} s", flush=True)

    sol = solve_nonlinear(pr, opts, progress=prog, allow_partial=True)
    path = [{"force_N": p.load_factor, "disp_A_m": float(-np.asarray(p.probes["A"])[0]),
             "negative_eigenvalues": p.instability, "kind": p.kind} for p in sol.path]
    f = np.array([q["force_N"] for q in path])
    d = np.array([q["disp_A_m"] for q in path])
    cps = [{k: v for k, v in cp.items() if k != "probes"} | {"disp_A_m": float(-cp["probes"]["A"][0])}
           for cp in sol.critical_points]
    return {"label": label, "thickness_m": t, "below_edge_m": below, "height_m": height, "bottom": bottom,
            "n_theta": n_theta, "n_z": n_z, "n_control": int(pr.shell.n_control),
            "linear_m_per_N": lin, "completed": bool(sol.completed), "stop_reason": sol.stop_reason,
            "seconds": time.perf_counter() - t0, "n_factorisations": int(sol.n_factorisations),
            "critical_points": cps, "path": path,
            "disp_at_paper_force_m": _first_crossing(f, d, F_PAPER), "force_at_paper_disp_N": _first_crossing(d, f, D_PAPER),
            "max_force_followed_N": float(f.max()), "max_disp_followed_m": float(d.max())}


def table(results) -> str:
    rows = ["| case: wall, pin below the edge, height, bottom, quarter mesh | linear at 0.76 N | nonlinear at 0.76 N "
            "| force at 1.42 mm | first change of stability | control vertices, time |",
            "|---|---|---|---|---|---|"]
    for r in results:
        cp = r["critical_points"][0] if r["critical_points"] else None
        cps = (f"{cp['kind']}, {cp['load_factor']:.3f} N, {cp['disp_A_m'] * 1e3:.3f} mm" if cp
               else f"none to {r['max_force_followed_N']:.2f} N / {r['max_disp_followed_m'] * 1e3:.2f} mm")
        d76, fd = r["disp_at_paper_force_m"], r["force_at_paper_disp_N"]
        rows.append(f"| {r['label']} | {r['linear_m_per_N'] * F_PAPER * 1e3:.3f} mm "
                    f"| {'—' if d76 is None else f'{d76 * 1e3:.3f} mm'} "
                    f"| {'not reached' if fd is None else f'{fd:.3f} N'} | {cps}"
                    f"{'' if r['completed'] else ' (stopped: ' + str(r['stop_reason'])[:60] + ')'} "
                    f"| {r['n_control']}, {r['seconds']:.0f} s |")
    return "\n".join(rows)


def figure(results, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for r in results:
        d = np.array([p["disp_A_m"] for p in r["path"]]) * 1e3
        f = np.array([p["force_N"] for p in r["path"]])
        ax.plot(d, f, "-", lw=1.2, label=r["label"])
    ax.plot([D_PAPER * 1e3], [F_PAPER], "k*", ms=12, label="paper: 1.42 mm at 0.76 N")
    ax.axhline(F_PAPER, color="0.6", lw=0.8)
    ax.axvline(D_PAPER * 1e3, color="0.6", lw=0.8)
    ax.set_xlabel("load-point displacement (inward, per finger) [mm]")
    ax.set_ylabel("force per finger [N]")
    ax.set_title("half can pinched at its open end, SVK, arc length")
    ax.legend(fontsize=6.5)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def cases(a) -> list[dict]:
    """The study's cases: the base case on every mesh, then each unknown varied alone on the base mesh."""
    meshes = [tuple(int(v) for v in m.split("x")) for m in a.meshes.split(",")]
    base = meshes[-1] if a.fast else meshes[min(1, len(meshes) - 1)]
    out = [dict(n_theta=m[0], n_z=m[1]) for m in meshes]
    out += [dict(n_theta=base[0], n_z=base[1], t=float(x) * 1e-6) for x in a.thicknesses.split(",")
            if not math.isclose(float(x) * 1e-6, T)]
    out += [dict(n_theta=base[0], n_z=base[1], below=float(x) * 1e-3) for x in a.below.split(",") if float(x) != 0]
    out += [dict(n_theta=base[0], n_z=base[1], height=float(x) * 1e-3) for x in a.heights.split(",")
            if not math.isclose(float(x) * 1e-3, L)]
    out += [dict(n_theta=base[0], n_z=base[1], bottom=b) for b in a.bottoms.split(",") if b != "clamped"]
    return out


def fit_thickness(n_theta: int, n_z: int, t0: float = 90e-6, t1: float = 100e-6, rtol: float = 2e-3,
                  progress=print) -> dict:
    """The wall thickness [m] at which the base case (pins on the open edge) reaches the paper's 1.42 mm at
    0.76 N: secant iterations on log d(0.76 N) against log t (d falls steeply and smoothly with t), each
    evaluation an SVK path to 0.8 N; stops when |d / 1.42 mm - 1| <= rtol.  A fit to the one measurement
    there is, so it predicts nothing: it says how far the source's 90-110 um wall must be stretched."""
    def d_at(t):
        r = run_case(n_theta, n_z, t, max_force=0.8, max_disp=5e-3, steps=8, progress=lambda *a, **k: None)
        progress(f"  fit: t = {t * 1e6:.3f} um -> {r['disp_at_paper_force_m'] * 1e3:.4f} mm at 0.76 N", flush=True)
        return r["disp_at_paper_force_m"]

    xs, ys = [math.log(t0), math.log(t1)], [math.log(d_at(t0)), math.log(d_at(t1))]
    for _ in range(8):
        if abs(math.exp(ys[-1]) / D_PAPER - 1) <= rtol:
            break
        x = xs[-1] + (math.log(D_PAPER) - ys[-1]) * (xs[-1] - xs[-2]) / (ys[-1] - ys[-2])
        xs.append(x)
        ys.append(math.log(d_at(math.exp(x))))
    return {"thickness_m": math.exp(xs[-1]), "disp_at_paper_force_m": math.exp(ys[-1]), "evaluations": len(xs),
            "mesh": f"{n_theta}x{n_z}", "history": [{"thickness_m": math.exp(a), "disp_m": math.exp(b)} for a, b in zip(xs, ys)]}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fast", action="store_true", help="the coarsest mesh only (32 x 48), for a quick look")
    ap.add_argument("--meshes", default="32x48,64x96,96x144", help="quarter meshes n_theta x n_z (convergence)")
    ap.add_argument("--thicknesses", default="90,100,110", help="walls [um] (the source's 90-110 um)")
    ap.add_argument("--below", default="0,2,5", help="the pins' distance below the open edge [mm]")
    ap.add_argument("--heights", default="61,50,80", help="height of the half can [mm]")
    ap.add_argument("--bottoms", default="clamped,simply_supported", help="support of the closed end")
    ap.add_argument("--max-force", type=float, default=2.5, help="[N per finger] end of the path")
    ap.add_argument("--max-disp-mm", type=float, default=3.0, help="[mm] the path also ends here")
    ap.add_argument("--steps", type=int, default=24,
                    help="initial arc length = the tangent's length over max_force / steps (it adapts)")
    ap.add_argument("--fit", action="store_true",
                    help="only the wall thickness at which the pins on the open edge give 1.42 mm at 0.76 N (a fit)")
    ap.add_argument("--out", default=str(ROOT / "out" / "can_half"))
    a = ap.parse_args()
    if a.fast:
        a.meshes = a.meshes.split(",")[0]

    from graspdef import runtime

    runtime.configure()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    if a.fit:
        mesh = [int(v) for v in (a.meshes.split(",")[0] if a.fast else a.meshes.split(",")[min(1, a.meshes.count(","))]).split("x")]
        fit = fit_thickness(*mesh)
        (out / "can_half_fit.json").write_text(json.dumps({"units": "m", **fit}, indent=1) + "\n")
        print(f"wall thickness for 1.42 mm at 0.76 N (pins on the open edge, {fit['mesh']}): "
              f"{fit['thickness_m'] * 1e6:.2f} um ({fit['evaluations']} evaluations); wrote {out / 'can_half_fit.json'}")
        return 0
    results = []
    for c in cases(a):
        r = run_case(**c, max_force=a.max_force, max_disp=a.max_disp_mm * 1e-3, steps=a.steps)
        results.append(r)
        print(table([r]).splitlines()[-1], flush=True)
        (out / "can_half.json").write_text(json.dumps(
            {"units": {"force": "N per finger", "displacement": "m", "lengths": "m"},
             "model": "quarter half can (symmetry planes y = 0, x = 0), SVK, arc length; point loads on (or below) "
                      f"the open edge; R = {R} m, E = {E} Pa, nu = {NU}",
             "paper": {"force_N": F_PAPER, "max_displacement_m": D_PAPER}, "results": results}, indent=1) + "\n")
    figure(results, out / "can_half.png")
    print()
    print(table(results))
    print(f"\nwrote {out / 'can_half.json'}, {out / 'can_half.png'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
