"""From a scan to a simulation mesh: a checked watertight manifold control mesh of a chosen size,
and the shell mid-surface (the scanned outer surface offset inward by half the thickness).

Two remeshing methods:

* ``"project"`` — an icosphere of the chosen level is projected radially onto the scan from its
  centroid.  Only for star-shaped closed scans (every ray from the centre must cross the surface
  exactly once; checked).  The result has the icosphere's connectivity (valence 6 except twelve
  valence-5 vertices), the best control mesh for Loop subdivision; its vertices lie on the scan.
* ``"decimate"`` — quadric edge-collapse decimation (Garland & Heckbert 1997, open3d's
  ``simplify_quadric_decimation``) to the chosen number of faces, for any closed scan.
* ``"isotropic"`` — explicit isotropic remeshing (Botsch & Kobbelt 2004: split, collapse, flip,
  tangential smoothing, reprojection; pymeshlab's ``meshing_isotropic_explicit_remeshing``) to the
  edge length of about the chosen number of equilateral faces: near-equilateral triangles
  (smallest angle 23-29 degrees on the mustard bottle and the duck, against 1 degree after
  decimation) and valence 6 almost everywhere, what Loop subdivision converges best on.

Both results are checked: ``validate_mesh`` (manifold, consistently oriented, no degenerate
faces), closed, same Euler characteristic as the scan, outward orientation, and the two-sided
deviation from the scan is measured and reported.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from graspdef.errors import MeshError, ProblemError
from graspdef.geometry import TriMesh, icosphere, is_closed, validate_mesh
from graspdef.geometry.mesh import unique_edges, vertex_valence


@dataclass(frozen=True)
class ControlMeshReport:
    """Checks and measurements of a control mesh made from a scan (lengths in metres).

    Attributes
    ----------
    method : str
    n_vertices, n_faces : int
    euler : int
        Euler characteristic V - E + F (2 for a closed genus-0 surface).
    volume : float
        Enclosed volume [m^3] (positive: normals point outward).
    scan_to_mesh_max, scan_to_mesh_rms : float
        Distance from the scan's vertices to the control mesh [m].
    mesh_to_scan_max : float
        Distance from the control mesh's vertices to the scan [m].
    min_angle_deg : float
        Smallest triangle angle.
    valence_min, valence_max : int
    """

    method: str
    n_vertices: int
    n_faces: int
    euler: int
    volume: float
    scan_to_mesh_max: float
    scan_to_mesh_rms: float
    mesh_to_scan_max: float
    min_angle_deg: float
    valence_min: int
    valence_max: int


def _euler(faces: np.ndarray, n_vertices: int) -> int:
    return int(n_vertices - unique_edges(faces).shape[0] + faces.shape[0])


def clean_scan(mesh: TriMesh) -> TriMesh:
    """Drop duplicate faces and unreferenced vertices of a scan.  Zero-area faces (a few YCB
    scans hold some) are kept, as removing them opens the surface; the remeshing removes them.
    Vertices are not welded: welding can create pinch points."""
    faces = mesh.faces
    _, first = np.unique(np.sort(faces, axis=1), axis=0, return_index=True)
    faces = faces[np.sort(first)]
    used = np.zeros(mesh.n_vertices, dtype=bool)
    used[faces.ravel()] = True
    remap = np.cumsum(used) - 1
    return TriMesh(mesh.vertices[used], remap[faces])


def _closest_distance(points: np.ndarray, mesh: TriMesh) -> np.ndarray:
    """Unsigned distance [m] from each point to the triangle mesh (trimesh, float64)."""
    import trimesh  # here, not at import (start-up: a run whose control mesh is cached needs none)

    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    return np.asarray(trimesh.proximity.closest_point(tm, points)[1], dtype=np.float64)


def _check(mesh: TriMesh, scan: TriMesh, method: str, euler_scan: int) -> ControlMeshReport:
    import trimesh

    name = f"control mesh ({method})"
    validate_mesh(mesh.vertices, mesh.faces, name)
    if not is_closed(mesh.faces):
        raise MeshError(f"{name}: not watertight (has boundary edges)")
    euler = _euler(mesh.faces, mesh.n_vertices)
    if euler != euler_scan:
        raise MeshError(f"{name}: Euler characteristic {euler} differs from the scan's "
                        f"{euler_scan} (topology changed)")
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    volume = float(tm.volume)
    if volume <= 0:
        raise MeshError(f"{name}: normals point inward (enclosed volume {volume:.3g} m^3)")
    d_scan = _closest_distance(scan.vertices, mesh)
    d_mesh = _closest_distance(mesh.vertices, scan)
    angles = np.degrees(tm.face_angles.min())
    val = vertex_valence(mesh.faces, mesh.n_vertices)
    return ControlMeshReport(method, mesh.n_vertices, mesh.n_faces, euler, volume,
                             float(d_scan.max()), float(np.sqrt(np.mean(d_scan**2))),
                             float(d_mesh.max()), float(angles), int(val.min()), int(val.max()))


def _project(scan: TriMesh, n_faces: int) -> TriMesh:
    import trimesh

    level = math.log(n_faces / 20, 4)
    if n_faces < 20 or abs(level - round(level)) > 1e-9:
        raise ProblemError(f"method 'project' makes icospheres: n_faces must be 20 * 4**k "
                           f"(80, 320, 1280, 5120, 20480, ...), got {n_faces}")
    tm = trimesh.Trimesh(scan.vertices, scan.faces, process=False)
    centre = np.asarray(tm.center_mass if tm.is_volume else tm.centroid)
    sphere = icosphere(1.0, int(round(level)))
    dirs = sphere.vertices / np.linalg.norm(sphere.vertices, axis=1, keepdims=True)
    origins = np.broadcast_to(centre, dirs.shape)
    locs, ray_idx, _ = tm.ray.intersects_location(origins, dirs, multiple_hits=True)
    hits = np.bincount(ray_idx, minlength=len(dirs))
    if np.any(hits != 1):
        bad = np.flatnonzero(hits != 1)
        raise MeshError(f"scan is not star-shaped about its centroid: {bad.size} of {len(dirs)} "
                        f"rays cross the surface {sorted(set(hits[bad].tolist()))} times "
                        "(use method='decimate')")
    vertices = np.empty_like(dirs)
    vertices[ray_idx] = locs
    # trimesh's ray hits can sit up to ~0.2 mm off a 16k-face scan (tolerant inside-triangle
    # test): snap each to the closest surface point (a tangential shift of that order)
    vertices = np.asarray(trimesh.proximity.closest_point(tm, vertices)[0])
    return TriMesh(vertices, sphere.faces)


def _decimate(scan: TriMesh, n_faces: int) -> TriMesh:
    try:
        import open3d as o3d  # lazy: only this method needs it
    except (ImportError, OSError) as exc:  # OSError: libusb-1.0.so.0 missing (Debian)
        raise MeshError(f"method 'decimate' needs open3d ({exc}); install open3d-cpu==0.20.0 "
                        "(Debian: libusb-1.0-0), or use method='project'") from exc

    om = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(scan.vertices),
                                   o3d.utility.Vector3iVector(scan.faces.astype(np.int32)))
    out = om.simplify_quadric_decimation(target_number_of_triangles=int(n_faces))
    out.remove_degenerate_triangles()
    out.remove_unreferenced_vertices()
    return TriMesh(np.asarray(out.vertices), np.asarray(out.triangles))


def _isotropic(scan: TriMesh, n_faces: int) -> TriMesh:
    try:
        import pymeshlab  # lazy: only this method needs it
    except ImportError as exc:
        raise MeshError(f"method 'isotropic' needs pymeshlab ({exc}): pip install 'graspdef[objects]'") from exc
    import trimesh

    area = float(trimesh.Trimesh(scan.vertices, scan.faces, process=False).area)
    length = math.sqrt(4.0 * area / (math.sqrt(3.0) * n_faces))     # n_faces equilateral triangles
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(scan.vertices, scan.faces))
    ms.meshing_isotropic_explicit_remeshing(iterations=10, targetlen=pymeshlab.PureValue(length), featuredeg=180)
    m = ms.current_mesh()
    return TriMesh(np.asarray(m.vertex_matrix(), np.float64), np.asarray(m.face_matrix(), np.int64))


def _relax(mesh: TriMesh, scan: TriMesh, iterations: int, step: float = 0.5) -> TriMesh:
    """Tangential umbrella smoothing, each step projected back onto the scan: evens out the
    triangles of a decimated mesh (connectivity unchanged)."""
    import trimesh
    from scipy.sparse import coo_matrix

    tm_scan = trimesh.Trimesh(scan.vertices, scan.faces, process=False)
    e = unique_edges(mesh.faces)
    n = mesh.n_vertices
    adj = coo_matrix((np.ones(2 * len(e)), (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])),
                     shape=(n, n)).tocsr()
    deg = np.asarray(adj.sum(axis=1)).ravel()
    v = mesh.vertices.copy()
    for _ in range(iterations):
        normal = vertex_normals(TriMesh(v, mesh.faces))
        d = adj @ v / deg[:, None] - v
        d -= np.einsum("ij,ij->i", d, normal)[:, None] * normal
        v = np.asarray(trimesh.proximity.closest_point(tm_scan, v + step * d)[0])
    return TriMesh(v, mesh.faces)


def control_mesh(scan: TriMesh, n_faces: int, method: str = "auto", relax: int = 0
                 ) -> tuple[TriMesh, ControlMeshReport]:
    """A watertight, manifold control mesh with about ``n_faces`` faces from a closed scan.

    Parameters
    ----------
    scan : TriMesh
        Closed scan surface [m] (e.g. :func:`graspdef.scans.load_scan`); cleaned first with
        :func:`clean_scan`.
    n_faces : int
        Target number of faces (exact for ``"project"``, which needs ``20 * 4**k``; decimation
        reaches it to within a few faces).
    method : {"auto", "project", "decimate", "isotropic"}
        ``"auto"``: ``"project"`` when ``n_faces`` is an icosphere size and the scan is
        star-shaped, otherwise ``"decimate"``.  ``"isotropic"`` reaches ``n_faces`` to within
        about 10 %.
    relax : int
        Iterations of tangential smoothing projected onto the scan after decimation (0: none).
        Decimated meshes have slivers (smallest angle 1-2 degrees on the YCB mustard bottle and
        the LINEMOD duck); 20 iterations raise it to 14-15 degrees but round off sharp features
        (mustard bottle, 2,000 faces: scan -> mesh max 0.80 -> 2.2 mm; duck, 3,000 faces:
        0.31 -> 0.94 mm).

    Returns
    -------
    mesh : TriMesh
        The validated control mesh [m].
    report : ControlMeshReport
        The checks' measurements (deviation from the scan, Euler characteristic, angles, ...).

    Raises
    ------
    MeshError
        If the scan is not closed, or the result is not a watertight manifold mesh of the scan's
        topology with outward normals.
    ProblemError
        For an unknown method or an impossible size.
    """
    if method not in ("auto", "project", "decimate", "isotropic"):
        raise ProblemError(f"unknown remeshing method {method!r}; use auto, project, decimate or isotropic")
    if int(n_faces) < 20:
        raise ProblemError(f"n_faces must be >= 20, got {n_faces}")
    scan = clean_scan(scan)
    if not is_closed(scan.faces):
        raise MeshError("scan is not closed (has boundary or non-manifold edges): a control mesh "
                        "of a closed object needs a watertight scan")
    euler_scan = _euler(scan.faces, scan.n_vertices)
    if method == "auto":
        level = math.log(max(n_faces, 1) / 20, 4)
        method = "decimate"
        if abs(level - round(level)) < 1e-9 and euler_scan == 2:
            try:
                return control_mesh(scan, n_faces, "project")
            except MeshError:
                pass
    if method == "project":
        mesh = _project(scan, int(n_faces))
    elif method == "isotropic":
        mesh = _isotropic(scan, int(n_faces))
    else:
        mesh = _decimate(scan, int(n_faces))
        if relax:
            mesh = _relax(mesh, scan, int(relax))
            method = f"decimate+relax{int(relax)}"
    return mesh, _check(mesh, scan, method, euler_scan)


def _unit(vectors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows scaled to unit length (rows of length <= 1e-13 left as they are) and which were
    longer -- trimesh.util.unitize's operations, so that the results equal trimesh's to the bit."""
    norm = np.sqrt(np.dot(vectors * vectors, [1.0] * vectors.shape[1]))
    valid = norm > 1e-13
    norm[valid] **= -1
    return vectors * norm.reshape((-1, 1)), valid


