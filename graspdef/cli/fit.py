"""``graspdef fit OBJECT --data TABLE.csv | --scan SCAN --force F  --params E[,pressure,thickness] [--analysis ...] [--out DIR]``."""
from __future__ import annotations

import argparse

from ._common import progress, warn

DESCRIPTION = ("Identify material parameters of an object from a measured force-displacement table (CSV with "
               "units in its header: force_N,displacement_mm,point): weighted least squares on the "
               "log-parameters through the object's grasp chain (MuJoCo once per force, the shell per "
               "evaluation), finite-difference sensitivities. Prints the fitted values with standard errors, "
               "the residual of every row, the correlations, and a warning when parameters trade off; writes "
               "fit.json (SI) to --out. Or from a scan of the deformed object (--scan FILE --force F): its points "
               "near the load points fitted by their distances to the predicted outer surface after registration. "
               "Exit status 1 when the fit does not converge. docs/fit.md.")


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("scene", help="an object folder (graspdef object add), a scene.xml, or a name under scenes/")
    ap.add_argument("--data", help="the measured table: CSV with header force_<unit>,"
                    "displacement_<unit>[,point][,sigma_<unit>], e.g. force_N,displacement_mm,point")
    ap.add_argument("--scan", help="instead of --data: a scan of the deformed object (PLY/OBJ/STL; units in the file "
                    "or --scan-units), taken at --force: registered onto the predicted outer surface, its points "
                    "within --near of the load points fitted by their distances to it (docs/fit.md)")
    ap.add_argument("--scan-units", dest="scan_units", help="the scan file's length unit when it states none (mm, m)")
    ap.add_argument("--force", help="with --scan: the force per finger the scan was taken at, e.g. 21.48N")
    ap.add_argument("--near", default="20mm", help="with --scan: radius around the load points whose scan points are "
                    "fitted (20mm)")
    ap.add_argument("--align-region", dest="align_region",
                    help="with --scan: align the scan only on this part of the predicted surface, one that stays "
                         "undeformed (a predicate of x, y, z, r, rho, theta in mm, object frame, e.g. 'abs(z) < 10'; "
                         "as graspdef score --region); default: the whole surface")
    ap.add_argument("--scan-sigma", dest="scan_sigma", help="with --scan: the scan's noise, e.g. 0.1mm (weights and "
                    "standard errors; default: unweighted)")
    ap.add_argument("--params", required=True, help="parameters to fit, comma-separated: E, pressure (the enclosed "
                    "air's gauge pressure; nonlinear), thickness")
    ap.add_argument("--analysis", choices=["linear", "nonlinear"], default="nonlinear")
    ap.add_argument("--start", help="start values with units, e.g. E=2MPa,pressure=50kPa (default: object.toml's)")
    ap.add_argument("--max-iterations", dest="max_iterations", type=int, default=30,
                    help="optimiser iterations (each: one evaluation, and one per parameter for the Jacobian) (30)")
    ap.add_argument("--model", choices=["full", "patch"], default="full",
                    help="forward model: full (the whole object, default) or patch (the paper's clamped patch per "
                         "finger contact, nu = 0.5, no air; graspdef grasp --model patch)")
    ap.add_argument("--patch-size", default="45mm", help="the patch model's square side (45mm)")
    ap.add_argument("--out", help="folder to write fit.json and data.csv to (a fit folder is replaced)")


def _si(name: str, value: float) -> str:
    from ..fit import PARAMETERS
    from ..units import unit_factor

    p = PARAMETERS[name]
    return f"{value / unit_factor(p.display, p.dimension):.5g} {p.display}"


def _print_parameters(r) -> None:
    """The fitted values with their standard errors and starts, one line each."""
    import math

    print(f"{'parameter':<10} {'value':>14} {'std':>14} {'std %':>7} {'start':>14}")
    for n, v, s, s0 in zip(r.names, r.values, r.std, r.start):
        rel = f"{100 * s / v:7.2f}" if math.isfinite(s) and s < 1e3 * v else "    inf"
        print(f"{n:<10} {_si(n, v):>14} {_si(n, s) if math.isfinite(s) else 'n/a':>14} {rel} {_si(n, s0):>14}")


