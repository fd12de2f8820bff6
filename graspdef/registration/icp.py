"""Rigid registration of a scan (points) to a predicted surface (triangle mesh) with open3d.

Procedure (lengths in metres):

1. checks: enough finite points; sizes of scan and surface agree (a millimetre file declared in
   metres is 1000 times too large: refused, naming the likely unit);
2. coarse initialisation: ``"pca"`` (centroids and principal axes with the four proper sign
   choices, plus the identity and the centroid shift; each refined by a coarse ICP on a
   subsample, the best kept), ``"centroid"`` (translation
   only), ``"identity"``, or a given 4x4 transform (e.g. the object's pose in the MuJoCo scene);
3. fine ICP: point-to-plane with Tukey's robust kernel (open3d legacy pipeline; the tensor
   pipeline was 20-150 times slower, ../shared/MEASURED.md), scan points against points sampled
   uniformly on the surface with their face normals;
4. optionally the procedure of Tian & Jia (2010, Sec. IX): align on a region known to be
   undeformed only (the scan points whose closest surface point lies in the region), then
   measure everywhere;
5. convergence check: 5 more ICP iterations from the result must move the scan points along
   the surface normal by less than ``converge_tol`` (RMS); otherwise the result is flagged
   ``not_converged``.  Every ICP runs on one thread (:func:`_icp`), so a registration is a
   function of its input: the same scan and surface give the same transform and flags.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from graspdef.errors import GraspdefError
from graspdef.geometry import TriMesh
from graspdef.units import LENGTH_UNITS

#: Fewest scan points registration accepts.
MIN_POINTS = 100


class RegistrationError(GraspdefError):
    """A scan cannot be registered to a surface (empty, no overlap, wrong units, ...)."""


@dataclass(frozen=True)
class Registration:
    """Result of :func:`register`.

    Attributes
    ----------
    transform : ndarray, shape (4, 4)
        Rigid transform from the scan frame to the surface frame (``x = R p + t``).
    fitness : float
        Fraction of the scan points used within ``max_distance`` of the surface after
        registration (1 = all).
    inlier_rmse : float
        open3d's RMS distance of the fine ICP's correspondences to the surface sample points
        [m] (includes the sample spacing; the scores measure distances to the surface itself).
    converged : bool
        False if further iterations still moved the result by more than the tolerance.
    last_step : tuple of float
        Motion of the convergence check (5 more iterations): RMS motion of the scan points
        along the surface normal [m], and the rotation angle [rad].
    init : str
        The initialisation used.
    flags : list of str
        Problems that did not prevent a result (``not_converged``, ``low_overlap``).
    """

    transform: np.ndarray
    fitness: float
    inlier_rmse: float
    converged: bool
    last_step: tuple[float, float]
    init: str
    n_points: int
    n_region_points: int | None = None
    flags: list[str] = field(default_factory=list)


def apply(transform: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Apply a 4x4 rigid transform to points (n, 3)."""
    return points @ transform[:3, :3].T + transform[:3, 3]


def rotation_angle(rotation: np.ndarray) -> float:
    """Angle [rad] of a 3x3 rotation matrix."""
    return float(np.arccos(np.clip((np.trace(rotation) - 1.0) / 2.0, -1.0, 1.0)))


def _check_points(points) -> np.ndarray:
    points = np.asarray(points, dtype=np.float64)
    if points.size == 0:
        raise RegistrationError("the scan is empty (no points)")
    if points.ndim != 2 or points.shape[-1] != 3:
        raise RegistrationError(f"scan points must have shape (n, 3), got {points.shape}")
    if not np.all(np.isfinite(points)):
        raise RegistrationError("the scan has non-finite (NaN or inf) coordinates")
    if points.shape[0] < MIN_POINTS:
        raise RegistrationError(f"the scan has {points.shape[0]} points; registration needs at "
                                f"least {MIN_POINTS}")
    return points


def _size(points: np.ndarray) -> float:
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))


