"""The command line: a run folder for a good problem file, and for every kind of bad input one
clear error naming the problem and where, exit status 2, and no output files."""
import json
from pathlib import Path

import numpy as np
import pytest

from graspdef.cli import main
from graspdef.testing import plate_problem

BASE = plate_problem("small_plate", 6)


def _run(tmp_path: Path, text: str, capsys, name="p.toml"):
    f = tmp_path / name
    f.write_text(text)
    out = tmp_path / "run"
    code = main(["-q", "solve", str(f), "--out", str(out)])
    err = capsys.readouterr().err
    return code, err, out


def test_solve_writes_run_folder_in_si(tmp_path, capsys):
    """Units are converted at I/O only: the problem file is in mm and N (E = 1000 N/mm^2 = 1 GPa,
    the plate 100 mm wide), the run folder SI; the centre deflection follows Timoshenko's
    0.0116 P a^2 / D within the coarse-mesh error."""
    code, err, out = _run(tmp_path, BASE, capsys)
    assert code == 0, err
    rec = json.loads((out / "result.json").read_text())
    assert rec["units"]["length"] == "m"
    w = rec["probes"]["centre"]["displacement"][2] * 1e3                # mm
    D = 1000.0 * 1.0 ** 3 / (12 * (1 - 0.09))           # N mm
    assert w == pytest.approx(-0.0116008 * 1.0 * 100.0 ** 2 / D, rel=0.02)
    assert rec["derived"]["max_displacement"]["value"] * 1e3 == pytest.approx(abs(w), rel=1e-3)
    assert rec["n_control"] == 49
    assert set(rec["timings_s"]) >= {"assembly", "factor", "solve"}
    head = (out / "deformed.ply").read_bytes()[:300]
    assert b"comment units m\n" in head
    assert (out / "problem.toml").read_text() == BASE


BAD = {
    "missing units": (BASE.replace('[units]\nlength = "mm"\nforce = "N"\n', ""), "missing [units]"),
    "misspelled key": (BASE.replace("thickness = 1.0", "thicknes = 1.0"), "did you mean 'thickness'"),
    "unknown section": (BASE + "\n[solvr]\nbackend = 'auto'\n", "unknown key 'solvr'"),
    "unknown length unit": (BASE.replace('length = "mm"', 'length = "furlong"'), "unknown length unit"),
    "zero thickness": (BASE.replace("thickness = 1.0", "thickness = 0.0"), "thickness must be positive"),
    "negative modulus": (BASE.replace("E = 1000.0", "E = -5.0"), "Young's modulus"),
    "nu above 0.5": (BASE.replace("nu = 0.3", "nu = 0.6"), "Poisson's ratio"),
    "nu negative": (BASE.replace("nu = 0.3", "nu = -0.1"), "Poisson's ratio"),
    "NaN": (BASE.replace("E = 1000.0", "E = nan"), "must be finite"),
    "probe off surface": (BASE.replace('name = "centre"\nat = [0.0, 0.0, 0.0]', 'name = "centre"\nat = [0.0, 0.0, 30.0]'),
                          "off the surface"),
    "under-supported": (BASE.replace('kind = "simply_supported"', 'kind = "symmetry"\nnormal = [1.0, 0.0, 0.0]'),
                        "under-supported"),
    "unknown region": (BASE.replace('region = "edges"', 'region = "edgs"'), "did you mean 'edges'"),
    "bad support kind": (BASE.replace('kind = "simply_supported"', 'kind = "simply_suported"'), "did you mean 'simply_supported'"),
    "bad region expression": (BASE.replace("abs(abs(x) - 50)", "__import__('os')"), "region 'edges'"),
    "not toml": ("this is = = not toml", "not valid TOML"),
    "missing mesh file": (BASE.replace('type = "rectangle"\nlx = 100.0\nly = 100.0\nnx = 6\nny = 6',
                                       'type = "mesh"\npath = "nowhere.ply"\nunits = "mm"'), "not found"),
    "mesh without units": (BASE.replace('type = "rectangle"\nlx = 100.0\nly = 100.0\nnx = 6\nny = 6',
                                        'type = "mesh"\npath = "m.ply"'), "needs 'units'"),
}


@pytest.mark.parametrize("case", list(BAD), ids=list(BAD))
def test_bad_problem_file_is_one_clear_error(tmp_path, capsys, case):
    text, message = BAD[case]
    code, err, out = _run(tmp_path, text, capsys)
    assert code == 2
    assert err.startswith("graspdef: error:") and err.count("\n") == 1, err
    assert message in err, err
    assert not out.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".run")]


