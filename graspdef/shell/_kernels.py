"""Compiled element kernels (numba).  Pure functions of arrays; the numpy reference path in
``energy.py`` computes the same quantities and the tests compare the two."""
from __future__ import annotations

import numpy as np

from ..compiled import kernel, prange


@kernel(parallel=True)
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
    for f in prange(nf):
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


@kernel()
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


@kernel()
def sorted_search(cols, lo, hi, c):
    """The first position in cols[lo:hi] (sorted) whose value is not below c (hi if none)."""
    while lo < hi:
        mid = (lo + hi) // 2
        if cols[mid] < c:
            lo = mid + 1
        else:
            hi = mid
    return lo


@kernel(parallel=True, work=0, aot=("i8[::1](i8[:,::1], i8[::1], i8[::1])",))
def block_positions(stencils, indptr, cols):
    """Position in the block-CSR pattern (indptr, cols; sorted columns) of every stencil pair
    (stencils[f, s], stencils[f, t]), flattened in (f, s, t) order; binary search per row."""
    nf, S = stencils.shape
    out = np.empty(nf * S * S, np.int64)
    for f in prange(nf):
        for s in range(S):
            r = stencils[f, s]
            lo0, hi0 = indptr[r], indptr[r + 1]
            for t in range(S):
                out[(f * S + s) * S + t] = sorted_search(cols, lo0, hi0, stencils[f, t])
    return out


@kernel(aot=("UniTuple(i8[::1], 2)(i8[::1], i8[::1], i4[::1], i4[::1])",))     # int64 indices (> 2**31 entries): JIT
def scalar_pattern(indptr, cols, sptr, idx):
    """The scalar CSR pattern of the 3x3-block pattern (indptr, cols), written into ``sptr``
    (3 n + 1) and ``idx`` (9 nnzb) (scalar indptr and indices, of the caller's integer type);
    returns (base, stride): block p (row r, k-th of the L blocks of its row) holding its entry
    (a, b) at base[p] + a stride[p] + b with base[p] = 9 indptr[r] + 3 k and stride[p] = 3 L."""
    n = indptr.shape[0] - 1
    nnzb = cols.shape[0]
    sptr[0] = 0
    for r in range(n):
        L = indptr[r + 1] - indptr[r]
        for a in range(3):
            sptr[3 * r + a + 1] = 9 * indptr[r] + 3 * L * (a + 1)
    base = np.empty(nnzb, np.int64)
    stride = np.empty(nnzb, np.int64)
    for r in range(n):
        p0 = indptr[r]
        L = indptr[r + 1] - p0
        for k in range(L):
            p = p0 + k
            base[p] = 9 * p0 + 3 * k
            stride[p] = 3 * L
            for a in range(3):
                q = 9 * p0 + 3 * L * a + 3 * k
                for b in range(3):
                    idx[q + b] = 3 * cols[p] + b
    return base, stride


# ------------------------------------------------------------------------------------------------
# fused kernels of the energy, gradient and Hessian (energy.ShellEnergy); numpy reference path:
# ShellEnergy._local with kinematics.strains / strain_jacobian / strain_hessian_contract
# ------------------------------------------------------------------------------------------------
@kernel(parallel=True, work=1, aot=("Tuple((f8[:,:,:,::1], f8[:,:,::1]))(f8[:,::1], i8[:,::1], f8[:,:,:,::1], i8, f8[:,:,::1], f8[:,:,::1])",))
def point_strains(x, stencils, D, dstride, rest_a, rest_b):
    """Surface derivatives y (nf, nq, 5, 3) = sum_s D[f, q, s, K] x[stencils[f, s]] and the strain
    vector s (nf, nq, 6) of ``kinematics.strains`` at every quadrature point.

    x : (n, 3) control points; stencils : (nf, S); D : (nf|1, nq, S, 5) basis derivatives
    (dN, ddN), ``dstride`` = 0 when D is shared by all faces; rest_a, rest_b : (nf, nq, 3)."""
    nf, S = stencils.shape
    nq = D.shape[1]
    y = np.empty((nf, nq, 5, 3))
    s = np.empty((nf, nq, 6))
    for f in prange(nf):
        df = f * dstride
        for q in range(nq):
            for K in range(5):
                for a in range(3):
                    acc = 0.0
                    for t in range(S):
                        acc += D[df, q, t, K] * x[stencils[f, t], a]
                    y[f, q, K, a] = acc
            a1 = y[f, q, 0]
            a2 = y[f, q, 1]
            m0 = a1[1] * a2[2] - a1[2] * a2[1]
            m1 = a1[2] * a2[0] - a1[0] * a2[2]
            m2 = a1[0] * a2[1] - a1[1] * a2[0]
            j = np.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
            n0, n1, n2 = m0 / j, m1 / j, m2 / j
            s[f, q, 0] = 0.5 * ((a1[0] * a1[0] + a1[1] * a1[1] + a1[2] * a1[2]) - rest_a[f, q, 0])
            s[f, q, 1] = 0.5 * ((a2[0] * a2[0] + a2[1] * a2[1] + a2[2] * a2[2]) - rest_a[f, q, 1])
            s[f, q, 2] = 2.0 * (0.5 * ((a1[0] * a2[0] + a1[1] * a2[1] + a1[2] * a2[2]) - rest_a[f, q, 2]))
            for i in range(3):
                c = y[f, q, 2 + i]
                b = c[0] * n0 + c[1] * n1 + c[2] * n2
                k = b - rest_b[f, q, i]
                s[f, q, 3 + i] = 2.0 * k if i == 2 else k
    return y, s


