"""Enclosed volume of a closed limit surface as a function of the control points.

    V(x) = 1/3 int x . n dA = 1/3 sum_faces sum_q w_q  x_q . (a1_q x a2_q)

(divergence theorem; w_q are the chart quadrature weights).  V is the potential of a follower
pressure (-p V) and the state variable of an enclosed gas.  The value, gradient and Hessian are
those of this one discrete functional, so Newton's method sees an exactly consistent tangent.
For an oriented closed surface with outward normals V > 0.

Hessian block of control points (s, t): the skew matrix [v_st]_x with
    v_st = sum_q w_q/3 [ a2 (dN1_s N_t - N_s dN1_t) + a1 (N_s dN2_t - dN2_s N_t)
                         + x (dN2_s dN1_t - dN1_s dN2_t) ],
antisymmetric in (s, t), so the assembled Hessian is symmetric.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..compiled import kernel, prange
from .energy import BlockPattern, block_pattern
from .model import Shell

_CHUNK = 4096


@kernel(parallel=True, work=1, aot=("f8(f8[:,::1], i8[:,::1], f8[:,:,::1], f8[:,:,:,::1], f8[::1], i8, i8, i8[::1], i8[::1], i8[::1], f8[:,::1], f8[::1], i8[::1], i8[::1], i8[::1], i8[::1], f8[::1])",))
def _volume_terms(x, stencils, N, dN, w, nstride, order, index, base, bstride, grad, data,
                  forder, bstart, cblocks, cstart, vblock):
    """Fused value / gradient (order >= 1) / Hessian (order 2, added into the scalar CSR ``data``
    of the shell's block pattern: block p = index[(f S + s) S + t], entry (a, b) at
    base[p] + a bstride[p] + b) of V over one face group; returns V.
    N (f|1, q, S), dN (f|1, q, S, 2), w (q,) including the 1/3.

    Faces are visited as the shell's assembly visits them (graspdef.shell.energy._Schedule): in
    ``forder``, in blocks (bstart: offsets into forder) of one colour (cblocks[cstart[c]:cstart[c +
    1]] the blocks of colour c), and blocks of one colour share no control vertex, so they run in
    parallel without write races; each block's volume goes to vblock[block] and V is their sum in
    block order -- the same numbers for any number of threads, serial or parallel build."""
    nf, S = stencils.shape
    nq = w.shape[0]
    ncol = cstart.shape[0] - 1
    for col in range(ncol):
        for bi in prange(cstart[col], cstart[col + 1]):
            blk = cblocks[bi]
            p = np.empty((nq, 3))
            a1 = np.empty((nq, 3))
            a2 = np.empty((nq, 3))
            P = np.empty((nq, S, 3))
            Q = np.empty((nq, S, 3))
            R = np.empty((nq, S, 3))
            Vb = 0.0
            for k in range(bstart[blk], bstart[blk + 1]):
                f = forder[k]
                fb = f * nstride
                for q in range(nq):
                    for d in range(3):
                        sp_ = 0.0
                        s1 = 0.0
                        s2 = 0.0
                        for s in range(S):
                            xv = x[stencils[f, s], d]
                            sp_ += N[fb, q, s] * xv
                            s1 += dN[fb, q, s, 0] * xv
                            s2 += dN[fb, q, s, 1] * xv
                        p[q, d] = sp_
                        a1[q, d] = s1
                        a2[q, d] = s2
                    m0 = a1[q, 1] * a2[q, 2] - a1[q, 2] * a2[q, 1]
                    m1 = a1[q, 2] * a2[q, 0] - a1[q, 0] * a2[q, 2]
                    m2 = a1[q, 0] * a2[q, 1] - a1[q, 1] * a2[q, 0]
                    Vb += w[q] * (p[q, 0] * m0 + p[q, 1] * m1 + p[q, 2] * m2)
                    if order >= 1:
                        # dV = w [N_s (a1 x a2) + dN1_s (a2 x p) + dN2_s (p x a1)]
                        b0 = a2[q, 1] * p[q, 2] - a2[q, 2] * p[q, 1]
                        b1 = a2[q, 2] * p[q, 0] - a2[q, 0] * p[q, 2]
                        b2 = a2[q, 0] * p[q, 1] - a2[q, 1] * p[q, 0]
                        c0 = p[q, 1] * a1[q, 2] - p[q, 2] * a1[q, 1]
                        c1 = p[q, 2] * a1[q, 0] - p[q, 0] * a1[q, 2]
                        c2 = p[q, 0] * a1[q, 1] - p[q, 1] * a1[q, 0]
                        for s in range(S):
                            Ns, d1, d2 = w[q] * N[fb, q, s], w[q] * dN[fb, q, s, 0], w[q] * dN[fb, q, s, 1]
                            r = stencils[f, s]
                            grad[r, 0] += Ns * m0 + d1 * b0 + d2 * c0
                            grad[r, 1] += Ns * m1 + d1 * b1 + d2 * c1
                            grad[r, 2] += Ns * m2 + d1 * b2 + d2 * c2
                if order < 2:
                    continue
                # v_st = sum_q [dN1_s P_t + N_s Q_t + dN2_s R_t] with P_t = w (N_t a2 - dN2_t x),
                # Q_t = w (dN2_t a1 - dN1_t a2), R_t = w (dN1_t x - N_t a1) (the docstring's sum,
                # grouped by the s factors)
                for q in range(nq):
                    for t in range(S):
                        Nt, d1t, d2t = w[q] * N[fb, q, t], w[q] * dN[fb, q, t, 0], w[q] * dN[fb, q, t, 1]
                        for d in range(3):
                            P[q, t, d] = Nt * a2[q, d] - d2t * p[q, d]
                            Q[q, t, d] = d2t * a1[q, d] - d1t * a2[q, d]
                            R[q, t, d] = d1t * p[q, d] - Nt * a1[q, d]
                for s in range(S):
                    for t in range(s + 1, S):
                        v0 = 0.0
                        v1 = 0.0
                        v2 = 0.0
                        for q in range(nq):
                            Ns, d1s, d2s = N[fb, q, s], dN[fb, q, s, 0], dN[fb, q, s, 1]
                            v0 += d1s * P[q, t, 0] + Ns * Q[q, t, 0] + d2s * R[q, t, 0]
                            v1 += d1s * P[q, t, 1] + Ns * Q[q, t, 1] + d2s * R[q, t, 1]
                            v2 += d1s * P[q, t, 2] + Ns * Q[q, t, 2] + d2s * R[q, t, 2]
                        # block (s, t) = [v]_x, block (t, s) = its transpose
                        kk = index[(f * S + s) * S + t]
                        o, st_ = base[kk], bstride[kk]
                        data[o + 1] -= v2
                        data[o + 2] += v1
                        data[o + st_] += v2
                        data[o + st_ + 2] -= v0
                        data[o + 2 * st_] -= v1
                        data[o + 2 * st_ + 1] += v0
                        kk = index[(f * S + t) * S + s]
                        o, st_ = base[kk], bstride[kk]
                        data[o + 1] += v2
                        data[o + 2] -= v1
                        data[o + st_] -= v2
                        data[o + st_ + 2] += v0
                        data[o + 2 * st_] += v1
                        data[o + 2 * st_ + 1] -= v0
            vblock[blk] = Vb
    V = 0.0
    for b in range(vblock.shape[0]):
        V += vblock[b]
    return V


class EnclosedVolume:
    """Volume functional of a shell's limit surface (all real faces, or a boolean face mask)."""

    def __init__(self, shell: Shell, pattern: BlockPattern | None = None):
        self.shell = shell
        self._pattern = pattern

    @property
    def pattern(self) -> BlockPattern:
        if self._pattern is None:
            self._pattern = block_pattern(self.shell)
        return self._pattern

    def _chunks(self):
        for g in self.shell.basis.groups:
            for start in range(0, len(g.faces), _CHUNK):
                sl = slice(start, min(len(g.faces), start + _CHUNK))
                N = g.N if g.N.shape[0] == 1 else g.N[sl]
                dN = g.dN if g.dN.shape[0] == 1 else g.dN[sl]
                yield g, sl, N, dN

    def _fields(self, g, sl, N, dN, x):
        X = x[g.stencils[sl]]                                     # (f, S, 3)
        nf = len(X)
        N = np.broadcast_to(N, (nf,) + N.shape[1:])
        dN = np.broadcast_to(dN, (nf,) + dN.shape[1:])
        p = np.einsum("fqs,fsd->fqd", N, X)
        a1 = np.einsum("fqs,fsd->fqd", dN[..., 0], X)
        a2 = np.einsum("fqs,fsd->fqd", dN[..., 1], X)
        return N, dN, p, a1, a2

    # ---- compiled path (``_volume_terms``) ---------------------------------------------------
    def _compiled(self, x: np.ndarray, order: int, hessian_scale: float = 1.0):
        x = np.ascontiguousarray(x, dtype=float).reshape(self.shell.n_control, 3)
        w = np.ascontiguousarray(self.shell.basis.qweights / 3.0)
        grad = np.zeros((self.shell.n_control, 3))
        pat = self.pattern if order == 2 else None
        data = np.zeros(9 * pat.nnzb) if order == 2 else np.zeros(1)
        empty = np.zeros(1, np.int64)
        V = 0.0
        for gi, (g, sch) in enumerate(zip(self.shell.basis.groups, self.shell.face_schedules)):
            V += _volume_terms(x, np.ascontiguousarray(g.stencils, dtype=np.int64), np.ascontiguousarray(g.N),
                               np.ascontiguousarray(g.dN), w, 0 if g.N.shape[0] == 1 else 1, order,
                               pat.maps[gi] if pat is not None else empty,
                               pat.base if pat is not None else empty, pat.stride if pat is not None else empty,
                               grad, data, sch.order, sch.bstart, sch.cblocks, sch.cstart,
                               np.zeros(len(sch.bstart) - 1))
        H = None
        if order == 2:
            if hessian_scale != 1.0:
                data *= hessian_scale
            H = pat.csr(data)
        return float(V), grad.ravel(), H

    def value(self, x: np.ndarray) -> float:
        """V [m^3] at control points ``x`` (n_control, 3) [m]."""
        return self._compiled(x, 0)[0]

    def gradient(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """V and dV/dx (3 n_control,) [m^2]."""
        V, g, _ = self._compiled(x, 1)
        return V, g

    def hessian(self, x: np.ndarray, scale: float = 1.0) -> tuple[float, np.ndarray, sp.csr_matrix]:
        """V, dV/dx and ``scale`` d2V/dx2 (3 n_control, 3 n_control) [m] on the shell's block
        pattern (the same CSR structure as :class:`~graspdef.shell.energy.ShellEnergy`'s Hessian)."""
        return self._compiled(x, 2, scale)

    # ---- numpy reference path (tests) ---------------------------------------------------------
    def _value_reference(self, x: np.ndarray) -> float:
        """V [m^3] at control points ``x`` (n_control, 3) [m]."""
        w = self.shell.basis.qweights / 3.0
        V = 0.0
        for g, sl, N, dN in self._chunks():
            _, _, p, a1, a2 = self._fields(g, sl, N, dN, x)
            V += float(np.einsum("fqd,fqd,q->", p, np.cross(a1, a2), w))
        return V

    def _gradient_reference(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        w = self.shell.basis.qweights / 3.0
        V = 0.0
        grad = np.zeros((self.shell.n_control, 3))
        for g, sl, N, dN in self._chunks():
            N, dN, p, a1, a2 = self._fields(g, sl, N, dN, x)
            m = np.cross(a1, a2)
            V += float(np.einsum("fqd,fqd,q->", p, m, w))
            ge = (np.einsum("fqs,fqd,q->fsd", N, m, w)
                  + np.einsum("fqs,fqd,q->fsd", dN[..., 0], np.cross(a2, p), w)
                  + np.einsum("fqs,fqd,q->fsd", dN[..., 1], np.cross(p, a1), w))
            np.add.at(grad, g.stencils[sl], ge)
        return V, grad.ravel()

    def _hessian_reference(self, x: np.ndarray) -> tuple[float, np.ndarray, sp.csr_matrix]:
        """V, dV/dx and d2V/dx2 by numpy (einsum) -- the independent reference of ``_volume_terms``:
        block (s, t) = [v_st]_x with v_st as in the module docstring."""
        w = self.shell.basis.qweights / 3.0
        V, grad = self._gradient_reference(x)
        blocks: list[list] = [[] for _ in self.shell.basis.groups]
        gi_of = {id(g): i for i, g in enumerate(self.shell.basis.groups)}
        for g, sl, N, dN in self._chunks():
            N, dN, p, a1, a2 = self._fields(g, sl, N, dN, x)
            d1, d2 = dN[..., 0], dN[..., 1]
            v = (np.einsum("q,fqs,fqt,fqd->fstd", w, d1, N, a2) - np.einsum("q,fqs,fqt,fqd->fstd", w, N, d1, a2)
                 + np.einsum("q,fqs,fqt,fqd->fstd", w, N, d2, a1) - np.einsum("q,fqs,fqt,fqd->fstd", w, d2, N, a1)
                 + np.einsum("q,fqs,fqt,fqd->fstd", w, d2, d1, p) - np.einsum("q,fqs,fqt,fqd->fstd", w, d1, d2, p))
            blk = np.zeros(v.shape[:3] + (3, 3))
            blk[..., 0, 1], blk[..., 0, 2], blk[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
            blk[..., 1, 0], blk[..., 2, 0], blk[..., 2, 1] = v[..., 2], -v[..., 1], v[..., 0]
            blocks[gi_of[id(g)]].append((sl, blk))
        return V, grad, self.pattern.assemble(blocks)
