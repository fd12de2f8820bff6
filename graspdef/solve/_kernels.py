"""Compiled kernels of the sparse solver (numba): the pattern of the KKT matrix's upper triangle and its values."""
from __future__ import annotations

import numpy as np

from ..compiled import kernel


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
