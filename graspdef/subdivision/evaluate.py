"""Evaluation of the Loop limit surface at arbitrary points of a control mesh."""
from __future__ import annotations

import numpy as np

from ..errors import MeshError

from .basis import _is_regular, irregular_basis, regular_stencils, vertex_faces
from .halfedge import HalfEdges, face_counts, interior_mask
from .patch import regular_basis
from .rules import limit_weight


class SurfaceEvaluator:
    """Basis functions of one control mesh at any (face, chart point); topology built once.

    Parameters
    ----------
    faces : (n_faces, 3) int     oriented control mesh (with its ghost layer, if open).
    n_control : int
    """

    def __init__(self, faces: np.ndarray, n_control: int):
        self.faces = np.asarray(faces, dtype=np.int64)
        self.n_control = int(n_control)
        self._he = HalfEdges.build(self.faces, self.n_control)
        self._vf = vertex_faces(self.faces, self.n_control)
        self._counts = face_counts(self.faces, self.n_control)
        self._inner = interior_mask(self.faces, self.n_control)
        self._cache: dict = {}          # local patches already evaluated (irregular_basis)
        self._stencils: dict = {}       # face -> its 12-vertex stencil, or None if irregular

    def is_regular(self, faces: np.ndarray) -> np.ndarray:
        """True for faces whose three vertices are interior with valence 6 (box-spline patches)."""
        return _is_regular(self.faces[np.asarray(faces, dtype=np.int64)], self._counts, self._inner)

    def regular_stencils(self, faces: np.ndarray) -> np.ndarray:
        """12-vertex stencils (n, 12) of regular faces, in ``patch.LATTICE`` order."""
        return regular_stencils(self._he, self.faces[np.asarray(faces, dtype=np.int64)])

    def basis(self, face: int, pts: np.ndarray):
        """Stencil (S,), N (q, S), dN (q, S, 2), ddN (q, S, 3) at chart points ``pts`` (q, 2)."""
        tri = self.faces[face]
        if not self._inner[tri].all():
            raise MeshError(f"face {face} has a vertex with an open one-ring: evaluate the ghosted mesh")
        pts = np.atleast_2d(np.asarray(pts, dtype=float))
        face = int(face)
        if face not in self._stencils:
            reg = _is_regular(tri[None], self._counts, self._inner)[0]
            self._stencils[face] = regular_stencils(self._he, tri[None])[0] if reg else None
        st = self._stencils[face]
        if st is not None:
            N, dN, ddN = regular_basis(pts)
            return st.copy(), N, dN, ddN
        return irregular_basis(self.faces, self._vf, face, pts, self._cache)

    def values(self, face: int, bary: np.ndarray, tol: float = 1e-12) -> tuple[np.ndarray, np.ndarray]:
        """Control indices (S,) and weights (S,) of the limit point with barycentric coordinates
        ``bary`` (b0, b1, b2) in ``face`` (chart v = b1, w = b2); exact limit masks at vertices."""
        b = np.asarray(bary, dtype=float)
        corner = np.flatnonzero(b > 1.0 - tol)
        if len(corner):
            vtx = int(self.faces[face][corner[0]])
            if not self._inner[vtx]:
                raise MeshError(f"vertex {vtx} has an open one-ring: evaluate the ghosted mesh")
            nbrs = np.unique(self.faces[self._vf[vtx].indices])
            nbrs = nbrs[nbrs != vtx]
            chi = float(limit_weight(len(nbrs)))
            weights = np.concatenate([[1.0 - len(nbrs) * chi], np.full(len(nbrs), chi)])
            return np.concatenate([[vtx], nbrs]), weights
        st, N, _, _ = self.basis(face, b[None, 1:3])
        return st, N[0]

    def point(self, x: np.ndarray, face: int, bary: np.ndarray) -> np.ndarray:
        """Limit-surface point (3,) of control points ``x`` (n_control, 3)."""
        st, w = self.values(face, bary)
        return w @ x[st]


def _inside(vw: np.ndarray, margin: float = 1e-10) -> np.ndarray:
    """Clamp a chart point into the triangle, ``margin`` away from its corners (an exact corner
    may be an extraordinary vertex, where derivatives are not defined)."""
    vw = np.clip(vw, 0.0, 1.0)
    if vw.sum() > 1.0:
        vw = vw / vw.sum()
    u = 1.0 - vw.sum()
    if max(u, vw[0], vw[1]) > 1.0 - margin:
        vw = (1.0 - 3.0 * margin) * vw + margin
    return vw


