"""Stability along paths (issue 17, item 3): a bifurcation point located from the tangent's
inertia, and the branch switch along the critical eigenvector.

Euler's column as a shell: a cantilever strip (L = 10, b = 1, t = 0.1, E = 1.2e6, nu = 0, so
EI = 100 and the plate is a beam exactly; 20 x 2 cells) clamped at the root and compressed by a dead
end force.  Critical load P_cr = pi^2 EI / (4 L^2) = 2.4674 (Euler 1744; Timoshenko & Gere, Theory
of Elastic Stability, 2nd ed., 2.1); the axial strain there is 2e-5, so the inextensible elastica
describes the secondary branch: omega L = K(k), tip deflection delta = 2 k / omega, omega^2 = P / EI,
k = sin(alpha / 2) with alpha the tip rotation (Timoshenko & Gere 2.7).  The load is P_cr times the
load factor.
"""
import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import ellipk

from graspdef.errors import ProblemError
from graspdef.geometry import rectangle
from graspdef.problem.loads import EdgeLoad
from graspdef.problem.problem import Problem
from graspdef.problem.supports import EdgeSupport
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell
from graspdef.solve.nonlinear import PathOptions, solve_nonlinear

L, B, T, E = 10.0, 1.0, 0.1, 1.2e6
EI = E * B * T ** 3 / 12
P_CR = np.pi ** 2 * EI / (4 * L ** 2)


def strip():
    m = rectangle(L, B, 20, 2, center=(L / 2, B / 2))
    sh = Shell(m.vertices, m.faces, LinearElastic(E, 0.0), T)
    pr = Problem(sh, [EdgeLoad(lambda p: np.abs(p[:, 0] - L) < 1e-9, (-P_CR / B, 0.0, 0.0))],
                 [EdgeSupport("clamped", lambda p: np.abs(p[:, 0]) < 1e-9, name="root")])
    pr.probes["tip"] = pr.locate((L, B / 2, 0.0))
    return pr


def elastica_deflection(load_factor: float) -> float:
    om = np.sqrt(load_factor * P_CR / EI)
    k = brentq(lambda k: ellipk(k * k) - om * L, 1e-12, 1 - 1e-12)
    return 2 * k / om


def test_euler_load_located_from_the_inertia():
    """The straight strip loses stability at P_cr: one negative eigenvalue appears, the load does
    not turn (a bifurcation point), and bisection ("locate") narrows the bracket to within 1e-4 of
    Euler's load (measured: bracket [0.99996, 1.00005])."""
    sol = solve_nonlinear(strip(), PathOptions(max_load=1.2, steps=10, bifurcation="locate"))
    assert sol.completed
    (cp,) = sol.critical_points
    assert cp["kind"] == "bifurcation point"
    assert (cp["instability_before"], cp["instability_after"]) == (0, 1)
    lo, hi = cp["bracket"]
    assert lo <= 1.0 <= hi and hi - lo < 1e-4
    assert not cp["branch_switched"]
    # the fundamental path stays straight past it (the perfect strip): no lateral deflection
    assert abs(sol.path[-1].probes["tip"][2]) < 1e-9


def test_branch_switch_follows_the_elastica():
    """With "switch" the path leaves the fundamental branch along the critical mode and follows
    the buckled strip: its tip deflection at 1.1 and 1.2 P_cr within 0.5 % of the elastica's
    (5.139 and 6.488; measured 0.02 % and 0.01 %), the buckled branch is stable, and the critical
    point is reported as switched."""
    sol = solve_nonlinear(strip(), PathOptions(max_load=1.2, steps=10, bifurcation="switch", targets=(1.1,)))
    assert sol.completed
    (cp,) = sol.critical_points
    assert cp["kind"] == "bifurcation point" and cp["branch_switched"]
    for lam in (1.1, 1.2):
        w = abs(float(sol.at(lam).probes["tip"][2]))
        assert abs(w / elastica_deflection(lam) - 1) < 5e-3, (lam, w, elastica_deflection(lam))
    after = [p for p in sol.path if p.kind in ("branch", "step", "target") and p.load_factor > 1.0 + 1e-3]
    assert after and all(p.instability == 0 for p in after)


def test_bifurcation_option_is_checked():
    with pytest.raises(ProblemError, match="bifurcation must be one of"):
        PathOptions(bifurcation="jump")



def _step_bracket():
    """The load step across Euler's load on the path to 1.2 in 10 initial steps (the steps grow:
    0.12, 0.36, 0.84, then 1.2): its two path points' load factors."""
    sol = solve_nonlinear(strip(), PathOptions(max_load=1.2, steps=10))
    lam = [p.load_factor for p in sol.path]
    k = next(i for i, p in enumerate(sol.path) if p.instability == 1)
    return lam[k - 1], lam[k]


