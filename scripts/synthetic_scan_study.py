"""Synthetic-scan study (issue 6 acceptance): do nonlinear predictions score better than linear
ones against scans of a trusted reference deformation, and does the linear error grow with the
force as in Tian & Jia 2010, Table I?

    python scripts/synthetic_scan_study.py [--fast] [--out out/synthetic_scan_study]
                                           [--subdivisions 3 4] [--points 30000] [--seed 0]

The reference (trusted, independent of the 3-D solver)
------------------------------------------------------
A closed sphere squeezed at its poles, solved by the **axisymmetric solver**
(:mod:`graspdef.axisym`, the thesis method: exact axisymmetric kinematics, shooting, converged to
6 digits; cross-checked against the 3-D solver in docs/crosscheck.md):
``pinched_sphere(R, t, MooneyRivlin, F, contact_radius=0.2 R)`` -- each of the two opposite forces
spread uniformly over a ring of undeformed radius 0.2 R around its pole (a vertical dead load, the
sphere held by symmetry), incompressible Mooney-Rivlin with C2/C1 = 0.1, R/t = 10, no enclosed gas.
Physical size: R = 32.5 mm (a tennis ball's radius), t = 3.25 mm, and C1 chosen so that the paper's
largest force, 21.48 N, is F/(C1 t^2) = 1.8 (below the axisymmetric limit load 2.046):
C1 = 1.130 MPa (E = 6 (C1 + C2) = 7.46 MPa, near the 8.17 MPa that makes a linear tennis-ball shell
match the paper's first row).  Both solvers are scale-free, so the problem is solved with R = 1,
C1 = 1 and the lengths scaled to metres afterwards.  Forces: the paper's four, 10.63, 16.50,
20.37, 21.48 N.

The deformed meridian (100 points, pole to equator, mirrored for the lower half) is revolved into
a fine surface (an icosphere of 6 subdivisions, 40,962 vertices, each vertex placed at the same
fraction of the deformed meridian's arc length as its polar angle is of a quarter turn): the
*shape* of the reference deformation.  It is scanned with the scanner model
(:func:`graspdef.scans.scan_surface`: 6 turntable views, hidden-point removal, 4 holes of 3 mm,
Gaussian noise sigma = 0.127 mm, a uniformly random pose).  The scanned surface is the
mid-surface (both the reference and the predictions are mid-surfaces; no offset).

Predictions (3-D Loop-subdivision Kirchhoff-Love shell, coarser meshes)
----------------------------------------------------------------------
The same sphere as an icosphere control mesh (subdivisions 3, 4: 642, 2,562 control vertices; 2:
162, in --fast), 64 point loads of F/64 on each ring (as in scripts/crosscheck_axisym_3d.py), held
by RigidModes, same Mooney-Rivlin material (3 Gauss points through the thickness):

* **nonlinear**: one load-controlled path landing on the four forces;
* **linear**: the Hessian at rest of the same energy (``solve_linear``), scaled to each force;
* **undeformed**: the rest sphere (every score's baseline).

Each prediction's limit surface is scored against the scan of each force with
:func:`graspdef.registration.score` (open3d point-to-plane ICP, PCA initialisation; the scan is
registered separately to each surface, so rigid misalignment is not counted as shape error).

Expected: nonlinear RMS < linear RMS at every force; the linear error grows with the force.  What
was measured is written to ``study.json`` and ``study.csv`` (and a bar chart ``study.png``) and
quoted in docs/report.md.  The script reports what it measures and asserts nothing.
"""
from __future__ import annotations

import argparse
import csv
import json
import sys
import time
from pathlib import Path

import numpy as np

R_M = 0.0325                        # sphere radius [m]
R_OVER_T = 10.0
GAMMA = 0.1                         # C2 / C1
RING = 0.2                          # ring radius / R
N_RING = 64
FORCES_N = (10.63, 16.50, 20.37, 21.48)     # Tian & Jia 2010, Table I
MEASURED_MM = (2.56, 6.05, 9.12, 10.27)     # the paper's measured max. displacement (for the table only)
L_MAX = 1.8                         # F / (C1 t^2) at the largest force
T_M = R_M / R_OVER_T
C1_PA = FORCES_N[-1] / (L_MAX * T_M ** 2)
MM = 1e3


def load_level(force_n: float) -> float:
    """F / (C1 t^2) of a force [N]."""
    return force_n / (C1_PA * T_M ** 2)