def _inside_rows(vw: np.ndarray, margin: float = 1e-10) -> np.ndarray:
    """:func:`_inside` for each row of vw (m, 2)."""
    vw = np.clip(vw, 0.0, 1.0)
    t = vw.sum(axis=1)
    vw = np.where((t > 1.0)[:, None], vw / np.where(t > 1.0, t, 1.0)[:, None], vw)
    u = 1.0 - vw.sum(axis=1)
    near = np.maximum(u, vw.max(axis=1)) > 1.0 - margin
    return np.where(near[:, None], (1.0 - 3.0 * margin) * vw + margin, vw)


def _chart_steps(N: np.ndarray, dN: np.ndarray, X: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Gauss-Newton steps (m, 2) in the charts of m faces: N (m, S), dN (m, S, 2), X (m, S, 3)."""
    r = np.einsum("ms,msd->md", N, X) - p
    A = np.einsum("msk,msd->mkd", dN, X)                     # (m, 2, 3): a1, a2
    M = np.einsum("mkd,mld->mkl", A, A)
    b = -np.einsum("mkd,md->mk", A, r)
    # 2 x 2 normal equations, by Cramer's rule where M is well conditioned (det above 1e-12 of
    # its trace squared: condition number below ~1e12), least squares (np.linalg.lstsq) elsewhere
    det = M[:, 0, 0] * M[:, 1, 1] - M[:, 0, 1] * M[:, 1, 0]
    tr = M[:, 0, 0] + M[:, 1, 1]
    good = det > 1e-12 * tr * tr
    out = np.empty_like(b)
    dg = np.where(good, det, 1.0)
    out[:, 0] = (M[:, 1, 1] * b[:, 0] - M[:, 0, 1] * b[:, 1]) / dg
    out[:, 1] = (M[:, 0, 0] * b[:, 1] - M[:, 1, 0] * b[:, 0]) / dg
    for i in np.flatnonzero(~good):
        out[i] = np.linalg.lstsq(M[i], b[i], rcond=None)[0]
    return out


def project_point(ev: SurfaceEvaluator, x: np.ndarray, target: np.ndarray, candidates: np.ndarray,
                  iterations: int = 12) -> tuple[int, np.ndarray, float]:
    """Closest point of the limit surface (control points ``x``) to ``target`` among the
    ``candidates`` faces: Gauss-Newton in each face chart, clamped to the triangle (the regular
    faces' iterations in one batch: they share the box-spline basis).

    Returns (face, barycentric (3,), distance)."""
    best = (-1, np.zeros(3), np.inf)
    p = np.asarray(target, dtype=float)
    cands = np.asarray(candidates, dtype=np.int64)
    reg = ev.is_regular(cands) if len(cands) else np.zeros(0, bool)
    found = {}
    if reg.any():
        fr = cands[reg]
        X = x[ev.regular_stencils(fr)]                      # (m, 12, 3)
        vw = np.full((len(fr), 2), 1.0 / 3.0)
        live = np.ones(len(fr), bool)
        for _ in range(iterations):
            if not live.any():
                break
            N, dN, _ = regular_basis(vw[live])
            step = _chart_steps(N, dN, X[live], p)
            vw[live] = _inside_rows(vw[live] + step)
            live[np.flatnonzero(live)[np.linalg.norm(step, axis=1) < 1e-13]] = False
        found.update(zip(fr.tolist(), vw))
    for f in cands[~reg]:
        vw = np.array([1.0 / 3.0, 1.0 / 3.0])
        for _ in range(iterations):
            st, N, dN, _ = ev.basis(int(f), vw[None])
            step = _chart_steps(N, dN, x[st][None], p)[0]
            vw = _inside(vw + step)
            if np.linalg.norm(step) < 1e-13:
                break
        found[int(f)] = vw
    for f in cands.tolist():
        vw = found[f]
        bary = np.array([1.0 - vw.sum(), vw[0], vw[1]])
        d = float(np.linalg.norm(ev.point(x, int(f), bary) - p))
        if d < best[2]:
            best = (int(f), bary, d)
    return best
