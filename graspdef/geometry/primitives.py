"""Analytic test geometries as validated triangle meshes.

All lengths are in metres and angles in radians.  Structured grids split every cell by the same
diagonal, from its (low, low) to its (high, high) parameter corner, so interior vertices have
valence 6 and straight-edge boundary vertices valence 4.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable

import numpy as np

from graspdef.errors import ProblemError
from graspdef.geometry.mesh import TriMesh


def _positive(value: float, what: str) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise ProblemError(f"{what} must be a number, got {value!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise ProblemError(f"{what} must be a positive finite number, got {value!r}")
    return value


def _count(value: int, what: str, minimum: int = 1) -> int:
    try:
        count = operator.index(value)
    except TypeError:
        raise ProblemError(f"{what} must be an integer, got {value!r}") from None
    if count < minimum:
        raise ProblemError(f"{what} must be >= {minimum}, got {count}")
    return count


def _grid_faces(nu: int, nv: int, periodic_u: bool = False) -> np.ndarray:
    """Faces of an ``nu`` x ``nv`` cell grid, counter-clockwise in the (u, v) parameter plane.

    Vertex ``(i, j)`` has index ``i + j * nu_vertices`` with ``nu_vertices = nu`` if the grid is
    periodic in u (column ``nu`` wraps onto column 0) and ``nu + 1`` otherwise.  Each cell is split
    along its (i, j)-(i+1, j+1) diagonal.

    Returns
    -------
    ndarray, shape (2 nu nv, 3), int64
    """
    row = nu if periodic_u else nu + 1
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="xy")
    v00 = (i + j * row).ravel()
    v10 = ((i + 1) % row + j * row).ravel()
    v01, v11 = v00 + row, v10 + row
    return np.concatenate([np.stack([v00, v10, v11], axis=1),
                           np.stack([v00, v11, v01], axis=1)]).astype(np.int64)


def height_field(f: Callable[[np.ndarray, np.ndarray], np.ndarray],
                 x_range: tuple[float, float], y_range: tuple[float, float],
                 nx: int, ny: int) -> TriMesh:
    """Graph ``z = f(x, y)`` over a rectangle, triangulated like :func:`rectangle`.

    Parameters
    ----------
    f : callable
        Vectorised ``f(x, y)`` taking and returning arrays of shape (n,) [m].
    x_range, y_range : (float, float)
        ``(min, max)`` of the domain [m].
    nx, ny : int
        Number of cells along x and y (>= 1).

    Returns
    -------
    TriMesh
        ``(nx + 1) * (ny + 1)`` vertices, ``2 * nx * ny`` faces, normals with positive z.
    """
    (x0, x1), (y0, y1) = map(float, x_range), map(float, y_range)
    _positive(x1 - x0, "x_range width")
    _positive(y1 - y0, "y_range width")
    nx, ny = _count(nx, "nx"), _count(ny, "ny")
    x, y = np.meshgrid(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1), indexing="xy")
    x, y = x.ravel(), y.ravel()
    z = np.asarray(f(x, y), dtype=np.float64)
    if z.shape != x.shape:
        raise ProblemError(f"height function must return shape {x.shape}, got {z.shape}")
    return TriMesh(np.stack([x, y, z], axis=1), _grid_faces(nx, ny)).validated("height_field")


def rectangle(lx: float, ly: float, nx: int, ny: int,
              center: tuple[float, float] = (0.0, 0.0)) -> TriMesh:
    """Flat rectangular plate in z = 0 with +z normals.

    Parameters
    ----------
    lx, ly : float
        Side lengths [m].
    nx, ny : int
        Number of cells along x and y (>= 1).
    center : (float, float)
        Centre of the plate [m].

    Returns
    -------
    TriMesh
        ``(nx + 1) * (ny + 1)`` vertices (vertex ``(i, j)`` at index ``i + j * (nx + 1)``),
        ``2 * nx * ny`` faces.
    """
    hx, hy = _positive(lx, "lx") / 2, _positive(ly, "ly") / 2
    cx, cy = map(float, center)
    return height_field(lambda x, y: np.zeros_like(x), (cx - hx, cx + hx), (cy - hy, cy + hy),
                        nx, ny)


def square_plate(a: float, n: int) -> TriMesh:
    """Square plate of side ``a`` [m] with ``n`` x ``n`` cells: ``rectangle(a, a, n, n)``.

    Returns
    -------
    TriMesh
        ``(n + 1)**2`` vertices, ``2 n**2`` faces.
    """
    return rectangle(a, a, n, n)


def cylinder(radius: float, length: float, n_theta: int, n_z: int,
             theta0: float = 0.0, theta1: float = 2 * math.pi) -> TriMesh:
    """Open cylindrical tube (or partial arc) about the z axis, z from 0 to ``length``.

    Vertex ``(i, j)`` is at ``(R cos t_i, R sin t_i, z_j)`` with ``t_i`` equally spaced from
    ``theta0`` to ``theta1`` and ``z_j`` from 0 to ``length``.  Normals point away from the axis.

    Parameters
    ----------
    radius, length : float
        [m].
    n_theta, n_z : int
        Number of cells around and along the axis (``n_theta >= 3`` for a full circle).
    theta0, theta1 : float
        Angular extent [rad], ``0 < theta1 - theta0 <= 2 pi``.  A full turn gives a periodic seam
        without duplicated vertices.

    Returns
    -------
    TriMesh
        Full circle: ``n_theta * (n_z + 1)`` vertices; partial arc: ``(n_theta + 1) * (n_z + 1)``
        vertices with straight boundaries at ``theta0`` and ``theta1``.  ``2 n_theta n_z`` faces.
    """
    radius, length = _positive(radius, "radius"), _positive(length, "length")
    span = _positive(float(theta1) - float(theta0), "theta1 - theta0")
    full = math.isclose(span, 2 * math.pi, rel_tol=1e-12)
    if span > 2 * math.pi and not full:
        raise ProblemError(f"theta1 - theta0 must not exceed 2 pi, got {span!r}")
    n_theta = _count(n_theta, "n_theta", 3 if full else 1)
    n_z = _count(n_z, "n_z")
    theta = float(theta0) + span * np.arange(n_theta + (0 if full else 1)) / n_theta
    t, z = np.meshgrid(theta, np.linspace(0.0, length, n_z + 1), indexing="xy")
    vertices = np.stack([radius * np.cos(t), radius * np.sin(t), z], axis=-1).reshape(-1, 3)
    return TriMesh(vertices, _grid_faces(n_theta, n_z, periodic_u=full)).validated("cylinder")


def icosphere(radius: float, subdivisions: int) -> TriMesh:
    """Closed sphere centred at the origin from a subdivided icosahedron, outward normals.

    Parameters
    ----------
    radius : float
        [m]; every vertex lies on the sphere to rounding.
    subdivisions : int
        Number of 1-to-4 refinements of the icosahedron (>= 0).

    Returns
    -------
    TriMesh
        ``10 * 4**subdivisions + 2`` vertices, ``20 * 4**subdivisions`` faces.
    """
    radius = _positive(radius, "radius")
    subdivisions = _count(subdivisions, "subdivisions", 0)
    import trimesh.creation  # here, not at import (start-up: the other primitives need no trimesh)

    ico = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    v = np.array(ico.vertices, dtype=np.float64)
    v *= radius / np.linalg.norm(v, axis=1, keepdims=True)
    return TriMesh(v, np.array(ico.faces, dtype=np.int64)).validated("icosphere")


sphere = icosphere


def ellipsoid(a: float, b: float, c: float, subdivisions: int) -> TriMesh:
    """Closed ellipsoid ``(x/a)**2 + (y/b)**2 + (z/c)**2 = 1``: an icosphere scaled per axis.

    Parameters
    ----------
    a, b, c : float
        Semi-axes along x, y, z [m].
    subdivisions : int
        As :func:`icosphere`.

    Returns
    -------
    TriMesh
        ``10 * 4**subdivisions + 2`` vertices, ``20 * 4**subdivisions`` faces.
    """
    scale = np.array([_positive(a, "a"), _positive(b, "b"), _positive(c, "c")])
    unit = icosphere(1.0, subdivisions)
    return TriMesh(unit.vertices * scale, unit.faces).validated("ellipsoid")


def _hex_ring_faces(k: int, start: int) -> np.ndarray:
    """Faces of the hexagonal lattice strip between ring ``k`` and ring ``k + 1``.

    Ring ``k`` has ``6 k`` vertices (1 for ``k = 0``) numbered counter-clockwise from ``start``;
    ring ``k + 1`` follows immediately.  Side ``s`` of ring ``k`` holds local indices
    ``s k .. s k + k - 1``.  The strip has ``12 k + 6`` triangles, counter-clockwise seen from +z.
    """
    n_in, n_out = max(6 * k, 1), 6 * (k + 1)
    s, t = np.meshgrid(np.arange(6), np.arange(k + 1), indexing="ij")
    s, t = s.ravel(), t.ravel()
    inner = start + (s * k + t) % n_in  # inner (s, t)
    outer = start + n_in + s * (k + 1) + t  # outer (s, t)
    outer_next = start + n_in + (s * (k + 1) + t + 1) % n_out  # outer (s, t + 1)
    inner_next = start + (s * k + t + 1) % n_in  # inner (s, t + 1)
    return np.concatenate([np.stack([outer, outer_next, inner], axis=1),
                           np.stack([inner, outer_next, inner_next], axis=1)[t < k]])


def hemisphere(radius: float, n_rings: int, hole_angle: float = 0.0) -> TriMesh:
    """Upper hemisphere ``z >= 0`` with a free edge on the equator in the plane z = 0.

    The mesh is a triangulated hexagon of a regular triangle lattice mapped onto the sphere:
    ring ``k`` has ``6 k`` vertices (ring 0 is the pole) equally spaced in azimuth starting at
    azimuth 0, at polar angle ``phi_k = k / n_rings * pi / 2``.  Every interior vertex has
    valence 6 and every vertex lies on the sphere to rounding.  Normals point outward.

    With ``hole_angle > 0`` the rings ``k0 .. n_rings`` are kept, with
    ``k0 = max(1, round(n_rings * hole_angle / (pi / 2)))`` (which must be below ``n_rings``) and
    ``phi_k = hole_angle + (k - k0) / (n_rings - k0) * (pi / 2 - hole_angle)``, so the cap
    inside ring ``k0`` is removed and a free edge lies exactly at polar angle ``hole_angle``.

    Parameters
    ----------
    radius : float
        [m].
    n_rings : int
        Index of the equator ring (>= 1).
    hole_angle : float
        Polar angle of the hole's edge [rad], ``0 <= hole_angle < pi / 2``.

    Returns
    -------
    TriMesh
        Without a hole: ``3 n (n + 1) + 1`` vertices and ``6 n**2`` faces (``n = n_rings``);
        with a hole: ``3 n (n + 1) - 3 k0 (k0 - 1)`` vertices and ``6 (n**2 - k0**2)`` faces.
    """
    radius = _positive(radius, "radius")
    n = _count(n_rings, "n_rings")
    hole_angle = float(hole_angle)
    if not 0.0 <= hole_angle < math.pi / 2:
        raise ProblemError(f"hole_angle must be in [0, pi/2), got {hole_angle!r}")
    if hole_angle > 0:
        k0 = max(1, round(n * hole_angle / (math.pi / 2)))
        if k0 >= n:
            raise ProblemError(f"hole_angle {hole_angle!r} leaves no rings with n_rings = {n}; "
                               "increase n_rings")
    else:
        k0 = 0
    rings = np.arange(k0, n + 1)
    sizes = np.maximum(6 * rings, 1)
    starts = np.cumsum(sizes) - sizes
    ring = np.repeat(rings, sizes)
    local = np.arange(ring.size) - np.repeat(starts, sizes)
    azimuth = 2 * math.pi * local / sizes[ring - k0]
    phi = hole_angle + (ring - k0) / (n - k0) * (math.pi / 2 - hole_angle)
    vertices = radius * np.stack([np.sin(phi) * np.cos(azimuth), np.sin(phi) * np.sin(azimuth),
                                  np.cos(phi)], axis=1)
    vertices[ring == n, 2] = 0.0
    faces = np.concatenate([_hex_ring_faces(k, start) for k, start in zip(rings[:-1], starts)])
    return TriMesh(vertices, faces).validated("hemisphere")


def monkey_saddle(half_width: float = 50.0, n: int = 16, scale: float = 5000.0) -> TriMesh:
    """Monkey saddle ``x**3 - 3 x y**2 = scale * z`` over ``[-half_width, half_width]**2``.

    Parameters
    ----------
    half_width : float
        Half the side of the square domain [m].
    n : int
        Number of cells per side.
    scale : float
        Coefficient [m**2] (non-zero).

    Returns
    -------
    TriMesh
        ``(n + 1)**2`` vertices, ``2 n**2`` faces, triangulated like :func:`rectangle`.
    """
    h = _positive(half_width, "half_width")
    scale = float(scale)
    if not (math.isfinite(scale) and scale != 0):
        raise ProblemError(f"scale must be a non-zero finite number, got {scale!r}")
    return height_field(lambda x, y: (x**3 - 3 * x * y**2) / scale, (-h, h), (-h, h), n, n)


def annulus(r_inner: float, r_outer: float, n_theta: int, n_r: int,
            slit: float | None = None) -> TriMesh:
    """Flat annular plate ``r_inner <= r <= r_outer`` in z = 0 with +z normals, a structured grid.

    Vertex ``(i, j)`` is at ``r_j (cos t_i, sin t_i, 0)`` with ``r_j`` equally spaced from
    ``r_inner`` (``j = 0``) to ``r_outer`` (``j = n_r``) and ``t_i`` equally spaced in azimuth;
    the ``n_theta`` x ``n_r`` cells are split like :func:`cylinder`'s, so interior vertices have
    valence 6 and the vertices on both circles valence 4.

    With ``slit`` (an azimuth [rad]) the ring is cut open along the ray ``theta = slit``: the
    first azimuth is ``slit`` and the column of vertices there is duplicated at ``slit + 2 pi``
    (bit-identical positions), so the two lips of the cut are separate boundary edges -- free
    edges of the subdivision surface.  The lip whose faces lie at ``theta`` just above ``slit``
    is vertex column 0, the other column ``n_theta``.

    Parameters
    ----------
    r_inner, r_outer : float
        Radii [m], ``0 < r_inner < r_outer``.
    n_theta, n_r : int
        Number of cells around (>= 3; >= 4 with a slit) and across the ring (>= 1).
    slit : float, optional
        Azimuth of the cut [rad]; ``None`` (default) for a closed ring.

    Returns
    -------
    TriMesh
        Closed ring: ``n_theta (n_r + 1)`` vertices; slit ring: ``(n_theta + 1) (n_r + 1)``.
        ``2 n_theta n_r`` faces.
    """
    r_inner, r_outer = _positive(r_inner, "r_inner"), _positive(r_outer, "r_outer")
    if r_inner >= r_outer:
        raise ProblemError(f"r_inner must be smaller than r_outer, got r_inner = {r_inner!r}, "
                           f"r_outer = {r_outer!r}")
    open_ring = slit is not None
    n_theta = _count(n_theta, "n_theta", 4 if open_ring else 3)
    n_r = _count(n_r, "n_r")
    if open_ring:
        slit = float(slit)
        if not math.isfinite(slit):
            raise ProblemError(f"slit must be a finite angle, got {slit!r}")
    t0 = slit if open_ring else 0.0
    theta = t0 + 2 * math.pi * np.arange(n_theta) / n_theta
    t, r = np.meshgrid(theta, np.linspace(r_inner, r_outer, n_r + 1), indexing="xy")
    ring = np.stack([r * np.cos(t), r * np.sin(t), np.zeros_like(r)], axis=-1)   # (n_r+1, n_theta, 3)
    if open_ring:
        ring = np.concatenate([ring, ring[:, :1]], axis=1)        # the second lip: same positions
    # (theta, r) is clockwise in the plane: reverse the grid's faces for +z normals
    faces = _grid_faces(n_theta, n_r, periodic_u=not open_ring)[:, [0, 2, 1]]
    return TriMesh(ring.reshape(-1, 3), faces).validated("annulus")


def _segments_cross(p: np.ndarray, q: np.ndarray, adjacent_ok: bool) -> np.ndarray:
    """Pairs ``(i, k)`` of closed polygon edges ``p[i] -> p[i+1]`` and ``q[k] -> q[k+1]`` that
    intersect or touch (shared end points of neighbouring edges of one polygon excepted when
    ``adjacent_ok``).  Exact orientation tests on the given floats, O(n m)."""
    a, b = p, np.roll(p, -1, axis=0)
    c, d = q, np.roll(q, -1, axis=0)

    def orient(u, v, w):
        return np.sign((v[..., 0] - u[..., 0]) * (w[..., 1] - u[..., 1])
                       - (v[..., 1] - u[..., 1]) * (w[..., 0] - u[..., 0]))

    A, B, C, D = a[:, None], b[:, None], c[None, :], d[None, :]
    o1, o2, o3, o4 = orient(A, B, C), orient(A, B, D), orient(C, D, A), orient(C, D, B)
    proper = (o1 * o2 < 0) & (o3 * o4 < 0)

    def on(u, v, w, o):                     # w on segment u-v, given orient(u, v, w) == 0
        lo, hi = np.minimum(u, v), np.maximum(u, v)
        return (o == 0) & np.all((lo <= w) & (w <= hi), axis=-1)

    touch = on(A, B, C, o1) | on(A, B, D, o2) | on(C, D, A, o3) | on(C, D, B, o4)
    hit = proper | touch
    if adjacent_ok:                          # p is q: neighbouring edges share their end point,
        n = len(p)                           # and only a reversal (a spike) makes them overlap
        i, j = np.arange(n), (np.arange(n) + 1) % n
        hit[i, i] = False
        e = b - a
        spike = (orient(a, b, b[j]) == 0) & (np.einsum("ij,ij->i", e, e[j]) < 0)
        hit[i, j] = hit[j, i] = spike
    return np.argwhere(hit)


def _signed_area(p: np.ndarray) -> float:
    """Shoelace area of a closed polygon [m^2], positive when counter-clockwise."""
    q = np.roll(p, -1, axis=0)
    return 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))


def _inside(points: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Even-odd point-in-polygon test, (n,) bool (points on an edge count either way)."""
    x, y = points[:, 0:1], points[:, 1:2]
    a, b = poly[None, :], np.roll(poly, -1, axis=0)[None, :]
    straddle = (a[..., 1] > y) != (b[..., 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = a[..., 0] + (y - a[..., 1]) * (b[..., 0] - a[..., 0]) / (b[..., 1] - a[..., 1])
    return (np.count_nonzero(straddle & (x < xc), axis=1) % 2) == 1


def _polygon_array(points, what: str) -> np.ndarray:
    try:
        p = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError):
        raise ProblemError(f"{what} must be a list of [x, y] points, got {points!r}") from None
    if p.ndim != 2 or p.shape[1] != 2:
        raise ProblemError(f"{what} must be a list of [x, y] points, got shape {p.shape}")
    if len(p) < 3:
        raise ProblemError(f"{what} needs at least 3 points, got {len(p)}")
    if not np.all(np.isfinite(p)):
        raise ProblemError(f"{what} has non-finite coordinates")
    if np.allclose(p[0], p[-1], rtol=0, atol=0):
        p = p[:-1]                                   # a closing repeat of the first point
    step = np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)
    if np.any(step == 0):
        raise ProblemError(f"{what} repeats point {int(np.flatnonzero(step == 0)[0]) + 1} "
                           "(zero-length edge)")
    return p