# --------------------------------------------------------------------------------------------
# reference: the axisymmetric solver
# --------------------------------------------------------------------------------------------
def reference_meridians(levels) -> list[dict]:
    """Deformed meridian (r, z) [m], pole to equator, and the apex displacement [m] per level."""
    from graspdef.axisym import AxisymMaterial, pinched_sphere, solve_load

    R, t = 1.0, 1.0 / R_OVER_T
    model = pinched_sphere(R, t, AxisymMaterial("mooney_rivlin", C1=1.0, gamma=GAMMA), F=t ** 2,
                           contact_radius=RING * R)
    out = []
    for L in levels:
        eq = solve_load(model, L, increments=max(2, int(np.ceil(4 * L))))
        rz = eq.shape[:, :2] * t                    # nondimensional (rho, eps) -> lengths / R
        out.append({"level": float(L), "r": rz[:, 0] * R_M, "z": rz[:, 1] * R_M,
                    "apex_m": float((eq.nodes[0, 1] * t - R) * R_M), "n_negative": int(eq.n_negative)})
    return out


def revolve(meridian: dict, subdivisions: int = 6):
    """The deformed shape as a triangle mesh [m]: an icosphere whose vertex at polar angle theta
    is moved to the point of the (mirrored) deformed meridian at the same fraction of its arc
    length, at the same azimuth."""
    from scipy.interpolate import CubicSpline

    from graspdef.geometry import TriMesh, icosphere

    r, z = np.asarray(meridian["r"]), np.asarray(meridian["z"])
    ds = np.hypot(np.diff(r), np.diff(z))
    keep = np.concatenate([[True], ds > 1e-12 * R_M])           # segment ends are listed twice
    r, z = r[keep], z[keep]
    s = np.concatenate([[0.0], np.cumsum(ds[keep[1:]])])
    s /= s[-1]
    fr, fz = CubicSpline(s, r), CubicSpline(s, z)
    ball = icosphere(1.0, subdivisions)
    v = ball.vertices
    theta = np.arccos(np.clip(v[:, 2], -1.0, 1.0))            # 0 at the top pole
    frac = np.where(theta <= np.pi / 2, theta, np.pi - theta) / (np.pi / 2)
    psi = np.arctan2(v[:, 1], v[:, 0])
    rr = np.maximum(fr(frac), 0.0)
    zz = np.sign(v[:, 2]) * np.maximum(fz(frac), 0.0)
    verts = np.stack([rr * np.cos(psi), rr * np.sin(psi), zz], axis=1)
    return TriMesh(verts, ball.faces)


# --------------------------------------------------------------------------------------------
# predictions: the 3-D shell solver
# --------------------------------------------------------------------------------------------
def limit_surface_map(faces: np.ndarray, n_control: int, min_vertices: int = 10_000):
    """Sparse map from control points to the limit points of the control mesh Loop-refined until
    it has at least ``min_vertices`` vertices, and the refined faces: the scored surface is the
    limit surface sampled finely (a flat-faceted 642-vertex sphere of R = 32.5 mm is off the
    limit surface by up to 0.1 mm between its vertices; 10,242 vertices: 0.02 mm)."""
    import scipy.sparse as sp

    from graspdef.subdivision.rules import limit_matrix, refine

    M = sp.identity(n_control, format="csr")
    f, n = np.asarray(faces, dtype=np.int64), n_control
    while n < min_vertices:
        S, f = refine(f, n)
        M, n = (S @ M).tocsr(), S.shape[0]
    return (limit_matrix(f, n, np.arange(n)) @ M).tocsr(), f


