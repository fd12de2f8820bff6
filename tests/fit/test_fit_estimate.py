"""The estimator (graspdef.fit.estimate) on cheap callable forward models: exact recovery from
exact data, the trade-off warning when two parameters enter only as a product, standard errors
that match the scatter of repeated noisy fits, and honest failure reports (an optimiser that runs
out of iterations, a forward model that fails)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from graspdef.errors import ProblemError, SolverError
from graspdef.fit import MeasuredTable, fit

F = np.array([1.0, 2.0, 4.0, 6.0, 8.0, 10.0])


def stiffening(theta):
    """A spring with an offset: u = F / E + 1 / p -- E and p separable (correlation ~0.85)."""
    return F / theta["E"] + 1.0 / theta["pressure"]


def product(theta):
    """u = F / (E t): only the product E t is seen."""
    return F / (theta["E"] * theta["thickness"])


def _table(u, sigma=None):
    return MeasuredTable(F.copy(), np.asarray(u, float), ("finger",) * len(F), sigma)


def test_exact_data_are_recovered_exactly():
    """Noise-free data of known parameters, a start 2x off: recovered to 1e-6, residuals ~0, no warning."""
    true = {"E": 2000.0, "pressure": 500.0}
    r = fit(stiffening, _table(stiffening(true)), {"E": 4000.0, "pressure": 1000.0})
    assert r.converged, r.message
    assert np.allclose(r.values, [2000.0, 500.0], rtol=1e-6)
    assert r.rms < 1e-9 * np.abs(stiffening(true)).max()
    assert not r.warnings


def test_product_parameters_are_flagged_as_not_identifiable():
    """E and t entering only as E t: the fit converges (to some pair with the right product), and the
    report says E and thickness are not separately identifiable (|corr| ~ 1, cond(J^T J) huge),
    with standard errors that say so (larger than the values), not the pseudo-inverse's small ones."""
    true = {"E": 2000.0, "thickness": 2e-3}
    rng = np.random.default_rng(3)
    u = product(true) * (1 + 0.01 * rng.standard_normal(len(F)))
    r = fit(product, _table(u), {"E": 4000.0, "thickness": 4e-3})
    assert any("E and thickness are not separately identifiable" in w for w in r.warnings), r.warnings
    assert abs(r.correlation[0, 1]) > 0.999 and r.condition > 1e8
    assert np.all(r.std > r.values)
    assert r.value("E") * r.value("thickness") == pytest.approx(4.0, rel=0.02)


def test_standard_errors_match_the_scatter_of_repeated_fits():
    """30 seeded noise draws (1 %, the table's sigma): the spread of the fitted E and p is the
    reported standard error (its RMS over the draws) to within 40 %, and the true value lies within 3 reported sigma in at least 28 of 30 fits."""
    true = {"E": 2000.0, "pressure": 500.0}
    u0 = stiffening(true)
    rng = np.random.default_rng(7)
    est, se, inside = [], [], 0
    for _ in range(30):
        r = fit(stiffening, _table(u0 * (1 + 0.01 * rng.standard_normal(len(F))), sigma=0.01 * u0),
                {"E": 4000.0, "pressure": 1000.0})
        assert r.converged
        est.append(r.values)
        se.append(r.std)
        inside += bool(np.all(np.abs(r.values - [2000.0, 500.0]) <= 3 * r.std))
    spread = np.std(np.array(est), axis=0, ddof=1)
    rms_se = np.sqrt(np.mean(np.array(se) ** 2, axis=0))          # E[s^2] = sigma^2
    assert np.allclose(rms_se, spread, rtol=0.4), (spread, rms_se)
    assert inside >= 28


def test_an_unconverged_fit_is_not_reported_as_converged():
    """One optimiser iteration from far away: converged is False and the first warning says NOT."""
    true = {"E": 2000.0, "pressure": 500.0}
    r = fit(stiffening, _table(stiffening(true)), {"E": 200000.0, "pressure": 50.0}, max_nfev=1)
    assert not r.converged
    assert "did NOT converge" in r.warnings[0]
    assert r.to_json()["converged"] is False


def test_a_failing_forward_model_is_reported():
    """A forward model that fails at the start: not converged, the reason and theta in the message,
    and what to change (other start values)."""
    def broken(theta):
        raise SolverError("the load path stopped at load factor 0.3")

    r = fit(broken, _table(F), {"E": 1.0})
    assert not r.converged and "load path stopped" in r.message and "E = 1" in r.message
    assert "give other start values" in r.message
    assert all(math.isnan(s) for s in r.std)


def test_a_trial_step_that_fails_is_stepped_back_from():
    """A forward model that fails for 1500 < E < 1650 Pa (as a path that stops near a critical point
    would), where the optimiser's first trial step from E = 1000 lands (E = 1570): the optimiser
    shrinks its step, still converges to E = 2000, and the report counts the failed trial."""
    seen = []

    def model(theta):
        seen.append(theta["E"])
        if 1500.0 < theta["E"] < 1650.0:
            raise SolverError("path stopped")
        return F / theta["E"]

    r = fit(model, _table(F / 2000.0), {"E": 1000.0})
    assert any(1500.0 < e < 1650.0 for e in seen)
    assert r.converged and r.value("E") == pytest.approx(2000.0, rel=1e-6)
    assert any("1 trial step(s) of the optimiser failed" in w for w in r.warnings), r.warnings


def test_fewer_rows_than_parameters_is_refused():
    """Two rows cannot fit three parameters: one line before any forward evaluation."""
    t = MeasuredTable(F[:2], F[:2], ("finger",) * 2)
    with pytest.raises(ProblemError, match="2 rows for 3 parameters"):
        fit(lambda th: F[:2], t, {"E": 1.0, "pressure": 1.0, "thickness": 1.0})
