"""A layer of ghost control vertices around the open boundaries of a control mesh.

Every boundary edge ``a -> b`` of a face ``(a, b, c)`` gets a ghost vertex at ``a + b - c`` and a
ghost triangle ``(b, a, g)``.  Around every boundary vertex the outside is then closed by a fan:
as many triangles as bring the vertex to valence 6 (one at a straight edge of a regular mesh,
three at a 90 degree grid corner), with new fan vertices placed by the lattice's parallelogram rule
``r_{k+2} = r_{k+1} - r_k + b`` -- so a boundary of a regular mesh becomes part of a regular
lattice and the limit surface keeps linear precision up to the boundary and into the corners.
Then every real vertex has a closed one-ring, every real face has a complete Loop stencil, and
the ghost triangles are never integrated.  The ghost vertices are ordinary degrees of freedom:
supports are constraints on the limit surface (``graspdef.problem.supports``).  After Cirak,
Ortiz & Schroeder (2000), Sec. 4.3.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import MeshError
from .rules import limit_matrix


@dataclass(frozen=True)
class GhostedMesh:
    """Control mesh extended by a ghost layer.

    Attributes
    ----------
    vertices : (n_real + n_ghost, 3)   real vertices first.
    faces : (n_real_faces + n_ghost_faces, 3)   real faces first.
    n_real : int
    n_real_faces : int
    boundary_edges : (n_edges_b, 2)   directed boundary edges a -> b (real face on the left).
    boundary_faces : (n_edges_b,)     the real face owning each boundary edge.
    extension_map : (n_control, n_real) sparse; rest control points = extension_map @ real points.
    """

    vertices: np.ndarray
    faces: np.ndarray
    n_real: int
    n_real_faces: int
    boundary_edges: np.ndarray
    boundary_faces: np.ndarray
    extension_map: sp.csr_matrix

    @property
    def n_control(self) -> int:
        return len(self.vertices)

    def interpolating(self) -> "GhostedMesh":
        """The same mesh with control points moved so that the limit surface passes through the
        original real vertices (limit point of vertex i = vertices[i]); ghosts re-extrapolated.

        Solves the sparse, diagonally dominant system L E X = P (Loop limit masks L)."""
        E = self.extension_map
        L = limit_matrix(self.faces, self.n_control, np.arange(self.n_real))
        X = spla.splu((L @ E).tocsc()).solve(self.vertices[: self.n_real])
        return GhostedMesh(E @ X, self.faces, self.n_real, self.n_real_faces, self.boundary_edges,
                           self.boundary_faces, E)


def add_ghost_layer(vertices: np.ndarray, faces: np.ndarray) -> GhostedMesh:
    """Extend an oriented manifold triangle mesh by one ring of ghost vertices and triangles.

    A closed mesh is returned unchanged (no ghosts).
    """
    x = np.asarray(vertices, dtype=float)
    f = np.asarray(faces, dtype=np.int64)
    nv, nf = len(x), len(f)
    a = f.ravel()
    b = np.roll(f, -1, axis=1).ravel()
    c = np.roll(f, -2, axis=1).ravel()
    owner = np.repeat(np.arange(nf), 3)
    fwd = a * nv + b
    rev = np.sort(b * nv + a)
    pos = np.minimum(np.searchsorted(rev, fwd), len(rev) - 1)
    bnd = rev[pos] != fwd
    ba, bb, bc, bf = a[bnd], b[bnd], c[bnd], owner[bnd]
    ng = len(ba)
    if ng == 0:
        return GhostedMesh(x, f, nv, nf, np.zeros((0, 2), np.int64), np.zeros(0, np.int64),
                           sp.identity(nv, format="csr"))
    if np.bincount(bb, minlength=nv).max() > 1 or np.bincount(ba, minlength=nv).max() > 1:
        bad = np.flatnonzero((np.bincount(bb, minlength=nv) > 1) | (np.bincount(ba, minlength=nv) > 1))
        raise MeshError(f"boundary vertices {bad[:5].tolist()} lie on more than one boundary loop "
                        "(non-manifold vertex)")
    # extension rows: real vertices are themselves; edge ghosts a + b - c
    rows = [np.arange(nv), nv + np.repeat(np.arange(ng), 3)]
    cols = [np.arange(nv), np.stack([ba, bb, bc], 1).ravel()]
    vals = [np.ones(nv), np.tile([1.0, 1.0, -1.0], ng)]
    ghost_ids = nv + np.arange(ng)
    ghost_faces = np.stack([bb, ba, ghost_ids], axis=1)
    incoming = np.full(nv, -1, np.int64)      # ghost of the boundary edge u -> v, at v
    outgoing = np.full(nv, -1, np.int64)      # ghost of the boundary edge v -> w, at v
    prev_of = np.full(nv, -1, np.int64)       # u (the incoming edge's start)
    incoming[bb] = ghost_ids
    outgoing[ba] = ghost_ids
    prev_of[bb] = ba
    vb = np.flatnonzero(incoming >= 0)
    n_faces_at = np.bincount(f.ravel(), minlength=nv)
    n_fan = np.maximum(1, 6 - 2 - n_faces_at[vb])            # fan triangles to reach valence 6
    simple = n_fan == 1
    fans = [np.stack([vb[simple], incoming[vb[simple]], outgoing[vb[simple]]], axis=1)]
    next_id = nv + ng
    extra_rows, extra_cols, extra_vals = [], [], []
    E_rows = {}                                                # combination of each fan vertex

    def combo(i: int) -> dict:
        if i < nv:
            return {i: 1.0}
        if i < nv + ng:
            k = i - nv
            return {int(ba[k]): 1.0, int(bb[k]): 1.0, int(bc[k]): -1.0}
        return E_rows[i]

    for v, k in zip(vb[~simple], n_fan[~simple]):
        prev, cur = int(prev_of[v]), int(incoming[v])
        ring = [cur]
        for _ in range(k - 1):
            new = next_id
            next_id += 1
            comb: dict = {}
            for src, s in ((cur, 1.0), (prev, -1.0), (int(v), 1.0)):
                for idx, w in combo(src).items():
                    comb[idx] = comb.get(idx, 0.0) + s * w
            E_rows[new] = {i: w for i, w in comb.items() if w != 0.0}
            ring.append(new)
            prev, cur = cur, new
        ring.append(int(outgoing[v]))
        fans.append(np.array([[v, ring[j], ring[j + 1]] for j in range(k)], dtype=np.int64))
    for new, comb in E_rows.items():
        extra_rows.append(np.full(len(comb), new))
        extra_cols.append(np.fromiter(comb.keys(), np.int64))
        extra_vals.append(np.fromiter(comb.values(), float))
    n_control = next_id
    E = sp.csr_matrix((np.concatenate(vals + extra_vals), (np.concatenate(rows + extra_rows),
                                                           np.concatenate(cols + extra_cols))),
                      shape=(n_control, nv))
    return GhostedMesh(
        vertices=E @ x,
        faces=np.vstack([f, ghost_faces] + fans),
        n_real=nv,
        n_real_faces=nf,
        boundary_edges=np.stack([ba, bb], axis=1),
        boundary_faces=bf,
        extension_map=E,
    )
