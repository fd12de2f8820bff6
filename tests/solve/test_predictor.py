"""The first iterate of a load-controlled step (graspdef.solve.nonlinear.extrapolate,
PathOptions.predictor): the polynomial through the last two path points with the tangent du/dlam
at the last ("quadratic", the default) or at both ("cubic"; Hermite interpolation, e.g. Burden &
Faires, Numerical Analysis, 3.4), extrapolated to the next load factor."""
import numpy as np
import pytest

from graspdef.errors import ProblemError
from graspdef.solve.nonlinear import PathOptions, extrapolate, solve_nonlinear
from test_inexact_newton import _ball

KINDS = ("linear", "quadratic", "cubic")


def _predict(path, dpath, lam0, lam1, lam2, kind):
    return extrapolate(path(lam1), dpath(lam1), lam2 - lam1, path(lam0), lam1 - lam0, dpath(lam0), kind)


@pytest.mark.parametrize("degree", [1, 2, 3])
def test_each_predictor_is_exact_on_polynomial_paths_of_its_degree(degree):
    """On a path u(lam) that is a polynomial of degree p, the linear, quadratic and cubic
    predictors are exact (to round-off) for p <= 1, 2 and 3 respectively, whatever the step
    lengths (here unequal: the next step 1.4 times the last, as after a step's growth), and the
    lower ones are not exact for higher p."""
    rng = np.random.default_rng(degree)
    C = rng.standard_normal((degree + 1, 40))
    path = lambda s: sum(C[k] * s ** k for k in range(degree + 1))                        # noqa: E731
    dpath = lambda s: sum(k * C[k] * s ** (k - 1) for k in range(1, degree + 1))          # noqa: E731
    lam0, lam1 = 0.3, 0.5
    lam2 = lam1 + 1.4 * (lam1 - lam0)
    scale = np.abs(path(lam2) - path(lam1)).max()
    for order, kind in enumerate(KINDS, start=1):
        err = np.abs(_predict(path, dpath, lam0, lam1, lam2, kind) - path(lam2)).max() / scale
        if degree <= order:
            assert err <= 1e-13, (kind, err)
        else:
            assert err > 1e-4, (kind, err)


def test_the_predictors_errors_fall_at_their_orders():
    """On a smooth path that is no polynomial (u = exp(lam) a + sin(3 lam) b), halving both steps
    divides the linear, quadratic and cubic predictors' errors by 4, 8 and 16 (local errors
    O(h^2), O(h^3), O(h^4)); the measured ratios are within 15 % of these."""
    rng = np.random.default_rng(7)
    a, b = rng.standard_normal((2, 30))
    path = lambda s: np.exp(s) * a + np.sin(3 * s) * b                     # noqa: E731
    dpath = lambda s: np.exp(s) * a + 3 * np.cos(3 * s) * b                # noqa: E731
    lam1 = 0.4
    for order, kind in enumerate(KINDS, start=2):
        errs = []
        for h in (0.04, 0.02, 0.01):
            errs.append(np.linalg.norm(_predict(path, dpath, lam1 - h, lam1, lam1 + h, kind) - path(lam1 + h)))
        ratios = [errs[0] / errs[1], errs[1] / errs[2]]
        assert all(abs(r / 2 ** order - 1) < 0.15 for r in ratios), (kind, ratios)


def test_the_cubic_falls_back_to_the_quadratic_where_its_term_outgrows():
    """Where the cubic term of the extrapolation is larger than its quadratic term (the two points
    do not resolve the path's curvature: the series is not converging) the cubic predictor is the
    quadratic one; where it is smaller, it is not; without the previous tangent there is no cubic."""
    u, t, ub, h = np.zeros(3), np.array([1.0, 0, 0]), np.array([-1.0, 0.1, 0]), 1.0
    d = ub - u + h * t                                             # the quadratic term (0, 0.1, 0)
    for tb, outgrows in ((t + np.array([0, -0.15, 0.0]), False), (t + np.array([0, 0.0, 0.5]), True)):
        b = 2 * d + h * (tb - t)
        assert (np.linalg.norm(b) > np.linalg.norm(d)) == outgrows
        cub, quad = (extrapolate(u, t, 1.0, ub, h, tb, k) for k in ("cubic", "quadratic"))
        assert np.array_equal(cub, quad) == outgrows
    with pytest.raises(ValueError, match="tangent at the previous point"):
        extrapolate(u, t, 1.0, ub, h, None, "cubic")
    with pytest.raises(ProblemError, match="predictor must be one of quadratic, linear, cubic"):
        PathOptions(predictor="quartic")


def test_the_predictors_reach_the_same_equilibria():
    """Only a step's first iterate depends on the predictor: the air-filled rubber ball squeezed to
    20 N (642 control vertices) reaches the same equilibria at 0.5 and 1 of the load with each of
    the three (to the Newton tolerance, 1e-8 of the force scale: the displacements to ~1e-7 of the
    largest), and the curved predictors take fewer Newton iterations than the linear one (measured
    17 cubic, 17 quadratic, 26 linear; on the 10,242-vertex ball the cubic's path has 8 points and
    19 factorisations against the quadratic's 10 and 22)."""
    pr = _ball(2, 20.0)
    sols = {k: solve_nonlinear(pr, PathOptions(steps=10, targets=(0.5,), predictor=k)) for k in KINDS}
    assert all(s.completed for s in sols.values())
    ref = sols["cubic"]
    for lam in (0.5, 1.0):
        for k in ("quadratic", "linear"):
            a, b = ref.at(lam).u, sols[k].at(lam).u
            assert np.abs(a - b).max() <= 1e-6 * np.abs(a).max(), (k, lam)
    its = {k: sum(s.iterations()) for k, s in sols.items()}
    assert its["cubic"] < its["linear"] and its["quadratic"] < its["linear"], its
