"""Compiled element kernels (numba).  Pure functions of arrays; the numpy reference path in
``energy.py`` computes the same quantities and the tests compare the two."""
from __future__ import annotations

import numba as nb
import numpy as np


@nb.njit(cache=True, parallel=True, fastmath=False)
def material_hessian_blocks(D, J, C, dstride, Hg=None):
    """sum_q G_q^T C_q G_q per face with G = ds/dx, G[i, s, a] = sum_K D[s, K] J[i, K, a].

    D : (nf|1, nq, S, 5) basis derivatives; J : (nf, nq, 6, 5, 3) ds/dy; C : (nf, nq, 6, 6)
    weighted material tangent, which must be symmetric (a Hessian of the energy density; only
    the upper triangle of each 36x36 block is computed and mirrored); ``dstride`` = 0 when D has a leading axis of 1 (shared), else 1.
    ``Hg`` (nf, nq, 5, 3, 5, 3), optional: the stress (geometric) part sum_i sig_i d2 s_i/dy2 at
    each point, added as sum_KL D[s, K] Hg[K, a, L, b] D[t, L].
    Returns (nf, S, S, 3, 3) blocks [s, t, a, b]."""
    nf, nq = J.shape[0], J.shape[1]
    S = D.shape[2]
    out = np.zeros((nf, S, S, 3, 3))
    for f in nb.prange(nf):
        df = f * dstride
        G = np.empty((6, S, 3))
        CG = np.empty((6, S, 3))
        T = np.empty((S, 3, 5, 3))
        for q in range(nq):
            for i in range(6):
                for s in range(S):
                    for a in range(3):
                        acc = 0.0
                        for K in range(5):
                            acc += D[df, q, s, K] * J[f, q, i, K, a]
                        G[i, s, a] = acc
            for j in range(6):
                for s in range(S):
                    for a in range(3):
                        acc = 0.0
                        for i in range(6):
                            acc += C[f, q, j, i] * G[i, s, a]
                        CG[j, s, a] = acc
            for s in range(S):
                for t in range(s, S):
                    for a in range(3):
                        for b in range(3):
                            acc = 0.0
                            for i in range(6):
                                acc += G[i, s, a] * CG[i, t, b]
                            out[f, s, t, a, b] += acc
            if Hg is not None:
                for s in range(S):
                    for a in range(3):
                        for L in range(5):
                            for b in range(3):
                                acc = 0.0
                                for K in range(5):
                                    acc += D[df, q, s, K] * Hg[f, q, K, a, L, b]
                                T[s, a, L, b] = acc
                for s in range(S):
                    for t in range(s, S):
                        for a in range(3):
                            for b in range(3):
                                acc = 0.0
                                for L in range(5):
                                    acc += T[s, a, L, b] * D[df, q, t, L]
                                out[f, s, t, a, b] += acc
        for s in range(S):
            for t in range(s + 1, S):
                for a in range(3):
                    for b in range(3):
                        out[f, t, s, b, a] = out[f, s, t, a, b]
    return out


@nb.njit(cache=True)
def scatter_blocks(data, index, blocks, base, stride):
    """Add blocks[f, s, t] (3x3) into a scalar CSR ``data`` array: the block goes to block
    position p = index[f*S*S + s*S + t], whose entry (a, b) lives at base[p] + a*stride[p] + b
    (sequential: no write races)."""
    nf, S = blocks.shape[0], blocks.shape[1]
    k = 0
    for f in range(nf):
        for s in range(S):
            for t in range(S):
                p = index[k]
                for a in range(3):
                    q = base[p] + a * stride[p]
                    for b in range(3):
                        data[q + b] += blocks[f, s, t, a, b]
                k += 1


@nb.njit(cache=True, parallel=True)
def block_positions(stencils, indptr, cols):
    """Position in the block-CSR pattern (indptr, cols; sorted columns) of every stencil pair
    (stencils[f, s], stencils[f, t]), flattened in (f, s, t) order; binary search per row."""
    nf, S = stencils.shape
    out = np.empty(nf * S * S, np.int64)
    for f in nb.prange(nf):
        for s in range(S):
            r = stencils[f, s]
            lo0, hi0 = indptr[r], indptr[r + 1]
            for t in range(S):
                c = stencils[f, t]
                lo, hi = lo0, hi0
                while lo < hi:
                    mid = (lo + hi) // 2
                    if cols[mid] < c:
                        lo = mid + 1
                    else:
                        hi = mid
                out[(f * S + s) * S + t] = lo
    return out
