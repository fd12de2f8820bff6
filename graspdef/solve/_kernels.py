"""Compiled kernels of the sparse solver (numba): the pattern of the KKT matrix's upper triangle and
its values; the row sums a tangent's factorisation and round-off level need."""
from __future__ import annotations

import numpy as np

from ..compiled import kernel, prange


@kernel(aot=("UniTuple(i8[::1], 3)(i8[::1], i8[::1], i8[::1], i8[::1], i8, i8)",))
def kkt_upper_pattern(k_indptr, k_indices, ct_indptr, ct_indices, n, m):
    """CSR pattern of the upper triangle of [[K, C^T], [C, 0]] (n + m rows) and where each entry
    comes from.  Row i < n holds K's entries of row i with column >= i (in K's order), then C^T's
    row i (columns n + j, in C^T's order); row n + j holds only its (zero) diagonal.

    Returns (indptr, indices, src): src >= 0 is the index into K.data, -1 - k the index k into
    C^T.data, and -(nnz(C^T) + 1) marks the constraint block's zero diagonals."""
    cnt = np.empty(n, np.int64)
    for i in range(n):
        c = 0
        for p in range(k_indptr[i], k_indptr[i + 1]):
            if k_indices[p] >= i:
                c += 1
        cnt[i] = c + ct_indptr[i + 1] - ct_indptr[i]
    indptr = np.empty(n + m + 1, np.int64)
    indptr[0] = 0
    for i in range(n):
        indptr[i + 1] = indptr[i] + cnt[i]
    for j in range(m):
        indptr[n + j + 1] = indptr[n + j] + 1
    nnz = indptr[n + m]
    indices = np.empty(nnz, np.int64)
    src = np.empty(nnz, np.int64)
    zero = -(ct_indptr[n] + 1)
    for i in range(n):
        q = indptr[i]
        for p in range(k_indptr[i], k_indptr[i + 1]):
            if k_indices[p] >= i:
                indices[q] = k_indices[p]
                src[q] = p
                q += 1
        for p in range(ct_indptr[i], ct_indptr[i + 1]):
            indices[q] = n + ct_indices[p]
            src[q] = -1 - p
            q += 1
    for j in range(m):
        indices[indptr[n + j]] = n + j
        src[indptr[n + j]] = zero
    return indptr, indices, src


@kernel(aot=("f8[::1](i8[::1], f8[::1], f8[::1], f8)",))
def kkt_upper_values(src, k_data, ct_data, scale):
    """The values of :func:`kkt_upper_pattern`'s entries: K.data[src] where src >= 0,
    ``scale`` C^T.data[-1 - src] where it points into C^T, 0 on the constraint block's diagonal."""
    nct = ct_data.shape[0]
    out = np.empty(src.shape[0])
    for q in range(src.shape[0]):
        s = src[q]
        if s >= 0:
            out[q] = k_data[s]
        elif s >= -nct:
            out[q] = scale * ct_data[-1 - s]
        else:
            out[q] = 0.0
    return out


#: rows longer than this (plus one) are summed by numpy in :func:`graspdef.solve.sparse.row_summary`
#: (numpy's pairwise summation recurses above its block of 128 entries)
PAIRWISE_BLOCK = 128


@kernel(parallel=True, work=6, per_face=1.5,      # rows; int64 indices (> 2**31 entries): JIT
        aot=("void(i4[::1], i4[::1], f8[::1], f8[::1], f8[::1], f8[::1], f8[::1], f8[::1], f8[::1])",))
