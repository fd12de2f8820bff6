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
