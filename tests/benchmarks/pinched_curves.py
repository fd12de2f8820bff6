"""Shared check of the pinched-cylinder benchmark files against nligaStruct's Kirchhoff-Love curves
(tests/benchmarks/test_pinched_cylinder_symmetry.py, test_pinched_cylinder_neo_hookean.py: two files,
so that pytest-xdist's loadfile mode runs them on different workers)."""
from pathlib import Path

from graspdef.bench import run_nonlinear_benchmark

NL = Path(__file__).resolve().parents[2] / "benchmarks" / "nonlinear"


def at(records, quantity, level):
    return next(r["value"] for r in records if r["name"].endswith(f"{quantity} @ {level:g}"))


def along_kl_curve(name, n_levels, material, w_a_pmax, u_b_pmax):
    """Run a pinched-cylinder file and :func:`check_kl_curve` its records; returns them."""
    return check_kl_curve(run_nonlinear_benchmark(NL / name), n_levels, material, w_a_pmax, u_b_pmax)


def check_kl_curve(records, n_levels, material, w_a_pmax, u_b_pmax):
    """Every judged point of a pinched-cylinder file's records (nligaStruct's KL curve in
    ``material``) passes, -W_A at P_max within 0.5 % and U_B within 1 % of the given values, and
    the S4R context is reported, never judged; returns the records."""
    judged = [r for r in records if r["tolerance"] is not None]
    assert len(judged) == 2 * n_levels
    assert all("nligaStruct" in r["source"] and material in r["source"] for r in judged)
    bad = [(r["name"], r["value"], r["reference"], r["rel_error"]) for r in judged if not r["passed"]]
    assert not bad, bad
    w_a, u_b = at(judged, "-probe.A.x", 1.0), at(judged, "probe.B.y", 1.0)
    assert abs(w_a - w_a_pmax) <= 0.005 * w_a_pmax, w_a
    assert abs(u_b - u_b_pmax) <= 0.01 * u_b_pmax, u_b
    context = [r for r in records if r["tolerance"] is None]
    assert context and all("S4R" in r["source"] for r in context)
    return records
