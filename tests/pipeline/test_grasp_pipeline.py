"""The grasp chain end to end (linear shell, tennis ball) and its bad input."""
import json

import numpy as np
import pytest

import mujoco  # noqa: F401  (the sim extra is part of make test)

from graspdef.errors import GraspdefError
from graspdef.cli import main as graspdef_main
from graspdef.pipeline import run_grasp


def grasp_cli(argv):
    return graspdef_main(["grasp", *argv])


def test_tennis_ball_linear_chain(tmp_path):
    """Per-finger forces at the target, loads balanced (force to round-off after adding the
    weight), run folder complete.  Linear theory: indentation ~ F (Reissner: 2.0 mm/N for
    this ball, ../shared/MEASURED.md), so 10.63 N gives ~20 mm."""
    out = tmp_path / "run"
    r = run_grasp("tennis_ball", 10.63, "point", "linear", out).result
    for s in ("left", "right"):
        assert r["fingers"][s]["axial_force_N"] == pytest.approx(10.63, rel=1e-6)
        assert r["fingers"][s]["normal_force_N"] == pytest.approx(10.63, rel=0.01)
    assert np.allclose(r["residual"]["net_force_N"], 0, atol=1e-4)          # MuJoCo settled to ~1e-5 N
    assert np.allclose(r["load_mapping"]["moment_defect_Nm"], 0, atol=1e-14)
    ind = r["feedback"]["indentation_per_finger_m"]
    assert 15e-3 < ind < 25e-3
    for f in ("result.json", "contacts.json", "deformed.ply", "undeformed.ply"):
        assert (out / f).is_file()
    assert json.loads((out / "result.json").read_text())["object"] == "tennis_ball"


def test_bad_input_leaves_nothing(tmp_path, capsys):
    out = tmp_path / "bad"
    assert grasp_cli(["tennis_ball", "--force", "300", "--analysis", "linear", "--out", str(out)]) == 2
    assert "beyond what the gripper can exert (0..235 N" in capsys.readouterr().err
    assert not out.exists()
    assert grasp_cli(["no_such_scene", "--force", "5", "--out", str(out)]) == 2
    assert grasp_cli(["tennis_ball", "--force", "nan", "--contact", "geometric", "--out", str(out)]) == 2
    assert "--force must be finite, got 'nan'" in capsys.readouterr().err      # parsed with its unit (N implied)
    assert grasp_cli(["tennis_ball", "--force=-3N", "--out", str(out)]) == 2
    assert "positive number of newtons" in capsys.readouterr().err
    with pytest.raises(GraspdefError, match="contact must be"):
        run_grasp("tennis_ball", 5.0, "pressure", "linear", out)
    assert not out.exists() and not list(tmp_path.glob(".bad*"))
    with pytest.raises(GraspdefError, match="no object.toml beside the scene"):
        run_grasp("test_sphere", 5.0, "point", "linear", None)


def test_open_scan_is_refused(monkeypatch, tmp_path):
    """A scan that is not watertight cannot give a closed shell: MeshError before any output."""
    from graspdef.errors import MeshError
    from types import SimpleNamespace

    from graspdef.geometry import icosphere, save_ply
    from graspdef.objects import build
    from graspdef.pipeline import grasp as gp

    ball = icosphere(radius=0.03, subdivisions=3)
    keep = ball.vertices[ball.faces].mean(axis=1)[:, 2] > -0.01        # cut the bottom off
    open_scan = tmp_path / "open_scan.ply"
    save_ply(open_scan, ball.vertices, ball.faces[keep], units="m")
    monkeypatch.setattr(build, "scan_entry", lambda scan_id: SimpleNamespace(file=lambda: open_scan, units="m"))
    out = tmp_path / "run"
    with pytest.raises(MeshError, match="not closed"):
        gp.run_grasp("tennis_ball", 10.0, "point", "linear", out)
    assert not out.exists()


def test_stages_alone_and_the_equilibrium_warning():
    """The chain's stages run one by one (typed inputs and outputs); a free object whose mapped
    loads do not balance (here: 1 N added to the settled residual of ~1e-5 N) carries a warning
    with the net force and moment in its record."""
    from graspdef.pipeline import grasp as gp

    obj = gp.prepare_object("tennis_ball", "linear", control_faces=320)
    st = gp.settle(obj, 5.0)
    setup = gp.shell_problem(obj, st, "point")
    assert setup.free and np.linalg.norm(setup.residual_F) < 1e-3
    solved = gp.solve_shell(setup, "linear", 4)
    ok = gp.grasp_record(obj, st, setup, solved, 5.0, "point", "linear", {})
    assert not [w for w in ok.record["warnings"] if "equilibrium" in w]
    setup.residual_F = setup.residual_F + np.array([1.0, 0.0, 0.0])
    bad = gp.grasp_record(obj, st, setup, solved, 5.0, "point", "linear", {})
    assert [w for w in bad.record["warnings"] if "not in equilibrium: net force 1 N" in w], bad.record["warnings"]


def test_a_stopped_path_says_how_much_force_and_why(monkeypatch, tmp_path, capsys):
    """A grasp whose load path stops short (e.g. a soft shell snapping under point loads) exits 0
    with its last equilibrium, and says on one warning line which fraction of the force that is,
    in newtons per finger, and the path's own stop reason."""
    from types import SimpleNamespace

    import graspdef.pipeline.grasp as gp

    result = {"object": "duck", "analysis": "nonlinear", "contact": "point", "force_N": 40.0,
              "derived": {"indentation_per_finger": {"label": "indentation per finger", "value": 0.01318},
                          "max_displacement": {"label": "max. displacement", "value": 0.01346}},
              "convergence": {"completed": False, "load_factor": 0.03125,
                              "stop_reason": "the load path stopped at load factor 0.03125 after 3 steps: "
                                             "a limit point of the load"},
              "timings_s": {"total": 7.3}, "warnings": []}
    monkeypatch.setattr(gp, "run_grasp", lambda *a, **k: SimpleNamespace(result=result, out=tmp_path / "run"))
    assert grasp_cli(["tennis_ball", "--force", "40", "--out", str(tmp_path / "run")]) == 0
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if "load factor 0.0312 of the 40 N per finger asked (1.25 N)" in ln]
    assert len(lines) == 1 and lines[0].endswith("a limit point of the load")
