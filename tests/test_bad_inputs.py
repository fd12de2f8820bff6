"""The bad-input matrix (issue 15): every class of bad input a user can give any subcommand is
answered with exit status 2 and one line ``graspdef: error: ...`` naming the file, key or value
and what is accepted -- never a traceback -- and nothing is written."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from graspdef.cli import main
from graspdef.testing import plate_problem

REPO = Path(__file__).resolve().parents[1]

PLATE = plate_problem("plate", 4, probe=False)

#: a plate of 20,000 x 20,000 cells: 400 million control vertices, refused before it is generated
BIG_SPHERE = PLATE.replace("nx = 4\nny = 4", "nx = 20000\nny = 20000")

#: a free sphere (held by rigid_modes only) pushed by one force: nothing balances it
UNBALANCED = """
name = "unbalanced"
[units]
length = "mm"
force = "N"
[geometry]
type = "sphere"
radius = 30.0
subdivisions = 2
[material]
E = 1.0
nu = 0.3
[shell]
thickness = 1.0
[[supports]]
kind = "rigid_modes"
[[loads]]
kind = "point"
at = [30.0, 0.0, 0.0]
force = [-1.0, 0.0, 0.0]
"""

TRI = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"

SPEC = """
[sweep]
name = "bad"
[grid]
scenes = ["tennis_ball"]
forces_N = [5.0]
materials = ["linear"]
contacts = ["point"]
control_faces = [320]
"""


def _scene_copy(tmp: Path, edit) -> str:
    """A copy of the tennis-ball scene with its gripper beside it (the include stays valid), its
    object.toml edited by ``edit``; returns the scene folder."""
    root = tmp / "scenes"
    shutil.copytree(REPO / "scenes" / "parallel_gripper", root / "parallel_gripper")
    shutil.copytree(REPO / "scenes" / "tennis_ball", root / "tennis_ball")
    f = root / "tennis_ball" / "object.toml"
    f.write_text(edit(f.read_text()))
    return str(root / "tennis_ball")


def _replace(old: str, new: str):
    def edit(text: str) -> str:
        assert old in text, old
        return text.replace(old, new, 1)
    return edit


def _file(tmp: Path, name: str, text: str | bytes) -> str:
    p = tmp / name
    p.write_bytes(text) if isinstance(text, bytes) else p.write_text(text)
    return str(p)


def _mesh(tmp: Path, name: str, kind: str = "sphere") -> str:
    """A mesh file [mm] for ``object add``: a closed sphere (R 30 mm, or 100 mm: "big"), an open
    one, two spheres, a point cloud, or a tetrahedron with a fin on one edge (non-manifold)."""
    import numpy as np
    import trimesh

    s = trimesh.creation.icosphere(3, 30.0)
    if kind == "big":
        s = trimesh.creation.icosphere(3, 100.0)
    elif kind == "open":
        s.update_faces(s.face_normals[:, 2] < 0.5)          # the top cap cut off
        s.remove_unreferenced_vertices()
    elif kind == "two":
        s = trimesh.util.concatenate([s, s.copy().apply_translation([100.0, 0, 0])])
    elif kind == "cloud":
        p = tmp / name
        p.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                     "property float z\nend_header\n0 0 0\n10 0 0\n0 10 0\n")
        return str(p)
    elif kind == "fin":
        v = np.array([[0, 0, 0], [40, 0, 0], [0, 40, 0], [0, 0, 40], [20, -30, 20.0]])
        s = trimesh.Trimesh(v, [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2], [0, 1, 4]], process=False)
    s.export(tmp / name)
    return str(tmp / name)


ADD = ["--thickness", "1mm", "--law", "neo-hookean", "--E", "2MPa", "--nu", "0.45", "--mass", "50g"]


def _case(name: str, tmp: Path) -> tuple[list[str], str]:
    """(argv, a phrase the error line must contain)."""
    out = str(tmp / "out")
    plate = lambda text: _file(tmp, "p.toml", text)  # noqa: E731
    cases = {
        # --- solve: problem files
        "solve: missing file": lambda: (["solve", str(tmp / "nope.toml"), "--out", out], "nope.toml"),
        "solve: TOML syntax": lambda: (["solve", plate(PLATE + "\n[oops\n"), "--out", out], "line"),
        "solve: unknown key": lambda: (["solve", plate(PLATE.replace("thickness = 1.0", "thicknes = 1.0")), "--out", out],
                               "did you mean 'thickness'"),
        "solve: missing units": lambda: (["solve", plate(PLATE.replace('[units]\nlength = "mm"\nforce = "N"\n', "")),
                                  "--out", out], "[units]"),
        "solve: unknown unit": lambda: (["solve", plate(PLATE.replace('length = "mm"', 'length = "furlong"')), "--out", out],
                                "furlong"),
        "solve: NaN": lambda: (["solve", plate(PLATE.replace("E = 1000.0", "E = nan")), "--out", out], "finite"),
        "solve: zero thickness": lambda: (["solve", plate(PLATE.replace("thickness = 1.0", "thickness = 0.0")),
                                   "--out", out], "thickness"),
        "solve: nu above 0.5": lambda: (["solve", plate(PLATE.replace("nu = 0.3", "nu = 0.7")), "--out", out], "Poisson"),
        "solve: binary garbage": lambda: (["solve", _file(tmp, "g.toml", bytes(range(256))), "--out", out], "g.toml"),
        "solve: --out holds other files": lambda: (["solve", plate(PLATE), "--out", str(tmp / "photos")],
                                           "not a graspdef run folder"),
        "solve: --out is a file": lambda: (["solve", plate(PLATE), "--out", _file(tmp, "afile", "x")], "is a file"),
        # --- grasp
        "grasp: unknown scene": lambda: (["grasp", "no_such_scene", "--force", "5", "--out", out], "scene not found"),
        "grasp: force beyond the gripper": lambda: (["grasp", "tennis_ball", "--force", "1e9", "--out", out],
                                            "beyond what the gripper can exert"),
        "grasp: negative force": lambda: (["grasp", "tennis_ball", "--force", "-3", "--out", out], "force"),
        "grasp: fingertips the scene lacks": lambda: (["grasp", "duck", "--fingertips", "pad", "--force", "5",
                                                        "--out", out], "no scene_pad.xml"),
        "grasp: NaN force": lambda: (["grasp", "tennis_ball", "--force", "nan", "--out", out], "force"),
        "grasp: gas on without [gas]": lambda: (["grasp", "duck", "--force", "5", "--gas", "on", "--out", out], "[gas]"),
        "grasp: gas with a linear shell": lambda: (["grasp", "tennis_ball", "--force", "5", "--gas", "on", "--analysis",
                                            "linear", "--out", out], "nonlinear"),
        "grasp: negative friction": lambda: (["grasp", "tennis_ball", "--force", "5", "--friction", "-0.5", "--out", out],
                                     "friction coefficient (--friction) must be a finite number >= 0, got -0.5"),
        "grasp: NaN friction": lambda: (["grasp", "tennis_ball", "--force", "5", "--friction", "nan", "--out", out],
                                "friction coefficient (--friction)"),
        "grasp: patch size zero": lambda: (["grasp", "tennis_ball", "--force", "5", "--model", "patch",
                                            "--patch-size", "0mm", "--out", out], "patch size"),
        "grasp: patch larger than the object": lambda: (["grasp", "tennis_ball", "--force", "5", "--model", "patch",
                                                         "--patch-size", "200mm", "--out", out], "larger than the object"),
        "grasp: patch model with geometric contact": lambda: (["grasp", "tennis_ball", "--force", "5", "--model",
                                                               "patch", "--contact", "geometric", "--out", out],
                                                              "--contact point only"),
        "fit: pressure with the patch model": lambda: (["fit", "tennis_ball", "--data",
                                                       str(REPO / "scenes" / "tennis_ball" / "table1_tian_jia_2010.csv"),
                                                       "--params", "pressure", "--model", "patch", "--out", out],
                                                      "no air"),
        "grasp: bad E": lambda: (["grasp", "tennis_ball", "--force", "5", "--E-MPa", "-1", "--out", out], "E"),
        "grasp: --out holds other files": lambda: (["grasp", "tennis_ball", "--force", "5", "--out", str(tmp / "photos")],
                                           "not a graspdef run folder"),
        # --- object data (object.toml beside a scene)
        "object: unknown key": lambda: (["object", "show", _scene_copy(tmp, _replace("[gas]", "[gass]"))], "gass"),
        "object: wrong dimension": lambda: (["object", "show", _scene_copy(tmp, _replace('thickness = "2.5 mm"',
                                                                                  'thickness = "2.5 kg"'))], "kg"),
        "object: unknown scene": lambda: (["object", "show", "no_such_scene"], "scene not found"),
        "grasp: thickness outside the thin-shell range": lambda: (
            ["grasp", _scene_copy(tmp, _replace('thickness = "2.5 mm"', 'thickness = "0.004 mm"')), "--force", "5",
             "--analysis", "linear", "--out", out], "a thin shell needs"),
        "grasp: pad size with pin fingertips": lambda: (["grasp", "tennis_ball", "--pad-size", "30mm", "--force", "5",
                                                    "--out", out], "a pad size is for pad fingertips"),
        # --- object add (a mesh of one's own)
        "object add: missing mesh": lambda: (["object", "add", "ball", "--mesh", str(tmp / "no.stl"), *ADD, "--out", out],
                                     "file not found"),
        "object add: unknown mesh format": lambda: (["object", "add", "ball", "--mesh", _file(tmp, "b.xyz", "0 0 0\n"),
                                             *ADD, "--out", out], "unknown mesh format '.xyz'"),
        "object add: point cloud": lambda: (["object", "add", "ball", "--mesh", _mesh(tmp, "c.ply", "cloud"), "--units",
                                     "mm", *ADD, "--out", out], "a point cloud"),
        "object add: open surface": lambda: (["object", "add", "ball", "--mesh", _mesh(tmp, "o.stl", "open"), *ADD,
                                      "--out", out], "the surface is open: 1 hole ("),
        "object add: two objects in one file": lambda: (["object", "add", "ball", "--mesh", _mesh(tmp, "t.stl", "two"),
                                                 *ADD, "--out", out], "2 separate objects in one file"),
        "object add: non-manifold edge": lambda: (["object", "add", "ball", "--mesh", _mesh(tmp, "f.obj", "fin"),
                                           "--units", "mm", *ADD, "--out", out], "1 non-manifold edge (shared by 3 or more faces), e.g. vertex pairs (0, 1) at (20.00, 0.00, 0.00) mm"),
        "object add: bad name": lambda: (["object", "add", "my ball", "--mesh", _mesh(tmp, "s.stl"), *ADD, "--out", out],
                                 "object name 'my ball'"),
        "object add: no mass or density": lambda: (["object", "add", "ball", "--mesh", _mesh(tmp, "s.stl"), *ADD[:-2],
                                            "--out", out], "--density"),
        "object add: thickness outside the thin-shell range": lambda: (
            ["object", "add", "ball", "--mesh", _mesh(tmp, "s.stl"), *ADD[:1], "0.001mm", *ADD[2:], "--out", out],
            "a thin shell needs"),
        "object add: E in the wrong unit": lambda: (["object", "add", "ball", "--mesh", _mesh(tmp, "s.stl"), *ADD[:5],
                                             "2mm", *ADD[6:], "--out", out], "expected a pressure"),
        "object add: grasp axis without a point": lambda: (["object", "add", "ball", "--mesh", _mesh(tmp, "s.stl"), *ADD,
                                                    "--grasp-axis", "[1, 0, 0]", "--out", out], "together"),
        "object add: grasp wider than the gripper": lambda: (
            ["object", "add", "ball", "--mesh", _mesh(tmp, "b.stl", "big"), *ADD, "--grasp-axis", "[1, 0, 0]",
             "--grasp-point", "[0, 0, 0] mm", "--out", out], "the gripper takes"),
        "object add: too many faces": lambda: (["object", "add", "ball", "--mesh", _mesh(tmp, "s.stl"), *ADD, "--faces",
                                        "1000000", "--out", out], "--faces must be"),
        "object add: --out not empty": lambda: (["object", "add", "ball", "--mesh", _mesh(tmp, "s.stl"), *ADD, "--out",
                                         str(tmp / "photos")], "not empty"),
        "solve: unbalanced loads on a free body": lambda: (
            ["solve", _file(tmp, "ub.toml", UNBALANCED), "--out", out], "net force (-1, 0, 0) N"),
        "solve: mesh too large for the memory": lambda: (
            ["solve", _file(tmp, "big.toml", BIG_SPHERE), "--out", out], "GiB to solve"),
        # --- report / view / score on run folders
        "report: missing folder": lambda: (["report", str(tmp / "nowhere")], "does not exist"),
        "report: not a run folder": lambda: (["report", str(tmp / "photos")], "incomplete"),
        "report: bad table file": lambda: (["report", "--table", _file(tmp, "t.csv", "folder\nx\n"), "--out",
                                    str(tmp / "r.html")], "'run' column"),
        "view: missing folder": lambda: (["view", str(tmp / "nowhere"), "--port", "0"], "does not exist"),
        "score: missing prediction": lambda: (["score", str(tmp / "nowhere.ply"), "ycb_056_tennis_ball", "--out", out],
                                      "nowhere.ply"),
        "score: unknown scan id": lambda: (["score", _file(tmp, "pred.obj", TRI), "no_such_scan_id", "--undeformed",
                                            str(tmp / "pred.obj"), "--prediction-units", "m", "--out", out], "no_such_scan_id"),
        "score: empty scan": lambda: (["score", _file(tmp, "pred.obj", TRI), "--undeformed", str(tmp / "pred.obj"), "--prediction-units", "m",
                               _file(tmp, "empty.ply", "ply\nformat ascii 1.0\ncomment units mm\nelement vertex 0\n"
                                     "property float x\nproperty float y\nproperty float z\nend_header\n"),
                               "--out", out], "empty.ply"),
        # --- sweep
        "sweep: unknown key": lambda: (["sweep", _file(tmp, "s.toml", SPEC.replace("[grid]", "[gridd]")), "--out", out],
                               "gridd"),
        "sweep: force beyond the gripper": lambda: (["sweep", _file(tmp, "s.toml", SPEC.replace("[5.0]", "[500.0]")),
                                             "--out", out], "beyond what the actuators"),
        "sweep: unreachable scheduler": lambda: (["sweep", _file(tmp, "s.toml", SPEC), "--out", out, "--scheduler",
                                          "tcp://127.0.0.1:9"], "127.0.0.1:9"),
        # --- rank
        "rank: negative force": lambda: (["rank", "test_sphere", "--force", "-3", "--out", out], "--force must be"),
        "rank: force that is not a number": lambda: (["rank", "test_sphere", "--force", "lots", "--out", out],
                                                     "not a number with a unit"),
        "rank: no candidates": lambda: (["rank", "test_sphere", "--force", "5", "--candidates", "0", "--out", out],
                                        "--candidates must be"),
        "rank: strain limit above 100 %": lambda: (["rank", "test_sphere", "--force", "5", "--strain-limit", "150%",
                                                    "--out", out], "--strain-limit must be"),
        "rank: pad size beyond the gripper's": lambda: (["rank", "test_sphere", "--force", "5", "--pad-size", "1m",
                                                         "--out", out], "pad size must be"),
        "rank: --chunks without Dask": lambda: (["rank", "test_sphere", "--force", "5", "--chunks", "4", "--out", out],
                                                "--chunks needs"),
        "rank: an object with a gas": lambda: (["rank", "tennis_ball", "--force", "5", "--out", out], "encloses a gas"),
        "rank: unknown object": lambda: (["rank", "no_such_scene", "--force", "5", "--out", out], "scene not found"),
        "rank: force range reversed": lambda: (["rank", "test_sphere", "--force-range", "10N", "2N", "--out", out],
                                               "0 < A < B"),
        "rank: force and force range": lambda: (["rank", "test_sphere", "--force", "5", "--force-range", "1", "2",
                                                 "--out", out], "one of them"),
        "rank: force beyond the gripper": lambda: (["rank", "soda_can", "--force", "400", "--out", out],
                                                   "beyond what the gripper"),
        "rank: --out holds other files": lambda: (["rank", "test_sphere", "--force", "5", "--out", str(tmp / "photos")],
                                                  "not a graspdef run folder"),
        # --- fit
        "fit: missing data file": lambda: (["fit", "tennis_ball", "--data", str(tmp / "no.csv"), "--params", "E",
                                            "--out", out], "data table not found"),
        "fit: header without units": lambda: (["fit", "tennis_ball", "--data", _file(tmp, "d.csv", "force,displacement\n"
                                               "10,2\n"), "--params", "E", "--out", out], "states no unit"),
        "fit: unknown parameter": lambda: (["fit", "tennis_ball", "--data", _file(tmp, "d.csv", "force_N,displacement_mm\n"
                                            "10,2\n"), "--params", "mu", "--out", out], "unknown parameter 'mu'"),
        "fit: non-positive force": lambda: (["fit", "tennis_ball", "--data", _file(tmp, "d.csv", "force_N,displacement_mm\n"
                                             "-1,2\n"), "--params", "E", "--out", out], "force must be positive"),
        "fit: fewer rows than parameters": lambda: (["fit", "tennis_ball", "--data", _file(
            tmp, "d.csv", "force_N,displacement_mm\n10,2\n"), "--params", "E,pressure", "--out", out], "1 rows for 2"),
        "fit: --align-region without --scan": lambda: (["fit", "tennis_ball", "--data", _file(
            tmp, "d.csv", "force_N,displacement_mm\n10,2\n"), "--params", "E", "--align-region", "z < 0", "--out", out],
            "--align-region belongs to --scan"),
        "fit: bad --align-region": lambda: (["fit", "tennis_ball", "--scan", _file(tmp, "s.xyz", "0 0 0\n"), "--force",
                                             "10N", "--params", "E", "--align-region", "zz < 0", "--out", out],
                                            "alignment region"),
        "fit: negative --scan-sigma": lambda: (["fit", "tennis_ball", "--scan", _file(tmp, "s.xyz", "0 0 0\n"), "--force",
                                                "10N", "--params", "E", "--scan-sigma=-1mm", "--out", out],
                                               "--scan-sigma must be a positive length, got -1mm"),
        # --- bench
        "bench: missing folder": lambda: (["bench", "linear", "--dir", str(tmp / "nowhere")], "nowhere"),
    }
    return cases[name]()


NAMES = sorted([
    "solve: missing file", "solve: TOML syntax", "solve: unknown key", "solve: missing units", "solve: unknown unit",
    "solve: NaN", "solve: zero thickness", "solve: nu above 0.5", "solve: binary garbage",
    "solve: --out holds other files", "solve: --out is a file", "grasp: unknown scene",
    "grasp: force beyond the gripper", "grasp: negative force", "grasp: fingertips the scene lacks", "grasp: NaN force", "grasp: gas on without [gas]",
    "grasp: gas with a linear shell", "grasp: negative friction", "grasp: NaN friction", "grasp: bad E", "grasp: --out holds other files", "object: unknown key",
    "object: wrong dimension", "object: unknown scene", "grasp: thickness outside the thin-shell range", "report: missing folder", "report: not a run folder",
    "report: bad table file", "view: missing folder", "score: missing prediction", "score: unknown scan id",
    "score: empty scan", "sweep: unknown key", "sweep: force beyond the gripper", "sweep: unreachable scheduler",
    "bench: missing folder", "grasp: pad size with pin fingertips", "object add: missing mesh",
    "object add: unknown mesh format", "object add: point cloud", "object add: open surface",
    "object add: two objects in one file", "object add: non-manifold edge", "object add: bad name",
    "object add: no mass or density", "object add: thickness outside the thin-shell range",
    "object add: E in the wrong unit", "object add: grasp axis without a point",
    "object add: grasp wider than the gripper", "object add: too many faces", "object add: --out not empty",
    "solve: mesh too large for the memory", "solve: unbalanced loads on a free body", "rank: negative force",
    "rank: force that is not a number", "rank: no candidates", "rank: strain limit above 100 %",
    "rank: pad size beyond the gripper's", "rank: --chunks without Dask", "rank: an object with a gas",
    "rank: unknown object", "rank: --out holds other files", "rank: force range reversed",
    "rank: force and force range", "rank: force beyond the gripper",
    "fit: missing data file", "fit: header without units", "fit: unknown parameter", "fit: non-positive force",
    "fit: fewer rows than parameters", "fit: --align-region without --scan", "fit: bad --align-region",
    "fit: negative --scan-sigma"])


def test_the_matrix_has_at_least_30_classes():
    assert len(NAMES) >= 30


@pytest.mark.parametrize("name", NAMES)
def test_bad_input_is_one_line_exit_2_and_writes_nothing(name, tmp_path, capsys):
    photos = tmp_path / "photos"
    photos.mkdir()
    (photos / "holiday.jpg").write_bytes(b"jpeg")
    argv, phrase = _case(name, tmp_path)
    before = sorted(str(p) for p in tmp_path.rglob("*"))
    code = main(["-q", *argv])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2, (name, err)
    assert len(err) == 1 and err[0].startswith("graspdef: error:"), (name, err)
    assert phrase in err[0], (name, err[0])
    assert sorted(str(p) for p in tmp_path.rglob("*")) == before, name          # nothing written
    assert (photos / "holiday.jpg").read_bytes() == b"jpeg"
    json.dumps(err)                                                              # plain text
