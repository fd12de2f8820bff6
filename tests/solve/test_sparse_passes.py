"""The tangent's sum and its row numbers in one pass, and the KKT residual's products on both
cores (issue 17, speed).

A nonlinear path's tangent is the sum of the terms' Hessians; its round-off level needs
sum_j H_ij^2 x_j^2 per row, and its KKT factorisation the diagonal (the constraint scale) and
sum_j |H_ij| (the norm of the backward error).  numpy and scipy made six passes over the 3.4 M
entries of the 10k ball's tangent for them; ``graspdef.solve.sparse.row_summary`` makes one.
The refinement's residuals and the inertia certificates multiply by the tangent ~170 times on the
ball's path; ``graspdef.solve.sparse.csr_product`` does it on both cores (scipy's product runs on
one, and between back-substitutions the matrix is out of cache).  Nothing may change but the
time: every number must be the one of those passes and products, to the bit, so that paths stay
the same to the bit (the ball's 19 factorisations and 17.540451221486 mm).
"""
import numpy as np
import pytest
import scipy.sparse as sp

import graspdef.solve.sparse as S
from graspdef.solve.equilibrium import ROUNDOFF_FACTOR, Equilibrium, _add, roundoff_floor, tangent_sum
from test_inexact_newton import _ball       # the bench's air-filled neo-Hookean ball pinched at its poles


def _random_csr(n, lengths, seed, dtype=np.int32):
    """A canonical CSR matrix (sorted, no duplicates) with the given row lengths (0 and 1 included,
    and rows longer than numpy's pairwise block of 128) and a second one on the same index arrays."""
    rng = np.random.default_rng(seed)
    cols = [np.sort(rng.choice(n, size=k, replace=False)) for k in lengths]
    indptr = np.concatenate([[0], np.cumsum(lengths)]).astype(dtype)
    indices = np.concatenate(cols).astype(dtype)
    nnz = int(indptr[-1])
    scales = 10.0 ** rng.uniform(-6, 6, nnz)               # magnitudes over 12 decades: rounding shows
    A = sp.csr_matrix((rng.standard_normal(nnz) * scales, indices, indptr), shape=(n, n))
    B = sp.csr_matrix((rng.standard_normal(nnz) * scales, A.indices, A.indptr), shape=(n, n))
    A.has_canonical_format = True
    return A, B


@pytest.mark.parametrize("dtype", [np.int32, np.int64])
@pytest.mark.parametrize("with_b", [False, True])
def test_one_pass_gives_the_numbers_of_numpy_and_scipy_to_the_bit(dtype, with_b):
    """On rows of 0, 1, 2-8, 9-129 and up to 300 entries (numpy's pairwise summation recurses above
    129), with and without a second matrix added, with 32- and 64-bit indices: the sum equals
    ``_add``'s, the absolute row sums ``_abs_row_sums``' (numpy's ``add.reduceat``), the diagonal
    scipy's ``diagonal()``, and sum_j H_ij^2 x_j^2 scipy's product of H o H with x o x -- exactly.
    A plain left-to-right sum of the absolute values would not be (checked: it differs)."""
    n = 400
    rng = np.random.default_rng(1)
    lengths = np.concatenate([[0, 1, 2, 7, 8, 9, 16, 17, 128, 129, 130, 300],
                              rng.integers(0, 140, n - 12)])
    A, B = _random_csr(n, lengths, 2, dtype)
    # the diagonal present in some rows only
    x = rng.standard_normal(n) * 10.0 ** rng.uniform(-3, 3, n)
    H, rows, sq = S.row_summary(A, B if with_b else None, x)
    ref = _add(A, B) if with_b else A
    assert np.array_equal(H.data, ref.data)
    assert S.same_array(H.indices, A.indices) and S.same_array(H.indptr, A.indptr) and H.has_canonical_format
    assert np.array_equal(rows.abs_sums, S._abs_row_sums(ref))
    assert np.array_equal(rows.diagonal, ref.diagonal())
    H2 = sp.csr_matrix((ref.data * ref.data, ref.indices, ref.indptr), shape=ref.shape)
    assert np.array_equal(sq, H2 @ (x * x))
    plain = np.array([sum(abs(v) for v in ref.data[ref.indptr[i]:ref.indptr[i + 1]]) for i in range(n)])
    assert not np.array_equal(plain, rows.abs_sums)        # the summation order matters here