def _subdivided(p: np.ndarray, h: float) -> np.ndarray:
    """The closed polygon with each edge split into ``ceil(length / h)`` equal pieces."""
    q = np.roll(p, -1, axis=0)
    parts = []
    for a, b in zip(p, q):
        k = max(1, math.ceil(np.linalg.norm(b - a) / h - 1e-9))
        s = np.arange(k)[:, None] / k
        parts.append(a + s * (b - a))
    return np.concatenate(parts)


def _boundary_row(loops: list[np.ndarray], outer: np.ndarray, holes: list[np.ndarray]) -> np.ndarray:
    """Apex points of equilateral triangles on the boundary pieces, inside the domain (k, 2).

    Each piece ``a -> b`` (domain on its left) gets the point ``(a + b) / 2 + sqrt(3) / 2 |b - a| n``
    with ``n`` its inward normal, unless that point lies within ``0.95 |b - a|`` of another
    boundary point (near corners and narrow parts) or within ``0.8 |b - a|`` of an apex already
    kept.  Meshed with these points, a boundary vertex on a straight part lies in exactly three
    triangles (valence 4), as on :func:`rectangle`'s edges: the ghost layer then makes it regular
    and the limit boundary curve of a straight boundary is straight.  With Delaunay
    refinement alone, boundary vertices in four or more triangles pull the limit curve inward
    (measured: a clamped square plate 4-7 % too flexible at 200-3,000 vertices).
    """
    from scipy.spatial import cKDTree

    a = np.concatenate(loops)
    b = np.concatenate([np.roll(q, -1, axis=0) for q in loops])
    d = b - a
    length = np.linalg.norm(d, axis=1)
    normal = np.stack([-d[:, 1], d[:, 0]], axis=1) / length[:, None]
    apex = 0.5 * (a + b) + (math.sqrt(3) / 2) * length[:, None] * normal
    near = cKDTree(a).query(apex, k=1)[0]
    keep = (near >= 0.95 * length) & _inside(apex, outer)
    for q in holes:
        keep &= ~_inside(apex, q)
    kept: list[int] = []
    tree_pts: list[np.ndarray] = []
    for i in np.flatnonzero(keep):
        if tree_pts and np.min(np.linalg.norm(np.array(tree_pts) - apex[i], axis=1)) < 0.8 * length[i]:
            continue
        kept.append(int(i))
        tree_pts.append(apex[i])
    return apex[kept] if kept else np.zeros((0, 2))


