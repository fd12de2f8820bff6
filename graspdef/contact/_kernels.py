"""Compiled kernels of the contact terms (numba): the distance functions of the fingertip
obstacles, for the many evaluations of the condensed finger advance over thousands of samples,
and the sample operator's gathers and scatters (graspdef.contact.sampling.SampleOperator).  Pure functions of arrays; the numpy methods
of graspdef.contact.obstacles compute the same quantities and tests/contact compares the two.

Each takes the points P (k, 3) and a shift (3,) subtracted from every point (the obstacle's
advance s e), so no shifted copy of P is made."""
from __future__ import annotations

import numpy as np

from ..compiled import kernel
from ..shell._kernels import sorted_search


@kernel()
def _barrier_sums_terms(d, dhat, w, d1, d2):
    """One point's terms of the condensed advance's sums: w b'(d) d1 and w (b''(d) d1^2 + b'(d) d2)
    for the log barrier b(d) = -(d - dh)^2 ln(d / dh), 0 < d < dh (graspdef.contact.barrier.log_barrier:
    the same formulas), d1 = dd/ds and d2 = d2d/ds2."""
    r = d - dhat
    lg = np.log(d / dhat)
    b1 = -2 * r * lg - r * r / d
    b2 = -2 * lg - 4 * r / d + r * r / (d * d)
    return w * b1 * d1, w * (b2 * d1 * d1 + b1 * d2)


@kernel()
def _box_scan(P, shift, c, R, h, rounding, e, kw, dhat, phi, n, d1, d2):
    """One pass over the points P - shift against the rounded box (:func:`box_distance`'s
    arguments) that fills phi, n, d1, d2 when they have a row per point, and returns the log
    barrier's sums of :func:`box_barrier_sums` with weights kw when kw has one (else zeros) --
    the two kernels' one per-point code, without a call per point."""
    fill = phi.shape[0] == P.shape[0]
    add = kw.shape[0] == P.shape[0]
    el = np.empty(3)
    for j in range(3):
        el[j] = R[0, j] * e[0] + R[1, j] * e[1] + R[2, j] * e[2]
    loc = np.empty(3)
    q = np.empty(3)
    sm = np.empty(3)
    gs = 0.0
    gss = 0.0
    dmin = np.inf
    for i in range(P.shape[0]):
        for j in range(3):
            loc[j] = ((P[i, 0] - shift[0] - c[0]) * R[0, j] + (P[i, 1] - shift[1] - c[1]) * R[1, j]
                      + (P[i, 2] - shift[2] - c[2]) * R[2, j])
        r2 = 0.0
        qmax = -np.inf
        dee = 0.0
        for j in range(3):
            q[j] = abs(loc[j]) - h[j]
            m = q[j] if q[j] > 0.0 else 0.0
            r2 += m * m
            sm[j] = -m if loc[j] < 0.0 else m
            if q[j] > qmax:
                qmax = q[j]
            if q[j] > 0.0:
                dee += el[j] * el[j]
        r = np.sqrt(r2)
        inside = r <= 0.0
        if r < 1e-300:
            r = 1e-300
        ne = (sm[0] * el[0] + sm[1] * el[1] + sm[2] * el[2]) / r
        d = (qmax if inside else r) - rounding
        dd = (dee - ne * ne) / r
        if fill:
            phi[i] = d
            for a in range(3):
                n[i, a] = (R[a, 0] * sm[0] + R[a, 1] * sm[1] + R[a, 2] * sm[2]) / r
            d1[i] = -ne
            d2[i] = dd
        if add:
            dmin = min(dmin, d)
            if d > 0.0 and d < dhat:
                g1, g2 = _barrier_sums_terms(d, dhat, kw[i], -ne, dd)
                gs, gss = gs + g1, gss + g2
    return gs, gss, dmin


@kernel(aot=("Tuple((f8[::1], f8[:,::1], f8[::1], f8[::1]))(f8[:,::1], f8[::1], f8[::1], f8[:,::1], f8[::1], f8, f8[::1])",))
def box_distance(P, shift, c, R, h, rounding, e):
    """Rounded box (centre c, axes = columns of R, inner half extents h, edge radius rounding):
    phi (k,), outward unit normal n (k, 3), and along the unit vector e the derivatives of
    phi(p - s e) in s: -n.e (k,) and e.H.e (k,)."""
    k = P.shape[0]
    phi = np.empty(k)
    n = np.empty((k, 3))
    d1 = np.empty(k)
    d2 = np.empty(k)
    _box_scan(P, shift, c, R, h, rounding, e, np.empty(0), 1.0, phi, n, d1, d2)
    return phi, n, d1, d2


