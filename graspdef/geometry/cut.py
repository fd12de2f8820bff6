"""A patch of a surface around a point: the faces of a control mesh inside a square box over the
tangent plane, the edge-connected piece that holds the point (Tian & Jia 2010, Sec. IX-A: "each
field is defined over a 45 mm x 45 mm patch" around a finger contact; graspdef.pipeline.patch).

The region (:func:`patch_region`): with the outward unit normal ``n`` at the point ``c`` and two
tangent axes ``e1``, ``e2``, a vertex ``x`` is inside when ``|(x - c).e1| <= a/2``,
``|(x - c).e2| <= a/2`` and ``(x - c).n >= -a/2``: a square of side ``a`` in the tangent plane,
extruded along the normal, no deeper than ``a/2`` below the point (so that on a small object the
square's shadow does not reach round onto the far side).  A face is kept when its three vertices
are inside; of the kept faces, the piece connected (through shared edges) to the face nearest the
point is the patch.

Why a square and not a geodesic disc of the same area: the paper states a 45 mm x 45 mm patch, and
the square is what the clamped-plate closed form (Timoshenko: w = 0.0056 P a^2 / D at the centre)
checks; on a curved surface the square is measured in the tangent plane, so along the surface it
is a little larger (on a sphere of radius R, the half-side's arc is R asin(a / 2R): 24.7 mm for
a = 45 mm, R = 33 mm).

The patch must be a disc (one boundary loop, Euler characteristic V - E + F = 1, manifold): a
cut that is empty, covers the whole (closed) surface, or is an annulus or a sphere with holes is
refused with one line (:class:`~graspdef.errors.ProblemError`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from graspdef.errors import MeshError, ProblemError
from graspdef.geometry.mesh import boundary_loops, unique_edges, validate_mesh


@dataclass(frozen=True)
class Patch:
    """A cut piece of a mesh.

    Attributes
    ----------
    vertices : (k, 3) float [m], the piece's vertices
    faces : (m, 3) int64, indexing ``vertices``, oriented as the source mesh
    vertex_index : (k,) int64, each vertex's index in the source mesh
    face_index : (m,) int64, each face's index in the source mesh
    axes : (3, 3) float, rows e1, e2, n: the tangent axes and the outward normal used
    boundary : (b,) int64, the boundary loop (indices into ``vertices``)
    """

    vertices: np.ndarray
    faces: np.ndarray
    vertex_index: np.ndarray
    face_index: np.ndarray
    axes: np.ndarray
    boundary: np.ndarray


def face_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area-weighted normals (m, 3) (length = twice the area; counter-clockwise orientation)."""
    p = np.asarray(vertices, float)[np.asarray(faces, np.int64)]
    return np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])


def outward_normal(vertices: np.ndarray, faces: np.ndarray, point, radius: float) -> np.ndarray:
    """Unit normal at ``point``: the area-weighted mean normal of the faces whose centroids lie
    within ``radius`` [m] of it (the nearest face alone if none does); outward for an outward
    oriented mesh."""
    v, f = np.asarray(vertices, float), np.asarray(faces, np.int64)
    cen = v[f].mean(axis=1)
    d = np.linalg.norm(cen - np.asarray(point, float), axis=1)
    sel = d <= radius
    if not sel.any():
        sel = d == d.min()
    n = face_normals(v, f[sel]).sum(axis=0)
    if np.linalg.norm(n) == 0:
        raise ProblemError("patch: the surface normal at the point is undefined (faces around it cancel)")
    return n / np.linalg.norm(n)


def tangent_axes(normal, axis=None) -> np.ndarray:
    """(3, 3) rows e1, e2, n: ``e1`` is ``axis`` projected onto the tangent plane (default: the
    coordinate axis least aligned with ``normal``), ``e2 = n x e1``."""
    n = np.asarray(normal, float)
    n = n / np.linalg.norm(n)
    a = np.eye(3)[int(np.argmin(np.abs(n)))] if axis is None else np.asarray(axis, float)
    e1 = a - (a @ n) * n
    if np.linalg.norm(e1) < 1e-8:
        raise ProblemError("patch: the axis given is along the surface normal")
    e1 /= np.linalg.norm(e1)
    return np.stack([e1, np.cross(n, e1), n])


