"""Blocks of right-hand sides in one back-substitution (issue 17, speed).

PARDISO's back-substitution reads the whole factor once per call whatever the number of columns
(on the 10k ball's tangent, 30,732 unknowns, one column 12.4 ms, two 14.3, four 14.1), so solves
that a factorisation needs anyway ride together: the Woodbury vectors of a rank-one tangent part
with the inertia certificate's iteration or with the next solve, and a converged point's load
tangent (the next step's predictor) with the Newton step on the same factorisation.  Each column
must still be its own solve to its own tolerance.
"""
import numpy as np
import pytest
import scipy.sparse as sp

import graspdef.solve.sparse as S
from graspdef.solve.equilibrium import Equilibrium
from graspdef.solve.nonlinear import PathOptions, PathSolver
from test_inexact_newton import _ball       # the bench's air-filled neo-Hookean ball pinched at its poles
from test_mixed_paths import _spd_with

pytestmark = pytest.mark.skipif(not S.pardiso_available(), reason="single-precision factors need PARDISO")


def _system(n=120, seed=5):
    K = _spd_with(np.logspace(0, 3, n), seed)
    C = np.zeros((2, n))
    C[0, :4] = 1.0
    C[1, 7] = 1.0
    return sp.csr_matrix(K), sp.csr_matrix(C)


def test_the_certificate_carries_right_hand_sides_to_a_solved_start():
    """certify_inertia_along(V): the same answer as certify_inertia on the same factor, in as many
    back-substitution calls (each now a block of 1 + k columns), and its iterates are a start that
    solve() accepts at once: the solution is the one of a solve from scratch to 1e-8, and the solve
    from the start needs at most one more call while the one from scratch needs two or more."""
    K, C = _system()
    V = np.random.default_rng(6).standard_normal((K.shape[0], 2))
    with S.KKTSystem(C, "pardiso", "mixed") as kkt:
        kkt.factor(K)
        c0 = kkt.n_back_calls
        assert kkt.certify_inertia()
        alone = kkt.n_back_calls - c0
        kkt.factor(K)
        c0 = kkt.n_back_calls
        ok, start = kkt.certify_inertia_along(V)
        assert ok and kkt.n_back_calls - c0 == alone and start.shape == (K.shape[0] + 2, 2)
        c0 = kkt.n_back_calls
        W, _, rel = kkt.solve(V, exact=False, start=start)
        after_start = kkt.n_back_calls - c0
        c0 = kkt.n_back_calls
        W0, _, _ = kkt.solve(V, exact=False)
        scratch = kkt.n_back_calls - c0
    assert rel <= 1e-8 and after_start <= 1 < scratch
    assert np.linalg.norm(W - W0) <= 1e-8 * np.linalg.norm(W0)


def test_a_failed_certificate_gives_no_start():
    """A nearly singular single factor (test_mixed_paths): the certificate fails, the system is
    refactorised in double, and no iterate of the discarded factor is handed on."""
    n = 60
    C = np.zeros((1, n))
    C[0, 0] = 1.0
    K = _spd_with(np.concatenate([[1e-12], np.linspace(1.0, 2.0, n - 1)]), 2)
    with S.KKTSystem(sp.csr_matrix(C), "pardiso", "mixed") as kkt:
        kkt.factor(sp.csr_matrix(K))
        ok, start = kkt.certify_inertia_along(np.ones((n, 1)))
        assert not ok and start is None and not kkt.single


@pytest.mark.parametrize("inertia", [False, True])
def test_the_gas_woodbury_vectors_ride_in_other_back_substitutions(inertia):
    """The air-filled ball's tangent H + c v v^T (its gas): with a single factor, W = A^-1 [v; 0] is
    solved inside the certificate's calls (a factorisation that gives the inertia) or with the next
    solve's right-hand side (one that does not), and that solve -- a Newton step to 1e-8 -- is the
    double factor's to 1e-7 of its size, the inertia the same.  Without inertia, the factorisation
    makes no back-substitution itself, and the first solve costs fewer calls than the Woodbury
    vectors and the solve apart."""
    pr = _ball(2, 20.0)
    u = (0.05 * Equilibrium(pr).X * np.array([0.5, 0.5, -1.0])).ravel()   # squashed along z
    lam = 0.4
    ref = Equilibrium(pr, precision="double")
    st = ref.evaluate(u, lam, 2)
    cres = ref.constraint_residual(u, lam)
    inst_ref = ref.factor(st)
    du_ref = ref.solve(-st.gradient, cres)
    ref.close()
    mixed = Equilibrium(pr, precision="mixed")
    try:
        st = mixed.evaluate(u, lam, 2)
        c0 = mixed.kkt.n_back_calls
        inst = mixed.factor(st, inertia=inertia)
        at_factor = mixed.kkt.n_back_calls - c0
        c0 = mixed.kkt.n_back_calls
        du = mixed.solve(-st.gradient, cres, rtol=1e-8)
        at_solve = mixed.kkt.n_back_calls - c0
        assert mixed.kkt.single
        if inertia:
            assert inst == inst_ref
        else:
            assert inst is None and at_factor == 0
            # the same two solves apart: the vectors first (precondition() needs them), then the step
            mixed.factor(st, inertia=False)
            c0 = mixed.kkt.n_back_calls
            mixed.precondition(np.zeros(mixed.n))
            apart = mixed.kkt.n_back_calls - c0 - 1            # less precondition's own back-substitution
            c0 = mixed.kkt.n_back_calls
            mixed.solve(-st.gradient, cres, rtol=1e-8)
            apart += mixed.kkt.n_back_calls - c0
            assert at_solve < apart
    finally:
        mixed.close()
    assert np.linalg.norm(du - du_ref) <= 1e-7 * np.linalg.norm(du_ref)