@kernel()
def _point_jacobian(y, J, n):
    """ds/dy at one point into J (6, 15) (column 3 K + a), as ``kinematics.strain_jacobian``;
    the unit normal into n (3,); returns the area element |a1 x a2|."""
    a1 = y[0]
    a2 = y[1]
    m0 = a1[1] * a2[2] - a1[2] * a2[1]
    m1 = a1[2] * a2[0] - a1[0] * a2[2]
    m2 = a1[0] * a2[1] - a1[1] * a2[0]
    j = np.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
    n[0], n[1], n[2] = m0 / j, m1 / j, m2 / j
    J[:, :] = 0.0
    for a in range(3):
        J[0, a] = a1[a]
        J[1, 3 + a] = a2[a]
        J[2, a] = a2[a]
        J[2, 3 + a] = a1[a]
    for i in range(3):
        blk = 2 + i
        fac = 2.0 if i == 2 else 1.0
        c = y[blk]
        cn = c[0] * n[0] + c[1] * n[1] + c[2] * n[2]
        g0 = (c[0] - cn * n[0]) / j                       # d(c.n)/dm = P c / j
        g1 = (c[1] - cn * n[1]) / j
        g2 = (c[2] - cn * n[2]) / j
        for a in range(3):
            J[3 + i, 3 * blk + a] = fac * n[a]
        J[3 + i, 0] = fac * (a2[1] * g2 - a2[2] * g1)       # a2 x g
        J[3 + i, 1] = fac * (a2[2] * g0 - a2[0] * g2)
        J[3 + i, 2] = fac * (a2[0] * g1 - a2[1] * g0)
        J[3 + i, 3] = fac * (g1 * a1[2] - g2 * a1[1])       # g x a1
        J[3 + i, 4] = fac * (g2 * a1[0] - g0 * a1[2])
        J[3 + i, 5] = fac * (g0 * a1[1] - g1 * a1[0])
    return j


@kernel()
def _skew(v, A):
    A[0, 0], A[0, 1], A[0, 2] = 0.0, -v[2], v[1]
    A[1, 0], A[1, 1], A[1, 2] = v[2], 0.0, -v[0]
    A[2, 0], A[2, 1], A[2, 2] = -v[1], v[0], 0.0


@kernel()
def _mm3(A, B, C):
    """C = A @ B (3 x 3)."""
    for i in range(3):
        for k in range(3):
            C[i, k] = A[i, 0] * B[0, k] + A[i, 1] * B[1, k] + A[i, 2] * B[2, k]