def check_units(scan_points: np.ndarray, surface: TriMesh, max_ratio: float = 3.0) -> float:
    """Compare the scan's size with the surface's (bounding-box diagonals).

    A partial scan is somewhat smaller than the surface, never several times larger or smaller:
    a ratio beyond ``max_ratio`` (either way) means the scan's declared units are wrong.

    Returns
    -------
    float
        The ratio scan size / surface size.

    Raises
    ------
    RegistrationError
        Naming the ratio and the unit conversion it most likely is.
    """
    ratio = _size(scan_points) / max(_size(surface.vertices), 1e-300)
    if 1.0 / max_ratio <= ratio <= max_ratio:
        return ratio
    factors = {f"{a} declared as {b}": LENGTH_UNITS[a] / LENGTH_UNITS[b]
               for a in LENGTH_UNITS for b in LENGTH_UNITS if a != b}
    # a file in unit a read as unit b is LENGTH_UNITS[b] / LENGTH_UNITS[a] times too large
    likely = min(factors, key=lambda k: abs(math.log(ratio * factors[k])))
    raise RegistrationError(
        f"unit mismatch: the scan is {ratio:.4g} times the size of the surface it is registered "
        f"to (bounding-box diagonals {_size(scan_points) * 1e3:.4g} mm vs "
        f"{_size(surface.vertices) * 1e3:.4g} mm); likely a file in {likely}")


def _o3d():
    """open3d, imported on first use; a clear error if it is missing or cannot load."""
    try:
        import open3d as o3d
    except (ImportError, OSError) as exc:  # OSError: libusb-1.0.so.0 missing (Debian)
        raise RegistrationError(
            f"registration needs open3d ({exc}); install it with `pip install "
            "open3d-cpu==0.20.0` and, on Debian, `apt-get install libusb-1.0-0`") from exc
    return o3d


def _cloud(points: np.ndarray, normals: np.ndarray | None = None):
    o3d = _o3d()
    pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    if normals is not None:
        pc.normals = o3d.utility.Vector3dVector(normals)
    return pc


def sample_surface(mesh: TriMesh, n: int, seed: int = 0, face_mask: np.ndarray | None = None):
    """``n`` points sampled uniformly by area on the mesh (or on the faces of ``face_mask``)
    with their face normals; returns (points, normals)."""
    faces = mesh.faces if face_mask is None else mesh.faces[face_mask]
    if faces.shape[0] == 0:
        raise RegistrationError("the alignment region contains no face of the surface")
    p = mesh.vertices[faces]
    cross = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    area = np.linalg.norm(cross, axis=1)
    normals = cross / np.maximum(area, 1e-300)[:, None]
    rng = np.random.default_rng(seed)
    face = rng.choice(len(area), size=n, p=area / area.sum())
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    tri = p[face]
    pts = tri[:, 0] + u[:, None] * (tri[:, 1] - tri[:, 0]) + v[:, None] * (tri[:, 2] - tri[:, 0])
    return pts, normals[face]


def _icp(source, target, init: np.ndarray, max_distance: float, tukey_k: float,
         iterations: int):
    """open3d's point-to-plane ICP with Tukey's loss, on one thread: with several, its parallel
    sums differ between runs at round-off (1e-13), which the nearly free rotations of a
    symmetric object amplify into different registrations (millimetres apart on a ball) and
    different convergence flags.  One thread makes a registration a function of its input; the
    thread count of the process is restored afterwards."""
    o3d = _o3d()
    reg = o3d.pipelines.registration
    est = reg.TransformationEstimationPointToPlane(reg.TukeyLoss(k=tukey_k))
    crit = reg.ICPConvergenceCriteria(relative_fitness=1e-10, relative_rmse=1e-10,
                                      max_iteration=int(iterations))
    threads = o3d.utility.get_max_threads()
    o3d.utility.set_max_threads(1)
    try:
        return reg.registration_icp(source, target, max_distance, init, est, crit)
    finally:
        o3d.utility.set_max_threads(threads)


def _pca_frame(points: np.ndarray):
    centre = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - centre, full_matrices=False)
    return centre, vt.T  # columns: principal axes, largest first