def test_the_predictor_tangent_rides_with_the_last_newton_step():
    """Along the ball's mixed-precision path, every converged point's load tangent du/dlam (the
    next step's predictor) that was solved with the Newton step on the same factorisation is the
    tangent a solve at the converged state gives, to 1e-7 of its size; and it is used at most
    points (the stability factorisation is usually within inertia_rtol before convergence)."""
    pr = _ball(2, 20.0)
    solver = PathSolver(pr, PathOptions(steps=5, max_steps=50), precision="mixed")
    used, points = [], []
    plain = PathSolver._load_tangent

    def checked(self, st):
        ahead = self._ahead
        t = plain(self, st)
        fresh = self.eq.solve(st.load, self.eq.g)
        points.append(np.linalg.norm(t - fresh) / np.linalg.norm(fresh))
        used.append(ahead is not None and ahead[0] == self.eq.n_factorisations)
        return t

    try:
        PathSolver._load_tangent = checked
        sol = solver.run()
    finally:
        PathSolver._load_tangent = plain
        solver.eq.close()
    assert sol.completed and sol.n_single == sol.n_factorisations
    assert len(points) == len(sol.path) - 1 and max(points) <= 1e-7
    assert sum(used) >= len(used) // 2 + 1


def test_each_column_of_a_block_is_solved_to_its_own_tolerance():
    """A loose single-precision solve (rtol 1e-6) of two right-hand sides: one of size 1 along the
    stiffest directions, one of size 1e-4 along the softest (eigenvalues 1 to 1e6): each column's
    KKT residual relative to its own right-hand side is at most rtol.  (A test on the block's norm, which the large column
    dominates, stopped with the small one's at 1.7e-4.)"""
    n = 150
    K = _spd_with(np.logspace(0, 6, n), 7)
    C = np.eye(1, n)
    _, Q = np.linalg.eigh(K)
    b_big = Q[:, -5:] @ np.ones(5)                 # the stiff directions: a raw solve is accurate there
    b_small = 1e-4 * (Q[:, :5] @ np.ones(5))       # the soft ones: float32's error times 1e6
    with S.KKTSystem(sp.csr_matrix(C), "pardiso", "mixed") as kkt:
        kkt.factor(sp.csr_matrix(K))
        U, L, rel = kkt.solve(np.stack([b_big, b_small], 1), rtol=1e-6, exact=False)
    worst = 0.0
    for j, b in enumerate((b_big, b_small)):
        r = np.concatenate([K @ U[:, j] + C.T @ L[:, j] - b, C @ U[:, j]])
        worst = max(worst, np.linalg.norm(r) / np.linalg.norm(b))
    assert worst <= 1e-6 and rel <= 1e-6


def test_the_stability_step_rides_in_the_certificate():
    """A factorisation that gives a point's stability is told the right-hand sides of its next
    solve (the Newton step and the load tangent, with the supports' residuals: what
    PathSolver.newton's direction solves there): their refinement steps ride in the certificate's
    back-substitution calls -- as many calls as the certificate alone -- and that solve then needs
    no call of its own, where from scratch it needs two or more; each column is the solve from
    scratch to 1e-7 of its size, the inertia the same.  Other right-hand sides after it are solved
    from scratch (the announced start is not theirs)."""
    pr = _ball(2, 20.0)
    u = (0.05 * Equilibrium(pr).X * np.array([0.5, 0.5, -1.0])).ravel()   # squashed along z
    lam = 0.4
    eq = Equilibrium(pr, precision="mixed")
    try:
        st = eq.evaluate(u, lam, 2)
        cres = eq.constraint_residual(u, lam)
        R, G = np.stack([-st.gradient, st.load], 1), np.stack([cres, eq.g], 1)
        calls = lambda: eq.kkt.n_back_calls                       # noqa: E731
        c0 = calls()
        inst0 = eq.factor(st)
        alone = calls() - c0
        c0 = calls()
        ref = eq.solve(R, G)
        scratch = calls() - c0
        c0 = calls()
        inst = eq.factor(st, ahead=(R, G))
        at_factor = calls() - c0
        c0 = calls()
        du = eq.solve(R, G)
        after = calls() - c0
        assert eq.kkt.single and inst == inst0
        assert at_factor == alone and after == 0 < 2 <= scratch
        for j in range(2):
            assert np.linalg.norm(du[:, j] - ref[:, j]) <= 1e-7 * np.linalg.norm(ref[:, j])
        eq.factor(st, ahead=(R, G))
        c0 = calls()
        other = eq.solve(R[:, 1], G[:, 1])
        assert calls() - c0 >= 1
        assert np.linalg.norm(other - ref[:, 1]) <= 1e-7 * np.linalg.norm(ref[:, 1])
    finally:
        eq.close()