def _failing_at(monkeypatch, loads):
    """Newton made to fail at the given load factors (to 1e-12 relative): a nearly singular tangent
    at a critical load does this (a perfect sphere under external pressure at p_cl loses stability
    in 2l + 1 modes at once)."""
    import graspdef.solve.nonlinear as nl

    newton = nl.PathSolver.newton

    def failing(self, u0, lam, *args, **kwargs):
        if any(abs(lam - x) <= 1e-12 * abs(x) for x in loads):
            raise nl._Failed(f"injected failure at load factor {lam:.6g}")
        return newton(self, u0, lam, *args, **kwargs)

    monkeypatch.setattr(nl.PathSolver, "newton", failing)


def test_locate_steps_aside_where_the_midpoint_fails(monkeypatch):
    """Where Newton fails at the first bisection point of Euler's bracket [a, b] (its midpoint),
    the point a quarter of the way in from the stable end is taken instead, and the bracket still
    narrows to within 3e-4 of P_cr at both ends (measured [0.999854, 0.999985], against [0.999941,
    1.000029] without the failure: each point's inertia comes from a tangent factorised within
    inertia_rtol = 1e-4 of equilibrium, which blurs the change of sign at that level; before, the
    bisection stopped at the first failure and left [a, b] = [0.84, 1.2], without a word)."""
    a, b = _step_bracket()
    _failing_at(monkeypatch, [0.5 * (a + b)])
    sol = solve_nonlinear(strip(), PathOptions(max_load=1.2, steps=10, bifurcation="locate"))
    (cp,) = sol.critical_points
    lo, hi = cp["bracket"]
    assert 1.0 - 3e-4 < lo < hi < 1.0 + 3e-4, (lo, hi)
    assert any(abs(p.load_factor - (0.75 * a + 0.25 * b)) < 1e-12 and p.kind == "refine" for p in sol.path)
    assert not any("bracket" in e.get("action", "") for e in sol.events)


def test_locate_reports_a_bracket_it_cannot_narrow(monkeypatch):
    """Where Newton fails at every trial point of a bisection step (the midpoint and the quarter
    points), the bracket stays [a, b] and the path's events say so."""
    a, b = _step_bracket()
    _failing_at(monkeypatch, [0.5 * (a + b), 0.75 * a + 0.25 * b, 0.25 * a + 0.75 * b])
    sol = solve_nonlinear(strip(), PathOptions(max_load=1.2, steps=10, bifurcation="locate"))
    (cp,) = sol.critical_points
    assert cp["bracket"] == pytest.approx([a, b], rel=1e-12)
    (ev,) = [e for e in sol.events if "bracket" in e.get("action", "")]
    assert (ev["from_load_factor"], ev["to_load_factor"]) == pytest.approx((a, b), rel=1e-12)
    assert "injected failure" in ev["reason"]


def test_arc_length_bracket_steps_aside_where_the_middle_fails(monkeypatch):
    """The same for the arc-length path (to 2 P_cr in 20 initial steps; its bracket across Euler's
    load is bisected in arc length): where the corrector fails at the first bisection point, a
    quarter of the way in is tried, and the bracket still narrows to within 3e-4 of P_cr (measured
    [0.99994, 1.00014] without the failure); where it fails at all three, the path's events say so."""
    import graspdef.solve.nonlinear as nl

    opts = PathOptions(method="arc_length", max_load=2.0, steps=20)
    bracket, arc_step = nl.PathSolver._bracket, nl.PathSolver._arc_step
    for fails in (1, 3):
        calls = []

        def in_bracket(self, *args, **kwargs):
            calls.append(0)                     # from now on, count the corrector's attempts
            return bracket(self, *args, **kwargs)

        def failing(self, *args, **kwargs):
            if calls:
                calls.append(1)
                if len(calls) <= 1 + fails:
                    raise nl._Failed("injected failure")
            return arc_step(self, *args, **kwargs)

        monkeypatch.setattr(nl.PathSolver, "_bracket", in_bracket)
        monkeypatch.setattr(nl.PathSolver, "_arc_step", failing)
        sol = solve_nonlinear(strip(), opts)
        (cp,) = sol.critical_points
        lo, hi = cp["bracket"]
        events = [e for e in sol.events if "bracket" in e.get("action", "")]
        if fails == 1:
            assert 1.0 - 3e-4 < lo < hi < 1.0 + 3e-4, (lo, hi)
            assert not events
        else:
            assert hi - lo > 0.5 and lo < 1.0 < hi           # the step's own ends, [0.7, 1.5]
            (ev,) = events
            assert "injected failure" in ev["reason"]