def midpoint_refined(mesh: TriMesh, levels: int = 1) -> TriMesh:
    """``mesh`` with every triangle split into four at its edge midpoints, ``levels`` times.

    The vertices stay where they are and each new one lies at its edge's midpoint, so a flat
    mesh stays flat and its boundary keeps its shape; every new vertex is regular (valence 6
    inside, 4 on a boundary), so the coarse mesh's irregular vertices end up isolated.  Loop
    subdivision reproduces quadratic fields only around regular vertices: on a mesh in which a
    fixed fraction of the vertices is irregular (any Delaunay mesh) the bending error does not
    fall under refinement, while midpoint refinement of a fixed coarse mesh converges
    (measured on clamped and simply supported square plates: docs in :func:`polygon`).

    Returns
    -------
    TriMesh
        ``4**levels`` times the faces; vertex ``i`` of ``mesh`` keeps index ``i``.
    """
    levels = _count(levels, "levels", 0)
    v, f = mesh.vertices, mesh.faces
    for _ in range(levels):
        he = np.stack([f, np.roll(f, -1, axis=1)], axis=-1).reshape(-1, 2)   # 3 k + i: f[k, i] -> f[k, i+1]
        edges, inverse = np.unique(np.sort(he, axis=1), axis=0, return_inverse=True)
        m = len(v) + inverse.reshape(-1, 3)                  # midpoint of edge i of each face
        v = np.concatenate([v, 0.5 * (v[edges[:, 0]] + v[edges[:, 1]])])
        a, b, c = f.T
        m0, m1, m2 = m.T
        f = np.concatenate([np.stack(t, axis=1) for t in
                            ((a, m0, m2), (m0, b, m1), (m2, m1, c), (m0, m1, m2))])
    return TriMesh(v, f)


