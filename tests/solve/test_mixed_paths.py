"""Single-precision tangents along nonlinear paths (issue 17, speed): the factor's inertia is
certified before it is reported as a stability, Newton's steps are solved to a forcing tolerance,
and the path is the double one's.

The certificate (``KKTSystem.certify_inertia``): plain iterative refinement with the single factor
M of a fixed pseudo-random right-hand side contracts to MIXED_BACKWARD_TOL only if the error
operator G = I - M^-1 A has no eigenvalue >= 1 in it; a different inertia of A and M would give G
a real eigenvalue 1/t >= 1 (M + t (A - M) = M (I - t G) singular for some t in (0, 1]).  So a
passed certificate means the single factor's inertia is A's; a failed one refactors in double.
"""
import numpy as np
import pytest
import scipy.sparse as sp

import graspdef.solve.sparse as S
from graspdef.solve.nonlinear import PathOptions, solve_nonlinear
from test_inexact_newton import _ball       # the bench's air-filled neo-Hookean ball pinched at its poles

pytestmark = pytest.mark.skipif(not S.pardiso_available(), reason="single-precision factors need PARDISO")


def _kkt_inertia(K: np.ndarray, C: np.ndarray) -> int:
    """Negative eigenvalues of the KKT matrix [[K, C^T], [C, 0]] (dense, exact to round-off)."""
    m = C.shape[0]
    A = np.block([[K, C.T], [C, np.zeros((m, m))]])
    return int((np.linalg.eigvalsh(A) < 0).sum())


def _spd_with(eigenvalues, seed=0):
    """Q diag(eigenvalues) Q^T with a random orthogonal Q whose first column (the first
    eigenvalue's eigenvector) has a zero first entry: it lies in the null space of the constraint
    row e_0 used below, so the constrained matrix has that eigenvalue too."""
    rng = np.random.default_rng(seed)
    n = len(eigenvalues)
    G = rng.standard_normal((n, n))
    G[0, 0] = 0.0
    Q, _ = np.linalg.qr(G)
    return (Q * np.asarray(eigenvalues)) @ Q.T


def test_a_well_conditioned_indefinite_single_factor_is_certified():
    """Eigenvalues in [-2, -1] u [1, 2] (an unstable tangent, 7 negative on the constraints' null
    space or so): the single factor's refinement contracts by ~1e-7 per step, the certificate holds,
    the factor stays single and its negative pivots are the dense eigenvalues' count."""
    n = 80
    d = np.concatenate([-np.linspace(1, 2, 8), np.linspace(1, 2, n - 8)])
    K = _spd_with(d, 1)
    C = np.zeros((2, n))
    C[0, :3] = 1.0
    C[1, 5] = 1.0
    with S.KKTSystem(sp.csr_matrix(C), "pardiso", "mixed") as kkt:
        kkt.factor(sp.csr_matrix(K))
        assert kkt.certify_inertia() and kkt.single and kkt.certificates == 1
        assert kkt.n_negative == _kkt_inertia(K, C)
        assert kkt.n_back <= 4                 # 1e-7 per step: two or three back-substitutions


def test_a_nearly_singular_single_factor_is_not_certified_and_refactors_in_double():
    """One eigenvalue 1e-12 of the largest (positive): float32's rounding (~6e-8 of the largest
    entry) moves it by far more than its size, so the single factor's inertia is a coin toss; the
    refinement cannot contract in that direction, the certificate fails, the system refactors in
    double, and the inertia then reported is the exact one (0 negative eigenvalues of K, m of the KKT
    matrix).  The same matrix with that eigenvalue at -1e-12 gives m + 1."""
    n = 60
    C = np.zeros((1, n))
    C[0, 0] = 1.0
    for small in (1e-12, -1e-12):
        K = _spd_with(np.concatenate([[small], np.linspace(1.0, 2.0, n - 1)]), 2)
        with S.KKTSystem(sp.csr_matrix(C), "pardiso", "mixed") as kkt:
            kkt.factor(sp.csr_matrix(K))
            assert not kkt.certify_inertia()
            assert not kkt.single and kkt.n_factor == 2
            assert kkt.n_negative == _kkt_inertia(K, C) == 1 + (small < 0)


