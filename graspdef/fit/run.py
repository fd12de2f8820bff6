"""``graspdef fit``'s library side: an object, a measured table and the parameters to fit ->
:class:`~graspdef.fit.estimate.FitResult`, and the fit folder (``fit.json`` and a copy of the
table)."""
from __future__ import annotations

import json
import math
import shutil
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import ProblemError
from ..units import quantity
from .estimate import PARAMETERS, FitResult, fit, parse_names
from .table import read_table

#: the file a fit folder holds (and is recognised by: a fit folder is replaced, other folders refused)
FIT_FILE = "fit.json"


def parse_start(text: str | None, names: list) -> dict:
    """``"E=2MPa,pressure=50kPa"`` -> {"E": 2e6, "pressure": 5e4} (SI); each value needs a unit."""
    out = {}
    for item in [t for t in (text or "").split(",") if t.strip()]:
        name, eq, value = item.partition("=")
        name = name.strip()
        if not eq:
            raise ProblemError(f"--start: {item.strip()!r} is not NAME=VALUE (e.g. E=2MPa)")
        if name not in names:
            raise ProblemError(f"--start: {name!r} is not a parameter being fitted ({', '.join(names)})")
        v = quantity(value.strip(), PARAMETERS[name].dimension, what=f"--start {name}")
        if not v > 0:
            raise ProblemError(f"--start {name}: must be positive, got {value.strip()!r}")
        out[name] = v
    return out


def fit_object(scene, data, params: str, analysis: str = "nonlinear", out=None, start: str | None = None,
               max_iterations: int = 30, progress: Callable[[str], None] | None = None, model: str = "full",
               patch_size: float = 0.045) -> FitResult:
    """Fit ``params`` (``"E,pressure"``) of the object of ``scene`` to the table ``data`` (a CSV
    file, graspdef.fit.table) through its grasp chain (:class:`~graspdef.fit.models.ObjectModel`,
    ``analysis`` linear or nonlinear, point loads).  Start: object.toml's values, or ``start``
    (``"E=2MPa"``).  ``out``: the folder to write fit.json (and data.csv, the table) to.  ``model``: "full"
    (the whole object) or "patch" (the paper's clamped patch per contact, side ``patch_size`` [m];
    graspdef.pipeline.patch)."""
    from ..runs.folder import atomic_folder, check_output_folder
    from .models import ObjectModel

    say = progress or (lambda msg: None)
    if analysis not in ("linear", "nonlinear"):
        raise ProblemError(f"analysis must be 'linear' or 'nonlinear', got {analysis!r}")
    if not (isinstance(max_iterations, int) and max_iterations >= 1):
        raise ProblemError(f"--max-iterations must be a positive integer, got {max_iterations!r}")
    names = parse_names(params)
    table = read_table(data)
    if len(table) < len(names):
        raise ProblemError(f"{table.file}: {len(table)} rows for {len(names)} parameters ({', '.join(names)}): a fit "
                           "needs at least as many rows as parameters")
    given = parse_start(start, names)
    if out is not None:
        check_output_folder(out, FIT_FILE)
    model = ObjectModel(scene, table, names, analysis, progress=say, model=model, patch_size=patch_size)
    theta0 = {**model.start(), **given}
    missing = [n for n in names if n not in theta0]
    if missing:
        raise ProblemError(f"no start value for {', '.join(missing)}: give --start")

    def step(info):
        th = ", ".join(f"{k} {v / _unit(k):.5g} {PARAMETERS[k].display}" for k, v in info["theta"].items())
        say(f"evaluation {info['evaluations']}: {th}: RMS residual {info['rms_m'] * 1e3:.4g} mm")

    say(f"fitting {', '.join(names)} to {len(table)} rows ({len(set(table.force.tolist()))} forces)")
    result = fit(model, table, {n: theta0[n] for n in names}, max_nfev=max_iterations, progress=step)
    if out is not None:
        with atomic_folder(out) as tmp:
            (Path(tmp) / FIT_FILE).write_text(json.dumps(result.to_json(), indent=2) + "\n")
            shutil.copyfile(table.file, Path(tmp) / "data.csv")
    return result


def _unit(name: str) -> float:
    from ..units import unit_factor

    p = PARAMETERS[name]
    return unit_factor(p.display, p.dimension)


