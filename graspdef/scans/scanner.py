"""A structured-light scanner model: synthetic scans of any surface, as a real scanner makes them.

The model, step by step (all lengths in metres):

1. points are sampled uniformly by area on the surface (several times more than kept);
2. visibility from each viewpoint (a turntable: ``n_views`` azimuths around +z at alternating
   elevations): a point is seen from a view if it faces the camera within ``max_incidence_deg``
   and survives hidden-point removal (Katz, Tal & Basri, "Direct visibility of point sets",
   SIGGRAPH 2007: spherical flipping about the camera, then the convex hull);
3. ``n_holes`` holes of radius ``hole_radius`` are cut at random seen points (dark or shiny
   patches that return no data);
4. Gaussian noise of standard deviation ``sigma`` (default 0.127 mm, the accuracy of the
   NextEngine desktop scanner used by Tian & Jia, IEEE T-RO 26(5) 2010, Sec. IX): per axis
   (``noise="isotropic"``), or along the line of sight of the view that saw the point
   (``noise="ray"``);
5. an unknown rigid pose: a uniformly random rotation and a random translation (up to
   ``max_translation``) applied to the points.

Optionally (``triangulate=True``) each view's points are meshed as a range image, the way a
structured-light scanner meshes each view.  The result carries its provenance (source,
settings, seed, the true pose); :func:`write_scan` writes the points (and triangles) as a PLY
file with ``<name>.provenance.json`` next to it.
"""

from __future__ import annotations

import datetime
import hashlib
import json
import math
from dataclasses import asdict, dataclass, field, fields
from os import PathLike
from pathlib import Path

import numpy as np

from graspdef.errors import ProblemError
from graspdef.geometry import TriMesh, ellipsoid, save_ply

#: Noise of the NextEngine desktop 3-D scanner quoted by Tian & Jia (2010), Sec. IX [m].
NEXTENGINE_SIGMA = 0.127e-3


