"""``graspdef fit OBJECT --data TABLE.csv --params E[,pressure,thickness] [--analysis ...] [--out DIR]``."""
from __future__ import annotations

import argparse

from ._common import progress, warn

DESCRIPTION = ("Identify material parameters of an object from a measured force-displacement table (CSV with "
               "units in its header: force_N,displacement_mm,point): weighted least squares on the "
               "log-parameters through the object's grasp chain (MuJoCo once per force, the shell per "
               "evaluation), finite-difference sensitivities. Prints the fitted values with standard errors, "
               "the residual of every row, the correlations, and a warning when parameters trade off; writes "
               "fit.json (SI) to --out. Exit status 1 when the fit does not converge. docs/fit.md.")


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("scene", help="an object folder (graspdef object add), a scene.xml, or a name under scenes/")
    ap.add_argument("--data", required=True, help="the measured table: CSV with header force_<unit>,"
                    "displacement_<unit>[,point][,sigma_<unit>], e.g. force_N,displacement_mm,point")
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


def run(a: argparse.Namespace) -> int:
    import math

    import numpy as np

    from ..fit.run import fit_object

    from ..units import quantity

    model = getattr(a, "model", "full")
    size = quantity(getattr(a, "patch_size", "45mm"), "length", what="--patch-size") if model == "patch" else 0.045
    r = fit_object(a.scene, a.data, a.params, a.analysis, a.out, a.start, a.max_iterations,
                   progress=lambda msg: progress(a, msg), model=model, patch_size=size)
    doc = r.to_json()
    state = "converged" if r.converged else "NOT CONVERGED"
    solves = "" if r.n_solves is None else f", {r.n_solves} forward solves"
    how = "point loads" if model == "full" else f"patch model ({size * 1e3:g} mm, border clamped, nu = 0.5, no air)"
    print(f"{doc['model'].get('object', a.scene)}: {a.analysis} shell, {how}; {len(r.table)} rows, "
          f"{len(r.names)} parameters; {state} ({r.message}); {r.n_evaluations} evaluations{solves}, "
          f"{r.seconds:.1f} s")
    print(f"{'parameter':<10} {'value':>14} {'std':>14} {'std %':>7} {'start':>14}")
    for n, v, s, s0 in zip(r.names, r.values, r.std, r.start):
        rel = f"{100 * s / v:7.2f}" if math.isfinite(s) and s < 1e3 * v else "    inf"
        print(f"{n:<10} {_si(n, v):>14} {_si(n, s) if math.isfinite(s) else 'n/a':>14} {rel} {_si(n, s0):>14}")
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