def _initial_candidates(scan: np.ndarray, target_pts: np.ndarray,
                        init) -> list[tuple[str, np.ndarray]]:
    if isinstance(init, str):
        if init == "identity":
            return [("identity", np.eye(4))]
        c_s, c_t = scan.mean(axis=0), target_pts.mean(axis=0)
        if init == "centroid":
            t = np.eye(4)
            t[:3, 3] = c_t - c_s
            return [("centroid", t)]
        if init == "pca":
            c_s, a_s = _pca_frame(scan)
            c_t, a_t = _pca_frame(target_pts)
            centroid = np.eye(4)
            centroid[:3, 3] = c_t - c_s
            out = [("identity", np.eye(4)), ("centroid", centroid)]
            for sx, sy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
                s = np.diag([sx, sy, 1.0])
                r = a_t @ s @ a_s.T
                if np.linalg.det(r) < 0:
                    s[2, 2] = -1.0
                    r = a_t @ s @ a_s.T
                t = np.eye(4)
                t[:3, :3], t[:3, 3] = r, c_t - r @ c_s
                out.append((f"pca{sx:+d}{sy:+d}", t))
            return out
        raise RegistrationError(f"unknown initialisation {init!r}; use pca, centroid, identity "
                                "or a 4x4 transform")
    t = np.asarray(init, dtype=np.float64)
    if t.shape != (4, 4) or not np.allclose(t[:3, :3] @ t[:3, :3].T, np.eye(3), atol=1e-6) \
            or not np.allclose(t[3], [0, 0, 0, 1]):
        raise RegistrationError("the initial transform must be a 4x4 rigid transform")
    return [("given", t)]


def _region_faces(surface: TriMesh, region) -> np.ndarray:
    if callable(region):
        vmask = np.asarray(region(surface.vertices), dtype=bool)
    else:
        vmask = np.asarray(region, dtype=bool)
    if vmask.shape != (surface.n_vertices,):
        raise RegistrationError(f"the alignment region must give one bool per surface vertex "
                                f"({surface.n_vertices}), got shape {vmask.shape}")
    return vmask[surface.faces].all(axis=1)