@dataclass(frozen=True)
class Scanner:
    """Settings of the scanner model (lengths in metres, angles in degrees).

    Attributes
    ----------
    sigma : float
        Standard deviation of the Gaussian noise [m].
    noise : {"isotropic", "ray"}
        Per-axis noise, or noise along the line of sight only.
    n_points : int
        Points in the scan (after visibility and holes).
    n_views : int
        Turntable positions (azimuths evenly spaced around +z).
    elevations_deg : tuple of float
        Camera elevations, used in turn for successive views.
    distance : float
        Camera distance from the centre of the object's bounding box [m].
    max_incidence_deg : float
        A point is seen only if the angle between its normal and the line of sight is below this.
    n_holes : int
        Number of holes (regions without data).
    hole_radius : float
        Radius of each hole [m].
    random_pose : bool
        Apply a random rigid motion to the scan (its frame is then unknown to the user).
    max_translation : float
        Largest translation of the random pose [m].
    """

    sigma: float = NEXTENGINE_SIGMA
    noise: str = "isotropic"
    n_points: int = 50_000
    n_views: int = 6
    elevations_deg: tuple[float, ...] = (35.0, -15.0)
    distance: float = 0.4
    max_incidence_deg: float = 80.0
    n_holes: int = 4
    hole_radius: float = 3e-3
    random_pose: bool = True
    max_translation: float = 0.05

    def __post_init__(self) -> None:
        if self.noise not in ("isotropic", "ray"):
            raise ProblemError(f"scanner noise must be 'isotropic' or 'ray', got {self.noise!r}")
        for name in ("sigma", "hole_radius", "max_translation"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ProblemError(f"scanner {name} must be >= 0, got {value!r}")
        if not (math.isfinite(self.distance) and self.distance > 0):
            raise ProblemError(f"scanner distance must be > 0, got {self.distance!r}")
        if self.n_points < 1 or self.n_views < 1 or self.n_holes < 0:
            raise ProblemError("scanner n_points and n_views must be >= 1, n_holes >= 0")
        if not 0 < self.max_incidence_deg <= 90:
            raise ProblemError("scanner max_incidence_deg must be in (0, 90]")


@dataclass(frozen=True)
class SyntheticScan:
    """A synthetic scan.

    Attributes
    ----------
    points : ndarray, shape (n, 3)
        Scanned points in the scan frame [m].
    view : ndarray, shape (n,), int
        Index of the view each point was taken from.
    pose : ndarray, shape (4, 4)
        True rigid transform from the surface's frame to the scan frame
        (``points ≈ R @ x + t`` for surface points x); its inverse is what registration must find.
    provenance : dict
        Source, settings, seed, pose and counts (JSON-serialisable).
    faces : ndarray, shape (m, 3), int
        Triangles of the range-image mesh (``triangulate=True``), empty for a point cloud.
    """

    points: np.ndarray
    view: np.ndarray
    pose: np.ndarray
    provenance: dict = field(default_factory=dict)
    faces: np.ndarray = field(default_factory=lambda: np.empty((0, 3), dtype=np.int64))


def _sample_surface(mesh: TriMesh, n: int, rng: np.random.Generator):
    p = mesh.vertices[mesh.faces]
    cross = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    area = 0.5 * np.linalg.norm(cross, axis=1)
    if not np.any(area > 0):
        raise ProblemError("cannot scan a surface of zero area")
    normals = cross / np.maximum(2 * area, 1e-300)[:, None]
    face = rng.choice(len(area), size=n, p=area / area.sum())
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    tri = p[face]
    pts = tri[:, 0] + u[:, None] * (tri[:, 1] - tri[:, 0]) + v[:, None] * (tri[:, 2] - tri[:, 0])
    return pts, normals[face]


def hidden_point_removal(points: np.ndarray, camera: np.ndarray, gamma: float = 3.0) -> np.ndarray:
    """Indices of the points visible from ``camera`` (Katz, Tal & Basri 2007).

    Spherical flipping about the camera with radius ``R = max|p - C| * 10**gamma``, then the
    points on the convex hull of the flipped set and the camera are the visible ones.
    """
    q = points - camera
    norm = np.linalg.norm(q, axis=1, keepdims=True)
    radius = norm.max() * 10.0**gamma
    flipped = q + 2.0 * (radius - norm) * q / norm
    from scipy.spatial import ConvexHull      # here: scipy.spatial costs every grasp's start-up 0.06 s
    hull = ConvexHull(np.vstack([flipped, np.zeros((1, 3))]))
    idx = hull.vertices
    return idx[idx < len(points)]


def view_directions(n_views: int, elevations_deg=(35.0, -15.0)) -> np.ndarray:
    """Unit vectors from the object to the camera for a turntable scan, shape (n_views, 3)."""
    az = 2 * np.pi * np.arange(n_views) / n_views
    el = np.radians([elevations_deg[i % len(elevations_deg)] for i in range(n_views)])
    return np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)


def _mesh_digest(mesh: TriMesh) -> str:
    h = hashlib.sha256(np.ascontiguousarray(mesh.vertices).tobytes())
    h.update(np.ascontiguousarray(mesh.faces).tobytes())
    return h.hexdigest()[:16]


