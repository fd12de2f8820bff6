"""The pinched cylinder in an incompressible neo-Hookean material at large deformation
(benchmarks/nonlinear/pinched_cylinder_large_neo_hookean.toml: Sze, Liu & Lo 2004 test 3.6's geometry
and supports, mu = E / (2 (1 + nu)) of the SVK file, 3 Gauss points through the thickness; 1/8 model,
48 x 48, displacement control of the load point) against nligaStruct's Kirchhoff-Love isogeometric
curve in the same material (Du et al., github.com/duxxhf/nligaStruct @c038754,
examples/nonlinearKlShellExamplesData.xlsx, sheet pinchedCylinder: 2,860 bicubic elements, 96
points), with Abaqus S4R's curve from the same sheet as context.

The file sets the Nitsche penalty of its symmetry edges to nitsche_gamma = 1000: the load point lies
on two of them, and with 20, 100 and 300 the path stalls (at load factors 0.2394, 0.806 and 0.9575)
on a spurious edge mode that the stop reason names (tests/solve/test_nitsche_coercivity.py).  What
1000 costs in accuracy, measured on the SVK file at the same mesh: -W_A moves by at most 0.22 %
(median 0.09 %) along the whole path, -0.20 % at P_max.
"""
from pathlib import Path

import pytest

from graspdef.bench import run_nonlinear_benchmark

NL = Path(__file__).resolve().parents[2] / "benchmarks" / "nonlinear"


def _at(records, quantity, level):
    return next(r["value"] for r in records if r["name"].endswith(f"{quantity} @ {level:g}"))


@pytest.mark.slow
def test_neo_hookean_pinched_cylinder_follows_the_kirchhoff_love_curve():
    """Every one of the 96 tabulated points within the file's 2 % (measured worst: -W_A +1.01 % at
    P/P_max = 0.2089, in the snap), and at P_max -W_A = 80.4578 within 0.5 % (measured +0.08 %),
    U_B = 31.6403 within 1 % (+0.47 %).  The S4R context is reported, never judged (measured within
    1.34 %).  About three minutes on one core."""
    records = run_nonlinear_benchmark(NL / "pinched_cylinder_large_neo_hookean.toml")
    judged = [r for r in records if r["tolerance"] is not None]
    assert len(judged) == 2 * 96
    assert all("nligaStruct" in r["source"] and "neo-Hookean" in r["source"] for r in judged)
    bad = [(r["name"], r["value"], r["reference"], r["rel_error"]) for r in judged if not r["passed"]]
    assert not bad, bad
    w_a, u_b = _at(judged, "-probe.A.x", 1.0), _at(judged, "probe.B.y", 1.0)
    assert abs(w_a - 80.4578) <= 0.005 * 80.4578, w_a
    assert abs(u_b - 31.6403) <= 0.01 * 31.6403, u_b
    context = [r for r in records if r["tolerance"] is None]
    assert context and all("S4R" in r["source"] for r in context)
