"""Nitsche rotation terms at finite deformation (graspdef.problem.nitsche)."""
import numpy as np
import pytest

from graspdef.geometry import cylinder
from graspdef.problem.nitsche import NitscheRotation
from graspdef.problem.problem import Problem
from graspdef.problem.supports import EdgeSupport
from graspdef.shell.hyperelastic import NeoHookean
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell
from graspdef.testing import assert_fd_rate

from nitsche_reference import linear_nitsche_matrix


def _setup(mat):
    m = cylinder(1.0, 1.0, 6, 4, 0.0, np.pi / 2)
    sh = Shell(m.vertices, m.faces, mat, 0.05)
    sups = [EdgeSupport("clamped", lambda x: np.abs(x[:, 2]) < 1e-9),
            EdgeSupport("symmetry", lambda x: np.abs(x[:, 1]) < 1e-9, normal=(0, 1, 0))]
    return sh, sups


@pytest.mark.parametrize("mat", [LinearElastic(1e5, 0.3), NeoHookean(4e4)], ids=["svk", "neo_hookean"])
def test_nitsche_energy_is_linear_nitsche_at_rest_and_fd_consistent(mat):
    """At rest the Hessian equals the linear Nitsche matrix (Nitsche 1971), computed by an
    independent implementation of linear theory (tests/problem/nitsche_reference.py, the
    solver's first version); at a deformed state gradient and Hessian match central differences (O(h^2) rate)."""
    sh, sups = _setup(mat)
    N = NitscheRotation(sh, sups, sh.evaluator)
    X = sh.rest_positions
    _, g0, H0 = N.evaluate(X)
    K = linear_nitsche_matrix(sh, sups, sh.evaluator)
    assert abs(Problem(sh, [], sups).boundary_stiffness() - K).max() <= 1e-12 * abs(K).max()
    assert abs(H0 - K).max() <= 1e-12 * abs(K).max()
    assert np.abs(g0).max() <= 1e-12 * abs(K).max()
    rng = np.random.default_rng(0)
    x = X + 0.1 * np.sin(2 * X[:, [1, 2, 0]]) + 0.02 * rng.standard_normal(X.shape)
    _, g, H = N.evaluate(x)
    d = rng.standard_normal(x.shape)
    e = lambda h: (N.evaluate(x + h * d, 1)[0] - N.evaluate(x - h * d, 1)[0]) / (2 * h)  # noqa: E731
    G = lambda h: (N.evaluate(x + h * d, 1)[1] - N.evaluate(x - h * d, 1)[1]) / (2 * h)  # noqa: E731
    assert_fd_rate(g @ d.ravel(), e(1e-4), e(5e-5), what="gradient")
    # the hyperelastic Hessian's third-derivative part is itself a difference quotient (~1e-9)
    assert_fd_rate(H @ d.ravel(), G(2e-4), G(1e-4), floor=1e-7 if isinstance(mat, LinearElastic) else 1e-6,
                   what="Hessian")
    assert abs(H - H.T).max() <= 1e-12 * abs(H).max()


def test_the_rotation_measure_is_exact_at_finite_rotation():
    """theta = n0 . du/dnu vanishes for any deformation that keeps the slope across the edge,
    e.g. a rigid translation plus a uniform radial expansion of the cylinder (its tangent across
    the clamped ring z = 0 stays axial) -- so the penalty does not resist it."""
    sh, sups = _setup(LinearElastic(1e5, 0.3))
    N = NitscheRotation(sh, sups[:1], sh.evaluator)
    X = sh.rest_positions
    x = X * np.array([1.3, 1.3, 1.0]) + np.array([0.2, -0.1, 0.0])
    u = x - X
    theta = np.einsum("ksa,ksa->k", N._d[:, :, None] * N._n0[:, None, :], u[N._st])
    assert np.abs(theta).max() < 1e-12