def _triangulate_views(points: np.ndarray, view: np.ndarray, cameras: np.ndarray,
                       centre: np.ndarray, max_edge_factor: float = 3.0) -> np.ndarray:
    """Range-image meshes: each view's points triangulated in its image plane (Delaunay of the
    perspective projection), triangles with an edge longer than ``max_edge_factor`` times the
    view's median edge dropped (depth jumps, silhouettes, holes), oriented towards the camera."""
    from scipy.spatial import Delaunay

    out = []
    for k, cam in enumerate(cameras):
        idx = np.flatnonzero(view == k)
        if idx.size < 3:
            continue
        axis = (centre - cam) / np.linalg.norm(centre - cam)
        helper = np.array([0.0, 0.0, 1.0]) if abs(axis[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        ex = np.cross(helper, axis)
        ex /= np.linalg.norm(ex)
        ey = np.cross(axis, ex)
        rel = points[idx] - cam
        depth = rel @ axis
        uv = np.stack([rel @ ex / depth, rel @ ey / depth], axis=1)
        tri = Delaunay(uv).simplices
        p = points[idx][tri]
        edges = np.linalg.norm(p - np.roll(p, 1, axis=1), axis=2).max(axis=1)
        tri = tri[edges <= max_edge_factor * np.median(edges)]
        p = points[idx][tri]
        normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        flip = np.einsum("ij,ij->i", normal, cam - p[:, 0]) < 0
        tri[flip] = tri[flip][:, ::-1]
        out.append(idx[tri])
    return np.concatenate(out).astype(np.int64) if out else np.empty((0, 3), dtype=np.int64)


def scan_surface(mesh: TriMesh, scanner: Scanner = Scanner(), seed: int = 0,
                 source: str = "mesh", triangulate: bool = False) -> SyntheticScan:
    """Scan a surface with the scanner model (see the module docstring).

    Parameters
    ----------
    mesh : TriMesh
        The surface [m] (outward normals; any triangle mesh, open or closed).
    scanner : Scanner
        Settings.
    seed : int
        Seed of the random generator: the same seed gives the same scan.
    source : str
        Description of the surface for the provenance (a manifest id or a path).
    triangulate : bool
        Also return a mesh: each view's points triangulated as a range image (as a structured-
        light scanner meshes each view), not fused across views.

    Raises
    ------
    ProblemError
        If fewer than ``scanner.n_points`` points are visible after 4 rounds of sampling.
    """
    rng = np.random.default_rng(seed)
    lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    centre = 0.5 * (lo + hi)
    dirs = view_directions(scanner.n_views, scanner.elevations_deg)
    cameras = centre + scanner.distance * dirs
    cos_max = math.cos(math.radians(scanner.max_incidence_deg))
    n_sample = 3 * scanner.n_points
    for _ in range(4):
        pts, nrm = _sample_surface(mesh, n_sample, rng)
        best_cos = np.full(len(pts), -np.inf)
        view = np.full(len(pts), -1)
        for k, cam in enumerate(cameras):
            sight = cam - pts
            cos = np.einsum("ij,ij->i", nrm, sight) / np.linalg.norm(sight, axis=1)
            facing = np.flatnonzero(cos > cos_max)
            if facing.size < 4:
                continue
            seen = facing[hidden_point_removal(pts[facing], cam)]
            better = seen[cos[seen] > best_cos[seen]]
            best_cos[better], view[better] = cos[better], k
        keep = view >= 0
        holes = np.empty((0, 3))
        if scanner.n_holes and keep.any():
            holes = pts[rng.choice(np.flatnonzero(keep), size=scanner.n_holes)]
            for c in holes:
                keep &= np.linalg.norm(pts - c, axis=1) > scanner.hole_radius
        idx = np.flatnonzero(keep)
        if idx.size >= scanner.n_points or idx.size == 0:
            break
        n_sample = min(int(n_sample * 2.5 * scanner.n_points / idx.size), 50 * scanner.n_points)
    if idx.size < scanner.n_points:
        raise ProblemError(f"the scanner sees only {idx.size} points of the surface, fewer than "
                           f"n_points = {scanner.n_points}")
    idx = np.sort(rng.choice(idx, size=scanner.n_points, replace=False))
    pts, view = pts[idx], view[idx]
    faces = _triangulate_views(pts, view, cameras, centre) if triangulate else \
        np.empty((0, 3), dtype=np.int64)
    if scanner.noise == "isotropic":
        pts = pts + scanner.sigma * rng.standard_normal(pts.shape)
    else:
        sight = cameras[view] - pts
        sight /= np.linalg.norm(sight, axis=1, keepdims=True)
        pts = pts + scanner.sigma * rng.standard_normal((len(pts), 1)) * sight
    pose = np.eye(4)
    if scanner.random_pose:
        from scipy.spatial.transform import Rotation
        pose[:3, :3] = Rotation.random(random_state=rng).as_matrix()
        direction = rng.standard_normal(3)
        pose[:3, 3] = (direction / np.linalg.norm(direction) * scanner.max_translation
                       * rng.random() ** (1 / 3))
        # rotate about the object's centre, so the translation is the centre's displacement
        pose[:3, 3] += centre - pose[:3, :3] @ centre
    pts = pts @ pose[:3, :3].T + pose[:3, 3]
    provenance = {
        "generator": "graspdef.scans.scanner.scan_surface",
        "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "units": "m",
        "source": source,
        "source_digest": _mesh_digest(mesh),
        "seed": int(seed),
        "scanner": {k: (list(v) if isinstance(v, tuple) else v)
                    for k, v in asdict(scanner).items()},
        "n_points": int(len(pts)),
        "n_faces": int(len(faces)),
        "points_per_view": np.bincount(view, minlength=scanner.n_views).tolist(),
        "camera_positions_m": cameras.tolist(),
        "hole_centres_m": holes.tolist(),
        "frames_note": "camera positions and hole centres are in the source surface's frame",
        "pose_source_to_scan": pose.tolist(),
        "pose_note": "points = R @ x + t for x on the source surface; registration should "
                     "recover the inverse",
    }
    return SyntheticScan(pts, view, pose, provenance, faces)


#: recipe keys given in millimetres (scans/manifest.toml) -> Scanner settings in metres
_RECIPE_MM = {"sigma_mm": "sigma", "hole_radius_mm": "hole_radius", "distance_mm": "distance",
              "max_translation_mm": "max_translation"}
#: the keys a generated-scan recipe ([generated.<id>] of the manifest) may hold
RECIPE_KEYS = ("source", "seed", "triangulate") + tuple(sorted(
    ({f.name for f in fields(Scanner)} - set(_RECIPE_MM.values())) | set(_RECIPE_MM)))


def write_scan(scan: SyntheticScan, path: str | PathLike, units: str = "m") -> Path:
    """Write the scan as a PLY point cloud or mesh (``comment units``; per-point ``view``) and
    its provenance as ``<stem>.provenance.json`` next to it.  Returns the PLY path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    save_ply(path, scan.points, scan.faces, units=units,
             vertex_scalars={"view": scan.view.astype(np.float64)})
    prov = dict(scan.provenance, file=path.name, file_units=units)
    path.with_suffix(".provenance.json").write_text(json.dumps(prov, indent=2) + "\n")
    return path


def recipe_surface(source: str, manifest=None) -> TriMesh:
    """The surface a generated-scan recipe names: a real scan id of the manifest, or
    ``"ellipsoid:a,b,c"`` (semi-axes in mm; 4 icosphere subdivisions)."""
    if source.startswith("ellipsoid:"):
        try:
            a, b, c = (float(x) * 1e-3 for x in source.split(":", 1)[1].split(","))
        except ValueError:
            raise ProblemError(f"bad ellipsoid recipe {source!r}; use 'ellipsoid:a,b,c' (mm)") \
                from None
        return ellipsoid(a, b, c, 4)
    from graspdef.scans.manifest import load_scan

    return load_scan(source, manifest)


def generate_scan(scan_id: str, manifest=None, out_dir: str | PathLike | None = None) -> Path:
    """Make the generated scan ``scan_id`` of the manifest from its recipe and write it
    (``out/scans/<id>.ply`` and its provenance).  Returns the PLY path."""
    from graspdef.scans.manifest import load_manifest

    manifest = manifest or load_manifest()
    try:
        recipe = dict(manifest.generated[scan_id])
    except KeyError:
        raise ProblemError(f"unknown generated scan {scan_id!r}; known: "
                           + ", ".join(sorted(manifest.generated))) from None
    source = recipe.pop("source")
    seed = int(recipe.pop("seed", 0))
    triangulate = bool(recipe.pop("triangulate", False))
    settings = {}
    for key, value in recipe.items():
        if key in _RECIPE_MM:
            settings[_RECIPE_MM[key]] = value * 1e-3
        else:
            settings[key] = value
    scanner = Scanner(**settings)
    scan = scan_surface(recipe_surface(source, manifest), scanner, seed=seed, source=source,
                        triangulate=triangulate)
    out = Path(out_dir) if out_dir is not None else manifest.generated_dir
    return write_scan(scan, out / f"{scan_id}.ply")


def load_generated_scan(scan_id: str, manifest=None, out_dir: str | PathLike | None = None,
                        regenerate: bool = False) -> tuple[np.ndarray, dict]:
    """The points [m] and provenance of a generated scan of the manifest, made from its recipe
    first if it is not on disk yet (or ``regenerate``)."""
    from graspdef.scans.manifest import load_manifest, ply_units, read_surface

    manifest = manifest or load_manifest()
    out = Path(out_dir) if out_dir is not None else manifest.generated_dir
    path = out / f"{scan_id}.ply"
    if regenerate or not path.is_file():
        path = generate_scan(scan_id, manifest, out)
    points, _ = read_surface(path, ply_units(path) or "m")
    provenance = json.loads(path.with_suffix(".provenance.json").read_text())
    return points, provenance