def predictions(subdivisions: int, levels, n_ring: int = N_RING) -> dict:
    """Nonlinear and linear limit surfaces [m] of the 3-D shell at each level, and the rest one."""
    from graspdef.bench import ring_pinched_sphere
    from graspdef.geometry import TriMesh, sphere
    from graspdef.shell.hyperelastic import MooneyRivlin
    from graspdef.shell.model import Shell
    from graspdef.solve.linear import solve_linear
    from graspdef.solve.nonlinear import PathOptions, solve_nonlinear

    R, t = 1.0, 1.0 / R_OVER_T
    mesh = sphere(R, subdivisions)
    shell = Shell(mesh.vertices, mesh.faces, MooneyRivlin(1.0, GAMMA), t)
    Fmax = max(levels) * t ** 2
    pr = ring_pinched_sphere(shell, R, RING, n_ring, Fmax)
    factors = [L * t ** 2 / Fmax for L in levels]
    t0 = time.perf_counter()
    lin = solve_linear(pr)
    t_lin = time.perf_counter() - t0
    t0 = time.perf_counter()
    nl = solve_nonlinear(pr, PathOptions(steps=4, targets=tuple(factors)))
    t_nl = time.perf_counter() - t0
    Lmap, faces = limit_surface_map(shell.mesh.faces[: shell.mesh.n_real_faces], shell.mesh.n_control)
    X = shell.mesh.vertices

    def surf(u):
        return TriMesh(Lmap @ (X + u) * R_M, faces)

    out = {"n_control": int(shell.mesh.n_real), "seconds_linear": t_lin, "seconds_nonlinear": t_nl,
           "newton_iterations": int(sum(nl.iterations())), "undeformed": surf(np.zeros_like(X)),
           "linear": [], "nonlinear": [], "apex_linear_m": [], "apex_nonlinear_m": [], "factors": factors,
           "path": [(p.load_factor, p.iterations, np.asarray(p.probes["top"]) * R_M) for p in nl.path]}
    for f in factors:
        pt = nl.at(f)
        out["nonlinear"].append(surf(pt.u))
        out["linear"].append(surf(f * lin.u))
        out["apex_nonlinear_m"].append(0.5 * (pt.probes["top"][2] - pt.probes["bottom"][2]) * R_M)
        out["apex_linear_m"].append(0.5 * f * (lin.probe("top")[2] - lin.probe("bottom")[2]) * R_M)
    return out


# --------------------------------------------------------------------------------------------
# scans and scores
# --------------------------------------------------------------------------------------------
def run(subdivisions=(3, 4), forces=FORCES_N, n_points: int = 30_000, seed: int = 0,
        reference_subdivisions: int = 6, n_target: int = 60_000, n_ring: int = N_RING, runs_dir=None,
        progress=print) -> dict:
    """The study (see the module docstring); returns the record written to study.json.  ``n_target``:
    points sampled on each surface for the ICP (graspdef.registration.register); ``n_ring``: point
    loads per ring on the 3-D shell.  ``runs_dir``: also write every prediction as a run folder,
    score it with ``graspdef score`` (score_cli) and write ``report_<n>.html`` (graspdef report)
    with the Table I layout there."""
    from graspdef.registration import score
    from graspdef.scans import Scanner, scan_surface

    levels = [load_level(F) for F in forces]
    t0 = time.perf_counter()
    merid = reference_meridians(levels)
    progress(f"reference (axisymmetric) solved in {time.perf_counter() - t0:.1f} s: apex displacement "
             + ", ".join(f"{m['apex_m'] * MM:.3f}" for m in merid) + " mm")
    scanner = Scanner(n_points=n_points)
    scans = []
    for i, m in enumerate(merid):
        ref = revolve(m, reference_subdivisions)
        scans.append(scan_surface(ref, scanner, seed=seed + i, source=f"axisym pinched sphere {forces[i]} N"))
    progress(f"{len(scans)} synthetic scans of {n_points} points (sigma {scanner.sigma * MM} mm, "
             f"{scanner.n_holes} holes, random pose)")
    rows, meshes = [], []
    for s in subdivisions:
        t0 = time.perf_counter()
        pred = predictions(s, levels, n_ring)
        progress(f"3-D shell, {pred['n_control']} control vertices: linear {pred['seconds_linear']:.1f} s, "
                 f"nonlinear path {pred['seconds_nonlinear']:.1f} s ({pred['newton_iterations']} Newton iterations)")
        meshes.append({"subdivisions": s, "n_control": pred["n_control"], "seconds_linear": pred["seconds_linear"],
                       "seconds_nonlinear": pred["seconds_nonlinear"], "newton_iterations": pred["newton_iterations"]})
        for i, F in enumerate(forces):
            pts = scans[i].points
            res_nl = score(pts, pred["nonlinear"][i], pred["undeformed"], n_target=n_target)
            res_li = score(pts, pred["linear"][i], pred["undeformed"], n_target=n_target)
            row = {"force_N": F, "load_level": levels[i], "subdivisions": s, "n_control": pred["n_control"],
                   "reference_apex_mm": -merid[i]["apex_m"] * MM,
                   "nonlinear_apex_mm": -pred["apex_nonlinear_m"][i] * MM,
                   "linear_apex_mm": -pred["apex_linear_m"][i] * MM,
                   "paper_measured_mm": MEASURED_MM[FORCES_N.index(F)] if F in FORCES_N else None}
            for name, res in (("nonlinear", res_nl["prediction"]), ("linear", res_li["prediction"]),
                              ("undeformed", res_nl["baseline"])):
                st = res.stats
                row.update({f"{name}_rms_mm": st["rms"] * MM, f"{name}_mean_mm": st["mean"] * MM,
                            f"{name}_max_mm": st["max"] * MM, f"{name}_p95_mm": st["p95"] * MM})
            row["flags"] = sorted(set(res_nl["flags"] + [f.replace("prediction", "linear") for f in res_li["flags"]]))
            rows.append(row)
        if runs_dir is not None:
            page = write_runs(Path(runs_dir), pred, scans, forces, merid)
            progress(f"  run folders, scores and the report: {page}")
            progress(f"  {F:6.2f} N: RMS nonlinear {row['nonlinear_rms_mm']:.3f} mm, linear {row['linear_rms_mm']:.3f} mm, "
                     f"undeformed {row['undeformed_rms_mm']:.3f} mm; max {row['nonlinear_max_mm']:.3f} / "
                     f"{row['linear_max_mm']:.3f} / {row['undeformed_max_mm']:.3f} mm"
                     + (f"  FLAGS {row['flags']}" if row["flags"] else ""))
    checks = {}
    for s in subdivisions:
        rs = [r for r in rows if r["subdivisions"] == s]
        lin = [r["linear_rms_mm"] for r in rs]
        checks[str(s)] = {"nonlinear_better_at_every_force": all(r["nonlinear_rms_mm"] < r["linear_rms_mm"] for r in rs),
                          "linear_error_grows_with_force": bool(np.all(np.diff(lin) > 0)),
                          "no_flags": all(not r["flags"] for r in rs)}
    return {
        "reference": {"solver": "graspdef.axisym pinched_sphere (thesis method), Mooney-Rivlin C2/C1 = 0.1",
                      "R_mm": R_M * MM, "t_mm": T_M * MM, "C1_MPa": C1_PA / 1e6, "C2_MPa": GAMMA * C1_PA / 1e6,
                      "ring_radius_mm": RING * R_M * MM, "surface_vertices": int(10 * 4 ** reference_subdivisions + 2),
                      "apex_mm": [-m["apex_m"] * MM for m in merid]},
        "scanner": {"n_points": n_points, "sigma_mm": scanner.sigma * MM, "n_holes": scanner.n_holes,
                    "hole_radius_mm": scanner.hole_radius * MM, "n_views": scanner.n_views, "random_pose": True,
                    "seeds": [seed + i for i in range(len(forces))]},
        "meshes": meshes, "rows": rows, "checks": checks,
    }


