"""Loop's subdivision rules (Loop 1987) as sparse matrices.

``refine`` maps the control points of a mesh to those of its once-subdivided mesh,
``x_new = S @ x_old``; vertex points come first (same numbering), then one new vertex per edge.
Face ``f`` is split into the four children ``4f .. 4f+3``: the corners at its vertices 0, 1, 2 and
the centre triangle, all keeping the parent's orientation.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .halfedge import interior_mask


def loop_beta(valence: np.ndarray) -> np.ndarray:
    """Loop's vertex weight  beta(n) = (5/8 - (3/8 + cos(2 pi/n)/4)^2) / n."""
    n = np.asarray(valence, dtype=float)
    return (5.0 / 8.0 - (3.0 / 8.0 + 0.25 * np.cos(2.0 * np.pi / n)) ** 2) / n


def limit_weight(valence: np.ndarray) -> np.ndarray:
    """Weight chi of each one-ring neighbour in the limit-position mask of an interior vertex.

    The limit position is ``(1 - n chi) x + chi * sum(neighbours)`` with ``chi = 1/(3/(8 beta) + n)``.
    """
    n = np.asarray(valence, dtype=float)
    return 1.0 / (3.0 / (8.0 * loop_beta(n)) + n)


def mesh_edges(faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unique undirected edges (n_edges, 2) (sorted pairs) and, per face corner, the edge index of
    the face edge that starts there: ``face_edges[f, c]`` is edge (faces[f, c], faces[f, c+1])."""
    f = np.asarray(faces, dtype=np.int64)
    a = f.ravel()
    b = np.roll(f, -1, axis=1).ravel()
    pairs = np.sort(np.stack([a, b], axis=1), axis=1)
    edges, inv = np.unique(pairs, axis=0, return_inverse=True)
    return edges, inv.reshape(f.shape)


def refine(faces: np.ndarray, n_vertices: int) -> tuple[sp.csr_matrix, np.ndarray]:
    """One step of Loop subdivision.

    Interior vertices and edges use Loop's masks; boundary edges the midpoint and boundary
    vertices the cubic B-spline mask 1/8, 3/4, 1/8 (crease rules), so a refined open surface
    keeps its boundary curve.

    Parameters
    ----------
    faces : (n_faces, 3) int
        Oriented triangles.
    n_vertices : int

    Returns
    -------
    S : (n_vertices + n_edges, n_vertices) csr_matrix
        Subdivision matrix.
    new_faces : (4 n_faces, 3) int64
    """
    f = np.asarray(faces, dtype=np.int64)
    nv = int(n_vertices)
    edges, fe = mesh_edges(f)
    ne = len(edges)
    # faces per edge and the vertex opposite each edge in each face
    opp = np.roll(f, -2, axis=1).ravel()          # opposite to edge starting at corner c is corner c+2
    e_flat = fe.ravel()
    count = np.bincount(e_flat, minlength=ne)
    interior_e = count == 2

    rows, cols, vals = [], [], []
    # --- edge points
    e_ids = np.arange(ne)
    w_end = np.where(interior_e, 3.0 / 8.0, 0.5)
    for k in range(2):
        rows.append(nv + e_ids)
        cols.append(edges[:, k])
        vals.append(w_end)
    sel = interior_e[e_flat]
    rows.append(nv + e_flat[sel])
    cols.append(opp[sel])
    vals.append(np.full(sel.sum(), 1.0 / 8.0))

    # --- vertex points
    inner = interior_mask(f, nv)
    val = np.bincount(edges.ravel(), minlength=nv)           # valence (number of edges)
    beta = np.where(inner, loop_beta(np.maximum(val, 3)), 0.0)
    # interior: (1 - n beta) x + beta * sum(neighbours)
    ei = edges[:, 0]
    ej = edges[:, 1]
    rows += [ei, ej]
    cols += [ej, ei]
    vals += [beta[ei], beta[ej]]
    used = np.bincount(f.ravel(), minlength=nv) > 0
    centre = np.where(inner, 1.0 - val * beta, np.where(used, 0.75, 1.0))   # unused vertices stay put
    rows.append(np.arange(nv))
    cols.append(np.arange(nv))
    vals.append(centre)
    # boundary: 1/8 of each boundary neighbour
    b = edges[~interior_e]
    bi, bj = b[:, 0], b[:, 1]
    okb_i = ~inner[bi]
    okb_j = ~inner[bj]
    rows += [bi[okb_i], bj[okb_j]]
    cols += [bj[okb_i], bi[okb_j]]
    vals += [np.full(okb_i.sum(), 0.125), np.full(okb_j.sum(), 0.125)]

    S = sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(nv + ne, nv)
    )
    m = nv + fe                                     # new vertex on edge starting at each corner
    v0, v1, v2 = f[:, 0], f[:, 1], f[:, 2]
    m01, m12, m20 = m[:, 0], m[:, 1], m[:, 2]
    children = np.stack(
        [
            np.stack([v0, m01, m20], 1),
            np.stack([m01, v1, m12], 1),
            np.stack([m20, m12, v2], 1),
            np.stack([m12, m20, m01], 1),
        ],
        axis=1,
    ).reshape(-1, 3)
    return S, children


def limit_positions(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Limit-surface points of the interior control vertices (NaN at boundary vertices)."""
    x = np.asarray(vertices, dtype=float)
    inner = np.flatnonzero(interior_mask(np.asarray(faces, dtype=np.int64), len(x)))
    out = np.full_like(x, np.nan)
    out[inner] = limit_matrix(faces, len(x), inner) @ x
    return out


def limit_matrix(faces: np.ndarray, n_vertices: int, rows: np.ndarray) -> sp.csr_matrix:
    """Sparse (len(rows), n_vertices) map from control points to the limit points of the
    vertices ``rows`` (which must have closed one-rings)."""
    f = np.asarray(faces, dtype=np.int64)
    edges, _ = mesh_edges(f)
    val = np.bincount(edges.ravel(), minlength=n_vertices)
    chi = limit_weight(np.maximum(val, 3))
    rows = np.asarray(rows, dtype=np.int64)
    pos = np.full(n_vertices, -1, np.int64)
    pos[rows] = np.arange(len(rows))
    r, c, v = [pos[rows]], [rows], [1.0 - val[rows] * chi[rows]]
    for s, t in ((0, 1), (1, 0)):
        sel = pos[edges[:, s]] >= 0
        r.append(pos[edges[sel, s]])
        c.append(edges[sel, t])
        v.append(chi[edges[sel, s]])
    return sp.csr_matrix((np.concatenate(v), (np.concatenate(r), np.concatenate(c))),
                         shape=(len(rows), n_vertices))