def register(scan_points, surface: TriMesh, *, init="pca", region=None,
             max_distance: float | None = None, tukey_k: float = 2e-3,
             iterations: int = 60, n_target: int = 60_000, min_fitness: float = 0.5,
             converge_tol: float = 1e-5, seed: int = 0, coarse: bool = True,
             check_size: bool = True) -> Registration:
    """Register scan points to a surface (see the module docstring).

    Parameters
    ----------
    scan_points : array_like, shape (n, 3)
        The scan [m].
    surface : TriMesh
        Predicted (or undeformed) surface [m], outward normals.
    init : {"pca", "centroid", "identity"} or ndarray (4, 4)
        Coarse initialisation; a 4x4 array is a first guess of the scan → surface transform
        (e.g. the object pose of the MuJoCo scene).
    region : ndarray of bool (n_vertices,) or callable, optional
        Vertices of the surface known to be undeformed (or ``f(vertices) -> bool mask``); if
        given, the fine alignment uses only this region (Tian & Jia 2010, Sec. IX).
    max_distance : float, optional
        Correspondence distance of the fine ICP [m]; default 2 % of the surface's bounding-box
        diagonal, at least 2 mm.
    tukey_k : float
        Scale of Tukey's biweight [m].
    iterations : int
        Largest number of fine ICP iterations.
    n_target : int
        Points sampled on the surface.
    min_fitness : float
        If fewer than this fraction of the scan points lie within ``max_distance`` of the surface
        after registration, the scan does not overlap the surface: RegistrationError.  Below 0.9
        the result is flagged ``low_overlap``.
    coarse : bool
        Refine the initial candidates by coarse ICPs on a subsample (default); if False, the
        fine ICP starts from the first candidate as it is.
    check_size : bool
        Refuse scans whose size does not match the surface's (:func:`check_units`).
    converge_tol : float
        Largest RMS motion along the surface normal [m] of the scan points in 5 further ICP
        iterations for the result to count as converged (default 0.01 mm: the distances would
        change by less than that; motion along the surface, such as a turn of a sphere, changes
        no distance and is not counted).

    Raises
    ------
    RegistrationError
        Empty or too small scan, non-finite points, unit mismatch, no overlap.
    """
    scan = _check_points(scan_points)
    if check_size:
        check_units(scan, surface)
    diag = _size(surface.vertices)
    if max_distance is None:
        max_distance = max(0.02 * diag, 2e-3)
    t_pts, t_nrm = sample_surface(surface, n_target, seed)
    target = _cloud(t_pts, t_nrm)
    source = _cloud(scan)

    # coarse: every candidate refined briefly on a subsample, the best one refined further
    # (open3d builds a k-d tree of the target at every call: the coarse target is small)
    rng = np.random.default_rng(seed)
    sub_cloud = _cloud(scan[rng.choice(len(scan), size=min(len(scan), 1500), replace=False)])
    coarse_target = _cloud(t_pts[:5000], t_nrm[:5000])
    candidates = _initial_candidates(scan, t_pts, init)
    init_name, transform = candidates[0]
    if coarse:
        sub = np.asarray(sub_cloud.points)
        tree = cKDTree(t_pts[:5000])

        def quality(t):
            """(fitness to 2 digits, -point-to-plane RMS of the inliers) of a transform."""
            moved = apply(t, sub)
            dist, idx = tree.query(moved, workers=-1)
            inl = dist <= max_distance
            if not inl.any():
                return (0.0, -np.inf)
            plane = np.einsum("ij,ij->i", moved[inl] - t_pts[idx[inl]], t_nrm[idx[inl]])
            return (round(float(inl.mean()), 2), -float(np.sqrt(np.mean(plane**2))))

        best = None
        for name, t0 in candidates:
            refined = np.asarray(_icp(sub_cloud, coarse_target, t0, 0.1 * diag, 0.05 * diag,
                                      20).transformation)
            for t in (t0, refined):  # an exact first guess may only lose by a coarse step
                key = quality(t)
                if best is None or key > best[0]:
                    best = (key, name, t)
        _, init_name, transform = best
        transform = np.asarray(_icp(sub_cloud, coarse_target, transform, 0.03 * diag,
                                    max(0.015 * diag, tukey_k), 20).transformation)

    n_region = None
    if region is None:
        res = _icp(source, target, transform, max_distance, tukey_k, iterations)
        transform = np.asarray(res.transformation)
        fine_source = source
    else:
        from graspdef.registration.distance import SurfaceDistance

        fmask = _region_faces(surface, region)
        r_pts, r_nrm = sample_surface(surface, n_target, seed, fmask)
        target = _cloud(r_pts, r_nrm)
        dist = SurfaceDistance(surface)
        for _ in range(3):
            face = dist.closest(apply(transform, scan))[2]
            keep = fmask[face]
            n_region = int(keep.sum())
            if n_region < MIN_POINTS:
                raise RegistrationError(f"only {n_region} scan points fall in the alignment "
                                        f"region (need {MIN_POINTS})")
            fine_source = _cloud(scan[keep])
            res = _icp(fine_source, target, transform, max_distance, tukey_k, iterations)
            transform = np.asarray(res.transformation)

    # convergence: how far 5 more iterations move the scan points along the surface normal
    # (sliding along a symmetric surface, e.g. turning a sphere, changes no distance)
    check = _icp(fine_source, target, transform, max_distance, tukey_k, 5)
    step = np.asarray(check.transformation) @ np.linalg.inv(transform)
    used = np.asarray(fine_source.points)
    before = apply(transform, used)
    motion = apply(step, before) - before
    nearest = cKDTree(np.asarray(target.points)).query(before, workers=-1)[1]
    normal_motion = np.abs(np.einsum("ij,ij->i", motion, np.asarray(target.normals)[nearest]))
    moved = float(np.sqrt(np.mean(normal_motion**2)))
    turned = rotation_angle(step[:3, :3])
    converged = moved <= converge_tol

    # overlap over all scan points (not just the region); without a region the check's own
    # fitness is that of all points at (almost exactly) the final transform
    final = check if region is None else _o3d().pipelines.registration.evaluate_registration(
        source, _cloud(t_pts, t_nrm), max_distance, transform)
    flags = [] if converged else ["not_converged"]
    if final.fitness < min_fitness:
        raise RegistrationError(
            f"the scan does not overlap the surface: after registration only "
            f"{final.fitness * 100:.1f} % of its points lie within {max_distance * 1e3:.3g} mm of "
            f"it (need {min_fitness * 100:.0f} %)")
    if final.fitness < 0.9:
        flags.append("low_overlap")
    return Registration(transform, float(final.fitness), float(res.inlier_rmse), converged,
                        (moved, turned), init_name, len(scan), n_region, flags)
