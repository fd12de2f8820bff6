"""graspdef.units: quantities with units at I/O, SI out, the dimension checked."""
import math

import pytest

from graspdef.errors import ConfigError, ProblemError
from graspdef.units import (
    DIMENSIONS,
    LENGTH_UNITS,
    UNITS,
    format_quantity,
    length_scale,
    quantity,
    quantity_vector,
    unit_factor,
)


@pytest.mark.parametrize("text, dimension, si", [
    ("2.5 mm", "length", 2.5 * 1e-3),
    ("2.5mm", "length", 2.5 * 1e-3),
    ("  2.5   mm ", "length", 2.5 * 1e-3),
    ("1 in", "length", 0.0254),
    ("12 um", "length", 12 * 1e-6),
    ("3 cm", "length", 0.03),
    ("-41.65 mm", "length", -41.65 * 1e-3),
    ("1e-3 m", "length", 1e-3),
    ("1 MPa", "pressure", 1e6),
    ("80 kPa", "pressure", 80e3),
    ("200 GPa", "pressure", 200e9),
    ("101325 Pa", "pressure", 101325.0),
    ("1 psi", "pressure", 6894.757293168361),
    ("0.76 N", "force", 0.76),
    ("2 kN", "force", 2000.0),
    ("5 mN", "force", 5e-3),
    ("1100 kg/m^3", "density", 1100.0),
    ("1.1 g/cm^3", "density", 1.1 * 1e3),
    ("58 g", "mass", 58 * 1e-3),
    ("0.058 kg", "mass", 0.058),
])
def test_quantities_come_out_in_si(text, dimension, si):
    """The same float as the hand-written conversion (value * factor), e.g. 2.5 * 1e-3."""
    assert quantity(text, dimension) == si


def test_plain_numbers_need_an_implied_unit():
    assert quantity(2.5, "length", implied="mm") == 2.5 * 1e-3
    assert quantity("2.5", "length", implied="mm") == 2.5 * 1e-3
    assert quantity(3, "pressure", implied=1e6) == 3e6
    assert quantity(3.0, "pressure", implied=lambda v: v * 1.0 / 1e-3 ** 2) == 3.0 / 1e-6
    with pytest.raises(ConfigError, match=r"^f.toml: \[shell\] thickness needs a unit: 2.5 is a plain number; "
                                          r"write e.g. \"2.5 m\" \(a length: m, mm, cm, um, in\)$"):
        quantity(2.5, "length", what="f.toml: [shell] thickness")


@pytest.mark.parametrize("value, dimension, message", [
    ("2.5 MPa", "length", r"'2.5 MPa' is a pressure; expected a length \(m, mm, cm, um, in\)"),
    ("1 N", "pressure", r"'1 N' is a force; expected a pressure \(Pa, kPa, MPa, GPa, psi\)"),
    ("2.5 furlong", "length", r"'2.5 furlong' has an unknown unit 'furlong'; a length takes one of: m, mm"),
    ("2.5 MM", "length", r"unknown unit 'MM'"),
    ("mm", "length", r"'mm' is not a number with a unit"),
    ("2.5 m m", "length", r"is not a number with a unit"),
    ("nan mm", "length", r"must be finite, got 'nan mm'"),
    ("inf Pa", "pressure", r"must be finite, got 'inf Pa'"),
    (float("nan"), "length", r"must be finite, got nan"),
    (True, "length", r"must be a length such as \"2.5 m\", got True"),
    ([1, 2], "length", r"must be a length such as"),
    ("1e400 m", "length", r"must be finite"),
])
def test_bad_quantities_are_named(value, dimension, message):
    with pytest.raises(ConfigError, match=message):
        quantity(value, dimension, implied="mm" if not isinstance(value, str) else None, what="w")


def test_dimension_error_names_the_key():
    with pytest.raises(ProblemError) as exc:
        quantity("2.5 Pa", "length", what="scenes/x/object.toml: [shell] thickness")
    assert str(exc.value) == ("scenes/x/object.toml: [shell] thickness '2.5 Pa' is a pressure; expected a length "
                              "(m, mm, cm, um, in)")


def test_vectors():
    assert quantity_vector("[47.97, 4.19, -41.65] mm", "length") == (47.97 * 1e-3, 4.19 * 1e-3, -41.65 * 1e-3)
    assert quantity_vector(["1 mm", "2 cm", "3 m"], "length") == (1e-3, 0.02, 3.0)
    assert quantity_vector([1, 2, 3], "length", implied="mm") == (1e-3, 2e-3, 3e-3)
    assert quantity_vector("[1, 2] N", "force", n=None) == (1.0, 2.0)
    with pytest.raises(ConfigError, match="must have 3 entries, got 2"):
        quantity_vector("[1, 2] mm", "length")
    with pytest.raises(ConfigError, match="is a pressure; expected a length"):
        quantity_vector("[1, 2, 3] kPa", "length")
    with pytest.raises(ConfigError, match="the entries must be numbers"):
        quantity_vector("[1, x, 3] mm", "length")
    with pytest.raises(ConfigError, match="must be finite"):
        quantity_vector("[1, nan, 3] mm", "length")
    with pytest.raises(ConfigError, match="needs a unit"):
        quantity_vector("[1, 2, 3]", "length")


def test_unit_tables():
    assert unit_factor("mm", "length") == 1e-3 and length_scale("in") == 0.0254
    assert LENGTH_UNITS["um"] == 1e-6 and UNITS["kPa"] == ("pressure", 1e3)
    assert all(next(iter(t.values())) == 1.0 for t in DIMENSIONS.values())      # the first unit is the SI one
    assert len(UNITS) == sum(len(t) for t in DIMENSIONS.values())               # no unit in two dimensions
    with pytest.raises(ConfigError, match=r"^unknown length unit 'ft'; accepted: m, mm, cm, um, in$"):
        length_scale("ft")
    with pytest.raises(ConfigError, match=r"unknown length unit 'kPa' \('kPa' is a pressure unit\)"):
        unit_factor("kPa", "length")
    with pytest.raises(ValueError, match="unknown dimension"):
        quantity("1 m", "time")
    assert format_quantity(0.0025, "mm", "length") == "2.5 mm"
    assert math.isclose(quantity(format_quantity(8.17e6, "MPa", "pressure"), "pressure"), 8.17e6, rel_tol=1e-15)


def test_geometry_reexports_the_same_table():
    from graspdef.geometry import LENGTH_UNITS as G
    from graspdef.geometry.io import length_scale as g_scale
    from graspdef.problem.config import FORCE_UNITS
    from graspdef.units import FORCE_UNITS as F

    assert G is LENGTH_UNITS and g_scale is length_scale and FORCE_UNITS is F