#: triangle's quality bound: no angle below this [deg] (Shewchuk's Triangle is proven to
#: terminate for bounds up to about 33.8 degrees)
POLYGON_MIN_ANGLE_DEG = 30.0


def polygon(outer, holes=(), edge_length: float = 1.0, refinements: int = 2,
            max_vertices: int = 2_000_000) -> TriMesh:
    """Flat polygon with polygonal holes in z = 0 (+z normals), a quality triangle mesh.

    The boundaries are first split into pieces of at most ``edge_length``; the domain is then
    meshed by Shewchuk's Triangle (the ``triangle`` package: constrained conforming Delaunay
    refinement) with no angle below :data:`POLYGON_MIN_ANGLE_DEG` and no triangle larger than
    the equilateral one of side ``edge_length``.  Interior vertices have valence 6 on average
    (4 to 8 in practice; irregular ones get Loop's extraordinary-vertex patches), the control
    mesh covers the polygon exactly and every boundary edge lies on the given polygon.

    Parameters
    ----------
    outer : (n, 2) array_like
        Outer boundary [m], counter-clockwise (it sets the +z normal), simple, >= 3 points;
        a last point repeating the first is dropped.
    holes : sequence of (m, 2) array_like
        Hole boundaries [m] (either orientation), each simple, strictly inside ``outer`` and
        disjoint from the other holes.
    edge_length : float
        Target edge length [m] of the final mesh.
    refinements : int
        Number of midpoint refinements (:func:`midpoint_refined`) of the coarse Triangle mesh,
        whose target edge length is ``edge_length * 2**refinements`` (it must be below the
        polygon's diameter).  Refining a fixed coarse mesh (``refinements`` up by one,
        ``edge_length`` halved) is the convergent sequence.
    max_vertices : int
        Refuse an ``edge_length`` that would need more vertices than this (estimated from the
        area) before meshing.

    Returns
    -------
    TriMesh

    Raises
    ------
    ProblemError
        Naming the first defect: fewer than 3 points, a repeated point, a self-intersection,
        a clockwise or zero-area outer boundary, a hole crossing or outside the outer boundary
        or another hole, a bad ``edge_length``.
    """
    try:
        import triangle
    except ImportError:                         # pragma: no cover - a declared dependency
        raise ProblemError("polygon meshing needs the 'triangle' package (pip install triangle)") from None
    h = _positive(edge_length, "edge_length")
    refinements = _count(refinements, "refinements", 0)
    coarse = h * 2 ** refinements
    p = _polygon_array(outer, "outer polygon")
    hs = [_polygon_array(q, f"hole {k + 1}") for k, q in enumerate(holes)]
    for name, q in [("outer polygon", p)] + [(f"hole {k + 1}", q) for k, q in enumerate(hs)]:
        bad = _segments_cross(q, q, adjacent_ok=True)
        bad = bad[bad[:, 0] < bad[:, 1]]
        if len(bad):
            i, k = (int(v) + 1 for v in bad[0])
            raise ProblemError(f"{name} is self-intersecting (edges {i} and {k} meet; edge i runs "
                               "from point i to point i + 1)")
        scale = float(np.ptp(q, axis=0).max())
        if abs(_signed_area(q)) <= 1e-12 * scale ** 2:
            raise ProblemError(f"{name} is degenerate (zero area)")
    area = _signed_area(p)
    if area < 0:
        raise ProblemError("outer polygon is clockwise; list its points counter-clockwise "
                           "(the plate's normal is +z)")
    diameter = float(np.max(np.linalg.norm(p[:, None] - p[None, :], axis=-1)))
    if coarse >= diameter:
        raise ProblemError(f"edge_length x 2**refinements = {coarse:.6g} is not below the polygon's diameter "
                           f"{diameter:.6g}: too few cells (shorten edge_length or use fewer refinements)")
    for k, q in enumerate(hs):
        if len(_segments_cross(p, q, adjacent_ok=False)) or not _inside(q, p).all():
            raise ProblemError(f"hole {k + 1} is not strictly inside the outer polygon")
        for j in range(k):
            if (len(_segments_cross(hs[j], q, adjacent_ok=False)) or _inside(q[:1], hs[j])[0]
                    or _inside(hs[j][:1], q)[0]):
                raise ProblemError(f"holes {j + 1} and {k + 1} overlap")
    est = (abs(area) - sum(abs(_signed_area(q)) for q in hs)) / (math.sqrt(3) / 4 * h * h) / 2
    if est > max_vertices:
        raise ProblemError(f"edge_length {h!r} would need about {est:.3g} vertices "
                           f"(limit {max_vertices}); use a longer edge_length")
    # every loop with the domain on its left: outer counter-clockwise, holes clockwise
    loops = [_subdivided(q if k == 0 or _signed_area(q) < 0 else q[::-1], coarse)
             for k, q in enumerate([p] + hs)]
    starts = np.cumsum([0] + [len(q) for q in loops])
    segments = np.concatenate([s + np.stack([np.arange(len(q)), (np.arange(len(q)) + 1) % len(q)], 1)
                               for s, q in zip(starts, loops)])
    boundary = np.concatenate(loops)
    data = {"vertices": np.concatenate([boundary, _boundary_row(loops, p, hs)])}
    data["segments"] = segments
    if hs:                                   # a point inside each hole: a triangle of the hole's own mesh
        seeds = []
        for q in hs:
            t = triangle.triangulate({"vertices": q, "segments": np.stack(
                [np.arange(len(q)), (np.arange(len(q)) + 1) % len(q)], 1)}, "pQ")
            seeds.append(t["vertices"][t["triangles"][0]].mean(axis=0))
        data["holes"] = np.array(seeds)
    max_area = math.sqrt(3) / 4 * coarse * coarse
    # p: planar straight-line graph, q: minimum angle, a: maximum area, Y: no Steiner points on the
    # boundary (kept as split above), Q: quiet
    out = triangle.triangulate(data, f"pq{POLYGON_MIN_ANGLE_DEG:g}a{max_area:.17g}YQ")
    xy, tri = out["vertices"], np.asarray(out["triangles"], dtype=np.int64)
    used = np.unique(tri)
    remap = np.full(len(xy), -1, np.int64)
    remap[used] = np.arange(len(used))
    vertices = np.column_stack([xy[used], np.zeros(len(used))])
    faces = remap[tri]
    e1, e2 = vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]]
    flip = (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) < 0
    faces[flip] = faces[flip][:, [0, 2, 1]]
    return midpoint_refined(TriMesh(vertices, faces), refinements).validated("polygon")