def face_unit_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit face normals (m, 3), zero for a degenerate face: trimesh's ``face_normals`` computed
    the same way (equal to the bit, tests/scans/test_scan_remesh.py) without importing trimesh."""
    tri = np.asarray(vertices, np.float64)[np.asarray(faces, np.int64)]
    edges = tri[:, 1:, :] - tri[:, :2, :]
    unit, valid = _unit(np.cross(edges[:, 0], edges[:, 1]))
    unit[~valid] = 0.0
    return unit


def face_angles(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Interior angles (m, 3) [rad] at the faces' corners, all zero for a face with an angle below
    1e-8: trimesh's ``face_angles`` computed the same way (equal to the bit)."""
    tri = np.asarray(vertices, np.float64)[np.asarray(faces, np.int64)]
    u = _unit(tri[:, 1] - tri[:, 0])[0]
    v = _unit(tri[:, 2] - tri[:, 0])[0]
    w = _unit(tri[:, 2] - tri[:, 1])[0]
    out = np.zeros((len(tri), 3), dtype=np.float64)
    out[:, 0] = np.arccos(np.clip(np.dot(u * v, [1.0] * 3), -1, 1))
    out[:, 1] = np.arccos(np.clip(np.dot(-u * w, [1.0] * 3), -1, 1))
    out[:, 2] = np.pi - out[:, 0] - out[:, 1]
    out[(out < 1e-8).any(axis=1), :] = 0.0
    return out


