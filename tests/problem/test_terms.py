"""The energy-term protocol (graspdef.problem.terms): every term a problem builds satisfies it,
building a term leaves its specification unchanged, and Equilibrium's sum of the terms -- shell,
Nitsche clamp, dead point load, enclosed gas -- has the gradient, Hessian and load direction of
central finite differences (O(h^2) rate)."""
from __future__ import annotations

import dataclasses

import numpy as np

from graspdef.geometry import rectangle, sphere
from graspdef.problem.loads import PointLoad
from graspdef.problem.potentials import EdgeMoment, EnclosedGas, FollowerPressure
from graspdef.problem.problem import Problem
from graspdef.problem.supports import EdgeSupport, RigidModes
from graspdef.problem.terms import DeadLoads, EnergyTerm, NitscheTerm, RestQuadratic, ShellElastic
from graspdef.shell.hyperelastic import NeoHookean
from graspdef.shell.model import Shell
from graspdef.solve.equilibrium import Equilibrium
from graspdef.testing import assert_fd_rate


def _plate():
    """A clamped neo-Hookean plate with a point load and a follower edge moment."""
    m = rectangle(2.0, 1.0, 6, 3, center=(1.0, 0.5))
    sh = Shell(m.vertices, m.faces, NeoHookean(1e5), 0.05)
    pr = Problem(sh, [EdgeMoment(lambda x: np.abs(x[:, 0] - 2) < 1e-9, 30.0, (0, -1, 0))],
                 [EdgeSupport("clamped", lambda x: np.abs(x[:, 0]) < 1e-9)])
    p = pr.locate((1.5, 0.5, 0.0))
    pr.loads.append(PointLoad(p.face, p.bary, (0.0, 0.3, -2.0)))
    return pr


def _ball():
    """A neo-Hookean ball with enclosed gas, a follower pressure and two dead point loads."""
    m = sphere(1.0, 1)
    sh = Shell(m.vertices, m.faces, NeoHookean(2e5), 0.05)
    pr = Problem(sh, [EnclosedGas(2e4, 1e5), FollowerPressure(5e3)], [RigidModes()])
    for z in (1.0, -1.0):
        p = pr.locate((0.0, 0.0, z))
        pr.loads.append(PointLoad(p.face, p.bary, (0.0, 0.0, -300.0 * z)))
    return pr


def test_every_term_satisfies_the_protocol_and_building_changes_no_specification():
    for pr, kinds in ((_plate(), {ShellElastic, NitscheTerm, DeadLoads, EdgeMoment}),
                      (_ball(), {ShellElastic, DeadLoads, EnclosedGas, FollowerPressure})):
        specs = [dataclasses.replace(ld) if dataclasses.is_dataclass(ld) else ld for ld in pr.loads]
        before = [dict(vars(s)) for s in specs]
        terms = pr.energy_terms()
        assert {type(t) for t in terms} == kinds
        assert all(isinstance(t, EnergyTerm) for t in terms)
        assert [dict(vars(s)) for s in specs] == before                 # build() returned new objects
        assert not any(t is ld for t in terms for ld in pr.loads)
        assert [type(t) for t in pr.energy_terms("rest")][0] is RestQuadratic


def _check_sum(pr, lam=0.7):
    eq = Equilibrium(pr)
    rng = np.random.default_rng(3)
    X = pr.shell.rest_positions
    u = (0.02 * np.sin(3 * X[:, [1, 2, 0]]) + 0.005 * rng.standard_normal(X.shape)).ravel()
    st = eq.evaluate(u, lam)
    H = st.hessian.toarray()
    for c, v in st.rank_one:
        H += c * np.outer(v, v)
    d = rng.standard_normal(u.shape)

    def fd(fun, h):
        return (fun(u + h * d) - fun(u - h * d)) / (2 * h)
    E = lambda v: eq.evaluate(v, lam, 0).energy  # noqa: E731
    G = lambda v: eq.evaluate(v, lam, 1).gradient  # noqa: E731
    assert_fd_rate(st.gradient @ d, fd(E, 1e-4), fd(E, 5e-5), what="gradient")
    assert_fd_rate(H @ d, fd(G, 1e-4), fd(G, 5e-5), what="Hessian")
    # the load direction q = -d(grad)/d(lam)
    Gl = lambda l: eq.evaluate(u, l, 1).gradient  # noqa: E731
    q1 = -(Gl(lam + 1e-3) - Gl(lam - 1e-3)) / 2e-3
    q2 = -(Gl(lam + 5e-4) - Gl(lam - 5e-4)) / 1e-3
    assert_fd_rate(st.load, q1, q2, what="load direction")
    eq.close()


def test_sum_of_terms_matches_finite_differences_plate():
    _check_sum(_plate())


def test_sum_of_terms_matches_finite_differences_ball():
    _check_sum(_ball())
