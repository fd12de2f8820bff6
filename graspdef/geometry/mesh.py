"""Triangle mesh container, validation and vectorised topology helpers.

A mesh is a pair of arrays: ``vertices`` of shape (n, 3), float64, in metres, and ``faces`` of
shape (m, 3), int64, indexing ``vertices``.  Faces are counter-clockwise seen from the side the
normal points to, so normals point outward on closed surfaces.

Half-edge ``3*f + i`` of face ``f`` runs from ``faces[f, i]`` to ``faces[f, (i + 1) % 3]``; every
helper here uses that convention.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from graspdef.errors import MeshError

#: A face is degenerate when ``area <= DEGENERATE_AREA_RTOL * mean_edge_length**2`` (per face).
DEGENERATE_AREA_RTOL = 1e-10

_SHOW = 5  # how many offending items an error message lists


@dataclass(frozen=True, eq=False)
class TriMesh:
    """Triangle mesh.

    Attributes
    ----------
    vertices : ndarray, shape (n_vertices, 3), float64
        Vertex positions [m].
    faces : ndarray, shape (n_faces, 3), int64
        Vertex indices of each triangle, counter-clockwise around the normal.
    """

    vertices: np.ndarray
    faces: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "vertices", np.asarray(self.vertices, dtype=np.float64))
        faces = np.asarray(self.faces)
        if np.issubdtype(faces.dtype, np.integer):
            faces = faces.astype(np.int64, copy=False)
        object.__setattr__(self, "faces", faces)

    @property
    def n_vertices(self) -> int:
        """Number of vertices."""
        return int(self.vertices.shape[0])

    @property
    def n_faces(self) -> int:
        """Number of triangles."""
        return int(self.faces.shape[0])

    def validated(self, name: str = "mesh") -> TriMesh:
        """Run :func:`validate_mesh` on this mesh and return it unchanged.

        Raises
        ------
        MeshError
            If the mesh is unusable; the message starts with ``name``.
        """
        validate_mesh(self.vertices, self.faces, name)
        return self


def _listing(items: np.ndarray) -> str:
    """Format the first few offending indices (or index pairs) and the total count."""
    shown = ", ".join(str(tuple(int(v) for v in it)) if np.ndim(it) else str(int(it))
                      for it in items[:_SHOW])
    return shown + (f", ... ({len(items)} in total)" if len(items) > _SHOW else "")


def _half_edges(faces: np.ndarray) -> np.ndarray:
    """Directed half-edges, shape (3 m, 2); row ``3*f + i`` is ``faces[f, i] -> faces[f, i+1]``."""
    faces = np.asarray(faces, dtype=np.int64)
    return np.stack([faces, np.roll(faces, -1, axis=1)], axis=2).reshape(-1, 2)


def _edge_index(faces: np.ndarray):
    """Map every half-edge onto its undirected edge.

    Returns
    -------
    edges : ndarray, shape (n_edges, 2), int64
        Unique undirected edges ``(a, b)`` with ``a < b``, sorted lexicographically.
    inverse : ndarray, shape (3 m,), int64
        Edge index of each half-edge (see :func:`_half_edges`).
    counts : ndarray, shape (n_edges,), int64
        Number of faces containing each edge.
    order : ndarray, shape (3 m,), int64
        Half-edges sorted by edge index (stable), so the half-edges of each edge are adjacent.
    """
    he = np.sort(_half_edges(faces), axis=1)
    n = int(he.max()) + 1 if he.size else 1
    keys = he[:, 0] * n + he[:, 1]
    order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    first = np.ones(keys.size, dtype=bool)
    first[1:] = sorted_keys[1:] != sorted_keys[:-1]
    inverse = np.empty(keys.size, dtype=np.int64)
    inverse[order] = np.cumsum(first) - 1
    starts = np.flatnonzero(first)
    counts = np.diff(np.append(starts, keys.size))
    edge_keys = sorted_keys[starts]
    return np.stack([edge_keys // n, edge_keys % n], axis=1), inverse, counts, order


def unique_edges(faces: np.ndarray) -> np.ndarray:
    """Undirected edges of a triangle mesh.

    Parameters
    ----------
    faces : ndarray, shape (m, 3), int

    Returns
    -------
    ndarray, shape (n_edges, 2), int64
        Each edge once as ``(a, b)`` with ``a < b``, rows sorted lexicographically.
    """
    return _edge_index(faces)[0]


def edge_face_counts(faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Undirected edges and how many faces contain each.

    Parameters
    ----------
    faces : ndarray, shape (m, 3), int

    Returns
    -------
    edges : ndarray, shape (n_edges, 2), int64
        As :func:`unique_edges`.
    counts : ndarray, shape (n_edges,), int64
        1 for a boundary edge, 2 for an interior edge, more for a non-manifold edge.
    """
    edges, _, counts, _ = _edge_index(faces)
    return edges, counts


