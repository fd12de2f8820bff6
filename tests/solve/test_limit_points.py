"""Load control at a limit point of the load: the path snaps -- and says so -- or stops there.

The shallow hinged cylindrical roof (benchmarks/nonlinear/hinged_roof.toml, Sze, Liu & Lo 2004,
test 3.8, after Sabir & Lock 1972) under a central *force* P = P_max = 3000 (750 on the 1/4
model), 8 x 8 cells: its equilibrium path has a limit point at P/P_max = 0.7437 (Sze's Abaqus
S4R; this mesh by arc length, measured: 0.732830 at -W_C = 10.630, stability 0 -> 1, and the
minimum 0.17538 at 19.38, 1 -> 0), falls to 0.173 after it and climbs again, reaching P_max at
-W_C = 28.87 (Sze's table, linearly interpolated between 0.9643 at 28.66 and 1.0835 at 29.37).
A load-controlled path cannot follow the falling part: at 16 x 16 the code before this check
stepped from P/P_max 0.7185 (-W_C 9.08) straight to 0.9363 (-W_C 28.31), every point stable, no
critical point recorded.
"""
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from graspdef.errors import ProblemError
from graspdef.problem.config import load_problem
from graspdef.solve.nonlinear import PathOptions, fold_estimate, path_options, solve_nonlinear

NL = Path(__file__).resolve().parents[2] / "benchmarks" / "nonlinear"
ARC_LIMIT, ARC_W = 0.732830, 10.630      # the same 8 x 8 roof by arc length (measured, see above)


def _roof(write, tmp_path, **options):
    path = write(tmp_path / "hinged_roof_force.toml", 8, '[solver]\ntype = "nonlinear"\nmethod = "load"\nsteps = 10\n')
    path.write_text(path.read_text().split("[reference]")[0])
    spec = load_problem(path)
    return solve_nonlinear(spec.problem, replace(path_options(spec.solver), **options), backend=spec.backend,
                           allow_partial=True)


def test_load_control_snaps_at_the_limit_point_and_records_it(tmp_path, roof_under_force):
    """The path approaches the limit point in ever smaller steps (the predicted increment may grow
    by max_growth at most; each step aims 0.9 of the way to the limit load extrapolated from the
    tangents), brackets it to 2^-12 of the first step, and snaps at that load to the stiffening
    branch, recording a limit point passed by a jump; then it goes on to P_max.  Measured: limit
    0.732814 (-0.002 % from the arc length's 0.732830) at -W_C 10.587 (-0.4 %), the snap to -W_C
    26.9 at that load, and P_max at -W_C 28.6 (Sze 28.87), in 36 factorisations (166 when the
    bracket was found by halving alone).  ~5 s."""
    sol = _roof(roof_under_force, tmp_path)
    assert sol.completed, sol.stop_reason
    assert sol.n_factorisations <= 60, sol.n_factorisations
    assert len(sol.critical_points) == 1, sol.critical_points
    cp = sol.critical_points[0]
    assert cp["kind"] == "limit point (jumped)"
    assert abs(cp["load_factor"] - ARC_LIMIT) <= 1e-3 * ARC_LIMIT, cp
    assert abs(cp["load_factor"] - 0.7437) <= 0.03 * 0.7437
    assert abs(-cp["probes"]["C"][1] - ARC_W) <= 0.01 * ARC_W, cp        # the deflection at it
    assert (cp["instability_before"], cp["instability_after"]) == (0, 0)
    jump = cp["jump"]
    assert jump["to_load_factor"] == cp["load_factor"]                  # the snap at constant load
    landed = next(p for p in sol.path if p.load_factor == cp["load_factor"] and -p.probes["C"][1] > 19.85)
    assert landed.stable                                               # past the minimum (19.85): stiffening branch
    assert any(e["action"] == "jumped past a limit point" for e in sol.events)
    end = sol.at(1.0)
    assert end.stable and abs(-end.probes["C"][1] - 28.87) <= 0.03 * 28.87, end.probes


def test_limit_points_stop_ends_the_path_at_the_limit_load(tmp_path, roof_under_force):
    """``limit_points = "stop"``: the same path ends at the limit point, not completed, saying
    why; its last point is the limit load (to 0.1 %).  The roof's quarter model has two symmetry
    edges (Nitsche terms): the limit point is the shell's own, and the stop reason does not blame
    them (tests/solve/test_nitsche_coercivity.py has the opposite case)."""
    sol = _roof(roof_under_force, tmp_path, limit_points="stop")
    assert not sol.completed
    assert "limit point" in sol.stop_reason, sol.stop_reason
    assert "nitsche_gamma" not in sol.stop_reason, sol.stop_reason
    assert abs(sol.load_factor - ARC_LIMIT) <= 1e-3 * ARC_LIMIT, sol.load_factor
    assert not sol.critical_points


