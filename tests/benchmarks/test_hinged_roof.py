"""Snap-through of the shallow hinged cylindrical roof under a central point load
(benchmarks/nonlinear/hinged_roof.toml).

Reference: Sze, Liu & Lo (2004), "Popular benchmark problems for geometric nonlinear analysis of
shells", Finite Elem. Anal. Des. 40, 1551-1569, test 3.8 (after Sabir & Lock 1972): R = 2540,
straight hinged edges of length 508, half-angle 0.1 rad, curved edges free, E = 3102.75,
nu = 0.3, t = 12.7, P_max = 3000 (the total central load).  Sze's Abaqus S4R curve P/P_max
against the centre deflection -W_C as tabulated in MBDyn tests/plates/sze2004/sze38/
sze38_ref_a.dat (zanoni-mbdyn/MBDyn @425115db): limit point 0.7437 at -W_C = 10.88 (the
parabola through the tabulated maximum 0.7421 and its neighbours), minimum 0.173 near 19.9,
1.0835 at 29.37.

graspdef runs the 1/4 model (two symmetry edges) under displacement control of the centre, P from
the reaction.  Measured (P errors relative to max |P/P_max| = 1.0835, as the bench computes them):

  mesh (1/4)  control vertices  limit load        -W_C at it        worst curve point        time
  8 x 8       81                0.7327 (-1.5 %)   10.61 (-2.5 %)    +4.96 % (end)            ~10 s
  16 x 16     289               0.7393 (-0.6 %)   10.68 (-1.8 %)    +3.36 % (end)            14 s
  32 x 32     1,089             0.7410 (-0.4 %)   10.70 (-1.6 %)    +2.93 % (end)            33 s
  48 x 48     2,401             0.7413 (-0.3 %)   10.71 (-1.6 %)    +2.85 % (end)            43 s

The limit load converges onto Sze's from below; the largest differences are at the end of the
stiffening branch after the snap (-W_C = 29.4), where the Kirchhoff-Love roof is stiffer than the
shear-deformable S4R one and converges (1.6 % then 0.43 % per halving, 0.08 % from 32 to 48) to
about +2.8 %: a difference of shell theory (or of the reference's own mesh), not of ours.
3 % is the benchmark's tolerance.
"""
from pathlib import Path

import numpy as np
import pytest

from graspdef.bench import parabola_peak, run_nonlinear_benchmark

NL = Path(__file__).resolve().parents[2] / "benchmarks" / "nonlinear"


def _record(records, name):
    return next(r for r in records if r["name"].endswith(name))


def _check_snap(records):
    """The path goes through a limit point, falls to about a quarter of it and climbs again."""
    curve = [r for r in records if "reaction.C @" in r["name"]]
    p = np.array([r["value"] for r in curve])
    assert np.all(np.isfinite(p)) and len(p) == 36
    k = int(np.argmax(p[:20]))
    assert p[k] > 0.7 and p[k:25].min() < 0.25 * p[k] and p[-1] > 1.0


@pytest.mark.slow
def test_hinged_roof_matches_sze_within_the_benchmark_tolerance():
    """The benchmark file as it stands (32 x 32 on the 1/4 model): every compared point within 3 %.
    Measured: limit load -0.36 %, -W_C at it -1.63 %, worst curve point +2.93 % (P/P_max = 1.0835);
    33 s on the shared machine."""
    records = run_nonlinear_benchmark(NL / "hinged_roof.toml")
    _check_snap(records)
    bad = [(r["name"], r["value"], r["rel_error"]) for r in records if not r["passed"]]
    assert not bad, bad
    assert abs(_record(records, "limit load")["rel_error"]) <= 0.01


def test_hinged_roof_coarse_limit_point(tmp_path):
    """16 x 16 on the 1/4 model (289 control vertices; 5 s, 16 s on a cold numba cache).  The limit
    load and the deflection at it within the benchmark's 3 % (measured -0.60 % and -1.81 %), and the
    curve within the same 3 % up to the minimum after the snap (-W_C <= 20 of the 30 prescribed;
    measured worst -1.82 %, at the limit).  The end of the
    stiffening branch after it (+3.36 % at this mesh, +2.93 % at 32 x 32) is left to the slow test
    at the benchmark's own mesh: no tolerance is widened for the coarse mesh."""
    text = (NL / "hinged_roof.toml").read_text()
    assert "n_theta = 32" in text and "n_z = 32" in text
    spec = tmp_path / "hinged_roof_16.toml"
    spec.write_text(text.replace("n_theta = 32", "n_theta = 16").replace("n_z = 32", "n_z = 16"))
    records = run_nonlinear_benchmark(spec)
    _check_snap(records)
    limit = _record(records, "limit load")
    at = _record(records, "displacement at the limit load")
    assert abs(limit["rel_error"]) <= 0.03, limit
    assert abs(at["rel_error"]) <= 0.03, at
    upto_min = [r for r in records if "reaction.C @" in r["name"] and float(r["name"].split("@")[1]) <= 20.0 / 30.0]
    assert len(upto_min) >= 10
    worst = max(abs(r["rel_error"]) for r in upto_min)
    assert worst <= 0.03, worst


def test_hinged_roof_arc_length_finds_both_limit_points(tmp_path, roof_under_force):
    """The same 16 x 16 roof under the central force P = P_max (750 on the 1/4 model) by arc
    length: the path's critical points are the limit load (stability 0 -> 1) and the minimum
    after the snap (1 -> 0), where displacement control found them.  Measured: 0.73939 at
    -W_C = 10.70 (displacement control and the parabola: 0.7393 at 10.68; Sze 0.7437 at 10.88) and
    0.17170 at 19.47 (Sze's table: 0.1729 at 19.85).  15 s alone on the shared machine."""
    from graspdef.problem.config import load_problem
    from graspdef.solve.nonlinear import path_options, solve_nonlinear

    path = roof_under_force(tmp_path / "hinged_roof_arc.toml", 16,
                            '[solver]\ntype = "nonlinear"\nmethod = "arc_length"\nsteps = 40\n'
                            'max_steps = 400\nmax_probe_displacement = 30.0\n')
    spec = load_problem(path)
    sol = solve_nonlinear(spec.problem, path_options(spec.solver), backend=spec.backend)
    limits = [cp for cp in sol.critical_points if cp["kind"] == "limit point"]
    assert len(limits) >= 2, sol.critical_points
    top, bottom = limits[0], limits[1]
    assert (top["instability_before"], top["instability_after"]) == (0, 1)
    assert (bottom["instability_before"], bottom["instability_after"]) == (1, 0)
    assert abs(top["load_factor"] - 0.7437) <= 0.03 * 0.7437, top
    assert abs(-top["probes"]["C"][1] - 10.88) <= 0.03 * 10.88, top
    # the minimum against max |P/P_max| = 1.0835, as the benchmark compares the curve
    assert abs(bottom["load_factor"] - 0.1729) <= 0.03 * 1.0835, bottom


def test_parabola_peak_is_exact_on_a_parabola():
    x = np.array([10.0, 11.0, 12.5])
    y = 0.74 - 0.02 * (x - 10.9) ** 2
    assert np.allclose(parabola_peak(x, y), (10.9, 0.74))