def patch_region(vertices: np.ndarray, centre, axes: np.ndarray, size: float) -> np.ndarray:
    """Boolean mask (n,) of the vertices inside the patch's box (see the module docstring)."""
    d = (np.asarray(vertices, float) - np.asarray(centre, float)) @ np.asarray(axes, float).T
    h = 0.5 * size * (1 + 1e-12)
    return (np.abs(d[:, 0]) <= h) & (np.abs(d[:, 1]) <= h) & (d[:, 2] >= -h)


def cut_patch(vertices: np.ndarray, faces: np.ndarray, centre, size: float, normal=None, axis=None,
              name: str = "patch") -> Patch:
    """The patch of side ``size`` [m] around ``centre`` [m] (module docstring).  ``normal``: the
    outward normal there (default: :func:`outward_normal` of the faces within ``size / 8``);
    ``axis``: the direction of the square's first side (default: :func:`tangent_axes`).  Errors
    (one line, ProblemError, starting with ``name``): ``size`` not a positive number, a patch
    without a face, one that covers the whole closed surface (larger than the object), one that
    is not a disc."""
    v = np.asarray(vertices, float)
    f = np.asarray(faces, np.int64)
    c = np.asarray(centre, float)
    if not (isinstance(size, (int, float, np.floating)) and np.isfinite(size) and size > 0):
        raise ProblemError(f"{name}: the patch size must be a positive length, got {size!r}")
    if c.shape != (3,) or not np.all(np.isfinite(c)):
        raise ProblemError(f"{name}: the centre must be three finite numbers, got {centre!r}")
    n = outward_normal(v, f, c, size / 8) if normal is None else np.asarray(normal, float)
    axes = tangent_axes(n, axis)
    inside = patch_region(v, c, axes, size)
    kept = np.flatnonzero(inside[f].all(axis=1))
    if len(kept) == 0:
        raise ProblemError(f"{name}: no face lies wholly inside the {size * 1e3:.3g} mm patch (the control mesh's "
                           "faces are larger than the patch: give a larger patch or refine the mesh)")
    # the edge-connected piece holding the face nearest the centre
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    sub = f[kept]
    he = np.sort(np.stack([sub, np.roll(sub, -1, axis=1)], axis=2).reshape(-1, 2), axis=1)
    key = he[:, 0] * len(v) + he[:, 1]
    order = np.argsort(key, kind="stable")
    same = key[order][1:] == key[order][:-1]
    a, b = order[:-1][same] // 3, order[1:][same] // 3
    graph = coo_matrix((np.ones(len(a)), (a, b)), shape=(len(kept), len(kept)))
    _, label = connected_components(graph, directed=False)
    near = int(np.argmin(np.linalg.norm(v[sub].mean(axis=1) - c, axis=1)))
    piece = kept[label == label[near]]
    used = np.unique(f[piece])
    remap = np.full(len(v), -1, np.int64)
    remap[used] = np.arange(len(used))
    pv, pf = v[used], remap[f[piece]]
    try:
        validate_mesh(pv, pf, name)
        loops = boundary_loops(pf)
    except MeshError as exc:
        raise ProblemError(f"{name}: the {size * 1e3:.3g} mm patch is not a disc-like piece ({exc}); try another "
                           "patch size") from None
    if not loops:
        raise ProblemError(f"{name}: the {size * 1e3:.3g} mm patch covers the whole closed surface: it is larger "
                           "than the object")
    chi = len(pv) - len(unique_edges(pf)) + len(pf)
    if len(loops) != 1 or chi != 1:
        raise ProblemError(f"{name}: the {size * 1e3:.3g} mm patch is not a disc-like piece ({len(loops)} boundary "
                           f"loops, Euler characteristic {chi}; a disc has 1 and 1): the box reaches round the "
                           "object; give a smaller patch")
    return Patch(pv, pf, used.astype(np.int64), piece.astype(np.int64), axes, loops[0])
