"""Where the contact barrier looks: the faces near a fingertip (:func:`select_faces`) and samples of
the shell's limit surface on them (:func:`sample_faces`: sub-triangle centroids of each face's
parameter domain, weighted by their rest area) and :class:`SampleOperator`, the sparse map from
control points to those samples that the barrier and the friction term gather and scatter with."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import ProblemError
from ..subdivision.patch import regular_basis


def select_faces(shell, obstacle, e: np.ndarray, reach: float | None, depth: float | None,
                 spacing: float | None, name: str) -> tuple[np.ndarray, int]:
    """The real faces within the fingertip's reach and the sub-division L of each into L x L
    sample triangles.

    ``reach`` [m]: lateral radius about the axis ``e`` (faces whose control centroid is within it;
    default: the obstacle's lateral extent plus one control-mesh edge); ``depth`` [m]: at most this
    far in front of / behind the obstacle's front (default: half the shell's extent along e);
    ``spacing`` [m]: largest sample spacing (default: a third of the obstacle's smallest radius of
    curvature)."""
    X = shell.rest_positions
    mesh = shell.mesh
    real = mesh.faces[: mesh.n_real_faces]
    edge = float(np.linalg.norm(X[real[:, [1, 2, 0]]] - X[real], axis=-1).mean())
    cen = X[real].mean(axis=1)
    # front of the obstacle at s = 0: its distance-minimising point towards the shell's centroid
    c = X.mean(axis=0)
    phi, n = obstacle.distance(c[None], False)
    probe = c - phi[0] * n[0]
    rel = cen - probe
    ax = rel @ e
    lat = np.linalg.norm(rel - ax[:, None] * e, axis=1)
    reach = reach if reach is not None else obstacle.reach() + edge
    ext = (X @ e).max() - (X @ e).min()
    depth = depth if depth is not None else 0.5 * ext
    faces = np.flatnonzero((lat <= reach) & (ax <= depth) & (ax >= -depth))
    if len(faces) == 0:
        raise ProblemError(f"finger contact '{name}': no shell face within reach ({reach:.3g} m) of the fingertip")
    spacing = spacing if spacing is not None else obstacle.feature_radius / 3
    return faces, int(np.clip(np.ceil(edge / spacing), 1, 12))


def sample_faces(shell, ev, faces: np.ndarray, L: int):
    """Sub-triangle centroids of ``faces`` (L x L per face): stencils (F, S), N (F, q, S) and
    rest weights (F, q) [m^2]; S padded with zero weights."""
    pts = []
    for i in range(L):
        for j in range(L - i):
            pts.append(((i + 1 / 3) / L, (j + 1 / 3) / L))
            if i + j <= L - 2:
                pts.append(((i + 2 / 3) / L, (j + 2 / 3) / L))
    pts = np.array(pts)
    X = shell.rest_positions
    faces = np.asarray(faces, dtype=np.int64)
    reg = ev.is_regular(faces)
    bases = {}
    if reg.any():                                   # regular faces share one box-spline basis
        N, dN, _ = regular_basis(pts)
        for f, st in zip(faces[reg], ev.regular_stencils(faces[reg])):
            bases[int(f)] = (st, N, dN)
    for f in faces[~reg]:
        st, N, dN, _ = ev.basis(int(f), pts)
        bases[int(f)] = (st, N, dN)
    S = max(len(b[0]) for b in bases.values())
    stn = np.zeros((len(faces), S), np.int64)
    Nn = np.zeros((len(faces), len(pts), S))
    dNn = np.zeros((len(faces), len(pts), S, 2))
    for k, f in enumerate(faces):
        st, N, dN = bases[int(f)]
        stn[k, : len(st)] = st
        Nn[k, :, : len(st)] = N
        dNn[k, :, : len(st)] = dN
    # batched products (F, q, S) @ (F, S, 3): BLAS, ~15x faster than einsum's loop at 89k samples
    Xs = X[stn]
    a1 = np.ascontiguousarray(dNn[..., 0]) @ Xs
    a2 = np.ascontiguousarray(dNn[..., 1]) @ Xs
    return stn, Nn, np.linalg.norm(np.cross(a1, a2), axis=-1) / (2 * L * L)


class SampleOperator:
    """The samples of :func:`sample_faces` as one sparse matrix S (Q, n), Q = F q rows in (face,
    sample) order: the sample points are p = S x for control points x (n, 3).

    A term with per-sample values gathers its points with :meth:`points` and scatters its per-sample
    gradients (k, 3) and 3 x 3 Hessian blocks (k, 3, 3) of a subset of rows back to the control
    points with :meth:`gradient` and :meth:`hessian` (S^T g and (S (x) I3)^T H (S (x) I3)), by
    compiled loops over the rows (graspdef.contact._kernels).  With the shell's block ``pattern``
    (graspdef.shell.energy.BlockPattern; a sample's stencil is its face's, so every pair of it is
    in the pattern), :meth:`hessian` returns a matrix on the pattern's own index arrays: the sum
    with the shell's Hessian is then entry by entry and the tangent keeps one sparsity pattern."""

    def __init__(self, stencils: np.ndarray, N: np.ndarray, n_control: int, pattern=None):
        from ._kernels import sample_pair_positions

        F, q, S = N.shape
        rows = np.repeat(np.arange(F * q), S)
        cols = np.broadcast_to(stencils[:, None, :], (F, q, S)).ravel()
        M = sp.csr_matrix((N.ravel(), (rows, cols)), shape=(F * q, n_control))
        M.eliminate_zeros()                              # the stencils' zero-weight padding
        M.sort_indices()
        self.S, self.n = M, n_control
        self._ptr = M.indptr.astype(np.int64)
        self._cols = M.indices.astype(np.int64)
        self._vals = np.ascontiguousarray(M.data, dtype=float)
        self._pattern = None
        self._last = None            # (x, S x) of the last call of points(x): the terms ask for it repeatedly
        if pattern is not None:
            pptr, pos = sample_pair_positions(self._ptr, self._cols, pattern.indptr, pattern.cols)
            if pos.size and pos.min() >= 0:
                self._pattern, self._pptr, self._pos = pattern, pptr, pos

    def points(self, x: np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
        """Sample points (Q, 3) of control points x (n, 3), or of ``rows`` only (k, 3)."""
        if rows is None:
            last = self._last
            if last is not None and last[0].shape == np.shape(x) and np.array_equal(last[0], x):
                return last[1].copy()
            P = self.S @ x
            self._last = (np.array(x, dtype=float), P.copy())
            return P
        from ._kernels import sample_rows_points

        return sample_rows_points(self._ptr, self._cols, self._vals, np.ascontiguousarray(x, dtype=float),
                                  np.asarray(rows, np.int64))

    def gradient(self, g: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Per-sample gradients g (k, 3) of ``rows`` (k,) scattered to the control points: (3 n,)."""
        from ._kernels import sample_rows_gradient

        return sample_rows_gradient(self._ptr, self._cols, self._vals, np.ascontiguousarray(g, dtype=float),
                                    np.asarray(rows, np.int64), self.n)

    def hessian(self, H: np.ndarray, rows: np.ndarray) -> sp.csr_matrix:
        """Per-sample 3 x 3 Hessian blocks H (k, 3, 3) of ``rows`` (k,) assembled over the control
        points: the (3 n, 3 n) matrix sum_k (S_k (x) I3)^T H_k (S_k (x) I3)."""
        k = len(rows)
        n3 = 3 * self.n
        pat = self._pattern
        if pat is not None:
            from ._kernels import sample_rows_hessian

            data = np.zeros(pat.scalar_indices.size)
            if k:
                sample_rows_hessian(self._ptr, self._vals, self._pptr, self._pos, pat.base, pat.stride,
                                    np.ascontiguousarray(H, dtype=float), np.asarray(rows, np.int64), data)
            return pat.csr(data)
        if k == 0:
            return sp.csr_matrix((n3, n3))
        S3 = sp.kron(self.S[rows], sp.identity(3, format="csr"), format="csr")
        Hb = sp.bsr_matrix((np.ascontiguousarray(H, dtype=float), np.arange(k), np.arange(k + 1)), shape=(3 * k, 3 * k))
        return (S3.T @ (Hb.tocsr() @ S3)).tocsr()