def write_runs(root: Path, pred: dict, scans, forces, merid) -> Path:
    """Each prediction as a run folder (graspdef.runs.write_run: result.json, deformed.ply,
    undeformed.ply [m]; path.csv for the nonlinear ones), scored with ``graspdef score`` against the scan of its force
    (``<run>/score``), and ``graspdef report --table`` over them (``report_<n>.html``): the study
    in the layout of Table I, the reference's apex displacement as the "measured" value."""
    import csv as _csv

    from graspdef.registration import score_cli
    from graspdef.runs import derived
    from graspdef.runs.record import SI_UNITS, RunRecord
    from graspdef.runs.write import write_run
    from graspdef.report import build_report
    from graspdef.scans import write_scan

    n = pred["n_control"]
    und = pred["undeformed"]
    table = []
    for i, F in enumerate(forces):
        scan_path = root / "scans" / f"scan_{F:.2f}N.ply"
        if not scan_path.is_file():
            write_scan(scans[i], scan_path, units="m")
        for kind in ("nonlinear", "linear"):
            surf = pred[kind][i]
            d = root / f"{kind}_{n}_{F:.2f}N"
            u = surf.vertices - und.vertices
            apex = -pred[f"apex_{kind}_m"][i]
            f = pred["factors"][i]
            pts = [p for p in pred["path"] if p[0] <= f * (1 + 1e-9)]
            data = {"description": f"3-D shell ({n} control vertices), sphere pinched by rings of {F} N "
                                   "(scripts/synthetic_scan_study.py)",
                    "probes": {"apex": {"displacement": [0.0, 0.0, -apex]}}}
            path = None
            if kind == "nonlinear":
                data["convergence"] = {"completed": True, "load_factor": f,
                                       "newton_iterations": [p[1] for p in pts[1:]]}
                path = (["point", "load_factor", "newton_iterations", "top_ux[m]", "top_uy[m]", "top_uz[m]"],
                        [[k, lf, its, *top] for k, (lf, its, top) in enumerate(pts)])
            md = derived.max_displacement(und.vertices, u, "m", rigid_motion_removed=False, reference="rest shape")
            rec = RunRecord("synthetic", d.name, kind, dict(SI_UNITS), {"max_displacement": md}, {}, data)
            write_run(d, rec, rest=und.vertices, deformed=surf.vertices, faces=surf.faces, displacement=u,
                      path=path, provenance={"script": "scripts/synthetic_scan_study.py", "force_N": F})
            score_cli(d / "deformed.ply", scan_path, d / "score")
            table.append((d.name, F, -merid[i]["apex_m"] * MM))
    csv_path = root / f"table_{n}.csv"
    with csv_path.open("w", newline="") as fh:
        w = _csv.writer(fh)
        w.writerow(["run", "force_N", "measured_mm"])
        w.writerows(table)
    return build_report([], root / f"report_{n}.html", table=csv_path,
                        title=f"Synthetic-scan study: axisymmetric reference vs 3-D shell ({n} control vertices)")


