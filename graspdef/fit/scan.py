"""Material parameters from a deformed scan (issue 16, item 3): the fit's observations are the
signed distances from the scan's points near the contacts to the predicted deformed surface.

Procedure (lengths in metres, the object's frame), :func:`fit_scan`:

1. the whole scan is registered rigidly (graspdef.registration.register) onto the predicted outer
   surface at the start parameters -- the dents help fix the pose, which matters for a ball, whose
   undeformed part fixes no rotation; or, with ``region``, its fine alignment uses only the scan
   points whose closest predicted point lies in that region (one known to stay undeformed, Tian &
   Jia 2010, Sec. IX, as ``graspdef score --region``): then a start far from the fit (dents much too
   deep or too shallow) cannot pull the pose;
2. the scan points within ``near`` of a load point are kept (at most ``max_points``, a seeded
   subsample): the deformed region, where the parameters show;
3. with that pose fixed, the parameters are fitted (graspdef.fit.fit): per parameter set the
   forward model gives the deformed surface, and each kept point's signed distance to it
   (graspdef.registration.SurfaceDistance; positive outside) is one observation whose measured
   value is 0 (:func:`scan_table`, :class:`ScanModel`);
4. then the scan is registered again onto the prediction at the fitted values and the fit is
   repeated from them (``passes``, default 2): the pose no longer depends on the start.  Each
   pass's registration is reported (how far the pose moved).

A shell model gives its mid-surface: ``offset`` (half the thickness) moves it along its outward
normals to the outer side the scanner saw.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import ProblemError
from ..geometry import TriMesh
from .table import MeasuredTable

#: the point label of a scan observation in a table
SCAN_POINT = "scan"
#: the overlap (fraction of scan points near the surface) the first registration pass accepts: its
#: target, the prediction at the start values, may be far from the scan
FIRST_PASS_MIN_FITNESS = 0.2


def outer(mesh: TriMesh, offset: float) -> TriMesh:
    """``mesh`` moved by ``offset`` [m] along its outward vertex normals (0: unchanged)."""
    if not offset:
        return mesh
    from ..scans.remesh import vertex_normals

    return TriMesh(mesh.vertices + offset * vertex_normals(mesh), mesh.faces)


@dataclass(frozen=True)
class ScanSelection:
    """A deformed scan made ready for a fit.

    points : (m, 3) the kept scan points in the object's frame [m] (registered)
    transform : (4, 4) scan frame -> object frame (the identity when not registered)
    n_scan : points in the scan;  near : the kept radius around the load points [m]
    registration : the registration's summary (fitness, converged, flags), or None
    """

    points: np.ndarray
    transform: np.ndarray
    n_scan: int
    near: float
    registration: dict | None = None

    def to_json(self) -> dict:
        return {"kept_points": int(len(self.points)), "scan_points": self.n_scan, "near_m": self.near,
                "transform_scan_to_object": self.transform.tolist(), "registration": self.registration}


def check_scan(points) -> np.ndarray:
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) == 0 or not np.all(np.isfinite(pts)):
        raise ProblemError(f"the scan must be finite points of shape (n, 3) [m], got shape {pts.shape}")
    return pts


def prepare_scan(points, target: TriMesh | None, load_points, *, near: float, max_points: int = 800,
                 seed: int = 0, init="pca", min_fitness: float = 0.5, region=None) -> ScanSelection:
    """Register the scan ``points`` (n, 3) [m] onto ``target`` (a predicted outer surface, object
    frame; None: the scan is already in the object's frame) and keep the points within ``near`` [m]
    of a load point (see the module docstring).  ``region``: a predicate of the target's vertices
    (n, 3) [m] -> bool, the part to align on (graspdef.registration.register).  Bad input:
    ProblemError or RegistrationError, one line."""
    pts = check_scan(points)
    lp = np.asarray(load_points, dtype=float).reshape(-1, 3)
    if not (np.isfinite(near) and near > 0):
        raise ProblemError(f"near (the radius kept around the load points) must be a positive length, got {near!r} m")
    if not (isinstance(max_points, int) and max_points >= 1):
        raise ProblemError(f"max_points must be a positive integer, got {max_points!r}")
    T, reg = np.eye(4), None
    if target is not None:
        from ..registration.icp import apply, register

        r = register(pts, target, init=init, min_fitness=min_fitness, region=region)
        T = r.transform
        reg = {"fitness": r.fitness, "converged": r.converged, "init": r.init, "flags": list(r.flags),
               "n_region_points": r.n_region_points}
        pts = apply(T, pts)
    d = np.min(np.linalg.norm(pts[:, None, :] - lp[None, :, :], axis=2), axis=1)
    keep = np.flatnonzero(d < near)
    if len(keep) < 3:
        raise ProblemError(f"the scan has {len(keep)} points within near = {near * 1e3:g} mm of the load points: "
                           "nothing to fit (is it the deformed object, in the stated units?)")
    if len(keep) > max_points:
        keep = np.sort(np.random.default_rng(seed).choice(keep, max_points, replace=False))
    return ScanSelection(pts[keep], T, len(pts), float(near), reg)


def scan_table(sel: ScanSelection, force: float, sigma: float | None = None, file=None) -> MeasuredTable:
    """The fit's table: one row per kept point, measured distance 0 at ``force`` [N]; ``sigma``
    [m]: the scan's noise (the rows' weights), None: unweighted."""
    if sigma is not None and not (np.isfinite(sigma) and sigma > 0):
        raise ProblemError(f"the scan's sigma must be a positive length, got {sigma!r} m")
    m = len(sel.points)
    return MeasuredTable(np.full(m, float(force)), np.zeros(m), (SCAN_POINT,) * m,
                         None if sigma is None else np.full(m, float(sigma)), file, {"scan": "m"})


class ScanModel:
    """theta -> signed distances [m] of the kept scan points to ``surface(theta)`` (a TriMesh, the
    object's frame) moved out by ``offset`` [m]; a model for graspdef.fit.fit."""

    def __init__(self, surface: Callable[[dict], TriMesh], sel: ScanSelection, offset: float = 0.0,
                 description: dict | None = None):
        self.surface, self.sel, self.offset = surface, sel, float(offset)
        self.n_solves = 0
        self.description = {"kind": "deformed scan: signed distances of its points near the contacts to the "
                                    "predicted outer surface", "offset_m": self.offset, "scan": sel.to_json(),
                            **(description or {})}

    def __call__(self, theta: dict) -> np.ndarray:
        from ..registration.distance import SurfaceDistance

        mesh = outer(self.surface(theta), self.offset)
        self.n_solves += 1
        return SurfaceDistance(mesh).signed(self.sel.points)


def fit_scan(surface: Callable[[dict], TriMesh], points, load_points, force: float, start: dict, *,
             offset: float = 0.0, near: float, sigma: float | None = None, register: bool = True,
             passes: int = 2, max_points: int = 800, seed: int = 0, init="pca", max_nfev: int = 30,
             region=None, progress: Callable[[dict], None] | None = None):
    """Fit ``start``'s parameters to a deformed scan (module docstring): ``surface(theta)`` the
    predicted mid-surface (object frame), ``points`` the scan [m], ``load_points`` (k, 3) [m],
    ``force`` [N] per finger (the table's), ``offset`` [m] to the outer side, ``sigma`` [m] the
    scan's noise, ``region`` a predicate of surface points [m] -> bool: align on that region only.
    Returns (FitResult, [ScanSelection per pass]); the FitResult's model description holds every
    pass's registration and how far the pose moved between passes."""
    from .estimate import fit
    from ..registration.icp import rotation_angle

    if not (isinstance(passes, int) and passes >= 1):
        raise ProblemError(f"passes must be a positive integer, got {passes!r}")
    pts = check_scan(points)
    theta, sels, res = dict(start), [], None
    if register is False:
        passes = 1
    if sigma is not None and not (np.isfinite(sigma) and sigma > 0):
        raise ProblemError(f"the scan's sigma must be a positive length, got {sigma!r} m")
    for k in range(passes):
        target = outer(surface(theta), offset) if register else None
        # the first pass registers onto the start's prediction, which may be far off (dents three
        # times too deep): it accepts a smaller overlap; the last pass needs the usual 50 %
        sel = prepare_scan(pts, target, load_points, near=near, max_points=max_points, seed=seed, init=init,
                           min_fitness=FIRST_PASS_MIN_FITNESS if k < passes - 1 else 0.5, region=region)
        sels.append(sel)
        model = ScanModel(surface, sel, offset)
        res = fit(model, scan_table(sel, force, sigma), theta, max_nfev=max_nfev, progress=progress)
        theta = {n: res.value(n) for n in res.names}
        if not res.converged:
            break
    # how the passes' poses differ: as a rigid motion (a symmetric object, e.g. a ball, can turn
    # freely about its axis without any distance changing) and by what matters, the RMS distance
    # of the scan's kept points to the fitted surface under each pass's pose
    from ..registration.distance import SurfaceDistance
    from ..registration.icp import apply

    final = SurfaceDistance(outer(surface(theta), offset))
    last = apply(np.linalg.inv(sels[-1].transform), sels[-1].points)          # the kept points, scan frame
    rms = [float(np.sqrt(np.mean(final.signed(apply(sel.transform, last)) ** 2))) for sel in sels]
    moves = [{"translation_m": float(np.linalg.norm(b.transform[:3, 3] - a.transform[:3, 3])),
              "rotation_rad": rotation_angle(b.transform[:3, :3] @ a.transform[:3, :3].T)}
             for a, b in zip(sels[:-1], sels[1:])]
    for k, sel in enumerate(sels):
        sel.registration["rms_to_fitted_surface_m"] = rms[k] if sel.registration is not None else None
    res.start = np.array([float(start[n]) for n in res.names])      # the caller's start (pass 2 starts at pass 1's fit)
    res.model.update({"kind": "deformed scan: signed distances of its points near the contacts to the predicted "
                              "outer surface", "offset_m": float(offset), "force_N": float(force),
                      "passes": [s.to_json() for s in sels], "pose_change_between_passes": moves,
                      "rms_to_fitted_surface_per_pass_m": rms})
    return res, sels
