"""Local corrections on a reused tangent (issue 17, speed: ``PathOptions.local_rings``).

A step on the previous point's factorisation is preceded by an exact Newton step in the region
where the residual sits, with the Hessian's rows of that region only
(:meth:`graspdef.solve.equilibrium.Equilibrium.local_step`):

    d = d_R + A^-1 [-(grad + H_{:,R} d_R); g - C d_R],   H_RR d_R = -r_R.

If the factorised A is the current tangent H itself, the two parts add up to the Newton step
exactly (A^-1 H_{:,R} d_R is d_R extended by zeros): that identity checks the combination, the
rank-one (gas) parts and the constraints.  On a path the corrections change how fast Newton
converges, never where: the same equilibria, with fewer factorisations where the tangent changes
only near the point loads.
"""
import numpy as np
import pytest

from graspdef.errors import ProblemError
from graspdef.geometry import rectangle
from graspdef.problem.loads import PointLoad
from graspdef.problem.potentials import FollowerPressure
from graspdef.problem.problem import Problem
from graspdef.problem.supports import EdgeSupport
from graspdef.problem.terms import DeadLoads, RestQuadratic, ShellElastic
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell
from graspdef.shell.region import Region, vertex_rings
from graspdef.solve.equilibrium import Equilibrium
from graspdef.solve.nonlinear import PathOptions, solve_nonlinear
from test_inexact_newton import _ball       # the bench's air-filled neo-Hookean ball pinched at its poles


def _squashed(eq):
    X = eq.X
    return (0.12 * X * np.array([0.4, 0.4, -0.8])).ravel() + 1e-3 * np.sin(40 * X).ravel() * 0.0325


@pytest.mark.parametrize("elastic", ["finite", "rest"])
def test_local_step_on_the_current_tangent_is_the_newton_step(elastic):
    """The air-filled ball (six dense rigid-mode rows, the gas's rank-one tangent) at a squashed
    state, factorised there: the local correction plus the factorisation's step equals the Newton
    step to 1e-9, and meets the constraints; the local part alone does not.  Also with the linear
    shell's quadratic energy (``elastic = "rest"``), whose rows come as a slice of its fixed
    matrix, not on the region's pattern."""
    pr = _ball(3, 20.0)
    eq = Equilibrium(pr, terms=pr.energy_terms(elastic))
    try:
        u = _squashed(eq)
        lam = 0.6
        st = eq.evaluate(u, lam, 2)
        eq.factor(st)
        cres = eq.constraint_residual(u, lam)
        newton = eq.solve(-st.gradient, cres, rtol=1e-12)
        top = int(np.argmax(eq.X[:, 2]))
        reg = Region(pr.shell, vertex_rings(pr.shell, [top], 2))
        d = eq.local_step(u, lam, st, cres, reg, rtol=1e-12)
        assert eq.n_local == 1
        assert np.linalg.norm(d - newton) <= 1e-9 * np.linalg.norm(newton)
        assert np.linalg.norm(eq.C @ d - cres) <= 1e-9 * np.linalg.norm(d)
        local = np.zeros_like(d)
        local[reg.dofs] = d[reg.dofs]
        assert np.linalg.norm(local - newton) > 0.1 * np.linalg.norm(newton)
    finally:
        eq.close()


def test_local_step_on_a_stale_tangent_is_the_exact_local_step_then_the_stale_one():
    """The same squashed ball with the tangent factorised at rest: the step is d_R (the region's
    exact Newton step with the current Hessian and the gas's rank-one part, here solved densely
    from the whole Hessian) plus the stale factorisation's step for the residual after it, to 1e-8."""
    pr = _ball(3, 20.0)
    eq = Equilibrium(pr)
    try:
        u = _squashed(eq)
        lam = 0.6
        eq.factor(eq.evaluate(np.zeros(eq.n), 0.0, 2))
        st = eq.evaluate(u, lam, 2)
        cres = eq.constraint_residual(u, lam)
        reg = Region(pr.shell, vertex_rings(pr.shell, [int(np.argmax(eq.X[:, 2]))], 2))
        R = reg.dofs
        H = st.hessian.toarray()
        for c, v in st.rank_one:
            H += c * np.outer(v, v)
        r, _ = eq.projected_residual(st.gradient)
        dR = np.linalg.solve(H[np.ix_(R, R)], -r[R])
        d0 = np.zeros(eq.n)
        d0[R] = dR
        want = d0 + eq.solve(-(st.gradient + H[:, R] @ dR), cres - eq.C @ d0, rtol=1e-12)
        got = eq.local_step(u, lam, st, cres, reg, rtol=1e-12)
        assert np.linalg.norm(dR) > 0.1 * np.linalg.norm(got[R])
        assert np.linalg.norm(got - want) <= 1e-8 * np.linalg.norm(want)
    finally:
        eq.close()


