"""The object forward model (graspdef.fit.ObjectModel) on the tennis ball, linear shell, point
loads at 10 N per finger (MuJoCo settled once): E and thickness enter the grasp chain as they
should -- the linear displacements scale exactly as 1/E, a thinner wall indents more by about
Reissner's t^-2 -- and the start values are object.toml's."""
from __future__ import annotations

import numpy as np
import pytest

from graspdef.fit import MeasuredTable, ObjectModel


@pytest.fixture(scope="module")
def model():
    table = MeasuredTable(np.array([10.0, 10.0]), np.zeros(2), ("finger", "max"))
    return ObjectModel("tennis_ball", table, ["E", "thickness"], "linear")


def test_start_values_are_object_tomls(model):
    """E = 1 MPa and thickness = 2.5 mm (scenes/tennis_ball/object.toml), in SI."""
    assert model.start() == {"E": 1e6, "thickness": 2.5e-3}


def test_linear_displacements_scale_as_one_over_E(model):
    """Doubling E halves both rows to round-off (one solve per evaluation: one force)."""
    n0 = model.n_solves
    u1 = model({"E": 1e6, "thickness": 2.5e-3})
    u2 = model({"E": 2e6, "thickness": 2.5e-3})
    assert model.n_solves - n0 == 2
    assert np.all(u1 > 0)
    assert np.allclose(u2, u1 / 2, rtol=1e-8)


def test_a_thinner_wall_indents_by_about_t_to_the_minus_two(model):
    """2.0 mm instead of 2.5 mm: the indentation grows by (2.5/2)^2 = 1.56 within 15 % (Reissner's
    point-loaded sphere, w ~ F R / (E t^2); R/t = 13 is thick for it)."""
    u25 = model({"E": 1e6, "thickness": 2.5e-3})
    u20 = model({"E": 1e6, "thickness": 2.0e-3})
    ratio = u20[0] / u25[0]
    print(f"\nindentation at 10 N: {u25[0] * 1e3:.3f} mm (t = 2.5 mm), {u20[0] * 1e3:.3f} mm (2.0 mm): ratio {ratio:.3f}")
    assert ratio == pytest.approx(1.5625, rel=0.15)


def test_air_pressure_enters_the_nonlinear_chain():
    """Nonlinear shell with air: theta's pressure is the run record's gas p0, and less air indents
    more (20 kPa vs object.toml's 80 kPa at 10 N per finger)."""
    table = MeasuredTable(np.array([10.0]), np.zeros(1), ("finger",))
    m = ObjectModel("tennis_ball", table, ["pressure"], "nonlinear")
    assert m.start() == {"pressure": 80e3}
    rec = m.record({"pressure": 20e3}, 10.0)
    assert rec["gas_p0_Pa"] == 20e3 and rec["convergence"]["completed"]
    soft = rec["derived"]["indentation_per_finger"]["value"]
    stiff = m({"pressure": 80e3})[0]
    print(f"\nindentation at 10 N: {soft * 1e3:.3f} mm (20 kPa), {stiff * 1e3:.3f} mm (80 kPa)")
    assert soft > 1.2 * stiff > 0


def test_gas_off_removes_the_air():
    """gas=False (the paper's model: no air): the record holds no air and the ball indents far more
    at 2 N per finger than with object.toml's 80 kPa (1 MPa wall: without air, its pole inverts
    below 3.8 N); fitting a pressure without air is refused before any solve."""
    from graspdef.errors import ProblemError

    table = MeasuredTable(np.array([2.0]), np.zeros(1), ("finger",))
    off = ObjectModel("tennis_ball", table, ["E"], "nonlinear", gas=False)
    on = ObjectModel("tennis_ball", table, ["E"], "nonlinear")
    r_off, r_on = off.record({"E": 1e6}, 2.0), on.record({"E": 1e6}, 2.0)
    assert r_off["gas_p0_Pa"] == 0 and r_on["gas_p0_Pa"] == 80e3
    a, b = (r["derived"]["indentation_per_finger"]["value"] for r in (r_off, r_on))
    print(f"\n2 N, 1 MPa: {a * 1e3:.3f} mm without air, {b * 1e3:.3f} mm with 80 kPa")
    assert a > 3 * b > 0
    with pytest.raises(ProblemError, match="gas off"):
        ObjectModel("tennis_ball", table, ["E", "pressure"], "nonlinear", gas=False)