def test_the_ball_tangent_and_its_factorisation_are_unchanged_to_the_bit():
    """The air-filled ball (642 control vertices) at a deformed state: ``Equilibrium.evaluate``'s
    tangent (shell + gas on the shell's pattern, one pass) equals the sum of the terms' Hessians,
    its round-off level equals ``roundoff_floor``'s, and the KKT system factorised with the row
    numbers has the constraint scale and norm it computes itself from the matrix."""
    pr = _ball(3, 20.0)
    eq = Equilibrium(pr)
    try:
        u = (0.05 * eq.X * np.array([0.3, 0.3, -0.6])).ravel()
        st = eq.evaluate(u, 0.4)
        assert st.rows is not None                        # the one-pass path was taken
        x = eq.X + u.reshape(-1, 3)
        hs = [v.hessian for v in (t.evaluate(x, 0.4, 2, u) for t in eq.terms) if v.hessian is not None]
        assert len(hs) == 2
        ref = _add(hs[0], hs[1])
        assert np.array_equal(st.hessian.data, ref.data)
        assert st.floor == roundoff_floor(ref, x) > 0
        with S.KKTSystem(eq.C, "superlu") as a, S.KKTSystem(eq.C, "superlu") as b:
            a.factor(st.hessian, rows=st.rows)
            b.factor(ref)
            assert (a.scale, a.norm) == (b.scale, b.norm)
    finally:
        eq.close()


def test_the_shells_pattern_is_canonical_as_flagged():
    """The shell's block pattern flags its matrices as canonical (sorted, no duplicates) without
    scipy's check; scipy's own check of the same structure agrees."""
    pr = _ball(2, 20.0)
    pat = pr.shell.block_pattern
    M = pat.csr(np.ones(pat.scalar_indices.size))
    assert M.has_canonical_format
    fresh = sp.csr_matrix((M.data.copy(), M.indices.copy(), M.indptr.copy()), shape=M.shape)
    assert fresh.has_canonical_format and fresh.has_sorted_indices


def test_other_structures_keep_the_separate_passes():
    """Hessians on different structures (a term with its own pattern) are summed on their union as
    before, without row numbers; the floor is ``roundoff_floor``'s and an empty list gives none."""
    A, B = _random_csr(50, np.full(50, 6), 3)
    C = sp.csr_matrix(sp.random(50, 50, density=0.05, random_state=4))
    x = np.linspace(1.0, 2.0, 50)
    H, rows, floor = tangent_sum([A, C], x)
    assert rows is None
    ref = _add(A, C)
    assert np.array_equal(H.toarray(), ref.toarray()) and floor == roundoff_floor(ref, x)
    H, rows, floor = tangent_sum([A, B], x)
    assert rows is not None and floor == roundoff_floor(_add(A, B), x)
    assert floor == ROUNDOFF_FACTOR * np.finfo(float).eps * np.linalg.norm(
        np.sqrt(S.row_summary(A, B, x)[2]))
    assert tangent_sum([], x) == (None, None, 0.0)


@pytest.mark.parametrize("dtype", [np.int32, np.int64])
@pytest.mark.parametrize("k", [None, 1, 2, 3, 4, 5, 7])
@pytest.mark.parametrize("parallel", [True, False])
def test_the_parallel_product_is_scipys_to_the_bit(dtype, k, parallel, monkeypatch):
    """A x for one column (n,), and blocks of 1 to 7 columns (summed four, two and one at a time in
    one read of A): each column equals scipy's one-column product exactly, on rows of 0 to 300
    entries, with unsorted and duplicated column indices (the product sums in index order, as
    scipy's does) -- by the parallel kernel (forced here: below graspdef.compiled.SERIAL_MAX scipy
    multiplies; its first call may run the ahead-of-time export while the JIT build loads, so it is
    called again once that is loaded) and by scipy."""
    from graspdef import compiled

    if parallel:
        monkeypatch.setattr(compiled, "SERIAL_MAX", -1)
    n = 300
    rng = np.random.default_rng(7)
    A, _ = _random_csr(n, rng.integers(0, 160, n), 8, dtype)
    A.indices[:40] = A.indices[:40][::-1].copy()            # unsorted, and a duplicate column
    A.indices[41] = A.indices[42]
    A.has_canonical_format = False
    x = rng.standard_normal(n if k is None else (n, k)) * 10.0 ** rng.uniform(-4, 4, n if k is None else (n, k))
    ys = [S.csr_product(A, x)]
    if parallel:
        compiled._LOADER.join()
        ys.append(S.csr_product(A, x))
    for y in ys:
        assert y.shape == x.shape
        cols = [x] if k is None else [x[:, j] for j in range(k)]
        got = [y] if k is None else [y[:, j] for j in range(k)]
        for xc, yc in zip(cols, got):
            assert np.array_equal(yc, A @ xc)
