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


def test_the_symmetry_measure_vanishes_exactly_when_the_surface_meets_the_plane_at_right_angles():
    """A symmetry plane (normal N) may not be crossed: the mirrored surface is smooth only if the
    deformed surface meets the plane at right angles, i.e. its normal n lies in the plane (the
    symmetry conditions of Kirchhoff-Love shells: u . N = 0 and no rotation about the edge; e.g.
    Kiendl, Bletzinger, Linhard & Wuechner 2009, CMAME 198, 3902, on rotation conditions of KL
    shells).  At finite deformation the edge turns within the plane, so the condition is on the
    deformed normal, not on the rest one: for affine maps x -> F x that keep the plane z = L
    (F e_z = e_z + shear, F's third row (0, 0, 1)) -- which subdivision reproduces exactly -- theta
    must equal +-(n . N) |a_t x a_nu| / |a_t| at every Gauss point, in particular vanish for a
    turn about N with any in-plane stretch and not for a turn combined with a shear across the
    edge (the clamped measure n0 . du/dnu gets both wrong)."""
    m = cylinder(1.0, 1.0, 6, 4, 0.0, np.pi / 2)
    sh = Shell(m.vertices, m.faces, LinearElastic(1e5, 0.3), 0.05)
    N = NitscheRotation(sh, [EdgeSupport("symmetry", lambda x: np.abs(x[:, 2] - 1.0) < 1e-9, normal=(0, 0, 1))],
                        sh.evaluator)
    X = sh.rest_positions
    ez = np.array([0.0, 0.0, 1.0])
    c, s = np.cos(0.7), np.sin(0.7)
    turn = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    maps = {"turn": turn, "turn + in-plane stretch": turn @ np.diag([1.3, 0.8, 1.0]),
            "turn + shear across": turn @ np.array([[1, 0, 0.0], [0, 1, 0.4], [0, 0, 1]]),
            "shear across": np.array([[1, 0, 0.3], [0, 1, -0.2], [0, 0, 1.0]])}
    tilted = 0
    for name, F in maps.items():
        x = (X - ez) @ F.T + ez
        theta = N._theta(x)[0]
        y = np.einsum("ksK,ksd->kKd", N._D, x[N._st])
        n = np.cross(y[:, 0], y[:, 1])
        n /= np.linalg.norm(n, axis=1)[:, None]
        a_nu = np.einsum("ks,ksd->kd", N._d, x[N._st])
        a_t = np.einsum("ks,ksd->kd", N._tv, x[N._st])
        expected = np.abs(n @ ez) * np.linalg.norm(np.cross(a_t, a_nu), axis=1) / np.linalg.norm(a_t, axis=1)
        assert np.allclose(np.abs(theta), expected, rtol=1e-10, atol=1e-12), name
        tilted += bool(expected.max() > 1e-3)
    assert tilted == 2          # the two maps with a shear across the edge tilt the surface
