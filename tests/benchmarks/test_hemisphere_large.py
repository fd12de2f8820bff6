"""The hemisphere with an 18 degree hole under alternating radial point forces, large deformation
(Sze, Liu & Lo 2004, test 3.4; benchmarks/nonlinear/hemisphere_hole18_large.toml): the full model,
four forces P up to 400, the rigid-body modes removed by the mean-displacement/rotation rows.

Reference: nligaStruct's Kirchhoff-Love isogeometric shell (Du et al., SVK, 500 bicubic elements
on the quarter model; examples/nonlinearKlShellExamplesData.xlsx, sheet hemisphere), all 36
tabulated loads; Sze's Abaqus S4R curve is the file's context, reported only.
"""
from pathlib import Path

import pytest

from graspdef.bench import run_nonlinear_benchmark

NL = Path(__file__).resolve().parents[2] / "benchmarks" / "nonlinear"


@pytest.mark.slow
def test_hemisphere_follows_the_kirchhoff_love_iga_curve():
    """Every one of the 72 compared points (u_A outwards, -u_B inwards, 36 loads) within the file's
    2 % of the Kirchhoff-Love curve; measured on 32 rings (3,078 control vertices): worst -0.29 %
    (u_A at P_max, 4.0597 against 4.0714), and on 24 rings -0.70 %, so the difference halves under
    refinement.  The near-linear first load (P = 8) agrees within 0.15 % (the linear benchmark
    hemisphere_hole18.toml holds 0.0935 within 1 %).  About two minutes on one core."""
    records = run_nonlinear_benchmark(NL / "hemisphere_hole18_large.toml")
    judged = [r for r in records if r["tolerance"] is not None]
    assert len(judged) == 2 * 36 and all("nligaStruct" in r["source"] for r in judged)
    bad = [(r["name"], r["value"], r["reference"], r["rel_error"]) for r in judged if not r["passed"]]
    assert not bad, bad
    first = [r for r in judged if r["name"].endswith("@ 0.02")]
    assert len(first) == 2 and all(abs(r["rel_error"]) < 0.0015 for r in first), first
    context = [r for r in records if r["tolerance"] is None]
    assert len(context) == 2 * 20 and all("S4R" in r["source"] for r in context)