def enclosed_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    """Signed volume [m^3] enclosed by a closed triangle mesh (positive for outward normals): the
    sum of the tetrahedra (origin, a, b, c), a . (b x c) / 6."""
    tri = np.asarray(vertices, np.float64)[np.asarray(faces, np.int64)]
    return float(np.einsum("ij,ij->", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])) / 6.0)


def vertex_normals(mesh: TriMesh) -> np.ndarray:
    """Angle-weighted unit vertex normals (pseudo-normals), shape (n, 3)."""
    fn = face_unit_normals(mesh.vertices, mesh.faces)
    w = face_angles(mesh.vertices, mesh.faces)
    n = np.zeros_like(mesh.vertices)
    for i in range(3):
        np.add.at(n, mesh.faces[:, i], fn * w[:, i:i + 1])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def mid_surface(outer: TriMesh, thickness: float) -> TriMesh:
    """The shell mid-surface: the outer (scanned) surface offset inward by ``thickness / 2``.

    Each vertex moves by ``thickness / 2`` against its angle-weighted normal.  For a closed mesh
    "inward" is against the outward normal (checked by the enclosed volume); for an open mesh it
    is against the faces' orientation.

    Raises
    ------
    ProblemError
        If ``thickness`` is not a positive finite number.
    MeshError
        If a closed mesh's normals point inward, or the offset flips a face (half the thickness
        exceeds a local radius of curvature of the control mesh).
    """
    t = float(thickness)
    if not (math.isfinite(t) and t > 0):
        raise ProblemError(f"thickness must be a positive finite number, got {thickness!r}")
    validate_mesh(outer.vertices, outer.faces, "outer surface")
    closed = is_closed(outer.faces)
    volume = enclosed_volume(outer.vertices, outer.faces) if closed else None
    if closed and volume <= 0:
        raise MeshError("outer surface: normals point inward (negative enclosed volume); "
                        "flip the faces")
    mid = TriMesh(outer.vertices - 0.5 * t * vertex_normals(outer), outer.faces)
    before = face_unit_normals(outer.vertices, outer.faces)
    after = face_unit_normals(mid.vertices, mid.faces)
    flipped = np.flatnonzero(np.einsum("ij,ij->i", before, after) <= 0.0)
    if closed and not 0 < enclosed_volume(mid.vertices, mid.faces) < volume:
        raise MeshError(f"mid-surface offset by {t / 2 * 1e3:.3g} mm turns the surface inside "
                        "out (half the thickness exceeds the object's radius)")
    if flipped.size:
        # where: the shortest edge of the flipped faces (its midpoint) -- a feature that small (a scan's tiny
        # fold or handle, which remeshing keeps to keep the topology) decides it
        tri = outer.vertices[outer.faces[flipped]]
        lengths = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2)      # edge i: corners i, i - 1
        k, i = np.unravel_index(int(np.argmin(lengths)), lengths.shape)
        edge = lengths[k, i]
        at = ", ".join(f"{c * 1e3:.1f}" for c in 0.5 * (tri[k, i] + tri[k, i - 1]))
        raise MeshError(f"mid-surface offset by {t / 2 * 1e3:.3g} mm flips {flipped.size} faces "
                        f"(half the thickness exceeds the local radius of curvature), e.g. at ({at}) mm, "
                        f"where the control mesh has an edge of {edge * 1e3:.3g} mm: a fold or small "
                        "handle of the surface there")
    return mid
