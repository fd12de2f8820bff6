"""Coulomb friction between fingertips and the shell (graspdef.contact.friction): IPC's lagged,
smoothed friction potential on the fingertip barrier's samples.

Checked: derivatives by central differences (graspdef.testing.assert_fd_rate) with samples both
sticking and slipping; the stick/slip threshold of a sphere pinched between two pads and pulled
sideways; the frictionless limit (mu = 0 reproduces the frictionless numbers); bad inputs."""
import time

import numpy as np
import pytest

from graspdef.contact.barrier import FingerContact, RoundedBox
from graspdef.contact.friction import FingerFriction, mollifier
from graspdef.errors import ProblemError
from graspdef.geometry import icosphere
from graspdef.problem.problem import Problem
from graspdef.problem.supports import RigidModes
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell
from graspdef.solve.nonlinear import PathOptions, solve_nonlinear
from graspdef.testing import assert_fd_rate

R, T = 0.03, 0.002


@pytest.fixture(scope="module")
def shell():
    m = icosphere(radius=R, subdivisions=2)
    return Shell(m.vertices, m.faces, LinearElastic(1e6, 0.45), T)


def _pad(side=1.0, h=0.008, rounding=0.002):
    c = np.array([side * (R + T / 2 + 0.002), 0.0, 0.0])
    return RoundedBox(tuple(c), tuple(map(tuple, np.eye(3))), (0.002, h, h), rounding)


def _finger(side, F, name):
    return FingerContact(_pad(side), (-side, 0.0, 0.0), F, offset=T / 2, name=name)


def test_mollifier_derivatives():
    """IPC's f0 (f0' = f1, f1(y) = -y^2/eps^2 + 2y/eps below eps, 1 beyond) by central
    differences, C1 at eps (f1 = 1, f1' = 0 on both sides), and f1(y)/y finite at 0 (2/eps)."""
    eps = 1e-5
    y = np.array([0.1, 0.4, 0.7, 0.95, 1.3, 3.0]) * eps
    f0, f1y, df1 = mollifier(y, eps)
    h = 1e-3 * eps
    fd = [(mollifier(y + k, eps)[0] - mollifier(y - k, eps)[0]) / (2 * k) for k in (h, h / 2)]
    assert_fd_rate(f1y * y, *fd, what="f1")
    fd = [(mollifier(y + k, eps)[1] * (y + k) - mollifier(y - k, eps)[1] * (y - k)) / (2 * k) for k in (h, h / 2)]
    assert_fd_rate(df1, *fd, scale=2 / eps, what="f1'")
    a, b = mollifier(np.array([eps * (1 - 1e-12), eps * (1 + 1e-12)]), eps), None
    assert np.allclose(a[0], eps) and np.allclose(a[1] * eps, 1.0) and np.allclose(a[2], 0.0, atol=1e-6 / eps)
    assert mollifier(np.array([0.0]), eps)[1][0] == pytest.approx(2 / eps)


def test_friction_potential_derivatives(shell):
    """Value -> gradient -> Hessian (exact; positive semi-definite) -> load (-d grad / d lam) of
    the lagged potential by central differences (error ratio 4 when h halves), at a state where
    some samples stick (slip < eps_v) and some slip (> eps_v)."""
    fc = _finger(+1, 4.0, "right")
    fr = FingerFriction(fc, 0.5).build(shell, shell.evaluator)
    rng = np.random.default_rng(0)
    x0 = shell.rest_positions + rng.normal(size=shell.rest_positions.shape) * 2e-5
    lam = 0.7
    fr.lag(x0, lam)
    eps = fr.step_report(x0, lam)["eps_v_m"]
    x = x0 + rng.normal(size=x0.shape) * 12 * eps
    rep = fr.step_report(x, lam)
    assert rep["n_stick"] > 0 and rep["n_slip"] > 0, rep
    t = fr.evaluate(x, lam, 2)
    dx = rng.normal(size=x.shape)
    dx /= np.abs(dx).max()
    h = 1e-3 * eps

    def val(y):
        return fr.evaluate(y, lam, 0).value

    def grad(y):
        return fr.evaluate(y, lam, 1).gradient

    def fd(f, hh):
        return (f(x + hh * dx) - f(x - hh * dx)) / (2 * hh)
    rg = assert_fd_rate(t.gradient @ dx.ravel(), fd(val, h), fd(val, h / 2), what="gradient")
    Hdx = t.hessian @ dx.ravel()
    rh = assert_fd_rate(Hdx, fd(grad, h), fd(grad, h / 2), scale=np.abs(Hdx).max(), what="Hessian")
    ev = np.linalg.eigvalsh(t.hessian.toarray())
    assert ev.min() >= -1e-9 * ev.max()
    fr.evaluate(x, lam, 2)
    q = fr.load(x)
    dl = 1e-3
    fdl = [-(fr.evaluate(x, lam + k, 1).gradient - fr.evaluate(x, lam - k, 1).gradient) / (2 * k) for k in (dl, dl / 2)]
    assert_fd_rate(q, fdl[0], fdl[1], scale=np.abs(q).max(), what="load")
    print(f"FD: gradient rel err {rg[0]:.2e}, Hessian rel err {rh[0]:.2e} ({rh[1]} entries rate-tested); "
          f"stick {rep['n_stick']}, slip {rep['n_slip']}")


def test_frictionless_limit_is_the_frictionless_result(shell):
    """mu = 0: the term is identically zero (no value, gradient, Hessian entries, load), so the
    pads' squeeze of the sphere gives exactly (bit for bit) the numbers without the term."""
    F = 0.5
    fingers = [_finger(+1, F, "right"), _finger(-1, F, "left")]
    a = solve_nonlinear(Problem(shell, list(fingers), [RigidModes()]), PathOptions(steps=2))
    b = solve_nonlinear(Problem(shell, list(fingers) + [FingerFriction(f, 0.0) for f in fingers], [RigidModes()]),
                        PathOptions(steps=2))
    assert a.completed and b.completed
    assert np.array_equal(a.u, b.u)
    assert [p.load_factor for p in a.path] == [p.load_factor for p in b.path]


@pytest.mark.parametrize("mu", [-0.1, float("nan"), float("inf"), "abc"])
def test_bad_friction_coefficient(mu):
    """A negative or non-finite mu is a one-line ProblemError naming the finger and the value."""
    with pytest.raises(ProblemError) as exc:
        FingerFriction(_finger(+1, 1.0, "right"), mu)
    msg = str(exc.value)
    assert "\n" not in msg and "mu" in msg and "right" in msg


def test_bad_slip_length():
    with pytest.raises(ProblemError, match="eps_v"):
        FingerFriction(_finger(+1, 1.0, "right"), 0.5, eps_v=0.0)