def test_arc_length_path_narrows_a_change_in_its_last_step():
    """An arc-length path whose stability changes in the step that lands on its end (to 1.2 P_cr in
    10 steps: the last from 0.84 to 1.2) narrows that change down like any other (before: it landed
    and returned, the bracket [0.84, 1.2] and the spurious-mode check skipped; measured now
    [0.99994, 1.00003])."""
    sol = solve_nonlinear(strip(), PathOptions(method="arc_length", max_load=1.2, steps=10))
    assert sol.completed and sol.path[-1].load_factor == pytest.approx(1.2)
    (cp,) = sol.critical_points
    lo, hi = cp["bracket"]
    assert 1.0 - 3e-4 < lo < hi < 1.0 + 3e-4, (lo, hi)
    lam = sol.load_factors()
    assert np.all(np.diff(lam) > 0)                  # the refined points lie in path order


@pytest.mark.parametrize("targets", [(0.95, 1.05, 1.3), (0.95,), (1.05,)])
def test_arc_length_path_narrows_a_change_between_requested_levels(targets):
    """Requested load levels landed on inside the arc-length step that crosses Euler's load (to
    2 P_cr in 20 steps: the step from 0.70 to 1.50) no longer hide the change: it is narrowed down
    between the path point and the level (or the step's end) that enclose it (before: with levels
    0.95, 1.05 and 1.3 the bracket stayed [0.95, 1.05] and no point was refined; measured now
    [0.99998, 1.0], [0.99994, 1.00007] and [0.99992, 1.00001])."""
    sol = solve_nonlinear(strip(), PathOptions(method="arc_length", max_load=2.0, steps=20, targets=targets))
    assert sol.completed
    (cp,) = sol.critical_points
    lo, hi = cp["bracket"]
    assert 1.0 - 3e-4 < lo < hi < 1.0 + 3e-4, (lo, hi)
    assert np.all(np.diff(sol.load_factors()) > 0)
    for lam in targets:
        assert sol.at(lam).kind == "target"


def test_switch_is_refused_for_arc_length_paths():
    """An arc-length path narrows changes of stability down but stays on its branch: asking it to
    switch is one clear error, not an option silently not acted on (before 2026-11-27 the path
    ran to the end on the straight strip, tip deflection 0, ``branch_switched`` False)."""
    with pytest.raises(ProblemError, match="bifurcation 'switch' is made by load-controlled paths"):
        PathOptions(method="arc_length", bifurcation="switch")


@pytest.mark.parametrize("option,value", [("max_step", 0.05), ("jump_ratio", 0.1), ("predictor", "linear"),
                                          ("limit_points", "stop")])
def test_load_control_options_are_refused_for_arc_length_paths(option, value):
    """The options that only a load-controlled path reads are one clear error on an arc-length
    path, not silently ignored (before 2026-11-27 every one of them was accepted and had no effect):
    set to other than the default in Python, and given at all in a problem file's [solver] table
    (even at the default value); the same values on a load-controlled path are accepted."""
    from graspdef.solve.nonlinear import path_options

    with pytest.raises(ProblemError, match=f"^{option} is an option of load-controlled paths"):
        PathOptions(method="arc_length", **{option: value})
    default = PathOptions.__dataclass_fields__[option].default
    assert PathOptions(method="arc_length", **{option: default}).method == "arc_length"
    with pytest.raises(ProblemError, match=f"^{option} is an option of load-controlled paths"):
        path_options({"type": "nonlinear", "method": "arc_length", option: default})
    assert getattr(path_options({"method": "load", option: value}), option) == value


def test_graspdef_solve_names_every_refused_option(tmp_path, capsys):
    """graspdef solve on an arc-length problem file with two load-control options: exit 2, no run
    folder, and one line naming both."""
    from graspdef.cli import main
    from graspdef.testing import plate_problem

    path = tmp_path / "plate.toml"
    text = plate_problem(n=4)
    assert "[solver]" not in text
    path.write_text(text + '\n[solver]\ntype = "nonlinear"\nmethod = "arc_length"\nmax_step = 0.1\n'
                    'predictor = "linear"\n')
    r = main(["-q", "solve", str(path), "--out", str(tmp_path / "out")])
    assert r == 2
    assert not (tmp_path / "out" / "result.json").exists()
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert len(err) == 1 and "max_step, predictor are options of load-controlled paths" in err[0], err