def test_missing_problem_file(tmp_path, capsys):
    code = main(["-q", "solve", str(tmp_path / "none.toml"), "--out", str(tmp_path / "o")])
    assert code == 2
    assert "problem file not found" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def _write_obj(path: Path, vertices, faces):
    lines = [f"v {x} {y} {z}" for x, y, z in vertices] + ["f " + " ".join(str(i + 1) for i in f) for f in faces]
    path.write_text("\n".join(lines) + "\n")


MESH_GEOM = 'type = "mesh"\npath = "m.obj"\nunits = "mm"'
RECT = 'type = "rectangle"\nlx = 100.0\nly = 100.0\nnx = 6\nny = 6'


@pytest.mark.parametrize("case,vertices,faces,message", [
    ("non-manifold edge", [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [1, 1, 1]],
     [[0, 1, 2], [1, 0, 3], [0, 1, 4]], "non-manifold"),
    ("degenerate face", [[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]], "degenerate"),
    ("quads", [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]], "triangles"),
])
def test_bad_mesh_file(tmp_path, capsys, case, vertices, faces, message):
    _write_obj(tmp_path / "m.obj", np.array(vertices, float) * 50, faces)
    code, err, out = _run(tmp_path, BASE.replace(RECT, MESH_GEOM), capsys)
    assert code == 2
    assert message in err, err
    assert not out.exists()


def test_mesh_file_in_millimetres_is_converted(tmp_path, capsys):
    """The same plate read from an OBJ in mm gives the same answer as the built-in rectangle."""
    from graspdef.geometry import rectangle

    m = rectangle(100.0, 100.0, 6, 6)
    _write_obj(tmp_path / "m.obj", m.vertices, m.faces)
    code, err, out = _run(tmp_path, BASE.replace(RECT, MESH_GEOM), capsys)
    assert code == 0, err
    w_mesh = json.loads((out / "result.json").read_text())["probes"]["centre"]["displacement"][2]
    code, err, out2 = _run(tmp_path, BASE, capsys, name="q.toml")
    w_rect = json.loads((out2 / "result.json").read_text())["probes"]["centre"]["displacement"][2]
    assert w_mesh == pytest.approx(w_rect, rel=1e-10)