def boundary_edges(faces: np.ndarray) -> np.ndarray:
    """Edges that belong to exactly one face, directed as they appear in that face.

    Parameters
    ----------
    faces : ndarray, shape (m, 3), int

    Returns
    -------
    ndarray, shape (k, 2), int64
        Directed boundary edges ``(start, end)``; their face lies to the left when viewed
        against the normal, so boundary loops of a plate in z = 0 with +z normals run
        counter-clockwise on the outer boundary.
    """
    _, inverse, counts, _ = _edge_index(faces)
    return _half_edges(faces)[counts[inverse] == 1]


def boundary_loops(faces: np.ndarray) -> list[np.ndarray]:
    """Closed boundary loops, following the directed boundary edges.

    Parameters
    ----------
    faces : ndarray, shape (m, 3), int

    Returns
    -------
    list of ndarray, each shape (k_i,), int64
        Vertex indices of each loop in traversal order (first vertex not repeated at the end).
        Each loop starts at its smallest vertex index; loops are sorted by that vertex.
        Empty for a closed surface.

    Raises
    ------
    MeshError
        If a vertex has several outgoing boundary edges (non-manifold vertex).
    """
    be = boundary_edges(faces)
    starts = np.unique(be[:, 0])
    if starts.size != be.shape[0]:
        raise MeshError("non-manifold boundary: vertices with more than one outgoing boundary "
                        f"edge {_listing(_repeated(be[:, 0]))}")
    successor = dict(zip(be[:, 0].tolist(), be[:, 1].tolist()))
    loops = []
    for start in starts.tolist():
        if start not in successor:
            continue
        loop = [start]
        v = successor.pop(start)
        while v != start:
            if v not in successor:
                raise MeshError(f"boundary does not close into a loop at vertex {v}")
            loop.append(v)
            v = successor.pop(v)
        loops.append(np.array(loop, dtype=np.int64))
    return loops


def vertex_valence(faces: np.ndarray, n_vertices: int) -> np.ndarray:
    """Number of edges incident to each vertex.

    Parameters
    ----------
    faces : ndarray, shape (m, 3), int
    n_vertices : int

    Returns
    -------
    ndarray, shape (n_vertices,), int64
    """
    return np.bincount(unique_edges(faces).ravel(), minlength=n_vertices).astype(np.int64)


def is_closed(faces: np.ndarray) -> bool:
    """True if the mesh has faces and every edge is shared by exactly two faces."""
    counts = edge_face_counts(faces)[1]
    return bool(counts.size) and bool(np.all(counts == 2))


def _repeated(values: np.ndarray) -> np.ndarray:
    """Values that occur more than once."""
    uniq, counts = np.unique(values, return_counts=True)
    return uniq[counts > 1]


