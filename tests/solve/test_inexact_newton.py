"""Inexact Newton steps of the path solver: GMRES on the current tangent, preconditioned by the
factorisation of an earlier one (graspdef.solve.krylov, Equilibrium.inexact_step, PathOptions.krylov;
off by default)."""
import numpy as np

from graspdef.geometry import rectangle, sphere
from graspdef.problem.loads import EdgeLoad, PointLoad
from graspdef.problem.potentials import EnclosedGas
from graspdef.problem.problem import Problem
from graspdef.problem.supports import EdgeSupport, PointSupport, RigidModes
from graspdef.shell.hyperelastic import NeoHookean
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell
from graspdef.solve.equilibrium import Equilibrium
from graspdef.solve.krylov import gmres
from graspdef.solve.nonlinear import PathOptions, solve_nonlinear


def test_gmres_reaches_the_solution_and_reports_failure():
    """Right-preconditioned GMRES on a non-symmetric system: with the inverse of a nearby matrix as
    preconditioner it reaches the solution (to the requested true residual) in far fewer
    iterations than the dimension; with too few iterations it says it has not converged."""
    rng = np.random.default_rng(1)
    n = 60
    A = np.eye(n) * 4 + rng.standard_normal((n, n)) / np.sqrt(n)
    b = rng.standard_normal(n)
    Minv = np.linalg.inv(A + 0.05 * rng.standard_normal((n, n)) / np.sqrt(n))
    x, k, res, ok = gmres(lambda v: A @ v, b, 1e-12 * np.linalg.norm(b), 40, lambda v: Minv @ v)
    assert ok and k < 15, k
    assert np.linalg.norm(A @ x - b) <= 1.01e-12 * np.linalg.norm(b)
    assert np.allclose(x, np.linalg.solve(A, b), rtol=0, atol=1e-10 * np.abs(x).max())
    x2, k2, res2, ok2 = gmres(lambda v: A @ v, b, 1e-12 * np.linalg.norm(b), 3)   # no preconditioner
    assert not ok2 and k2 == 3 and res2 > 1e-12 * np.linalg.norm(b)


def _ball(sub: int, force: float):
    R, t = 0.0325, 0.0025
    m = sphere(R, sub)
    pr = Problem(Shell(m.vertices, m.faces, NeoHookean(1e6 / 3), t), [EnclosedGas(80e3)], [RigidModes()])
    top, bot = pr.locate((0, 0, R)), pr.locate((0, 0, -R))
    pr.loads += [PointLoad(top.face, top.bary, (0, 0, -force)), PointLoad(bot.face, bot.bary, (0, 0, force))]
    pr.probes["top"] = top
    return pr


def test_inexact_step_is_the_newton_step_of_the_current_tangent():
    """The air-filled ball (six rigid-mode constraints, the gas's rank-one tangent): factorise the
    tangent at the undeformed state, then ask for the Newton step at a squashed state (15 % of
    the radius).  GMRES preconditioned by the stale factorisation gives the step that a
    factorisation of the squashed state's own tangent gives, to the requested tolerance, and it
    satisfies the constraints; the modified-Newton step (the stale factorisation alone) does not."""
    pr = _ball(2, 20.0)
    eq = Equilibrium(pr)
    try:
        X = eq.X
        u_b = (0.15 * X * np.array([0.5, 0.5, -1.0])).ravel()       # squashed along z
        lam = 0.7
        eq.factor(eq.evaluate(np.zeros(eq.n), 0.0, 2))              # the stale tangent
        st = eq.evaluate(u_b, lam, 2)
        cres = eq.constraint_residual(u_b, lam)
        du0 = eq.solve(-st.gradient, cres)                          # modified-Newton step
        du = eq.inexact_step(u_b, lam, st, -st.gradient, du0, 1e-10, 200)      # products with H
        assert du is not None and eq.n_krylov > 1
        st1 = eq.evaluate(u_b, lam, 1)                              # no Hessian: gradient differences
        assert st1.hessian is None
        du_fd = eq.inexact_step(u_b, lam, st1, -st1.gradient, du0, 1e-6, 200)
        assert du_fd is not None
        assert eq.inexact_step(u_b, lam, st, -st.gradient, du0, 1e-10, 1) is None   # not in one iteration
        eq.factor(st)                                               # the current tangent, exactly
        exact = eq.solve(-st.gradient, cres)
    finally:
        eq.close()
    scale = np.abs(exact).max()
    print(np.abs(du - exact).max() / scale, np.abs(du_fd - exact).max() / scale, np.abs(du0 - exact).max() / scale)
    assert np.abs(du - exact).max() <= 1e-7 * scale
    assert np.abs(du_fd - exact).max() <= 1e-5 * scale
    assert np.abs(du0 - exact).max() > 1e-2 * scale                  # the stale step is far from it
    for d in (du, du_fd):
        assert np.abs(eq.C @ d - cres).max() <= 1e-12 * scale