def _boundary_vertices(faces: np.ndarray) -> np.ndarray:
    """Vertices on edges that belong to one face only."""
    f = np.asarray(faces, dtype=np.int64)
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    u, c = np.unique(e, axis=0, return_counts=True)
    return np.unique(u[c == 1])


def disk(radius: float, edge_length: float = 1.0, refinements: int = 2,
         center: tuple[float, float] = (0.0, 0.0)) -> TriMesh:
    """Flat disk in z = 0 (+z normals) whose boundary converges to the circle under refinement.

    The coarse mesh is :func:`polygon`'s mesh of the inscribed regular polygon with sides of about
    ``edge_length * 2**refinements``; it is then midpoint-refined ``refinements`` times and after
    each split the new boundary vertices are moved radially onto the circle (the interior ones stay
    at their edges' midpoints).  A polygon's boundary stays that polygon under refinement, and a
    simply supported polygon is not a simply supported disk (Babuška's paradox: a 64-gon of
    radius 50 under a central point load, -2.10, -1.72, -2.24, -3.05 % against Timoshenko at
    refinements 0..3, moving away); on the circle the same meshes converge at first order
    (-2.10, -1.01, -0.51 %), and so does this disk from edge length 10 (-3.14, -1.37, -0.56,
    -0.27 % at refinements 0..3; ``tests/benchmarks/test_disk_plate.py``).

    Parameters
    ----------
    radius : float   [m]
    edge_length : float   target edge length [m] of the final mesh
    refinements : int   midpoint refinements of the coarse mesh (the convergent sequence:
        ``refinements`` up by one, ``edge_length`` halved)
    center : (float, float)   [m]
    """
    r = _positive(radius, "radius")
    h = _positive(edge_length, "edge_length")
    levels = _count(refinements, "refinements", 0)
    coarse = h * 2 ** levels
    n = max(8, math.ceil(2 * math.pi * r / coarse))
    th = 2 * np.pi * np.arange(n) / n
    c = np.asarray(center, dtype=float)
    m = polygon(np.c_[r * np.cos(th), r * np.sin(th)], edge_length=coarse, refinements=0)
    for _ in range(levels):
        m = midpoint_refined(m, 1)
        b = _boundary_vertices(m.faces)
        v = m.vertices.copy()
        v[b, :2] *= (r / np.hypot(v[b, 0], v[b, 1]))[:, None]
        m = TriMesh(v, m.faces)
    v = m.vertices.copy()
    v[:, :2] += c
    return TriMesh(v, m.faces).validated("disk")