def _rows_case(term, x, lam, reg):
    v = term.evaluate(x, lam, 2)
    M, r1 = term.hessian_rows(x, lam, reg)
    if v.hessian is None:
        assert M is None
    else:
        H = v.hessian.tocsr()
        assert abs(M - H[reg.dofs]).max() <= 1e-13 * abs(H).max()
    assert len(r1) == len(v.rank_one)
    for (c, w), (c0, w0) in zip(r1, v.rank_one):
        assert c == pytest.approx(c0, rel=1e-14) and np.allclose(w, w0, rtol=0, atol=1e-15 * np.abs(w0).max())


def test_terms_give_their_hessians_rows():
    """hessian_rows of every term that has it: the rows of its own Hessian at the region (to
    round-off) and the same rank-one parts -- the shell, the enclosed gas, a follower pressure, the
    linear shell and the dead loads (no Hessian)."""
    pr = _ball(3, 20.0)
    eq = Equilibrium(pr)
    try:
        u = _squashed(eq)
        x = eq.X + u.reshape(-1, 3)
        reg = Region(pr.shell, vertex_rings(pr.shell, [int(np.argmax(eq.X[:, 2]))], 2))
        kinds = {type(t).__name__ for t in eq.terms}
        assert {"ShellElastic", "EnclosedGas", "DeadLoads"} <= kinds
        for t in eq.terms:
            _rows_case(t, x, 0.6, reg)
        _rows_case(FollowerPressure(5e3).build(pr.shell, pr.evaluator), x, 0.6, reg)
        _rows_case(RestQuadratic(pr.shell), x, 0.6, reg)
        _rows_case(ShellElastic(pr.shell), x, 0.6, reg)
        _rows_case(DeadLoads(np.ones(eq.n), eq.X), x, 0.6, reg)
    finally:
        eq.close()


def test_a_residual_that_is_not_local_gets_no_region():
    """A residual spread over the whole ball (the gas's inflation at the path's start) gives no
    region; one at a pole gives the pole's vertices and their rings."""
    pr = _ball(4, 20.0)
    eq = Equilibrium(pr)
    try:
        st = eq.evaluate(np.zeros(eq.n), 0.0, 1)
        assert eq.local_region(eq.projected_residual(st.gradient)[0], 5) is None
        r = np.zeros(eq.n)
        top = int(np.argmax(eq.X[:, 2]))
        r[3 * top + 2] = 1.0
        reg = eq.local_region(r, 3)
        assert reg is not None and top in reg.vertices
        assert np.array_equal(reg.vertices, np.flatnonzero(vertex_rings(pr.shell, [top], 3)))
    finally:
        eq.close()


def test_a_pinch_with_local_corrections_reaches_the_same_equilibria_with_fewer_factorisations():
    """The 2,562-vertex air-filled ball pinched to 20 N: with local corrections (the default, 5
    rings) and without them the path ends at the same pole displacement (to 1e-8, both converged to
    the default tolerance), every point stable, and the corrected path factorises fewer tangents
    (9 against 13 when written; the counts do not depend on the machine)."""
    runs = {}
    for rings in (0, 5):
        sol = solve_nonlinear(_ball(4, 20.0), PathOptions(steps=20, local_rings=rings))
        assert sol.completed and all(p.stable for p in sol.path)
        runs[rings] = sol
    assert runs[0].n_local == 0 < runs[5].n_local
    assert runs[5].convergence()["n_local_corrections"] == runs[5].n_local
    assert runs[5].n_factorisations < runs[0].n_factorisations
    assert np.allclose(runs[5].probe("top"), runs[0].probe("top"), rtol=0, atol=1e-8 * np.linalg.norm(runs[0].probe("top")))


def test_a_term_without_rows_turns_local_corrections_off():
    """A plate with a clamped edge (Nitsche rotation terms, which give no rows) under a point
    load: no local correction is taken, and the path is the one without them to the bit."""
    m = rectangle(1.0, 1.0, 8, 8)
    sh = Shell(m.vertices, m.faces, LinearElastic(1e7, 0.3), 0.01)
    pr = Problem(sh, [], [EdgeSupport("clamped", lambda x: np.abs(x[:, 0] + 0.5) < 1e-9)])
    loc = pr.locate((0.3, 0.0, 0.0))
    pr.loads.append(PointLoad(loc.face, loc.bary, (0, 0, -40.0)))
    pr.probes["p"] = loc
    a = solve_nonlinear(pr, PathOptions(steps=4, local_rings=5))
    b = solve_nonlinear(pr, PathOptions(steps=4, local_rings=0))
    assert any(type(t).__name__ == "NitscheTerm" for t in Equilibrium(pr).terms)
    assert a.n_local == 0 and a.n_factorisations == b.n_factorisations
    assert np.array_equal(a.probe("p"), b.probe("p"))


@pytest.mark.parametrize("bad", [-1, 1.5, True, "5"])
def test_local_rings_must_be_a_non_negative_integer(bad):
    with pytest.raises(ProblemError, match="local_rings must be a non-negative integer"):
        PathOptions(local_rings=bad)