def validate_mesh(vertices: np.ndarray, faces: np.ndarray, name: str = "mesh") -> None:
    """Check that a triangle mesh is usable as a Loop-subdivision control mesh.

    The checks, in order: array shapes and triangle faces, empty mesh, finite coordinates,
    index range, unreferenced vertices, repeated vertex in a face, degenerate faces
    (``area <= DEGENERATE_AREA_RTOL * mean_edge_length**2`` per face), non-manifold edges
    (in more than two faces), inconsistent orientation (an interior edge traversed in the same
    direction by both its faces) and non-manifold vertices (faces around a vertex not forming a
    single fan).

    Parameters
    ----------
    vertices : ndarray, shape (n, 3), float
        Vertex positions [m].
    faces : ndarray, shape (m, 3), int
        Vertex indices of each triangle.
    name : str
        Name of the mesh used at the start of error messages.

    Raises
    ------
    MeshError
        On the first failed check, naming the problem and the first few offending
        vertices, faces or edges.
    """
    def fail(message: str):
        raise MeshError(f"{name}: {message}")

    vertices = np.asarray(vertices)
    faces = np.asarray(faces)
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        fail(f"vertices must have shape (n, 3), got {vertices.shape}")
    if faces.ndim != 2:
        fail(f"faces must have shape (m, 3), got {faces.shape}")
    if faces.shape[1] != 3:
        fail(f"faces must be triangles (3 vertex indices per face), got {faces.shape[1]} per face")
    if vertices.dtype.kind not in "iuf":
        fail(f"vertices must be real numbers, got dtype {vertices.dtype}")
    if not np.issubdtype(faces.dtype, np.integer):
        fail(f"faces must be integer vertex indices, got dtype {faces.dtype}")
    n = vertices.shape[0]
    if n == 0 or faces.shape[0] == 0:
        fail(f"mesh is empty ({n} vertices, {faces.shape[0]} faces)")

    bad = np.flatnonzero(~np.all(np.isfinite(vertices), axis=1))
    if bad.size:
        fail(f"non-finite (NaN or inf) coordinates at vertices {_listing(bad)}")
    bad = np.flatnonzero(np.any((faces < 0) | (faces >= n), axis=1))
    if bad.size:
        fail(f"vertex indices out of range [0, {n}) in faces {_listing(bad)}")
    faces = faces.astype(np.int64, copy=False)
    bad = np.flatnonzero(np.bincount(faces.ravel(), minlength=n) == 0)
    if bad.size:
        fail(f"unreferenced vertices {_listing(bad)}")
    bad = np.flatnonzero((faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2])
                         | (faces[:, 2] == faces[:, 0]))
    if bad.size:
        fail(f"repeated vertex in faces {_listing(bad)}")

    p = vertices.astype(np.float64)[faces]
    e = p[:, [1, 2, 0]] - p
    cross = e[:, 0, [1, 2, 0]] * e[:, 1, [2, 0, 1]] - e[:, 0, [2, 0, 1]] * e[:, 1, [1, 2, 0]]
    area = 0.5 * np.sqrt(np.einsum("ij,ij->i", cross, cross))
    mean_len = np.sqrt(np.einsum("ijk,ijk->ij", e, e)).mean(axis=1)
    bad = np.flatnonzero(area <= DEGENERATE_AREA_RTOL * mean_len**2)
    if bad.size:
        fail(f"degenerate (zero-area) faces {_listing(bad)}")

    edges, inverse, counts, order = _edge_index(faces)
    bad = np.flatnonzero(counts > 2)
    if bad.size:
        fail(f"non-manifold edges (shared by more than 2 faces) {_listing(edges[bad])}")

    he = _half_edges(faces)
    n_forward = np.bincount(inverse[he[:, 0] < he[:, 1]], minlength=edges.shape[0])
    bad = np.flatnonzero((counts == 2) & (n_forward != 1))
    if bad.size:
        bad_faces = np.unique(np.flatnonzero(np.isin(inverse, bad)) // 3)
        fail(f"inconsistent face orientation across edges {_listing(edges[bad])} "
             f"(faces {_listing(bad_faces)}); flip faces so neighbours agree")

    bad = np.flatnonzero(_fans_per_vertex(faces, n, inverse, counts, order) > 1)
    if bad.size:
        fail(f"non-manifold vertices (faces around them form more than one fan) {_listing(bad)}")


def _fans_per_vertex(faces: np.ndarray, n_vertices: int, inverse: np.ndarray,
                     counts: np.ndarray, order: np.ndarray) -> np.ndarray:
    """Number of edge-connected face fans around each vertex, shape (n_vertices,).

    Corner ``c = 3 f + i`` sits at vertex ``faces[f, i]`` and starts half-edge ``c``.  If
    half-edge ``c`` (a -> b) has a twin ``t`` (b -> a), the next corner around ``a`` is the corner
    at the end of ``t``.  The fans are the connected components of these links.  Expects
    manifold edges and the output of :func:`_edge_index`.
    """
    n_corners = inverse.size
    twin = np.full(n_corners, -1)
    h, g = order[counts[inverse[order]] == 2].reshape(-1, 2).T
    twin[h], twin[g] = g, h
    linked = twin >= 0
    t = twin[linked]
    next_corner = 3 * (t // 3) + (t % 3 + 1) % 3
    graph = csr_matrix((np.ones(t.size), next_corner, np.concatenate([[0], np.cumsum(linked)])),
                       shape=(n_corners, n_corners))
    n_fans, fan = connected_components(graph, directed=True, connection="weak")
    fan_vertex = np.empty(n_fans, dtype=np.int64)
    fan_vertex[fan] = faces.ravel()
    return np.bincount(fan_vertex, minlength=n_vertices)
