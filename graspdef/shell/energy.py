"""Total elastic energy of a shell, its gradient and its Hessian, from one code path.

E(x) = sum_faces sum_q w_q J_q W(s(y(x)))  with y linear in the control points x (n_control, 3).
Gradient and Hessian apply the chain rule through ``kinematics``; the Hessian is assembled into a
3x3-block sparse matrix through an index map built once (np.bincount scatter, no COO sort).
The linear problem is this Hessian at the rest state.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ._kernels import block_positions, material_hessian_blocks, scatter_blocks
from .kinematics import strain_hessian_contract, strain_jacobian, strains
from .model import Shell, surface_derivatives

_CHUNK = 8192


class BlockPattern:
    """Sparsity pattern of the control-point coupling (vertex pairs sharing a stencil)."""

    def __init__(self, shell: Shell):
        n = shell.n_control
        rows, cols, off = [], [], 0
        for g in shell.basis.groups:                  # face-vertex incidence P; pattern = P P^T
            rows.append(g.stencils.ravel())
            cols.append(np.repeat(np.arange(off, off + len(g.stencils)), g.stencils.shape[1]))
            off += len(g.stencils)
        P = sp.csr_matrix((np.ones(sum(len(r) for r in rows), np.int32),
                           (np.concatenate(rows), np.concatenate(cols))), shape=(n, off))
        G = (P @ P.T).tocsr()
        G.sort_indices()
        self.indptr = G.indptr.astype(np.int64)
        self.cols = G.indices.astype(np.int64)
        self.maps = [block_positions(np.ascontiguousarray(g.stencils), self.indptr, self.cols)
                     for g in shell.basis.groups]
        self.n = n
        self.nnzb = len(self.cols)
        # scalar CSR of the 3x3-block pattern: block p (row r, k-th in its row, L blocks in the
        # row) holds entry (a, b) at  9 indptr[r] + 3 L a + 3 k + b
        row_len = np.diff(self.indptr)
        rowof = np.repeat(np.arange(n), row_len)
        k_in_row = np.arange(self.nnzb) - self.indptr[rowof]
        self.base = 9 * self.indptr[rowof] + 3 * k_in_row
        self.stride = 3 * row_len[rowof]
        self.scalar_indptr = np.concatenate([[0], np.cumsum(np.repeat(3 * row_len, 3))]).astype(np.int64)
        cols3 = (3 * self.cols[:, None] + np.arange(3)).reshape(-1)          # per block row, 3L columns
        idx = np.empty(9 * self.nnzb, np.int64)
        for a in range(3):
            pos = (self.base[:, None] + a * self.stride[:, None] + np.arange(3)).ravel()
            idx[pos] = cols3
        self.scalar_indices = idx

    def assemble(self, group_blocks: list[list[tuple[np.ndarray, np.ndarray]]]) -> sp.csr_matrix:
        """Sum element blocks into a CSR matrix; ``group_blocks[g]`` lists (face_slice, blocks
        (nf, S, S, 3, 3)) chunks in face order."""
        data = np.zeros(9 * self.nnzb)
        for gi, chunks in enumerate(group_blocks):
            m = self.maps[gi]
            for sl, blk in chunks:
                S = blk.shape[1]
                scatter_blocks(data, m[sl.start * S * S: sl.stop * S * S], blk, self.base, self.stride)
        return sp.csr_matrix((data, self.scalar_indices, self.scalar_indptr), shape=(3 * self.n, 3 * self.n))


class ShellEnergy:
    """Elastic energy of a :class:`Shell` as a function of the control points."""

    def __init__(self, shell: Shell):
        self.shell = shell
        self._pattern: BlockPattern | None = None

    @property
    def pattern(self) -> BlockPattern:
        if self._pattern is None:
            self._pattern = BlockPattern(self.shell)
        return self._pattern

    def _chunks(self):
        for g, r in zip(self.shell.basis.groups, self.shell.rest):
            nf = len(g.faces)
            for start in range(0, nf, _CHUNK):
                sl = slice(start, min(nf, start + _CHUNK))
                yield g, r, sl

    def _local(self, g, r, sl, x, order: int):
        st = g.stencils[sl]
        dN = g.dN if g.dN.shape[0] == 1 else g.dN[sl]
        ddN = g.ddN if g.ddN.shape[0] == 1 else g.ddN[sl]
        y = surface_derivatives(st, dN, ddN, x)
        s = strains(y, r.rest_a[sl], r.rest_b[sl])
        W, dW, ddW = self.shell.material.density(s, r.rest_inv[sl], r.thickness[sl])
        w = r.weights[sl]
        if order == 0:
            return (w * W).sum()
        D = np.broadcast_to(np.concatenate([dN, ddN], axis=-1), (len(st),) + dN.shape[1:3] + (5,))
        nf, nq, S = D.shape[:3]
        J = strain_jacobian(y)                                            # (f, q, 6, 5, 3) ds/dy
        dstride = 0 if dN.shape[0] == 1 else 1
        Dc = np.concatenate([dN, ddN], axis=-1)                           # (f|1, q, S, 5)
        if np.any(dW):
            ge = np.einsum("fqi,fqiKa,fqsK->fsa", dW * w[..., None], J, D, optimize=True)
        else:                                                             # at rest: no stress
            ge = np.zeros((nf, S, 3))
        if order == 1:
            return (w * W).sum(), ge
        if np.any(dW):                                                    # geometric (stress) part
            Hg = strain_hessian_contract(y, dW * w[..., None])            # (f, q, 5, 3, 5, 3)
            He = material_hessian_blocks(np.ascontiguousarray(Dc), J, ddW * w[..., None, None], dstride,
                                         np.ascontiguousarray(Hg))
        else:
            He = material_hessian_blocks(np.ascontiguousarray(Dc), J, ddW * w[..., None, None], dstride)
        return (w * W).sum(), ge, He

    def energy(self, x: np.ndarray) -> float:
        """Total elastic energy [J] at control points ``x`` (n_control, 3) [m]."""
        return float(sum(self._local(g, r, sl, x, 0) for g, r, sl in self._chunks()))

    def gradient(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """Energy and gradient (3 n_control,) [N]."""
        E = 0.0
        grad = np.zeros((self.shell.n_control, 3))
        for g, r, sl in self._chunks():
            e, ge = self._local(g, r, sl, x, 1)
            E += e
            np.add.at(grad, g.stencils[sl], ge)
        return float(E), grad.ravel()

    def hessian(self, x: np.ndarray) -> tuple[float, np.ndarray, sp.csr_matrix]:
        """Energy, gradient and Hessian (3 n_control, 3 n_control) [N/m] at ``x``."""
        E = 0.0
        grad = np.zeros((self.shell.n_control, 3))
        blocks: list[list] = [[] for _ in self.shell.basis.groups]
        gi_of = {id(g): i for i, g in enumerate(self.shell.basis.groups)}
        for g, r, sl in self._chunks():
            e, ge, He = self._local(g, r, sl, x, 2)
            E += e
            np.add.at(grad, g.stencils[sl], ge)
            blocks[gi_of[id(g)]].append((sl, He))
        return float(E), grad.ravel(), self.pattern.assemble(blocks)
