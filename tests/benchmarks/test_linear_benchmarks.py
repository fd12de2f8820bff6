"""The linear 'shell obstacle course': every benchmarks/*.toml with a tolerance is solved and
compared with its published or analytic reference (value, source and load convention are in
the file's [reference] table and in ../shared/BENCHMARKS.md):

* square plates, simply supported and clamped, uniform and central point load -- Timoshenko &
  Woinowsky-Krieger coefficients 0.00406235, 0.0116008, 0.00126532, 0.00560 (1 %, <= 2,000
  control vertices); the simply supported uniform case is the Tian & Jia plate (0.4436);
* pinched cylinder with rigid diaphragms -- 1.8248e-5 (MacNeal & Harder 1985; 2 %);
* pinched hemisphere, closed 0.0924 (Belytschko et al. 1985) and with an 18 degree hole 0.0935
  (KL value; 1 %);
* closed sphere under internal pressure -- membrane solution p R^2 (1 - nu) / (2 E t) (0.5 %);
* sphere squeezed by two point forces -- Reissner (1946), R/t = 100 (3 %).
"""
from pathlib import Path

import pytest

from graspdef.bench import run_benchmark

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"
FILES = sorted(p for p in BENCH.glob("*.toml") if "tolerance" in p.read_text())


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_benchmark_within_tolerance(path):
    rec = run_benchmark(path)
    assert abs(rec["rel_error"]) <= rec["tolerance"], (
        f"{rec['name']}: {rec['value']:.6g} vs reference {rec['reference']:.6g} "
        f"({100 * rec['rel_error']:+.2f} %, tolerance {100 * rec['tolerance']:.1f} %)")


def test_plates_use_at_most_2000_control_vertices():
    """The acceptance criterion for the plates is 1 % at <= 2,000 control vertices."""
    from graspdef.problem.config import load_problem

    for p in FILES:
        if p.stem.startswith("plate_"):
            assert load_problem(p).problem.shell.mesh.n_real <= 2000


def test_benchmark_set_is_complete():
    names = {p.stem for p in FILES}
    assert {"plate_ss_uniform", "plate_ss_point", "plate_clamped_uniform", "plate_clamped_point",
            "pinched_cylinder", "hemisphere_closed", "hemisphere_hole18", "sphere_pressure",
            "sphere_pinched"} <= names