def fit_object_scan(scene, scan, force: float, params: str, analysis: str = "nonlinear", out=None,
                    start: str | None = None, max_iterations: int = 30, scan_units: str | None = None,
                    near: float = 0.02, sigma: float | None = None, progress: Callable[[str], None] | None = None,
                    model: str = "full", patch_size: float = 0.045, passes: int = 2,
                    region: str | None = None) -> FitResult:
    """Fit ``params`` of the object of ``scene`` to a deformed scan (a mesh file, ``scan_units`` if
    it states none) taken at ``force`` [N] per finger (graspdef.fit.scan: registered onto the
    predicted outer surface, the points within ``near`` [m] of the load points kept, their signed
    distances fitted; ``sigma`` [m]: the scan's noise; ``region``: align only on this part of the
    predicted surface, a predicate of x, y, z, r, rho, theta in mm in the object's frame, e.g.
    ``"abs(z) < 10"``, as ``graspdef score --region``).  ``out``: the folder for fit.json."""
    from ..registration.score import read_scan
    from ..runs.folder import atomic_folder, check_output_folder
    from .models import ObjectModel
    from .scan import fit_scan
    from .table import MeasuredTable

    say = progress or (lambda msg: None)
    if analysis not in ("linear", "nonlinear"):
        raise ProblemError(f"analysis must be 'linear' or 'nonlinear', got {analysis!r}")
    if not (isinstance(max_iterations, int) and max_iterations >= 1):
        raise ProblemError(f"--max-iterations must be a positive integer, got {max_iterations!r}")
    if model != "full":
        raise ProblemError("--scan fits the full object's surface (--model full): the patch model has no whole "
                           "surface to register a scan onto")
    if not (isinstance(force, (int, float)) and force > 0):
        raise ProblemError(f"--force must be a positive force (the scan's force per finger), got {force!r}")
    if sigma is not None and not (isinstance(sigma, (int, float)) and math.isfinite(sigma) and sigma > 0):
        raise ProblemError(f"--scan-sigma must be a positive length, got {sigma!r} m")
    if not (isinstance(near, (int, float)) and math.isfinite(near) and near > 0):
        raise ProblemError(f"--near must be a positive length, got {near!r} m")
    align = None
    if region is not None:
        from ..geometry.regions import compile_predicate

        in_mm = compile_predicate(region, "alignment region (--align-region)", length_scale=1e-3)

        def align(v):
            return in_mm(np.asarray(v) / 1e-3)
    names = parse_names(params)
    given = parse_start(start, names)
    points = read_scan(scan, scan_units)
    if out is not None:
        check_output_folder(out, FIT_FILE)
    om = ObjectModel(scene, MeasuredTable(np.array([float(force)]), np.zeros(1), ("finger",)), names, analysis, progress=say,
                     model=model, patch_size=patch_size)
    theta0 = {**om.start(), **given}
    missing = [n for n in names if n not in theta0]
    if missing:
        raise ProblemError(f"no start value for {', '.join(missing)}: give --start")
    theta0 = {n: theta0[n] for n in names}
    memo: dict = {}

    def outcome(theta):
        key = tuple(sorted(theta.items()))
        if key not in memo:
            memo.clear()
            memo[key] = om.outcome(theta, float(force))
        return memo[key]

    def surface(theta):
        return om.surface(theta, float(force), "outer", outcome=outcome(theta))

    say(f"solving at the start values for the load points ({len(points)} scan points)")
    rec = outcome(theta0).record.to_json()
    loads = [f["load_point_m"] for f in rec["fingers"].values()]

    def step(info):
        th = ", ".join(f"{k} {v / _unit(k):.5g} {PARAMETERS[k].display}" for k, v in info["theta"].items())
        say(f"evaluation {info['evaluations']}: {th}: RMS distance {info['rms_m'] * 1e3:.4g} mm")

    result, sels = fit_scan(surface, points, loads, float(force), theta0, near=near, sigma=sigma, passes=passes,
                            max_nfev=max_iterations, progress=step, region=align)
    result.model.update({k: v for k, v in om.description.items() if k not in result.model})
    result.model["scan_file"] = str(scan)
    result.model["alignment_region_mm"] = region
    if out is not None:
        with atomic_folder(out) as tmp:
            (Path(tmp) / FIT_FILE).write_text(json.dumps(result.to_json(), indent=2) + "\n")
    return result