@kernel(aot=("UniTuple(f8, 3)(f8[:,::1], f8[::1], f8[::1], f8[::1], f8[:,::1], f8[::1], f8, f8[::1], f8)",))
def box_barrier_sums(P, kw, shift, c, R, h, rounding, e, dhat):
    """The condensed advance's sums for the log barrier of reach dhat over the points P (k, 3)
    with weights kw (k,) against the rounded box advanced along e (arguments as
    :func:`box_distance`'s): (B_s, B_ss, smallest gap) with B_s = sum kw b'(d) dd/ds and B_ss =
    sum kw (b''(d) (dd/ds)^2 + b'(d) d2d/ds2) over the points with d < dhat (+inf and 0 when a
    gap is <= 0; the smallest gap +inf for no point) -- without box_distance's arrays."""
    gs, gss, dmin = _box_scan(P, shift, c, R, h, rounding, e, kw, dhat, np.empty(0), np.empty((0, 3)),
                              np.empty(0), np.empty(0))
    if dmin <= 0.0:
        return np.inf, 0.0, dmin
    return gs, gss, dmin


@kernel()
def _capsule_scan(P, shift, a, b, radius, e, kw, dhat, phi, n, d1, d2):
    """:func:`_box_scan` for the capsule (:func:`capsule_distance`'s arguments)."""
    fill = phi.shape[0] == P.shape[0]
    add = kw.shape[0] == P.shape[0]
    ab = b - a
    L2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]
    ue = (ab[0] * e[0] + ab[1] * e[1] + ab[2] * e[2]) / np.sqrt(L2)
    ee = e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
    v = np.empty(3)
    gs = 0.0
    gss = 0.0
    dmin = np.inf
    for i in range(P.shape[0]):
        t = 0.0
        for j in range(3):
            t += (P[i, j] - shift[j] - a[j]) * ab[j]
        t /= L2
        t = min(max(t, 0.0), 1.0)
        r2 = 0.0
        for j in range(3):
            v[j] = P[i, j] - shift[j] - (a[j] + t * ab[j])
            r2 += v[j] * v[j]
        r = np.sqrt(r2)
        if r < 1e-300:
            r = 1e-300
        ne = (v[0] * e[0] + v[1] * e[1] + v[2] * e[2]) / r
        d = r - radius
        dd = (ee - ne * ne - (ue * ue if (t > 0.0 and t < 1.0) else 0.0)) / r
        if fill:
            for j in range(3):
                n[i, j] = v[j] / r
            phi[i] = d
            d1[i] = -ne
            d2[i] = dd
        if add:
            dmin = min(dmin, d)
            if d > 0.0 and d < dhat:
                g1, g2 = _barrier_sums_terms(d, dhat, kw[i], -ne, dd)
                gs, gss = gs + g1, gss + g2
    return gs, gss, dmin


@kernel(aot=("Tuple((f8[::1], f8[:,::1], f8[::1], f8[::1]))(f8[:,::1], f8[::1], f8[::1], f8[::1], f8, f8[::1])",))
def capsule_distance(P, shift, a, b, radius, e):
    """Capsule (segment a-b, radius): phi (k,), outward unit normal n (k, 3), and along the unit
    vector e the derivatives of phi(p - s e) in s: -n.e (k,) and e.H.e (k,)."""
    k = P.shape[0]
    phi = np.empty(k)
    n = np.empty((k, 3))
    d1 = np.empty(k)
    d2 = np.empty(k)
    _capsule_scan(P, shift, a, b, radius, e, np.empty(0), 1.0, phi, n, d1, d2)
    return phi, n, d1, d2


