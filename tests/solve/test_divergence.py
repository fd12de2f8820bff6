"""Newton's divergence test (issue 17, speed; PathSolver.newton, DIVERGENCE_ITERATIONS).

From iteration DIVERGENCE_ITERATIONS on, an attempt whose residual has grown tenfold over its first
iterate's ends, and the load step is halved.  The growth is judged on the absolute residual as
well as on the relative one: a wild iterate's own internal forces grow with it, so its residual
relative to the forces' scale stays near 1 -- the full pinched cylinder's failed steps had
residuals 1e4 to 5e8 times their first from the first step on and still ran their 25 iterations,
most of them on a fresh tangent.
"""
import numpy as np
import pytest

from graspdef.solve.equilibrium import Equilibrium
from graspdef.solve.nonlinear import DIVERGENCE_ITERATIONS, PathOptions, PathSolver, _Failed, solve_nonlinear
from test_inexact_newton import _ball       # the bench's air-filled neo-Hookean ball pinched at its poles


def test_a_wild_iteration_ends_the_attempt_at_the_divergence_iteration(monkeypatch):
    """Plain Newton steps on the 162-vertex air-filled ball from its equilibrium at zero load to
    0.3 of its pinch, each step made 3 times too long (an overshooting step, as on a wrong
    tangent): the residual grows by two orders of magnitude while the relative residual stays
    below ten times its first (the iterate's own forces grow with it), and the attempt ends at
    iteration DIVERGENCE_ITERATIONS, not at max_iterations (25)."""
    solver = PathSolver(_ball(2, 20.0), PathOptions(line_search=False, anderson=0))
    rel, absolute = [], []
    try:
        u0 = solver.newton(np.zeros(solver.eq.n), 0.0)[0]
        plain, converged = Equilibrium.solve, PathSolver._converged

        def watched(self, state, u, lam):
            out = converged(self, state, u, lam)
            rel.append(out[1])
            absolute.append(self.residual_norm)
            return out

        monkeypatch.setattr(Equilibrium, "solve", lambda self, *a, **k: 3.0 * plain(self, *a, **k))
        monkeypatch.setattr(PathSolver, "_converged", watched)
        with pytest.raises(_Failed, match="Newton diverges .* times the first iterate's"):
            solver.newton(u0, 0.3)
    finally:
        solver.eq.close()
    assert len(rel) == DIVERGENCE_ITERATIONS + 1 < 25
    assert max(rel) < 10 * rel[0] and absolute[-1] > 100 * absolute[0]


def test_paths_that_converge_are_unchanged():
    """The rule never fires on an attempt that would converge: the 642-vertex ball's pinch to 20 N
    takes the same points, Newton iterations and factorisations with the rule as with its
    start moved beyond max_iterations (the rule off)."""
    import graspdef.solve.nonlinear as N

    def path():
        sol = solve_nonlinear(_ball(3, 20.0), PathOptions(steps=5, max_steps=50))
        return [p.load_factor for p in sol.path], sol.iterations(), sol.n_factorisations, sol.events

    with_rule = path()
    old = N.DIVERGENCE_ITERATIONS
    N.DIVERGENCE_ITERATIONS = 10 ** 6
    try:
        without = path()
    finally:
        N.DIVERGENCE_ITERATIONS = old
    assert with_rule == without and not with_rule[3]


def test_an_anderson_step_that_raises_the_residual_is_taken_back(monkeypatch):
    """Safeguarded Anderson mixing (ANDERSON_GROWTH; a safeguard of the kind of Zhang, O'Donoghue
    & Boyd 2020): a mixed step whose iterate's residual is more than twice the one it started
    from is taken back and replaced by the plain step on the reused tangent.  On the slit annular
    plate (benchmarks/nonlinear, 891 vertices; its Anderson steps on reused tangents sometimes
    jump) steps are taken back, the path needs fewer factorisations than without the safeguard
    (measured 213 against 241), and it ends at the same equilibrium (the lifted lip's
    displacement to 1e-6 of itself; both converge to 1e-8)."""
    from pathlib import Path

    import graspdef.solve.nonlinear as N
    from graspdef.problem.config import load_problem

    toml = Path(__file__).resolve().parents[2] / "benchmarks" / "nonlinear" / "slit_annular_plate.toml"
    runs = {}
    for growth in (float("inf"), N.ANDERSON_GROWTH):
        monkeypatch.setattr(N, "ANDERSON_GROWTH", growth)
        spec = load_problem(toml)
        solver = PathSolver(spec.problem, N.path_options(spec.solver), precision=spec.precision)
        try:
            sol = solver.run()
        finally:
            solver.eq.close()
        runs[growth] = (sol, solver.n_anderson_rejected)
    (plain, none), (safe, taken_back) = runs[float("inf")], runs[2.0]
    assert plain.completed and safe.completed
    assert none == 0 < taken_back and safe.n_factorisations < plain.n_factorisations
    a, b = (np.asarray(s.probe(name)) for s in (plain, safe) for name in [sorted(spec.problem.probes)[0]])
    assert np.linalg.norm(a - b) <= 1e-6 * np.linalg.norm(a)