def run(a: argparse.Namespace) -> int:
    import numpy as np

    from ..fit.run import fit_object

    from ..units import quantity

    from ..errors import ProblemError

    model = getattr(a, "model", "full")
    size = quantity(getattr(a, "patch_size", "45mm"), "length", what="--patch-size") if model == "patch" else 0.045
    scan = getattr(a, "scan", None)
    if (a.data is None) == (scan is None):
        raise ProblemError("give exactly one of --data (a force-displacement table) and --scan (a deformed scan)")
    if scan is None:
        for opt in ("force", "scan_units", "scan_sigma", "align_region"):
            if getattr(a, opt, None) is not None:
                why = " (the table gives its own forces)" if opt == "force" else ""
                raise ProblemError(f"--{opt.replace('_', '-')} belongs to --scan{why}")
        r = fit_object(a.scene, a.data, a.params, a.analysis, a.out, a.start, a.max_iterations,
                       progress=lambda msg: progress(a, msg), model=model, patch_size=size)
    else:
        from ..fit.run import fit_object_scan

        if a.force is None:
            raise ProblemError("--scan needs --force: the force per finger the scan was taken at, e.g. 21.48N")
        force = quantity(a.force, "force", what="--force")
        near = quantity(a.near, "length", what="--near")
        sigma = quantity(a.scan_sigma, "length", what="--scan-sigma") if a.scan_sigma is not None else None
        for opt, text, v in (("--near", a.near, near), ("--scan-sigma", a.scan_sigma, sigma)):
            if v is not None and not v > 0:                  # the user's own words, not metres
                raise ProblemError(f"{opt} must be a positive length, got {text}")
        r = fit_object_scan(a.scene, scan, force, a.params, a.analysis, a.out, a.start, a.max_iterations,
                            scan_units=a.scan_units, near=near, sigma=sigma, progress=lambda msg: progress(a, msg),
                            model=model, patch_size=size, region=a.align_region)
        return _print_scan(a, r)
    doc = r.to_json()
    state = "converged" if r.converged else "NOT CONVERGED"
    solves = "" if r.n_solves is None else f", {r.n_solves} forward solves"
    how = "point loads" if model == "full" else f"patch model ({size * 1e3:g} mm, border clamped, nu = 0.5, no air)"
    print(f"{doc['model'].get('object', a.scene)}: {a.analysis} shell, {how}; {len(r.table)} rows, "
          f"{len(r.names)} parameters; {state} ({r.message}); {r.n_evaluations} evaluations{solves}, "
          f"{r.seconds:.1f} s")
    _print_parameters(r)
    print(f"{'force N':>8} {'point':<8} {'measured mm':>11} {'predicted mm':>12} {'residual mm':>11} {'res/sigma':>9}")
    for row in doc["rows"]:
        def mm(x):
            return "nan" if x is None else f"{x * 1e3:.4f}"
        nr = row["normalised_residual"]
        print(f"{row['force_N']:8.4g} {row['point']:<8} {mm(row['measured_m']):>11} {mm(row['predicted_m']):>12} "
              f"{mm(row['residual_m']):>11} {'nan' if nr is None else f'{nr:9.3f}':>9}")
    print(f"RMS residual {r.rms * 1e3:.4g} mm; chi2/dof {r.s2:.4g} ({r.dof} degrees of freedom)")
    if len(r.names) > 1 and np.all(np.isfinite(r.correlation)):
        pairs = [f"{r.names[i]}-{r.names[j]} {r.correlation[i, j]:+.4f}" for i in range(len(r.names))
                 for j in range(i + 1, len(r.names))]
        print(f"correlation: {', '.join(pairs)}; condition number of J^T J {r.condition:.3g}")
    for w in r.warnings:
        warn(w)
    if a.out:
        print(f"fit.json: {a.out}/fit.json")
    return 0 if r.converged else 1


def _print_scan(a, r) -> int:
    """The scan fit's summary: the parameters and the distances (one row per scan point is in fit.json)."""
    import numpy as np

    from ._common import warn

    state = "converged" if r.converged else "NOT CONVERGED"
    m = r.model
    passes = m.get("passes", [])
    print(f"{m.get('object', a.scene)}: {a.analysis} shell, deformed scan {m.get('scan_file')} at "
          f"{m.get('force_N', float('nan')):g} N; {len(r.table)} scan points within {passes[-1]['near_m'] * 1e3:g} mm of "
          f"the load points; {state} ({r.message}); {len(passes)} registration pass(es), {r.seconds:.1f} s")
    if m.get("alignment_region_mm"):
        counts = " / ".join(str((p.get("registration") or {}).get("n_region_points")) for p in passes)
        print(f"aligned on the region {m['alignment_region_mm']} (mm): {counts} scan points per pass")
    _print_parameters(r)
    d = np.abs(r.predicted)
    print(f"scan-to-surface distance: RMS {r.rms * 1e3:.4g} mm, median {np.median(d) * 1e3:.4g} mm, "
          f"max {d.max() * 1e3:.4g} mm; chi2/dof {r.s2:.4g}")
    rms = m.get("rms_to_fitted_surface_per_pass_m", [])
    if len(rms) > 1:
        print("the kept points' RMS distance to the fitted surface under each pass's registration: "
              + " / ".join(f"{x * 1e3:.4g} mm" for x in rms) + " (the first pass registered onto the start's "
              "prediction, the last onto the fitted one)")
    for w in r.warnings:
        warn(w)
    if a.out:
        print(f"fit.json: {a.out}/fit.json")
    return 0 if r.converged else 1
