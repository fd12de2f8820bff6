"""A Nitsche edge term that loses its coercivity at finite strain is named where a path stalls.

The Nitsche rotation term of a clamped / symmetry edge, -m_nn theta + gamma D / (2 h) theta^2
(graspdef.problem.nitsche), is bounded below only while its penalty dominates the edge moment's
tangent; D is the small-strain bending stiffness, and a hyperelastic law stiffens at large strain.
The neo-Hookean pinched cylinder (benchmarks/nonlinear/pinched_cylinder_large_neo_hookean.toml, the
load point on two symmetry edges) shows it: with gamma = 20 on 48 x 48 the displacement-controlled
path stalls at -W_A = 20.3, where the tangent's softest mode has curvature +1.57 from the shell and
-1.57 from the Nitsche term, and descending the energy from there finds it unbounded below (the
Nitsche energy -9e10 after 200 steps); with gamma = 1000 the path runs to the end and follows the
Kirchhoff-Love reference (slow test).  Here the same model on 8 x 8 with gamma = 2 stalls almost at
once on such a mode, and the stop reason says which term and which setting; with the default
gamma = 20 the same path runs past that load, every point stable -- the stall was not the shell's.
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
from graspdef.solve.nonlinear import path_options, solve_nonlinear

FILE = Path(__file__).resolve().parents[2] / "benchmarks" / "nonlinear" / "pinched_cylinder_large_neo_hookean.toml"


def _path(tmp_path, gamma, max_load=0.05):
    text = FILE.read_text().split("[reference]")[0]
    for a, b in (("n_theta = 48", "n_theta = 8"), ("n_z = 48", "n_z = 8"), ("steps = 180", "steps = 20")):
        assert a in text, a
        text = text.replace(a, b)
    text = text.replace("nitsche_gamma = 1000.0", f"nitsche_gamma = {gamma!r}")
    assert f"nitsche_gamma = {gamma!r}" in text
    f = tmp_path / f"pc_nh8_{gamma}.toml"
    f.write_text(text)
    spec = load_problem(f)
    assert spec.problem.nitsche_gamma == gamma
    return solve_nonlinear(spec.problem, replace(path_options(spec.solver), max_load=max_load),
                           backend=spec.backend, allow_partial=True)


def test_a_stall_on_a_spurious_nitsche_mode_names_the_term_and_the_setting(tmp_path):
    """gamma = 2: the path stops short of 0.05 (measured at 0.0016), and the reason names the
    Nitsche term and ``nitsche_gamma (now 2)``; its curvature along the softest mode cancels the
    shell's (measured 3.35 of 3.35)."""
    sol = _path(tmp_path, 2.0)
    assert not sol.completed
    assert sol.load_factor < 0.05
    assert "Nitsche rotation term" in sol.stop_reason and "nitsche_gamma (now 2)" in sol.stop_reason, sol.stop_reason


def test_with_the_default_penalty_the_same_path_passes_that_load(tmp_path):
    """gamma = 20 on the same mesh: every point to 0.05 stable, no critical point."""
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
