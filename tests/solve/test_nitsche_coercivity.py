"""A Nitsche edge term that loses its coercivity at finite strain is named where a path stalls.

The Nitsche rotation term of a clamped / symmetry edge, -m_nn theta + gamma D / (2 h) theta^2
(graspdef.problem.nitsche), is bounded below only while its penalty dominates the edge moment's
tangent; D is the small-strain bending stiffness, and a hyperelastic law stiffens at large strain.
The neo-Hookean pinched cylinder (benchmarks/nonlinear/pinched_cylinder_large_neo_hookean.toml, the
load point on two symmetry edges) shows it: with gamma = 20 on 48 x 48 the displacement-controlled
path stalls at -W_A = 20.3, where the tangent's softest mode has curvature +1.57 from the shell and
-1.57 from the Nitsche term, and descending the energy from there finds it unbounded below (the
Nitsche energy -9e10 after 200 steps); with gamma = 1000 the path runs to the end and follows the
Kirchhoff-Love reference (slow test).  Here the same model on 12 x 12 with gamma = 12 is stable at
rest and loses its stability on such a mode at a small load; the path stops at its last stable
point and says which term and which setting (before, it went on along the artefact's branch).  With
gamma = 2 (8 x 8) or 8 (12 x 12) the state at zero load itself is unstable, and is refused, naming
the term.  With the default
gamma = 20 the same path runs past those loads, every point stable -- the modes were not the shell's.
A physical limit point is not blamed on the edges (tests/solve/test_limit_points.py: the hinged roof).
"""
from dataclasses import replace
from pathlib import Path

import pytest

from graspdef.errors import ProblemError
from graspdef.geometry.primitives import rectangle
from graspdef.problem.config import load_problem
from graspdef.problem.problem import Problem
from graspdef.problem.supports import EdgeSupport
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell
from graspdef.solve.nonlinear import PathStopped, path_options, solve_nonlinear

FILE = Path(__file__).resolve().parents[2] / "benchmarks" / "nonlinear" / "pinched_cylinder_large_neo_hookean.toml"


def _write(tmp_path, gamma, n=12):
    """The benchmark file on n x n cells with nitsche_gamma = gamma (no reference), its path."""
    text = FILE.read_text().split("[reference]")[0]
    for a, b in (("n_theta = 48", f"n_theta = {n}"), ("n_z = 48", f"n_z = {n}"), ("steps = 180", "steps = 20")):
        assert a in text, a
        text = text.replace(a, b)
    text = text.replace("nitsche_gamma = 1000.0", f"nitsche_gamma = {gamma!r}")
    assert f"nitsche_gamma = {gamma!r}" in text
    f = tmp_path / f"pc_nh{n}_{gamma}.toml"
    f.write_text(text)
    return f


def _spec(tmp_path, gamma, n=12):
    spec = load_problem(_write(tmp_path, gamma, n))
    assert spec.problem.nitsche_gamma == gamma
    return spec


def _path(tmp_path, gamma, max_load=0.3, n=12, method="load"):
    spec = _spec(tmp_path, gamma, n)
    return solve_nonlinear(spec.problem, replace(path_options(spec.solver), max_load=max_load, method=method),
                           backend=spec.backend, allow_partial=True)


@pytest.mark.parametrize("method", ["load", "arc_length"])
def test_a_spurious_loss_of_stability_stops_the_path_and_names_the_term_and_the_setting(tmp_path, method):
    """gamma = 12 on 12 x 12 (steps of 0.015): stable at rest, then one negative eigenvalue at the
    first step, whose mode has curvature -2.75 from the Nitsche term against +2.69 from the shell
    (2.71 at rest, measured): the path stops at its last stable point, naming the term and
    ``nitsche_gamma (now 12)``.  (With steps of 0.005 the same path instead stalls at a fold at
    0.0029 on such a mode, named the same way.)  By arc length the same (measured at 0.0176)."""
    sol = _path(tmp_path, 12.0, method=method)
    assert not sol.completed and sol.load_factor < 0.1
    assert all(p.stable for p in sol.path), [p.instability for p in sol.path]
    assert "spurious mode, not the shell's" in sol.stop_reason, sol.stop_reason
    assert "Nitsche rotation term" in sol.stop_reason and "nitsche_gamma (now 12)" in sol.stop_reason, sol.stop_reason
    assert "lost stability" in sol.stop_reason, sol.stop_reason
    assert not sol.critical_points


@pytest.mark.parametrize("gamma, n, how", [(2.0, 8, "made soft by"), (8.0, 12, "possibly")])
def test_an_unstable_state_at_rest_is_refused_with_the_term_and_the_setting(tmp_path, gamma, n, how):
    """gamma = 2 on 8 x 8: the linear Nitsche matrix is not coercive (7 negative eigenvalues at
    rest), and the softest mode is the Nitsche term's.  gamma = 8 on 12 x 12: one negative
    eigenvalue at rest, but the softest mode (the eigenvalue closest to zero) is the shell's, so the
    term is named as the possible cause.  (Before, both paths ran, unstable from their start.)"""
    spec = _spec(tmp_path, gamma, n=n)
    with pytest.raises(PathStopped, match=rf"the state at zero load is unstable \(\d+ negative eigenvalue\(s\) .*"
                                          rf"{how} the Nitsche rotation term.*nitsche_gamma \(now {gamma:g}\)") as exc:
        solve_nonlinear(spec.problem, replace(path_options(spec.solver), max_load=0.1), backend=spec.backend)
    assert "\n" not in str(exc.value)


def test_with_the_default_penalty_the_same_path_passes_those_loads(tmp_path):
    """gamma = 20 on 12 x 12: every point to 0.3 stable, no critical point."""
    sol = _path(tmp_path, 20.0)
    assert sol.completed, sol.stop_reason
    assert all(p.stable for p in sol.path), [p.instability for p in sol.path]
    assert not sol.critical_points


@pytest.mark.parametrize("gamma", [-1.0, 0.0, float("nan"), True, "20"])
def test_a_bad_penalty_is_one_clear_line(gamma):
    m = rectangle(1.0, 1.0, 2, 2)
    sh = Shell(m.vertices, m.faces, LinearElastic(1e5, 0.3), 0.01)
    with pytest.raises(ProblemError, match=r"nitsche_gamma \(the Nitsche rotation penalty, dimensionless\) must be a "
                                           r"positive number") as exc:
        Problem(sh, [], [EdgeSupport("clamped", lambda x: x[:, 0] < 1e-9)], nitsche_gamma=gamma)
    assert "\n" not in str(exc.value)


def test_graspdef_solve_refuses_an_unstable_zero_load_state_in_one_line(tmp_path, capsys):
    """The command line with the gamma = 8 file: exit 2, one line naming the setting, no run folder
    (it used to crash with an IndexError on the empty path)."""
    from graspdef.cli import main

    f = _write(tmp_path, 8.0, n=12)
    code = main(["-q", "solve", str(f), "--out", str(tmp_path / "run")])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert err.count("\n") == 0 and "state at zero load is unstable" in err and "nitsche_gamma (now 8)" in err, err
    assert not (tmp_path / "run").exists()
