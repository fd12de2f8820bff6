"""PARDISO's 1x1 diagonal pivots (iparm 21 = 0, the default since 2026-11-28) against its
Bunch-Kaufman 1x1 and 2x2 pivots (iparm 21 = 1, now the first fallback).

A factorisation's inertia is Sylvester's: the signs of D in P A P^T = L D L^T, whatever the
pivots, as long as no pivot was perturbed.  So the 1x1 factor must count the same negative
eigenvalues as a dense eigen-decomposition (and as the Bunch-Kaufman factor), and its refined
solution must be the same solution.  Where 1x1 pivots are not enough (a perturbed pivot that the
refinement cannot repair, a wrong inertia) the checks of :class:`KKTSystem` refactor with
Bunch-Kaufman pivots (tests/solve/test_kkt_robust.py).
"""
import numpy as np
import pytest
import scipy.sparse as sp

from graspdef.solve import sparse as S
from graspdef.solve.equilibrium import Equilibrium

from test_inexact_newton import _ball       # the bench's air-filled neo-Hookean ball pinched at its poles

pytestmark = pytest.mark.skipif(not S.pardiso_available(), reason="PARDISO (pypardiso) not installed")


def test_the_defaults_pivot_1x1_and_fall_back_to_bunch_kaufman():
    """The settings themselves: 1x1 pivots by default; the first fallback restores Bunch-Kaufman
    pivots and every later fallback keeps them."""
    assert S._PARDISO_IPARM[21] == 0
    assert all(v.get(21) == 1 for v in S._PARDISO_FALLBACKS)


def _indefinite(n=240, m=40, shift=0.4, seed=0):
    """A sparse symmetric K (a 1-D Laplacian plus a seeded diagonal, shifted down so that some of
    its eigenvalues are negative) and m seeded constraint rows on neighbouring unknowns; returns K,
    C and the number of negative eigenvalues of K on the null space of C (dense)."""
    rng = np.random.default_rng(seed)
    K = sp.diags([-np.ones(n - 1), 2.0 + rng.random(n) - shift - 2.0 * (np.arange(n) < 6),
                  -np.ones(n - 1)], [-1, 0, 1], format="csr")
    rows, cols, vals = [], [], []
    for i, c0 in enumerate(rng.choice(n - 4, m, replace=False)):
        for j in range(4):
            rows.append(i), cols.append(c0 + j), vals.append(rng.standard_normal())
    C = sp.csr_matrix((vals, (rows, cols)), shape=(m, n))
    _, _, vt = np.linalg.svd(C.toarray())
    Z = vt[m:].T                                       # an orthonormal basis of the null space of C
    ev = np.linalg.eigvalsh(Z.T @ K.toarray() @ Z)
    assert np.abs(ev).min() > 1e-6 * np.abs(ev).max()  # no eigenvalue at the edge of its sign
    return K, C, int((ev < 0).sum())


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_1x1_pivots_count_the_inertia_and_solve_as_bunch_kaufman_does(monkeypatch, seed):
    """On indefinite saddle-point matrices (K with negative eigenvalues on the null space of C,
    asserted first so that the test can fail) the 1x1 factor's negative pivots are m plus the
    dense count, as Bunch-Kaufman's are (each factor's own count, no fallback), and the two
    solutions agree to 1e-10."""
    K, C, k = _indefinite(seed=seed)
    m = C.shape[0]
    assert k > 0
    f = np.random.default_rng(seed + 10).standard_normal(K.shape[0])
    out = {}
    for piv in (0, 1):
        monkeypatch.setitem(S._PARDISO_IPARM, 21, piv)
        with S.KKTSystem(C, "pardiso") as kkt:
            kkt.factor(K)
            neg = kkt.n_negative        # this factor's own count (negative_pivots(m) would refactor)
            u, _, rel = kkt.solve(f)
            out[piv] = (neg, u, rel, kkt.robust)
    for piv in (0, 1):
        assert out[piv][0] == m + k and out[piv][2] <= 1e-8 and not out[piv][3]
    assert np.abs(out[0][1] - out[1][1]).max() <= 1e-10 * np.abs(out[1][1]).max()


@pytest.mark.parametrize("precision", ["double", "mixed"])
def test_the_balls_tangent_needs_no_fallback(monkeypatch, precision):
    """The air-filled ball's tangent (642 control vertices, six dense rigid-mode rows, the gas's
    rank-one term by Woodbury): factorised with the 1x1 defaults and no fallback (``robust`` stays
    False; a single factor's inertia certified), six negative pivots for six constraints, and the
    Newton step is the Bunch-Kaufman factor's to 1e-9."""
    pr = _ball(3, 20.0)
    steps = {}
    for piv in (0, 1):
        monkeypatch.setitem(S._PARDISO_IPARM, 21, piv)
        eq = Equilibrium(pr, "pardiso", precision=precision)
        try:
            u = np.zeros(eq.n)
            st = eq.evaluate(u, 0.5, 2)
            inst = eq.factor(st)
            assert inst == 0 and eq.kkt.n_negative == 6 and not eq.kkt.robust
            assert eq.kkt.single == (precision == "mixed")
            steps[piv] = eq.solve(-st.gradient, eq.constraint_residual(u, 0.5), exact=True)
        finally:
            eq.close()
    assert np.abs(steps[0] - steps[1]).max() <= 1e-9 * np.abs(steps[1]).max()