def test_an_inexact_solve_stops_at_its_tolerance_and_a_double_solve_ignores_it():
    """``exact=False``: a single factor's solve stops refining once its relative residual is at
    most rtol (fewer back-substitutions than the exact solve, which goes on to a double solve's
    backward error); a double factor's solve is the same either way (to the bit)."""
    n = 200
    K = _spd_with(np.logspace(0, 4, n), 3)
    C = sp.csr_matrix(np.eye(1, n))
    b = np.random.default_rng(4).standard_normal(n)
    with S.KKTSystem(C, "pardiso", "mixed") as kkt:
        kkt.factor(sp.csr_matrix(K))
        n0 = kkt.n_back
        u_loose, _, rel_loose = kkt.solve(b, rtol=1e-3, exact=False)
        loose_backs = kkt.n_back - n0
        n0 = kkt.n_back
        u_exact, _, rel_exact = kkt.solve(b)
        exact_backs = kkt.n_back - n0
    assert rel_loose <= 1e-3 and loose_backs < exact_backs and rel_exact < 1e-10
    assert np.linalg.norm(u_loose - u_exact) <= 1e-1 * np.linalg.norm(u_exact)
    with S.KKTSystem(C, "pardiso", "double") as kkt:
        kkt.factor(sp.csr_matrix(K))
        a = kkt.solve(b, rtol=1e-3, exact=False)[0]
        e = kkt.solve(b, rtol=1e-3)[0]
    assert np.array_equal(a, e)


@pytest.mark.parametrize("predictor", ["quadratic", "cubic"])
def test_a_mixed_path_is_the_double_path(predictor):
    """The 642-vertex air-filled ball pinched to 20 N: with single-precision tangents (precision
    "mixed") the path takes the same steps and Newton iterations, every point's stability is the
    double path's, and the pole displacement agrees to 1e-8 (measured 2e-16 / 1e-15; both converge
    to the Newton tolerance 1e-8 of the force scale).  Every factor is single, and each one whose
    inertia became a point's stability was certified.  With the quadratic predictor the load factors
    are the same to the bit (its steps grow by iteration counts); with the cubic (the default) a
    step is capped where the predicted increment outgrows the last one (max_growth), a ratio of
    the converged states, which the two paths share to the Newton tolerance: the load factors agree
    to 1e-6 (measured 1.1e-8), the points and iterations are the same."""
    opts = PathOptions(steps=20, max_steps=200, predictor=predictor)
    mixed = solve_nonlinear(_ball(3, 20.0), opts, precision="mixed")
    double = solve_nonlinear(_ball(3, 20.0), opts, precision="double")
    assert mixed.completed and double.completed
    lm, ld = mixed.load_factors(), double.load_factors()
    assert len(lm) == len(ld) and mixed.iterations() == double.iterations()
    if predictor == "quadratic":
        assert lm.tolist() == ld.tolist()
    else:
        assert np.allclose(lm, ld, rtol=1e-6, atol=0), np.max(np.abs(lm - ld))
    assert [p.stable for p in mixed.path] == [p.stable for p in double.path] and all(p.stable for p in mixed.path)
    w_m, w_d = -mixed.probe("top")[2], -double.probe("top")[2]
    assert abs(w_m / w_d - 1) < 1e-8, (w_m, w_d)
    assert double.n_single == 0 and mixed.n_single == mixed.n_factorisations
    assert len(mixed.path) <= mixed.n_certificates <= mixed.n_factorisations
    assert mixed.convergence()["n_single_precision_factorisations"] == mixed.n_single


def test_auto_is_double_below_the_size_and_mixed_from_it(monkeypatch):
    """The default precision "auto" factorises a path's tangents in single precision from
    MIXED_MIN_UNKNOWNS unknowns on (the 642-vertex ball has 1,932), in double below."""
    opts = PathOptions(steps=20, max_steps=200, max_load=0.1)
    assert solve_nonlinear(_ball(3, 20.0), opts).n_single == 0
    monkeypatch.setattr(S, "MIXED_MIN_UNKNOWNS", 1000)
    sol = solve_nonlinear(_ball(3, 20.0), opts)
    assert sol.n_single == sol.n_factorisations > 0


def test_a_critical_point_is_located_the_same_with_single_factors():
    """Euler's strip (tests/solve/test_bifurcation.py: P_cr = pi^2 EI / 4 L^2) with single-precision
    tangents: the bifurcation is found and located to within 1e-4 of Euler's load as with double
    ones, stability 0 -> 1.  Next to it the tangent is nearly singular, the certificates fail and
    those tangents are refactorised in double (fewer single factors than factorisations)."""
    from test_bifurcation import strip

    sol = solve_nonlinear(strip(), PathOptions(max_load=1.2, steps=10, bifurcation="locate"), precision="mixed")
    assert sol.completed
    (cp,) = sol.critical_points
    assert cp["kind"] == "bifurcation point" and (cp["instability_before"], cp["instability_after"]) == (0, 1)
    lo, hi = cp["bracket"]
    assert lo <= 1.0 <= hi and hi - lo < 1e-4
    assert 0 < sol.n_single < sol.n_factorisations