def spherical_cap(radius: float, rise: float, edge_length: float = 1.0, refinements: int = 2) -> TriMesh:
    """Spherical cap of sphere radius ``radius`` and height ``rise`` over its base circle, apex up
    at (0, 0, rise), base circle in z = 0 (of radius sqrt(rise (2 radius - rise))), outward (+z
    side) normals.

    The mesh is :func:`disk`'s of radius R phi0 (the cap's meridian length; phi0 = acos(1 -
    rise / radius) is its half-angle) wrapped onto the sphere along geodesic polar coordinates: a
    disk point at distance s from the centre goes to the polar angle s / R.  Its boundary vertices
    are on the base circle exactly, and the edge lengths are those of the disk up to the factor
    sin(s/R) / (s/R) around the apex (at least 0.96 up to a 30 degree cap).

    Parameters
    ----------
    radius : float   sphere radius R [m]
    rise : float     height H of the apex over the base plane [m], 0 < H <= R (up to a hemisphere)
    edge_length : float   target edge length [m] of the final mesh (see :func:`disk`)
    refinements : int   midpoint refinements of the coarse mesh (see :func:`disk`)
    """
    R = _positive(radius, "radius")
    H = _positive(rise, "rise")
    if H > R * (1 + 1e-12):
        raise ProblemError(f"rise must not exceed the radius (a cap up to a hemisphere), got rise {H!r} > radius {R!r}")
    phi0 = math.acos(max(1.0 - H / R, 0.0))
    h = _positive(edge_length, "edge_length")
    coarse = h * 2 ** _count(refinements, "refinements", 0)
    if coarse >= 2 * R * phi0:
        raise ProblemError(f"edge_length x 2**refinements = {coarse:g} is not below the cap's width along the "
                           f"sphere, 2 R phi0 = {2 * R * phi0:g}: too few cells (shorten edge_length or use "
                           "fewer refinements)")
    m = disk(R * phi0, h, refinements)
    x, y = m.vertices[:, 0], m.vertices[:, 1]
    phi, th = np.hypot(x, y) / R, np.arctan2(y, x)
    v = np.stack([R * np.sin(phi) * np.cos(th), R * np.sin(phi) * np.sin(th), R * np.cos(phi) - (R - H)], axis=1)
    b = _boundary_vertices(m.faces)
    v[b, 2] = 0.0                    # on the base plane to the last bit (cos(phi0) R - (R - H) rounds)
    return TriMesh(v, m.faces).validated("spherical_cap")