@kernel(aot=("UniTuple(f8, 3)(f8[:,::1], f8[::1], f8[::1], f8[::1], f8[::1], f8, f8[::1], f8)",))
def capsule_barrier_sums(P, kw, shift, a, b, radius, e, dhat):
    """:func:`box_barrier_sums` for the capsule (arguments as :func:`capsule_distance`'s)."""
    gs, gss, dmin = _capsule_scan(P, shift, a, b, radius, e, kw, dhat, np.empty(0), np.empty((0, 3)),
                                  np.empty(0), np.empty(0))
    if dmin <= 0.0:
        return np.inf, 0.0, dmin
    return gs, gss, dmin


# ------------------------------------------------------------------------------------------------
# the sample operator S (graspdef.contact.sampling.SampleOperator): rows of a CSR matrix (ptr,
# cols, vals), each sample point p_k = sum_j vals[j] x[cols[j]] over its row's entries
@kernel(aot=("f8[:,::1](i8[::1], i8[::1], f8[::1], f8[:,::1], i8[::1])",))
def sample_rows_points(ptr, cols, vals, x, rows):
    """The points (k, 3) of the sample ``rows`` (k,) at control points x (n, 3)."""
    k = rows.shape[0]
    out = np.zeros((k, 3))
    for i in range(k):
        r = rows[i]
        for j in range(ptr[r], ptr[r + 1]):
            c = cols[j]
            w = vals[j]
            out[i, 0] += w * x[c, 0]
            out[i, 1] += w * x[c, 1]
            out[i, 2] += w * x[c, 2]
    return out


@kernel(aot=("f8[::1](i8[::1], i8[::1], f8[::1], f8[:,::1], i8[::1], i8)",))
def sample_rows_gradient(ptr, cols, vals, g, rows, n):
    """S[rows]^T g for per-sample vectors g (k, 3): the control points' (n, 3), flattened."""
    out = np.zeros(3 * n)
    for i in range(rows.shape[0]):
        r = rows[i]
        for j in range(ptr[r], ptr[r + 1]):
            c = 3 * cols[j]
            w = vals[j]
            out[c] += w * g[i, 0]
            out[c + 1] += w * g[i, 1]
            out[c + 2] += w * g[i, 2]
    return out


@kernel(aot=("UniTuple(i8[::1], 2)(i8[::1], i8[::1], i8[::1], i8[::1])",))
def sample_pair_positions(ptr, cols, indptr, bcols):
    """For every row of S, the block positions in the block pattern (indptr, bcols; sorted
    columns) of each pair (cols[i], cols[j]) of its entries, row by row in (i, j) order: (pptr,
    pos) with row r's pairs at pos[pptr[r]:pptr[r + 1]]; -1 where a pair is not in the pattern."""
    nr = ptr.shape[0] - 1
    pptr = np.empty(nr + 1, np.int64)
    pptr[0] = 0
    for r in range(nr):
        m = ptr[r + 1] - ptr[r]
        pptr[r + 1] = pptr[r] + m * m
    pos = np.empty(pptr[nr], np.int64)
    for r in range(nr):
        q = pptr[r]
        for i in range(ptr[r], ptr[r + 1]):
            a = cols[i]
            for j in range(ptr[r], ptr[r + 1]):
                c = cols[j]
                lo = sorted_search(bcols, indptr[a], indptr[a + 1], c)
                pos[q] = lo if (lo < indptr[a + 1] and bcols[lo] == c) else -1
                q += 1
    return pptr, pos


@kernel(aot=("void(i8[::1], f8[::1], i8[::1], i8[::1], i8[::1], i8[::1], f8[:,:,::1], i8[::1], f8[::1])",))
def sample_rows_hessian(ptr, vals, pptr, pos, base, stride, H, rows, out):
    """Add sum_k (S_k x I3)^T H_k (S_k x I3) for the sample ``rows`` (k,) with 3 x 3 blocks H
    (k, 3, 3) into ``out``, the data of the pattern's scalar CSR matrix (block p's entry (a, b)
    at base[p] + a stride[p] + b; see graspdef.shell._kernels.scalar_pattern)."""
    for i in range(rows.shape[0]):
        r = rows[i]
        j0 = ptr[r]
        m = ptr[r + 1] - j0
        q = pptr[r]
        for ii in range(m):
            wi = vals[j0 + ii]
            for jj in range(m):
                c = wi * vals[j0 + jj]
                p = pos[q + ii * m + jj]
                o = base[p]
                st = stride[p]
                for a in range(3):
                    for b in range(3):
                        out[o + a * st + b] += c * H[i, a, b]