def write(result: dict, out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    (out / "study.json").write_text(json.dumps(result, indent=2) + "\n")
    rows = result["rows"]
    keys = [k for k in rows[0] if k != "flags"] + ["flags"]
    with (out / "study.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(keys)
        for r in rows:
            w.writerow([";".join(r[k]) if k == "flags" else r[k] for k in keys])
    try:
        from graspdef.report.plots import bar_chart
    except ImportError:
        return
    for s in sorted({r["subdivisions"] for r in rows}):
        rs = [r for r in rows if r["subdivisions"] == s]
        png = bar_chart([f"{r['force_N']:g} N" for r in rs],
                        {"undeformed": [r["undeformed_rms_mm"] for r in rs],
                         "linear": [r["linear_rms_mm"] for r in rs],
                         "nonlinear": [r["nonlinear_rms_mm"] for r in rs]},
                        ylabel="RMS scan error [mm]",
                        title=f"synthetic scans of the axisymmetric reference, 3-D shell with {rs[0]['n_control']} "
                              "control vertices")
        (out / f"study_{rs[0]['n_control']}.png").write_bytes(png)


def format_table(result: dict) -> str:
    lines = ["| control vertices | force [N] | reference apex [mm] | nonlinear apex [mm] | linear apex [mm] | "
             "RMS nonlinear [mm] | RMS linear [mm] | RMS undeformed [mm] | max nonlinear / linear / undeformed [mm] |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        lines.append(f"| {r['n_control']} | {r['force_N']:.2f} | {r['reference_apex_mm']:.3f} | {r['nonlinear_apex_mm']:.3f} "
                     f"| {r['linear_apex_mm']:.3f} | {r['nonlinear_rms_mm']:.3f} | {r['linear_rms_mm']:.3f} | "
                     f"{r['undeformed_rms_mm']:.3f} | {r['nonlinear_max_mm']:.3f} / {r['linear_max_mm']:.3f} / "
                     f"{r['undeformed_max_mm']:.3f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fast", action="store_true", help="162 control vertices, 10,000 scan points, reference "
                                                        "surface 10,242 vertices")
    ap.add_argument("--subdivisions", type=int, nargs="+", help="icosphere subdivisions of the 3-D meshes (3 4)")
    ap.add_argument("--points", type=int, help="scan points (30000; --fast 10000)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="out/synthetic_scan_study")
    ap.add_argument("--runs", action="store_true", help="also write run folders, their scores and a "
                                                        "'graspdef report' page (OUT/runs/report_<n>.html)")
    a = ap.parse_args(argv)
    subs = a.subdivisions or ([2] if a.fast else [3, 4])
    pts = a.points or (10_000 if a.fast else 30_000)
    t0 = time.perf_counter()
    res = run(subs, n_points=pts, seed=a.seed, reference_subdivisions=5 if a.fast else 6,
              runs_dir=Path(a.out) / "runs" if a.runs else None,
              progress=lambda m: print(m, file=sys.stderr, flush=True))
    res["seconds"] = time.perf_counter() - t0
    write(res, Path(a.out))
    print(format_table(res))
    print(json.dumps(res["checks"]))
    print(f"wrote {a.out}/study.json, study.csv ({res['seconds']:.0f} s)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    sys.exit(main())
