"""A layer of ghost control vertices around the open boundaries of a control mesh.

Every boundary edge ``a -> b`` of a face ``(a, b, c)`` gets a ghost vertex at ``a + b - c`` and a
ghost triangle ``(b, a, g)``; at every boundary vertex a fan triangle joins the ghosts of its two
boundary edges.  Then every real vertex has a closed one-ring, so every real face has a complete
Loop stencil and the box-spline (or exact extraordinary) evaluation applies everywhere (the ghost
triangles are never integrated).  A boundary vertex with three faces becomes regular (valence 6).
The ghost vertices are ordinary degrees of freedom: supports are constraints on the limit surface
(``graspdef.problem.supports``), not on the ghosts.  Cirak, Ortiz & Schroeder (2000), Sec. 4.3.
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
    boundary_edges : (n_ghost, 2)   directed boundary edges a -> b (real face on the left).
    boundary_faces : (n_ghost,)     the real face owning each boundary edge.
    boundary_opposite : (n_ghost,)  the vertex of that face opposite the edge.
    """

    vertices: np.ndarray
    faces: np.ndarray
    n_real: int
    n_real_faces: int
    boundary_edges: np.ndarray
    boundary_faces: np.ndarray

    boundary_opposite: np.ndarray | None = None

    @property
    def n_control(self) -> int:
        return len(self.vertices)

    def extension(self) -> sp.csr_matrix:
        """(n_control, n_real) map from real to all control points: ghosts are a + b - c."""
        ng = len(self.boundary_edges)
        g = np.arange(ng)
        rows = np.concatenate([np.arange(self.n_real), self.n_real + np.repeat(g, 3)])
        cols = np.concatenate([np.arange(self.n_real),
                               np.stack([self.boundary_edges[:, 0], self.boundary_edges[:, 1],
                                         self.boundary_opposite], 1).ravel()])
        vals = np.concatenate([np.ones(self.n_real), np.tile([1.0, 1.0, -1.0], ng)])
        return sp.csr_matrix((vals, (rows, cols)), shape=(self.n_control, self.n_real))

    def interpolating(self) -> "GhostedMesh":
        """The same mesh with control points moved so that the limit surface passes through the
        original real vertices (limit point of vertex i = vertices[i]); ghosts re-extrapolated.

        Solves the sparse, diagonally dominant system L E X = P (Loop limit masks L)."""
        E = self.extension()
        L = limit_matrix(self.faces, self.n_control, np.arange(self.n_real))
        A = (L @ E).tocsc()
        X = spla.splu(A).solve(self.vertices[: self.n_real])
        return GhostedMesh(E @ X, self.faces, self.n_real, self.n_real_faces, self.boundary_edges,
                           self.boundary_faces, self.boundary_opposite)


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
        return GhostedMesh(x, f, nv, nf, np.zeros((0, 2), np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64))
    ghost_ids = nv + np.arange(ng)
    ghost_x = x[ba] + x[bb] - x[bc]
    ghost_faces = np.stack([bb, ba, ghost_ids], axis=1)
    # fan at each boundary vertex v: incoming edge (u -> v) with ghost g_in, outgoing (v -> w) with g_out
    incoming = np.full(nv, -1, np.int64)
    outgoing = np.full(nv, -1, np.int64)
    if np.bincount(bb, minlength=nv).max() > 1 or np.bincount(ba, minlength=nv).max() > 1:
        bad = np.flatnonzero((np.bincount(bb, minlength=nv) > 1) | (np.bincount(ba, minlength=nv) > 1))
        raise MeshError(f"boundary vertices {bad[:5].tolist()} lie on more than one boundary loop "
                        "(non-manifold vertex)")
    incoming[bb] = ghost_ids
    outgoing[ba] = ghost_ids
    vb = np.flatnonzero(incoming >= 0)
    fan = np.stack([vb, incoming[vb], outgoing[vb]], axis=1)
    return GhostedMesh(
        vertices=np.vstack([x, ghost_x]),
        faces=np.vstack([f, ghost_faces, fan]),
        n_real=nv,
        n_real_faces=nf,
        boundary_edges=np.stack([ba, bb], axis=1),
        boundary_faces=bf,
        boundary_opposite=bc,
    )