def test_help_lists_subcommands(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert "solve" in out and "bench" in out


def test_point_load_by_face_and_barycentric_position(tmp_path, capsys):
    """A load given as (face, bary) at the plate centre equals the one given by position: the
    6 x 6 rectangle's centre is a vertex; the limit point there is the same whichever of its
    faces names it."""
    from graspdef.geometry import rectangle

    m = rectangle(100.0, 100.0, 6, 6)
    centre = int(np.argmin(np.linalg.norm(m.vertices, axis=1)))
    face = int(np.flatnonzero((m.faces == centre).any(axis=1))[0])
    bary = [1.0 if v == centre else 0.0 for v in m.faces[face]]
    text = BASE.replace('kind = "point"\nat = [0.0, 0.0, 0.0]', f'kind = "point"\nface = {face}\nbary = {bary}')
    code, err, out = _run(tmp_path, text, capsys)
    assert code == 0, err
    w_fb = json.loads((out / "result.json").read_text())["probes"]["centre"]["displacement"][2]
    code, err, out2 = _run(tmp_path, BASE, capsys, name="q.toml")
    w_at = json.loads((out2 / "result.json").read_text())["probes"]["centre"]["displacement"][2]
    assert w_fb == pytest.approx(w_at, rel=1e-9)


NONLINEAR = BASE.replace("""[material]
E = 1000.0
nu = 0.3""", """[material]
model = "neo_hookean"
mu = 333.3""").replace("force = [0.0, 0.0, -1.0]", "force = [0.0, 0.0, -20.0]") + """
[solver]
type = "nonlinear"
steps = 4
"""


def test_solve_nonlinear_writes_the_path(tmp_path, capsys):
    """A nonlinear problem file: progress per converged point, path.csv with one row per point
    (start included) and a result.json that says so; the plate under a large central force
    deflects less than linear theory predicts (membrane stiffening)."""
    f = tmp_path / "p.toml"
    f.write_text(NONLINEAR)
    assert main(["solve", str(f), "--out", str(tmp_path / "run")]) == 0
    err = capsys.readouterr().err
    assert "Newton iterations" in err and "path:" in err
    rec = json.loads((tmp_path / "run" / "result.json").read_text())
    assert rec["analysis"] == "nonlinear" and rec["convergence"]["completed"] and rec["stable"]
    rows = (tmp_path / "run" / "path.csv").read_text().strip().splitlines()
    assert rows[0].startswith("point,kind,load_factor") and "centre_uz[m]" in rows[0]
    assert len(rows) == rec["convergence"]["n_points"] + 1 and float(rows[-1].split(",")[2]) == 1.0
    lin = tmp_path / "lin.toml"
    lin.write_text(NONLINEAR.replace('type = "nonlinear"\nsteps = 4', 'type = "linear"'))
    assert main(["solve", str(lin), "--out", str(tmp_path / "lin")]) == 0
    w_lin = json.loads((tmp_path / "lin" / "result.json").read_text())["probes"]["centre"]["displacement"][2]
    w_nl = rec["probes"]["centre"]["displacement"][2]
    assert 0 < w_nl / w_lin < 1


def test_a_stopped_path_keeps_its_converged_part_and_exits_2(tmp_path, capsys):
    f = tmp_path / "p.toml"
    f.write_text(NONLINEAR.replace("steps = 4", "steps = 50\nmax_steps = 2"))
    assert main(["solve", str(f), "--out", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err
    assert "max_steps" in err and "converged part" in err
    rec = json.loads((tmp_path / "run" / "result.json").read_text())
    conv = rec["convergence"]
    assert not conv["completed"] and conv["load_factor"] < 1 and "max_steps" in conv["stop_reason"]


@pytest.mark.parametrize("edit,message", [
    (('model = "neo_hookean"', 'model = "neo_hooke"'), "did you mean 'neo_hookean'"),
    (("mu = 333.3", "mu = -1.0"), "mu"),
    (('type = "nonlinear"', 'type = "nonlinear"\nmethod = "riks"'), "unknown path method"),
    (('type = "nonlinear"', 'type = "nonlinear"\nstepz = 3'), "did you mean 'steps'"),
    (('kind = "point"\nat = [0.0, 0.0, 0.0]\nforce', 'kind = "gas"\np0 = 1.0\n#'), "closed surface"),
])
def test_nonlinear_bad_input(tmp_path, capsys, edit, message):
    f = tmp_path / "p.toml"
    f.write_text(NONLINEAR.replace(*edit))
    assert main(["solve", str(f), "--out", str(tmp_path / "run")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "run").exists()


def test_object_show_prints_what_a_grasp_uses(capsys):
    """``graspdef object show``: the stated law with E and nu, the shell law of each analysis
    (nu < 0.5: the compressible form), the gas with its source; an unknown scene is one line."""
    assert main(["object", "show", "duck"]) == 0
    out = capsys.readouterr().out
    assert "law neo_hookean, E = 1 MPa, nu = 0.45" in out
    assert "nonlinear analysis uses: compressible_neo_hookean" in out and "enclosed air: none" in out
    assert main(["object", "show", "tennis_ball"]) == 0
    out = capsys.readouterr().out
    assert "nonlinear analysis uses: neo_hookean" in out and "p0 = 80 kPa gauge" in out and "source:" in out
    assert main(["object", "show", "no_such_object"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "scene not found" in err[0]


def test_fingertips_pick_the_scene_variant():
    """``--fingertips pad`` grips with the scene folder's rubber pads (scene_pad.xml), ``pin`` with
    its pins (scene.xml); an unknown variant is refused by name."""
    from graspdef.errors import ProblemError
    from graspdef.objects import scene_xml

    assert scene_xml("tennis_ball", "pad").name == "scene_pad.xml"
    assert scene_xml("tennis_ball", "pin").name == "scene.xml"
    assert scene_xml(scene_xml("tennis_ball"), "pad").name == "scene_pad.xml"
    with pytest.raises(ProblemError, match="accepted: pin, pad"):
        scene_xml("tennis_ball", "claw")


def test_a_value_with_a_minus_sign_reaches_its_option():
    """``--E -2MPa``: argparse would take "-2MPa" for an option ("expected one argument"); the
    CLI joins it to its option so that the value's own check answers.  Plain numbers ("-0.1",
    "-1e-3") are left to argparse, which accepts them; "--opt=value" is left as it is."""
    from graspdef.cli import join_negative_values

    assert join_negative_values(["object", "add", "x", "--E", "-2MPa", "--nu", "-0.1", "--thickness", "-1e-3"]) == [
        "object", "add", "x", "--E=-2MPa", "--nu", "-0.1", "--thickness", "-1e-3"]
    assert join_negative_values(["--grasp-point", "-.5mm", "--E=-3MPa", "-q"]) == ["--grasp-point=-.5mm", "--E=-3MPa", "-q"]
    assert join_negative_values(["--out", "dir", "--force", "-"]) == ["--out", "dir", "--force", "-"]


def test_a_negative_modulus_is_one_line_about_the_modulus(tmp_path, capsys):
    """The whole command: the error names the modulus, not argparse's missing argument."""
    code = main(["-q", "object", "add", "b", "--mesh", str(tmp_path / "none.stl"), "--thickness", "2mm", "--law",
                 "svk", "--E", "-2MPa", "--nu", "0.3", "--mass", "60g", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert "Young's modulus E must be a positive" in err[0] and "-2000000" in err[0], err
    assert not (tmp_path / "o").exists()


def test_console_script_exits_with_the_commands_status(tmp_path, monkeypatch):
    """The console script (graspdef.cli.console) exits with main's status through SystemExit (the
    normal teardown) unless the command asked for the process to end at once (only an out-of-core
    solve does: tests/solve/test_kkt_out_of_core.py runs that one in a process of its own): a missing
    problem file is one line and status 2."""
    from graspdef.cli import console

    monkeypatch.setattr("sys.argv", ["graspdef", "-q", "solve", str(tmp_path / "missing.toml"), "--out", str(tmp_path / "o")])
    with pytest.raises(SystemExit) as exc:
        console()
    assert exc.value.code == 2


def test_a_path_records_its_cut_attempts_in_words(tmp_path):
    """The run record lists every attempt the path cut (``convergence.events``), with its loads and
    the reason in words: here the nonlinear plate in one step with at most 2 Newton iterations,
    whose first attempt to the full load cannot converge and is halved (before 2026-11-27 the
    events never left the solver)."""
    f = tmp_path / "p.toml"
    f.write_text(NONLINEAR.replace("steps = 4", "steps = 1\nmax_iterations = 2"))
    main(["solve", str(f), "--out", str(tmp_path / "run")])
    rec = json.loads((tmp_path / "run" / "result.json").read_text())
    events = rec["convergence"]["events"]
    assert events, rec["convergence"]
    first = events[0]
    assert first["from_load_factor"] == 0.0 and first["to_load_factor"] == 1.0
    assert first["action"] == "load step halved" and "did not converge in 2 iterations" in first["reason"]


EULER_STRIP = """name = "euler_strip"
[units]
length = "consistent"
force = "consistent"
[geometry]
type = "rectangle"
lx = 10.0
ly = 1.0
nx = 20
ny = 2
center = [5.0, 0.5]
[material]
model = "saint_venant_kirchhoff"
E = 1.2e6
nu = 0.0
[shell]
thickness = 0.1
[regions]
root = "abs(x) < 1e-9"
tip = "abs(x - 10) < 1e-9"
[[supports]]
kind = "clamped"
region = "root"
[[loads]]
kind = "edge_load"
region = "tip"
force = [-2.4674011002723395, 0.0, 0.0]   # Euler's load pi^2 EI / (4 L^2) per unit width
[solver]
type = "nonlinear"
steps = 10
max_load = 1.2
bifurcation = "locate"
"""


def test_solve_says_when_a_critical_point_could_not_be_narrowed(tmp_path, capsys, monkeypatch):
    """Euler's strip through ``graspdef solve`` with Newton made to fail at every point that
    would narrow the bifurcation down: the progress says so in one line, with the reason, and
    result.json's events hold it (the strip's own narrowing is tests/solve/test_bifurcation.py)."""
    import graspdef.solve.nonlinear as nl

    newton, locate = nl.PathSolver.newton, nl.PathSolver._locate

    def locating(self, *args, **kwargs):
        self.locating = True
        try:
            return locate(self, *args, **kwargs)
        finally:
            self.locating = False

    def failing(self, u0, lam, *args, **kwargs):
        if getattr(self, "locating", False):
            raise nl._Failed(f"injected failure at load factor {lam:.6g}")
        return newton(self, u0, lam, *args, **kwargs)

    monkeypatch.setattr(nl.PathSolver, "_locate", locating)
    monkeypatch.setattr(nl.PathSolver, "newton", failing)
    f = tmp_path / "strip.toml"
    f.write_text(EULER_STRIP)
    assert main(["solve", str(f), "--out", str(tmp_path / "run")]) == 0
    err = capsys.readouterr().err
    assert "bifurcation point at load factor" in err
    line = next(ln for ln in err.splitlines() if "was not narrowed further" in ln)
    assert "injected failure" in line
    rec = json.loads((tmp_path / "run" / "result.json").read_text())
    assert [e["action"] for e in rec["convergence"]["events"]] == [nl.BRACKET_NOT_NARROWED]