@kernel()
def _point_geometric(y, sig, n, j, Hy, A1, A2, Hm, M, M2, PA):
    """Add the stress (geometric) part sum_i sig_i d2 s_i/dy2 (``kinematics.
    strain_hessian_contract``) to Hy (15, 15).  The curvature terms are linear in the second
    derivatives c_i = a_11, a_22, a_12, so their a1-a2 blocks are evaluated once with the
    weighted sum c = sum_i fac_i sig_{3+i} c_i."""
    a1 = y[0]
    a2 = y[1]
    w0, w1, w2 = sig[3], sig[4], 2.0 * sig[5]
    c0 = w0 * y[2, 0] + w1 * y[3, 0] + w2 * y[4, 0]
    c1 = w0 * y[2, 1] + w1 * y[3, 1] + w2 * y[4, 1]
    c2 = w0 * y[2, 2] + w1 * y[3, 2] + w2 * y[4, 2]
    cn = c0 * n[0] + c1 * n[1] + c2 * n[2]
    j2 = j * j
    cv = (c0, c1, c2)
    for a in range(3):
        for b in range(3):
            h = -cv[a] * n[b] - n[a] * cv[b] + 3.0 * cn * n[a] * n[b]
            if a == b:
                h -= cn
            Hm[a, b] = h / j2
    _skew(a1, A1)
    _skew(a2, A2)
    # H11 = -A2 Hm A2, H22 = -A1 Hm A1, H12 = -[g]x + A2 Hm A1 with g = P c / j
    _mm3(A2, Hm, M)
    _mm3(M, A2, M2)
    for a in range(3):
        for b in range(3):
            Hy[a, b] -= M2[a, b]
    _mm3(M, A1, M2)
    g0 = (c0 - cn * n[0]) / j
    g1 = (c1 - cn * n[1]) / j
    g2 = (c2 - cn * n[2]) / j
    M2[0, 1] += g2
    M2[0, 2] -= g1
    M2[1, 0] -= g2
    M2[1, 2] += g0
    M2[2, 0] += g1
    M2[2, 1] -= g0
    for a in range(3):
        for b in range(3):
            Hy[a, 3 + b] += M2[a, b]
            Hy[3 + b, a] += M2[a, b]
    _mm3(A1, Hm, M)
    _mm3(M, A1, M2)
    for a in range(3):
        for b in range(3):
            Hy[3 + a, 3 + b] -= M2[a, b]
    # membrane: sig_0 I, sig_1 I on the diagonal blocks, sig_2 I on the a1-a2 blocks
    for a in range(3):
        Hy[a, a] += sig[0]
        Hy[3 + a, 3 + a] += sig[1]
        Hy[a, 3 + a] += sig[2]
        Hy[3 + a, a] += sig[2]
    # c_i - a1 and c_i - a2 blocks: -(P A2)/j and (P A1)/j, weighted by fac_i sig_{3+i}
    for r in range(2):
        A = A2 if r == 0 else A1
        sgn = -1.0 if r == 0 else 1.0
        for k in range(3):
            na = n[0] * A[0, k] + n[1] * A[1, k] + n[2] * A[2, k]
            for a in range(3):
                PA[a, k] = sgn * (A[a, k] - n[a] * na) / j
        for i in range(3):
            blk = 2 + i
            wi = w0 if i == 0 else (w1 if i == 1 else w2)
            for a in range(3):
                for b in range(3):
                    v = wi * PA[a, b]
                    Hy[3 * blk + a, 3 * r + b] += v
                    Hy[3 * r + b, 3 * blk + a] += v