def test_fold_estimate_converges_at_order_three_halves():
    """The limit load extrapolated from the tangents |du/dlam| at two points approaching a
    quadratic fold: lam = u - u^3 has its limit at u = 1/sqrt(3), lam_c = 2 / (3 sqrt(3)).  With
    the points at distances 2d and d from it (in u), the estimate's error falls as d^3, i.e. as
    (lam_c - lam)^(3/2): 8x per halving of d (measured 8.5, 8.2, 8.1, 8.05), against d^2 for the
    nearer point itself; and it is None where the tangent does not grow."""
    uc, lc = 3 ** -0.5, 2 / (3 * 3 ** 0.5)
    lam, n = (lambda u: u - u ** 3), (lambda u: abs(1 / (1 - 3 * u * u)))
    err = []
    for d in 0.05 / 2.0 ** np.arange(5):
        u1, u2 = uc - 2 * d, uc - d
        err.append(fold_estimate(lam(u1), n(u1), lam(u2), n(u2)) - lc)
        assert abs(err[-1]) < 0.1 * (lc - lam(u2))
    rates = np.log2(np.abs(err[:-1]) / np.abs(err[1:]))
    assert np.all((rates > 2.9) & (rates < 3.2)), rates
    assert fold_estimate(0.1, 2.0, 0.2, 1.5) is None and fold_estimate(0.1, 2.0, 0.1, 3.0) is None


@pytest.mark.parametrize("kw, msg", [
    (dict(jump_ratio=-0.5), "jump_ratio must be a non-negative number"),
    (dict(jump_ratio="big"), "jump_ratio must be a non-negative number"),
    (dict(jump_ratio=float("nan")), "jump_ratio must be a non-negative number"),
    (dict(limit_points="fly"), "limit_points must be one of jump, stop"),
])
def test_bad_limit_point_options_are_one_clear_line(kw, msg):
    with pytest.raises(ProblemError, match=msg) as err:
        PathOptions(**kw)
    assert "\n" not in str(err.value)


@pytest.mark.slow
def test_pinched_cylinder_spurious_limit_point_stops_the_path_and_names_the_nitsche_penalty():
    """The 48 x 48 1/8 pinched cylinder (benchmarks/nonlinear/pinched_cylinder_large.toml, load
    point driven inwards), whose load point sits on two symmetry edges held by Nitsche terms.

    With the Nitsche penalty at its default (nitsche_gamma = 20) the load-controlled path meets a
    limit point at lambda = 0.961337 that the Nitsche term makes: along the tangent's softest mode
    there it takes 6.35 of the other terms' 6.37 curvature (graspdef.solve.nonlinear.PathSolver.
    soft_terms).  Until 2026-11-27 the path jumped past it and recorded a "limit point (jumped)" as
    if it were the shell's; now it stops at the last stable point and names the term and the
    setting.  With the file's penalty (1000; 100 does as well) there is no limit point: the path
    runs to lambda = 1 with every point stable.  The spurious point lies inside the bracket
    [0.9584, 0.9677] in which an arc-length path at the default penalty (steps = 200) loses
    stability.  ~3 minutes."""
    text = (NL / "pinched_cylinder_large.toml").read_text()
    assert "n_theta = 48" in text and "n_z = 48" in text and "nitsche_gamma = 1000.0" in text
    spec = load_problem(NL / "pinched_cylinder_large.toml")
    opts = path_options(spec.solver)
    # targets at Sze's 23 levels (the file's context)
    opts = replace(opts, targets=tuple(float(v) for v in spec.reference["context"]["load_factors"] if v < 1.0))
    sol = solve_nonlinear(spec.problem, opts, backend=spec.backend, allow_partial=True)
    assert sol.completed, sol.stop_reason
    assert sol.critical_points == []
    assert all(p.instability == 0 for p in sol.path[1:])

    spec.problem.nitsche_gamma = 20.0
    weak = solve_nonlinear(spec.problem, opts, backend=spec.backend, allow_partial=True)
    assert not weak.completed and weak.critical_points == []
    assert "the limit point is spurious" in weak.stop_reason and "nitsche_gamma (now 20)" in weak.stop_reason
    assert 0.9584 <= weak.load_factor <= 0.9677, weak.load_factor
    assert weak.path[-1].instability == 0


@pytest.mark.parametrize("line, msg", [
    ('jump_ratio = "big"', "jump_ratio"),
    ("jump_ratio = -1.0", "jump_ratio must be a non-negative number"),
    ('limit_points = "fly"', "limit_points must be one of jump, stop"),
    ('bifurcation = "maybe"', "bifurcation must be one of report, locate, switch"),
])
def test_limit_point_options_in_a_problem_file(tmp_path, line, msg):
    """The [solver] keys reach the path options from a problem file (``bifurcation`` too, which
    the README documented but the reader refused as an unknown key); a bad value is one line."""
    text = (NL / "hinged_roof.toml").read_text()
    solver = '[solver]\ntype = "nonlinear"\nmethod = "load"\nsteps = 60\nmax_steps = 2000\n'
    assert solver in text
    good = tmp_path / "good.toml"
    good.write_text(text.replace(solver, solver + 'jump_ratio = 0.2\nlimit_points = "stop"\nbifurcation = "locate"\n'))
    opts = path_options(load_problem(good).solver)
    assert (opts.jump_ratio, opts.limit_points, opts.bifurcation) == (0.2, "stop", "locate")
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace(solver, solver + line + "\n"))
    with pytest.raises(ProblemError, match=msg) as err:
        path_options(load_problem(bad).solver)
    assert "\n" not in str(err.value)