def row_sums(indptr, indices, a, b, out, x2, abs_sums, sq_sums, diag):
    """One pass over a CSR matrix's rows (in parallel: each row is its own): with ``b`` not empty
    the matrix is a + b (same structure), written to ``out``; per row i

    * ``abs_sums[i]`` = sum_j |h_ij|, summed as numpy's ``add.reduceat`` sums a row (the first entry
      plus numpy's pairwise sum of the rest: eight accumulators, combined ((0+1)+(2+3))+((4+5)+(6+7)),
      then the tail), so that it equals ``graspdef.solve.sparse._abs_row_sums`` to the bit -- except
      rows of more than PAIRWISE_BLOCK + 1 entries, where numpy recurses: -1 there, left to numpy
      (:func:`graspdef.solve.sparse.row_summary`);
    * ``sq_sums[i]`` = sum_j h_ij^2 x2_j, in index order (scipy's ``csr_matvec``'s order);
    * ``diag[i]`` = the sum of the row's entries in column i (scipy's ``diagonal``)."""
    n = abs_sums.shape[0]
    add = b.shape[0] > 0
    for i in prange(n):
        lo = indptr[i]
        hi = indptr[i + 1]
        s = 0.0
        d = 0.0
        for p in range(lo, hi):
            h = a[p]
            if add:
                h = h + b[p]
                out[p] = h
            s += (h * h) * x2[indices[p]]
            if indices[p] == i:
                d += h
        sq_sums[i] = s
        diag[i] = d
        m = hi - lo - 1                      # the entries after the first
        if m < 0:
            abs_sums[i] = 0.0
            continue
        if m > PAIRWISE_BLOCK:
            abs_sums[i] = -1.0
            continue
        v = out if add else a
        if m < 8:
            r = 0.0
            for p in range(lo + 1, hi):
                r += abs(v[p])
        else:
            q = lo + 1
            r0 = abs(v[q])
            r1 = abs(v[q + 1])
            r2 = abs(v[q + 2])
            r3 = abs(v[q + 3])
            r4 = abs(v[q + 4])
            r5 = abs(v[q + 5])
            r6 = abs(v[q + 6])
            r7 = abs(v[q + 7])
            k = 8
            while k < m - m % 8:
                r0 += abs(v[q + k])
                r1 += abs(v[q + k + 1])
                r2 += abs(v[q + k + 2])
                r3 += abs(v[q + k + 3])
                r4 += abs(v[q + k + 4])
                r5 += abs(v[q + k + 5])
                r6 += abs(v[q + k + 6])
                r7 += abs(v[q + k + 7])
                k += 8
            r = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
            while k < m:
                r += abs(v[q + k])
                k += 1
        abs_sums[i] = abs(v[lo]) + r


@kernel(parallel=True, work=4, per_face=1.5,      # rows; below its SERIAL_MAX scipy multiplies
        aot=("void(i4[::1], i4[::1], f8[::1], f8[:,::1], f8[:,::1])",))    # while the JIT loads (compiled._Loader)
def csr_products(indptr, indices, data, X, Y):
    """Y = A X for a CSR matrix A and a block X (n, k) of k columns, rows in parallel: each entry
    Y[i, j] is summed over row i in index order from 0 -- scipy's ``csr_matvec`` per column, to the
    bit.  Each row's entries are read once for all columns, four (then two, then one) summed at a
    time in registers: on the 10k ball's tangent, out of cache, two columns take 3.2 ms where scipy's
    two one-column products took 8.1; four took 11.9 ms one column at a time (A in cache after the
    first) and 4.0 ms in one pass (medians of the path's 18 calls, 2026-12-07)."""
    k = X.shape[1]
    for i in prange(Y.shape[0]):
        lo = indptr[i]
        hi = indptr[i + 1]
        j = 0
        while j + 4 <= k:
            s0 = 0.0
            s1 = 0.0
            s2 = 0.0
            s3 = 0.0
            for p in range(lo, hi):
                a = data[p]
                c = indices[p]
                s0 += a * X[c, j]
                s1 += a * X[c, j + 1]
                s2 += a * X[c, j + 2]
                s3 += a * X[c, j + 3]
            Y[i, j] = s0
            Y[i, j + 1] = s1
            Y[i, j + 2] = s2
            Y[i, j + 3] = s3
            j += 4
        if j + 2 <= k:
            s0 = 0.0
            s1 = 0.0
            for p in range(lo, hi):
                a = data[p]
                c = indices[p]
                s0 += a * X[c, j]
                s1 += a * X[c, j + 1]
            Y[i, j] = s0
            Y[i, j + 1] = s1
            j += 2
        if j < k:
            s0 = 0.0
            for p in range(lo, hi):
                s0 += data[p] * X[indices[p], j]
            Y[i, j] = s0