def test_path_with_inexact_steps_reaches_the_same_points_with_fewer_factorisations():
    """The air-filled ball squeezed by two point forces in large load steps (reuse_ratio 0.5, so
    that the stale tangent is refused often): with inexact Newton steps the path converges to the
    same points as with a factorisation at every refusal (krylov = 0) -- the same load factors,
    the same pole displacement to the Newton tolerance -- with fewer factorisations; every point's
    stability comes from a factorisation within inertia_rtol of it and equals the inertia of the
    Hessian factorised at the converged point itself."""
    pr = _ball(2, 20.0)
    opts = dict(steps=3, desired_iterations=1, reuse_ratio=0.5)     # three equal steps
    new = solve_nonlinear(pr, PathOptions(krylov=10, **opts))
    old = solve_nonlinear(pr, PathOptions(krylov=0, **opts))
    assert new.n_inexact > 0 and old.n_inexact == 0
    assert new.n_factorisations < old.n_factorisations, (new.n_factorisations, old.n_factorisations)
    assert np.allclose(new.load_factors(), old.load_factors(), rtol=0, atol=1e-12)
    w_new, w_old = new.probe_path("top")[:, 2], old.probe_path("top")[:, 2]
    assert np.allclose(w_new, w_old, rtol=1e-6, atol=0), (w_new, w_old)
    assert all(p.extra["inertia_residual"] <= 1e-4 for p in new.path)
    assert all(p.extra["residual_relative"] <= 1e-8 or p.converged_by != "residual" for p in new.path)
    eq = Equilibrium(pr)
    try:
        at_point = [eq.factor(eq.evaluate(p.u.ravel(), p.load_factor, 2)) for p in new.path]
    finally:
        eq.close()
    assert [p.instability for p in new.path] == at_point == [p.instability for p in old.path]


def test_stability_across_the_euler_load_with_inexact_steps():
    """A strip (L = 4, b = 0.5, t = 0.2, simply supported) compressed to 1.5 times its Euler load
    (as in test_nonlinear's stability test), with reuse_ratio 0.5 so that an inexact step is
    taken: the reported stability -- stable before P_e, one negative eigenvalue after -- is the
    inertia of the Hessian factorised at each converged point, and the end state is the one with
    factorisations only (krylov = 0)."""
    L, b, E, t = 4.0, 0.5, 1e6, 0.2
    m = rectangle(L, b, 32, 4, center=(L / 2, b / 2))
    ends = lambda x: (np.abs(x[:, 0]) < 1e-9) | (np.abs(x[:, 0] - L) < 1e-9)  # noqa: E731
    pr = Problem(Shell(m.vertices, m.faces, LinearElastic(E, 0.0), t), [],
                 [EdgeSupport("diaphragm", ends, normal=(1, 0, 0))])
    a = pr.locate((0.0, 0.0, 0))
    pr.supports.append(PointSupport(a.face, a.bary, ((1, 0, 0),)))
    P_e = np.pi ** 2 * E * b * t ** 3 / 12 / L ** 2
    pr.loads.append(EdgeLoad(lambda x: np.abs(x[:, 0] - L) < 1e-9, (-1.5 * P_e / b, 0, 0)))
    new = solve_nonlinear(pr, PathOptions(steps=6, reuse_ratio=0.5, krylov=10))
    old = solve_nonlinear(pr, PathOptions(steps=6, reuse_ratio=0.5, krylov=0))
    assert new.n_inexact > 0
    eq = Equilibrium(pr)
    try:
        at_point = [eq.factor(eq.evaluate(p.u.ravel(), p.load_factor, 2)) for p in new.path]
    finally:
        eq.close()
    reported = [p.instability for p in new.path]
    assert reported == at_point == [p.instability for p in old.path]
    assert reported[0] == 0 and reported[-1] == 1
    assert np.allclose(new.u, old.u, rtol=0, atol=1e-7 * np.abs(old.u).max())


def test_inexact_steps_are_off_by_default():
    """PathOptions.krylov is 0 unless asked for: the default path takes no inexact step."""
    assert PathOptions().krylov == 0
    sol = solve_nonlinear(_ball(2, 20.0), PathOptions(steps=3, desired_iterations=1, reuse_ratio=0.5))
    assert sol.n_inexact == 0 and sol.n_krylov == 0