@kernel(parallel=True, work=0, aot=("void(f8[:,:,:,::1], f8[:,::1], f8[:,:,::1], f8[:,:,:,::1], f8[:,:,:,::1], f8[:,:,:,::1], i8, i8[:,::1], i8[::1], i8[::1], i8[::1], i8[::1], i8[::1], i8[::1], i8[::1], f8[:,::1], f8[::1], b1)",))
def assemble_elements(y, w, dW, ddW, D, Dt, dstride, stencils, order, bstart, cblocks, cstart,
                      index, base, stride, grad, bdata, hess):
    """Gradient and (if ``hess``) Hessian of sum_q w_q W(s(y_q)) of every face, added in place
    into ``grad`` (n, 3) and ``bdata`` (9 nnzb): the data of the scalar CSR matrix of a
    :class:`~energy.BlockPattern`, block p's entry (a, b) at base[p] + a stride[p] + b.

    y : (nf, nq, 5, 3) surface derivatives; w : (nf, nq) weights; dW (nf, nq, 6), ddW
    (nf, nq, 6, 6) derivatives of the density; D : (nf|1, nq, S, 5) and Dt = D transposed to
    (nf|1, nq, 5, S4), zero-padded to S4 = a multiple of 4 >= S; ``dstride`` 0 when shared.  Per point the Hessian with respect to y is
    Hy = J^T (w ddW) J + sum_i w dW_i d2 s_i/dy2 (15 x 15), and the element matrix
    sum_q (D_q x I3)^T Hy_q (D_q x I3) is formed without the (5, 3, 5, 3) intermediates of the
    numpy path (only the blocks t >= s, mirrored); block (s, t) goes to block position
    p = index[(f S + s) S + t] of the pattern.

    Faces are visited in ``order``, in blocks (bstart: offsets into order) of one colour
    (cblocks[cstart[c]:cstart[c + 1]] are the blocks of colour c); blocks of one colour share no
    control vertex, so they run in parallel without write races, and the sums are the same for
    any number of threads."""
    nq = y.shape[1]
    S = D.shape[2]
    S4 = Dt.shape[3]
    ncol = cstart.shape[0] - 1
    u1, u2, u3, uS4 = np.uint64(1), np.uint64(2), np.uint64(3), np.uint64(S4)
    for col in range(ncol):
        for bi in prange(cstart[col], cstart[col + 1]):
            blk_id = cblocks[bi]
            J = np.empty((6, 15))
            CJ = np.empty((6, 6))
            Cw = np.empty((6, 6))
            Hy = np.empty((15, 15))
            Hyf = Hy.reshape(225)
            n = np.empty(3)
            sig = np.empty(6)
            gy = np.empty(15)
            ge = np.empty((S, 3))
            Tf = np.empty(nq * S * 45)
            out = np.empty(S * 3 * 3 * S4)
            A1 = np.empty((3, 3))
            A2 = np.empty((3, 3))
            Hm = np.empty((3, 3))
            M = np.empty((3, 3))
            M2 = np.empty((3, 3))
            PA = np.empty((3, 3))
            for k in range(bstart[blk_id], bstart[blk_id + 1]):
                f = order[k]
                df = f * dstride
                ge[:, :] = 0.0
                for q in range(nq):
                    wq = w[f, q]
                    for i in range(6):
                        sig[i] = dW[f, q, i] * wq
                    j = _point_jacobian(y[f, q], J, n)
                    for m in range(15):
                        acc = 0.0
                        for i in range(6):
                            acc += sig[i] * J[i, m]
                        gy[m] = acc
                    for s in range(S):
                        for a in range(3):
                            acc = 0.0
                            for K in range(5):
                                acc += D[df, q, s, K] * gy[3 * K + a]
                            ge[s, a] += acc
                    if not hess:
                        continue
                    # material part J^T C J, C = w ddW, using the sparsity of J: columns 0..5 (a1, a2)
                    # are dense, the curvature row 3 + k has fac_k n in the columns of a_(2+k) only
                    for i in range(6):
                        for l in range(6):
                            Cw[i, l] = ddW[f, q, i, l] * wq
                    for i in range(6):
                        for m in range(6):
                            acc = 0.0
                            for l in range(6):
                                acc += Cw[i, l] * J[l, m]
                            CJ[i, m] = acc
                    for m in range(6):
                        for mm in range(6):
                            acc = 0.0
                            for i in range(6):
                                acc += J[i, m] * CJ[i, mm]
                            Hy[m, mm] = acc
                        for k in range(3):
                            acc = 0.0
                            for i in range(6):
                                acc += J[i, m] * Cw[i, 3 + k]
                            fk = 2.0 if k == 2 else 1.0
                            for a in range(3):
                                v = acc * (fk * n[a])
                                Hy[m, 6 + 3 * k + a] = v
                                Hy[6 + 3 * k + a, m] = v
                    for k in range(3):
                        fk = 2.0 if k == 2 else 1.0
                        for l in range(3):
                            fl = 2.0 if l == 2 else 1.0
                            ckl = Cw[3 + k, 3 + l] * (fk * fl)
                            for a in range(3):
                                for b in range(3):
                                    Hy[6 + 3 * k + a, 6 + 3 * l + b] = ckl * (n[a] * n[b])
                    _point_geometric(y[f, q], sig, n, j, Hy, A1, A2, Hm, M, M2, PA)
                    # T[q, s, (a, L, b)] = sum_K D[s, K] Hy[3K + a, 3L + b]  (flat, unsigned indices:
                    # no negative-index wraparound in the inner loops)
                    for s in range(S):
                        tq = np.uint64((q * S + s) * 45)
                        for jj in range(45):
                            Tf[tq + np.uint64(jj)] = 0.0
                        for K in range(5):
                            d = D[df, q, s, K]
                            hk = np.uint64(45 * K)
                            for jj in range(45):
                                u = np.uint64(jj)
                                Tf[tq + u] += d * Hyf[hk + u]
                for s in range(S):
                    v = stencils[f, s]
                    for a in range(3):
                        grad[v, a] += ge[s, a]
                if not hess:
                    continue
                # out[s, a, b, t] = sum_q sum_L T[q, s, (a, L, b)] D[q, t, L] for t >= s, in
                # register blocks of 3 (b) x 4 (t); flat arrays with unsigned indices
                Dtf = Dt[df].reshape(nq * 5 * S4)
                for s in range(S):
                    for a in range(3):
                        r0 = np.uint64((s * 3 + a) * 3 * S4)
                        for t0 in range((s // 4) * 4, S4, 4):
                            c0 = 0.0
                            c1 = 0.0
                            c2 = 0.0
                            c3 = 0.0
                            d0 = 0.0
                            d1 = 0.0
                            d2 = 0.0
                            d3 = 0.0
                            e0 = 0.0
                            e1 = 0.0
                            e2 = 0.0
                            e3 = 0.0
                            for q in range(nq):
                                for L in range(5):
                                    jt = np.uint64((q * S + s) * 45 + 15 * a + 3 * L)
                                    tv = Tf[jt]
                                    uv = Tf[jt + u1]
                                    wv = Tf[jt + u2]
                                    kd = np.uint64((q * 5 + L) * S4 + t0)
                                    x0 = Dtf[kd]
                                    x1 = Dtf[kd + u1]
                                    x2 = Dtf[kd + u2]
                                    x3 = Dtf[kd + u3]
                                    c0 += tv * x0
                                    c1 += tv * x1
                                    c2 += tv * x2
                                    c3 += tv * x3
                                    d0 += uv * x0
                                    d1 += uv * x1
                                    d2 += uv * x2
                                    d3 += uv * x3
                                    e0 += wv * x0
                                    e1 += wv * x1
                                    e2 += wv * x2
                                    e3 += wv * x3
                            o = r0 + np.uint64(t0)
                            out[o] = c0
                            out[o + u1] = c1
                            out[o + u2] = c2
                            out[o + u3] = c3
                            o += uS4
                            out[o] = d0
                            out[o + u1] = d1
                            out[o + u2] = d2
                            out[o + u3] = d3
                            o += uS4
                            out[o] = e0
                            out[o + u1] = e1
                            out[o + u2] = e2
                            out[o + u3] = e3
                base_f = f * S * S
                for s in range(S):
                    # diagonal block symmetrised; off-diagonal block (s, t) and its transpose (t, s)
                    p = index[base_f + s * S + s]
                    pu = np.uint64(base[p])
                    su = np.uint64(stride[p])
                    for a in range(3):
                        for b in range(3):
                            bdata[pu + np.uint64(a) * su + np.uint64(b)] += 0.5 * (
                                out[np.uint64(((s * 3 + a) * 3 + b) * S4 + s)]
                                + out[np.uint64(((s * 3 + b) * 3 + a) * S4 + s)])
                    for t in range(s + 1, S):
                        p = index[base_f + s * S + t]
                        pt = index[base_f + t * S + s]
                        pu = np.uint64(base[p])
                        su = np.uint64(stride[p])
                        ptu = np.uint64(base[pt])
                        stu = np.uint64(stride[pt])
                        for a in range(3):
                            for b in range(3):
                                v = out[np.uint64(((s * 3 + a) * 3 + b) * S4 + t)]
                                bdata[pu + np.uint64(a) * su + np.uint64(b)] += v
                                bdata[ptu + np.uint64(b) * stu + np.uint64(a)] += v


# ------------------------------------------------------------------------------------------------
# thickness-integrated hyperelastic density (hyperelastic._ThicknessIntegrated.density), per point
# ------------------------------------------------------------------------------------------------
#: material kinds of density_points
NEO_HOOKEAN, MOONEY_RIVLIN, EXPONENTIAL, COMPRESSIBLE_NEO_HOOKEAN = 0, 1, 2, 3


@kernel()
def _incompressible_psi(kind, par, p, q):
    """psi(c, d) and derivatives of the incompressible laws (hyperelastic._Incompressible._psi)."""
    d = 1.0 + p + q
    c = 2.0 + p
    inv_d = 1.0 / d
    i1 = (p * p + p * q - q) * inv_d
    pq = p + q
    i2 = (pq * pq - q) * inv_d
    W11 = 0.0
    W12 = 0.0
    W22 = 0.0
    if kind == NEO_HOOKEAN:
        W = 0.5 * par[0] * i1
        W1 = 0.5 * par[0]
        W2 = 0.0
    elif kind == MOONEY_RIVLIN:
        W = par[0] * i1 + par[1] * i2
        W1 = par[0]
        W2 = par[1]
    else:                                                   # EXPONENTIAL: C0 (exp[C1 i1] - 1)
        a = par[1] * i1
        W1 = par[0] * par[1] * np.exp(a)
        W = par[0] * np.expm1(a)
        W2 = 0.0
        W11 = par[1] * W1
    inv_d2 = inv_d * inv_d
    I2d = 1.0 - c * inv_d2
    pc = W1 + W2 * inv_d
    pd = -W1 * inv_d2 + W2 * I2d
    pcc = W11 + 2.0 * W12 * inv_d + W22 * inv_d2
    pcd = -W11 * inv_d2 + W12 * (I2d - inv_d2 * inv_d) + W22 * inv_d * I2d - W2 * inv_d2
    pdd = (W11 * inv_d2 * inv_d2 - 2.0 * W12 * inv_d2 * I2d + W22 * I2d * I2d
           + 2.0 * inv_d2 * inv_d * (W1 + W2 * c))
    return W, pc, pd, pcc, pcd, pdd


@kernel()
def _compressible_psi(par, p, q, tol_eps, max_iter):
    """Compressible neo-Hookean psi with C33 from plane stress (hyperelastic.
    CompressibleNeoHookean._psi / _log_c33); the last value is False if Newton did not converge."""
    mu, lam = par[0], par[1]
    log_d = np.log1p(p + q)
    u = -lam * log_d / (2.0 * mu + lam)
    if log_d < 0.0:
        u = min(u, np.log1p(-lam * log_d / (2.0 * mu)))
    ok = not np.isfinite(log_d)
    tol = tol_eps * (1.0 + abs(log_d))
    for _ in range(max_iter):
        f = 2.0 * mu * np.expm1(u) + lam * (log_d + u)
        du = -f / (2.0 * mu * np.exp(u) + lam)
        u = u + du
        if abs(du) <= tol * (1.0 + abs(u)):
            ok = True
            break
    d = 1.0 + p + q
    L = log_d + u
    psi = 0.5 * mu * (p + np.expm1(u) - L) + 0.125 * lam * L * L
    pc = 0.5 * mu
    pd = (0.5 * lam * L - mu) / (2.0 * d)
    m = 2.0 * mu + lam - lam * L
    pdd = (m * m - lam * lam) / (4.0 * d * d * m)
    return psi, pc, pd, 0.0, 0.0, pdd, ok


@kernel(parallel=True, work=2, aot=("Tuple((f8[::1], f8[:,::1], f8[:,:,::1], b1[::1]))(i8, f8[::1], f8[:,::1], f8[:,::1], f8[::1], f8[::1], f8[::1], i8, f8, i8)",))
def density_points(kind, par, s, ri, half, xg, wg, order, tol_eps, max_iter):
    """Energy per unit rest area W (n,) and, for order >= 1 / 2, dW/ds (n, 6) and d2W/ds2
    (n, 6, 6) of a thickness-integrated hyperelastic material at n points; the compiled
    counterpart of ``hyperelastic._ThicknessIntegrated._density_numpy`` (same formulas).

    kind : NEO_HOOKEAN (par = mu), MOONEY_RIVLIN (C1, C2), EXPONENTIAL (C0, C1),
    COMPRESSIBLE_NEO_HOOKEAN (mu, lam); s (n, 6) strains; ri (n, 3) contravariant rest metric;
    half (n,) half the rest thickness; xg, wg Gauss-Legendre points and weights on [-1, 1].
    An inverted point (d <= 0 somewhere in the thickness) gets W = inf and NaN derivatives.
    Returns (W, dW, ddW, converged): ``converged`` False if a plane-stress Newton solve failed."""
    n = s.shape[0]
    ng = xg.shape[0]
    W = np.empty(n)
    dW = np.empty((n, 6)) if order >= 1 else np.empty((0, 6))
    ddW = np.empty((n, 6, 6)) if order >= 2 else np.empty((0, 6, 6))
    conv = np.ones(n, np.bool_)
    for i in prange(n):
        A11, A22, A12 = ri[i, 0], ri[i, 1], ri[i, 2]
        det_inv = A11 * A22 - A12 * A12
        gc0, gc1, gc2 = 2.0 * A11, 2.0 * A22, 2.0 * A12
        h = half[i]
        Wacc = 0.0
        G = np.zeros((2, 3))
        Hm = np.zeros((3, 6))
        gc = np.empty(3)
        gd = np.empty(3)
        hg = np.empty(6)
        gc[0], gc[1], gc[2] = gc0, gc1, gc2
        bad = False
        for ig in range(ng):
            x = xg[ig]
            hx = h * x
            v1 = s[i, 0] - hx * s[i, 3]
            v2 = s[i, 1] - hx * s[i, 4]
            v3 = s[i, 2] - hx * s[i, 5]
            p = 2.0 * (A11 * v1 + A22 * v2 + A12 * v3)
            q = det_inv * (4.0 * v1 * v2 - v3 * v3)
            gd[0] = 4.0 * v2 * det_inv + gc0
            gd[1] = 4.0 * v1 * det_inv + gc1
            gd[2] = -2.0 * v3 * det_inv + gc2
            if 1.0 + p + q <= 0.0:
                bad = True
                p = 0.0
                q = 0.0
            if kind == COMPRESSIBLE_NEO_HOOKEAN:
                psi, pc, pd, pcc, pcd, pdd, ok = _compressible_psi(par, p, q, tol_eps, max_iter)
                if not ok:
                    conv[i] = False
            else:
                psi, pc, pd, pcc, pcd, pdd = _incompressible_psi(kind, par, p, q)
            w = wg[ig]
            Wacc += w * psi
            if order >= 1:
                wx = w * x
                for c in range(3):
                    gr = pc * gc[c] + pd * gd[c]
                    G[0, c] += w * gr
                    G[1, c] += wx * gr
            if order >= 2:
                for jj in range(6):
                    a = 0 if jj == 0 or jj == 3 or jj == 4 else (1 if jj == 1 or jj == 5 else 2)
                    b = 0 if jj == 0 else (1 if jj == 1 or jj == 3 else 2)
                    hd = 0.0
                    if jj == 2:
                        hd = -2.0 * det_inv
                    elif jj == 3:
                        hd = 4.0 * det_inv
                    hg[jj] = (pcc * (gc[a] * gc[b]) + pcd * (gc[a] * gd[b] + gd[a] * gc[b])
                              + pdd * (gd[a] * gd[b]) + pd * hd)
                wx = w * x
                wxx = w * x * x
                for jj in range(6):
                    Hm[0, jj] += w * hg[jj]
                    Hm[1, jj] += wx * hg[jj]
                    Hm[2, jj] += wxx * hg[jj]
        h2 = h * h
        if bad:
            W[i] = np.inf
        else:
            W[i] = h * Wacc
        if order >= 1:
            for c in range(3):
                dW[i, c] = np.nan if bad else h * G[0, c]
                dW[i, 3 + c] = np.nan if bad else -(h2 * G[1, c])
        if order >= 2:
            for blk in range(3):
                # M0 = h Hm0, M1 = -h^2 Hm1, M2 = h^3 Hm2 in [[M0, M1], [M1, M2]]
                for a in range(3):
                    for b in range(3):
                        jj = a if a == b else (3 if a + b == 1 else (4 if a + b == 2 else 5))
                        if blk == 0:
                            v = h * Hm[0, jj]
                            ddW[i, a, b] = np.nan if bad else v
                        elif blk == 1:
                            v = -(h2 * Hm[1, jj])
                            ddW[i, a, 3 + b] = np.nan if bad else v
                            ddW[i, 3 + a, b] = np.nan if bad else v
                        else:
                            v = (h2 * h) * Hm[2, jj]
                            ddW[i, 3 + a, 3 + b] = np.nan if bad else v
    return W, dW, ddW, conv
