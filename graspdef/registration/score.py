"""Scores of a predicted surface against a scan, always with the undeformed shape as a baseline,
and the ``score.json`` run folder.

Every score is computed after registering the scan to the surface it is compared with
(:func:`graspdef.registration.icp.register`): signed distances from each scan point to the
surface (the error measure of Tian & Jia 2010, Sec. IX: "averaging the distances from the mesh
vertices to the deformed surface"), their mean, RMS, median, 95th percentile and maximum; the
Hausdorff distance (the larger of the scan → surface maximum and the surface → scan maximum;
the latter includes any part of the surface the scanner did not see, so the coverage is given
too); and the rigid transform found.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from os import PathLike
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from graspdef.geometry import TriMesh, compile_predicate, length_scale, save_ply
from graspdef.runs.folder import atomic_folder
from graspdef.runs.provenance import write_provenance
from graspdef.registration.distance import SurfaceDistance
from graspdef.registration.icp import (
    Registration,
    RegistrationError,
    apply,
    register,
    rotation_angle,
)
from graspdef.scans.manifest import load_manifest, ply_units, read_surface
from graspdef.scans.remesh import vertex_normals

MM = 1e3


@dataclass(frozen=True)
class SurfaceScore:
    """Scan → surface comparison after registration (lengths in metres).

    Attributes
    ----------
    registration : Registration
    scan_errors : ndarray, shape (n_scan,)
        Signed distance of each scan point to the surface [m] (positive outside).
    surface_errors : ndarray, shape (n_surface_vertices,)
        Distance of each surface vertex to the nearest scan point [m].
    stats : dict
        mean, rms, max, median, p95, mean_signed, hausdorff, surface_to_scan_max [m];
        coverage (fraction of surface vertices within the correspondence distance of the scan).
    """

    registration: Registration
    scan_errors: np.ndarray
    surface_errors: np.ndarray
    stats: dict


def score_surface(scan_points: np.ndarray, surface: TriMesh, coverage_distance: float = 1e-3,
                  **register_options) -> SurfaceScore:
    """Register ``scan_points`` to ``surface`` and measure the distances.

    ``register_options`` go to :func:`~graspdef.registration.icp.register`.  A surface vertex
    counts as covered if a scan point lies within ``coverage_distance`` [m] of it.
    """
    reg = register(scan_points, surface, **register_options)
    moved = apply(reg.transform, np.asarray(scan_points, dtype=np.float64))
    d = SurfaceDistance(surface).signed(moved)
    a = np.abs(d)
    back = cKDTree(moved).query(surface.vertices, workers=-1)[0]
    stats = {
        "mean": float(a.mean()), "rms": float(np.sqrt(np.mean(d**2))), "max": float(a.max()),
        "median": float(np.median(a)), "p95": float(np.percentile(a, 95)),
        "mean_signed": float(d.mean()), "surface_to_scan_max": float(back.max()),
        "hausdorff": float(max(a.max(), back.max())),
        "coverage": float(np.mean(back <= coverage_distance)),
    }
    return SurfaceScore(reg, d, back, stats)


def _registration_record(reg: Registration) -> dict:
    t = reg.transform
    angle = rotation_angle(t[:3, :3])
    w = np.array([t[2, 1] - t[1, 2], t[0, 2] - t[2, 0], t[1, 0] - t[0, 1]])
    axis = w / np.linalg.norm(w) if np.linalg.norm(w) > 1e-12 else np.array([0.0, 0.0, 1.0])
    matrix_mm = t.copy()
    matrix_mm[:3, 3] *= MM
    return {
        "transform_scan_to_surface": matrix_mm.tolist(),
        "transform_note": "x_surface = R @ p_scan + t; t in mm",
        "rotation_deg": float(np.degrees(angle)),
        "rotation_axis": axis.tolist(),
        "translation_mm": (t[:3, 3] * MM).tolist(),
        "init": reg.init,
        "fitness": reg.fitness,
        "converged": reg.converged,
        "last_step_mm": reg.last_step[0] * MM,
        "last_step_deg": float(np.degrees(reg.last_step[1])),
        "n_points": reg.n_points,
        "n_region_points": reg.n_region_points,
        "flags": list(reg.flags),
    }


def _stats_mm(stats: dict) -> dict:
    return {(k if k == "coverage" else f"{k}_mm"): (v if k == "coverage" else v * MM)
            for k, v in stats.items()}


def score(scan_points: np.ndarray, prediction: TriMesh, undeformed: TriMesh, *,
          surface_offset: float = 0.0, **register_options) -> dict:
    """Score a prediction against a scan, with the undeformed shape scored the same way.

    Parameters
    ----------
    scan_points : ndarray, shape (n, 3)
        Scan [m].
    prediction, undeformed : TriMesh
        Predicted (deformed) surface and the undeformed shape, same frame [m].
    surface_offset : float
        Offset both surfaces by this distance along their outward normals before comparing [m]
        (half the thickness when they are shell mid-surfaces and the scan sees the outer side).
    register_options
        Passed to :func:`~graspdef.registration.icp.register` (``init``, ``region``, ...).

    Returns
    -------
    dict
        ``{"prediction": SurfaceScore, "baseline": SurfaceScore, "flags": [...]}``.
    """
    if surface_offset:
        prediction = TriMesh(prediction.vertices + surface_offset * vertex_normals(prediction),
                             prediction.faces)
        undeformed = TriMesh(undeformed.vertices + surface_offset * vertex_normals(undeformed),
                             undeformed.faces)
    pred = score_surface(scan_points, prediction, **register_options)
    base = score_surface(scan_points, undeformed, **register_options)
    flags = [f"prediction: {f}" for f in pred.registration.flags]
    flags += [f"baseline: {f}" for f in base.registration.flags]
    return {"prediction": pred, "baseline": base, "flags": flags}


def _read(path: Path, declared: str | None, what: str) -> tuple[np.ndarray, np.ndarray, str]:
    stated = ply_units(path)
    if declared is not None and stated is not None and declared != stated:
        raise RegistrationError(f"{what} {path}: the file states units {stated!r} but "
                                f"{declared!r} was given")
    units = declared or stated
    if units is None:
        raise RegistrationError(f"{what} {path}: the file states no units (no 'comment units' "
                                "line); give them explicitly")
    length_scale(units)
    vertices, faces = read_surface(path, units)
    return vertices, faces, units


def read_scan(path: str | PathLike, units: str | None = None) -> np.ndarray:
    """A scan's points [m] (the vertices of a PLY/OBJ/STL file); ``units``: the file's length unit
    when it states none ("mm", ...), or a known real scan's id (scans/manifest.toml).
    RegistrationError: a missing file, no units, a unit conflict."""
    path = Path(path)
    if not path.exists() and str(path) in load_manifest().real:
        entry = load_manifest().real[str(path)]
        path, units = entry.file(), units or entry.units
    if not path.is_file():
        raise RegistrationError(f"scan {path}: no such file")
    return _read(path, units, "scan")[0]


def score_cli(prediction_path: str | PathLike, scan_path: str | PathLike,
              out_dir: str | PathLike, *, undeformed_path: str | PathLike | None = None,
              prediction_units: str | None = None, scan_units: str | None = None,
              init="pca", region: str | None = None, surface_offset_mm: float = 0.0,
              tukey_k_mm: float = 2.0, max_distance_mm: float | None = None) -> dict:
    """``graspdef score PREDICTION SCAN --out DIR``: register, score and write the run folder.

    Parameters
    ----------
    prediction_path : path
        Predicted surface (e.g. ``deformed.ply`` of ``graspdef solve``), a triangle mesh.
    scan_path : path or str
        The scan: a triangle mesh (its vertices are scored) or a point cloud; or the id of a
        real scan of the manifest (e.g. ``ycb_056_tennis_ball``, read with its stated units).
    out_dir : path
        Run folder to write (replaced if it exists; written only if everything succeeded):
        ``score.json``, ``scan_errors.ply`` (the scan in its own frame and units, with the signed
        errors ``error_mm`` and ``baseline_error_mm`` per point), ``prediction_errors.ply`` and
        ``undeformed_errors.ply`` (each surface with ``distance_to_scan_mm`` per vertex).
    undeformed_path : path, optional
        The undeformed shape in the prediction's frame; default ``undeformed.ply`` next to the
        prediction.  Required: every score comes with its baseline.
    prediction_units, scan_units : str, optional
        Length units of the files; default the PLY ``comment units`` line; a declared unit that
        contradicts it is an error.  The undeformed file uses the prediction's units unless it
        states its own.
    init : str or ndarray (4, 4)
        Coarse initialisation (``pca``, ``centroid``, ``identity``), or a first guess of the
        scan -> prediction transform in metres (e.g. the object pose of the MuJoCo scene).
    region : str, optional
        Undeformed region of the surfaces to align on (a predicate of x, y, z, r, rho, theta in
        the prediction file's units, e.g. ``"z < -10"``); the scores are measured everywhere.
    surface_offset_mm : float
        Offset of the surfaces along their outward normals before comparing [mm] (half the
        thickness for shell mid-surfaces).
    tukey_k_mm, max_distance_mm : float
        ICP robust-kernel scale and correspondence distance [mm].

    Returns
    -------
    dict
        The ``score.json`` record.

    Raises
    ------
    GraspdefError
        (``RegistrationError``, ``MeshError``, ``ProblemError``) for unreadable, empty,
        non-overlapping or wrongly scaled input; nothing is written then.
    """
    prediction_path, scan_path, out = Path(prediction_path), Path(scan_path), Path(out_dir)
    if not scan_path.exists() and str(scan_path) in load_manifest().real:
        entry = load_manifest().real[str(scan_path)]
        scan_path, scan_units = entry.file(), scan_units or entry.units
    if undeformed_path is None:
        undeformed_path = prediction_path.with_name("undeformed.ply")
        if not undeformed_path.is_file():
            raise RegistrationError(f"no undeformed shape: {undeformed_path} does not exist; give "
                                    "the undeformed surface (the baseline every score reports)")
    undeformed_path = Path(undeformed_path)
    pv, pf, p_units = _read(prediction_path, prediction_units, "prediction")
    stated = ply_units(undeformed_path)
    uv, uf, u_units = _read(undeformed_path, None if stated else p_units, "undeformed shape")
    if pf.shape[0] == 0 or uf.shape[0] == 0:
        raise RegistrationError("the prediction and the undeformed shape must be triangle meshes")
    sv, sf, s_units = _read(scan_path, scan_units, "scan")
    prediction, undeformed = TriMesh(pv, pf), TriMesh(uv, uf)
    options = {"init": init, "tukey_k": tukey_k_mm / MM}
    if max_distance_mm is not None:
        options["max_distance"] = max_distance_mm / MM
    if region is not None:
        scale = length_scale(p_units)
        pred_fn = compile_predicate(region, "alignment region", length_scale=scale)
        options["region"] = lambda v: pred_fn(v / scale)
    result = score(sv, prediction, undeformed, surface_offset=surface_offset_mm / MM, **options)
    pred, base = result["prediction"], result["baseline"]
    ps, bs = pred.stats, base.stats
    record = {
        "units": {"length": "mm", "angle": "deg",
                  "note": "every length field ends in _mm; coverage and fitness are fractions"},
        "inputs": {"prediction": str(prediction_path), "prediction_units": p_units,
                   "undeformed": str(undeformed_path), "undeformed_units": u_units,
                   "scan": str(scan_path), "scan_units": s_units,
                   "n_scan_points": int(len(sv)), "scan_is_mesh": bool(sf.shape[0])},
        "options": {"init": init if isinstance(init, str) else "given", "region": region,
                    "surface_offset_mm": surface_offset_mm,
                    "tukey_k_mm": tukey_k_mm, "max_distance_mm": max_distance_mm,
                    "icp": "open3d point-to-plane, Tukey loss"},
        "prediction": {"errors": _stats_mm(ps),
                       "registration": _registration_record(pred.registration)},
        "baseline": {"errors": _stats_mm(bs),
                     "registration": _registration_record(base.registration)},
        "summary": (f"the simulation changed the mean scan-to-surface error from "
                    f"{bs['mean'] * MM:.3f} mm (undeformed) to {ps['mean'] * MM:.3f} mm "
                    f"(RMS {bs['rms'] * MM:.3f} -> {ps['rms'] * MM:.3f} mm, max "
                    f"{bs['max'] * MM:.3f} -> {ps['max'] * MM:.3f} mm)"),
        "flags": result["flags"],
        "ok": not result["flags"],
        "files": {"scan_errors": "scan_errors.ply", "prediction_errors": "prediction_errors.ply",
                  "undeformed_errors": "undeformed_errors.ply"},
    }
    with atomic_folder(out) as tmp:
        (tmp / "score.json").write_text(json.dumps(record, indent=2) + "\n")
        write_provenance(tmp, {"inputs": record["inputs"], "options": record["options"]})
        save_ply(tmp / "scan_errors.ply", sv, sf, units=s_units,
                 vertex_scalars={"error_mm": pred.scan_errors * MM,
                                 "baseline_error_mm": base.scan_errors * MM})
        save_ply(tmp / "prediction_errors.ply", pv, pf, units=p_units,
                 vertex_scalars={"distance_to_scan_mm": pred.surface_errors * MM})
        save_ply(tmp / "undeformed_errors.ply", uv, uf, units=u_units,
                 vertex_scalars={"distance_to_scan_mm": base.surface_errors * MM})
    return record

