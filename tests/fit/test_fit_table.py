"""The measured table (graspdef.fit.table): units stated in the header are converted to SI at
I/O, and every malformed table is refused with one line naming the file and what is wrong."""
from __future__ import annotations

import numpy as np
import pytest

from graspdef.errors import ConfigError
from graspdef.fit import read_table


def _csv(tmp_path, text: str):
    p = tmp_path / "t.csv"
    p.write_text(text)
    return p


def test_units_are_converted_to_si(tmp_path):
    """kN -> N, mm -> m, um -> m; comment lines skipped; columns in any order; point kept."""
    t = read_table(_csv(tmp_path, "# a comment\ndisplacement_mm,force_kN,point,sigma_um\n"
                                  "2.5,0.01,finger,50\n6.0,0.0165,max,50\n"))
    assert np.allclose(t.force, [10.0, 16.5], rtol=1e-15)
    assert np.allclose(t.displacement, [2.5e-3, 6.0e-3], rtol=1e-15)
    assert np.allclose(t.sigma, [50e-6, 50e-6], rtol=1e-15)
    assert t.point == ("finger", "max")
    assert t.units == {"displacement": "mm", "force": "kN", "sigma": "um"}


def test_point_defaults_to_finger_and_sigma_to_none(tmp_path):
    """Without a point column every row measures 'finger'; without sigma the weights are equal."""
    t = read_table(_csv(tmp_path, "force_N,displacement_m\n1,0.001\n2,0.002\n"))
    assert t.point == ("finger", "finger") and t.sigma is None
    assert np.allclose(t.displacement, [1e-3, 2e-3])


@pytest.mark.parametrize("text, phrase", [
    ("force,displacement\n1,2\n", "states no unit"),
    ("force_N,displacement\n1,2\n", "column 'displacement' states no unit"),
    ("force_N,displacement_furlong\n1,2\n", "unknown length unit 'furlong'"),
    ("force_mm,displacement_mm\n1,2\n", "'mm' is a length unit"),
    ("force_N,disp_mm\n1,2\n", "unknown column 'disp_mm'"),
    ("force_N,point\n1,max\n", "no displacement column"),
    ("force_N,displacement_mm\n", "no data rows"),
    ("", "empty"),
    ("force_N,displacement_mm\n0,2\n", "force must be positive"),
    ("force_N,displacement_mm\n-1,2\n", "force must be positive"),
    ("force_N,displacement_mm\n1,abc\n", "'abc' is not a number"),
    ("force_N,displacement_mm\n1,nan\n", "must be finite"),
    ("force_N,displacement_mm\n1,2,3\n", "3 values for 2 columns"),
    ("force_N,displacement_mm,sigma_mm\n1,2,0\n", "sigma (a standard deviation) must be positive"),
    ("force_N,displacement_mm,force_kN\n1,2,3\n", "appears 2 times"),
])
def test_bad_tables_are_one_line(tmp_path, text, phrase):
    """Each malformed table raises a ConfigError whose single line names the file and the problem."""
    with pytest.raises(ConfigError) as e:
        read_table(_csv(tmp_path, text))
    msg = str(e.value)
    assert phrase in msg and "\n" not in msg and "t.csv" in msg


def test_missing_file(tmp_path):
    """A table that does not exist is one line naming it."""
    with pytest.raises(ConfigError, match="data table not found: .*nope.csv"):
        read_table(tmp_path / "nope.csv")
