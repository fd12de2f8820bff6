"""The run folder (graspdef.runs): one record, one writer, one reader.

* the record's schema: written, read back, newer / older / foreign schemas refused in one line;
* every file of a run folder truncated or corrupted in turn: ``report``, ``view`` and ``score``
  answer with one line and exit status 2, never a traceback;
* the writer is atomic: a failure leaves nothing, and never clobbers a good folder;
* the VTU export holds the same surface and field as deformed.ply.
"""
from __future__ import annotations

import json
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from graspdef.cli import main
from graspdef.errors import GraspdefError
from graspdef.runs.read import read_run
from graspdef.runs.record import SCHEMA_VERSION, RunFolderError, RunRecord
from graspdef.testing import cantilever_problem

#: a small nonlinear cantilever in mm and N (physical units: it can be scored against a scan)
CANTILEVER_MM = cantilever_problem("cantilever_mm", nx=8, force=0.02, steps=3, units="mm", length=100.0, width=10.0,
                                   E=2000.0, thickness=1.0)

CONTACTS = {"units": {"length": "mm", "force": "N"},
            "fingers": [{"name": "pad", "position": [100, 5, 3], "size": [5, 5, 5]}],
            "contacts": [{"position": [100, 5, 0.5], "force": [0, 0, -0.02], "finger": "pad"}]}


@pytest.fixture(scope="module")
def good_run(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("runs")
    src = root / "cantilever.toml"
    src.write_text(CANTILEVER_MM)
    out = root / "good"
    assert main(["-q", "solve", str(src), "--out", str(out)]) == 0
    (out / "contacts.json").write_text(json.dumps(CONTACTS))
    return out


def test_record_round_trip_and_si(good_run):
    """result.json carries the schema, SI units and the derived quantities with definitions."""
    doc = json.loads((good_run / "result.json").read_text())
    assert doc["schema"] == "graspdef.run" and doc["schema_version"] == SCHEMA_VERSION
    assert doc["units"] == {"length": "m", "force": "N", "energy": "J", "pressure": "Pa"}
    rec = RunRecord.from_json(doc, "x")
    assert rec.to_json() == doc
    md = rec.derived["max_displacement"]
    assert {"value", "unit", "label", "definition", "surface", "rigid_motion_removed", "at"} <= set(md)
    run = read_run(good_run)
    # the tip of a 100 mm cantilever moves by millimetres: SI metres in the record
    assert 1e-4 < run.max_displacement() < 0.1
    assert run.record["thickness_m"] == pytest.approx(1e-3) and run.outer_offset == pytest.approx(5e-4)
    header = (good_run / "path.csv").read_text().splitlines()[0].split(",")
    assert "tip_uz[m]" in header and "energy[J]" in header


@pytest.mark.parametrize("change, message", [
    (lambda d: d.update(schema_version=SCHEMA_VERSION + 1), "newer than this graspdef reads"),
    (lambda d: d.update(schema_version=1), "regenerate it"),
    (lambda d: d.update(schema_version="two"), "schema_version must be a positive integer"),
    (lambda d: d.pop("schema"), "not a graspdef run record"),
    (lambda d: d.update(units={"length": "mm"}), "run folders are SI"),
    (lambda d: d.update(derived={"max_displacement": 3.0}), "'derived' must map names"),
    (lambda d: d.update(kind="simulation"), "run kind must be one of"),
])
def test_schema_errors(good_run, tmp_path, change, message):
    d = tmp_path / "run"
    shutil.copytree(good_run, d)
    doc = json.loads((d / "result.json").read_text())
    change(doc)
    (d / "result.json").write_text(json.dumps(doc))
    with pytest.raises(RunFolderError, match=message) as info:
        read_run(d)
    assert "\n" not in str(info.value)


def test_schema_1_folder_says_how_to_regenerate(good_run, tmp_path):
    d = tmp_path / "old"
    shutil.copytree(good_run, d)
    (d / "result.json").write_text(json.dumps({"name": "x", "units": {"length": "mm"}, "max_displacement": 1.0}))
    with pytest.raises(RunFolderError, match="older graspdef .*schema 1.*regenerate"):
        read_run(d)


def _truncate(p: Path) -> None:
    b = p.read_bytes()
    p.write_bytes(b[: len(b) // 2])


def _garbage(p: Path) -> None:
    p.write_bytes(bytes(range(256)) * 4)


DAMAGE = {
    "result.json truncated": ("result.json", _truncate),
    "result.json garbage": ("result.json", _garbage),
    "deformed.ply truncated": ("deformed.ply", _truncate),
    "deformed.ply garbage": ("deformed.ply", _garbage),
    "undeformed.ply truncated": ("undeformed.ply", _truncate),
    "path.csv truncated": ("path.csv", _truncate),
    "path.csv garbage": ("path.csv", _garbage),
    "path.csv not numbers": ("path.csv", lambda p: p.write_text(p.read_text().replace("0.", "x.", 3))),
    "path_u.npz truncated": ("path_u.npz", _truncate),
    "path_u.npz garbage": ("path_u.npz", _garbage),
    "contacts.json truncated": ("contacts.json", _truncate),
    "contacts.json wrong types": ("contacts.json", lambda p: p.write_text(json.dumps(
        {"fingers": 3, "contacts": {"a": 1}, "per_finger": [1, 2]}))),
}


@pytest.mark.parametrize("damage", sorted(DAMAGE))
@pytest.mark.parametrize("command", ["report", "view", "score"])
def test_corrupt_file_is_one_line_exit_2(good_run, tmp_path, capsys, damage, command):
    """Each file a consumer reads, damaged in turn: one clear line on stderr and exit 2 from
    report, view and score, and nothing written."""
    d = tmp_path / "run"
    shutil.copytree(good_run, d)
    name, how = DAMAGE[damage]
    how(d / name)
    argv = {"report": ["report", str(d), "--out", str(tmp_path / "r.html")],
            "view": ["view", str(d), "--port", "0", "--no-live"],
            "score": ["score", str(d), str(good_run / "deformed.ply"), "--out", str(tmp_path / "s")]}[command]
    code = main(["-q", *argv])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2, err
    assert len(err) == 1 and err[0].startswith("graspdef: error:") and "Traceback" not in err[0], err
    assert not (tmp_path / "r.html").exists() and not (tmp_path / "s").exists()


def test_writer_is_atomic(good_run, tmp_path):
    """A writer that fails half-way leaves the good folder as it was and nothing partial."""
    from graspdef.runs.write import write_run

    d = tmp_path / "run"
    shutil.copytree(good_run, d)
    before = sorted(p.name for p in d.iterdir())
    run = read_run(d)
    with pytest.raises(GraspdefError):
        write_run(d, run.record, rest=run.rest_vertices, deformed=run.deformed_vertices, faces=run.faces,
                  displacement=run.displacements[:-1])           # wrong shape: fails inside the block
    assert sorted(p.name for p in d.iterdir()) == before
    assert [p.name for p in tmp_path.iterdir()] == ["run"]         # no temporary folder left
    read_run(d)


def test_vtu_export_matches_the_ply(good_run):
    """deformed.vtu (ParaView) holds the deformed surface and the stored displacement field."""
    run = read_run(good_run)
    root = ET.parse(good_run / "deformed.vtu").getroot()
    piece = root.find("UnstructuredGrid/Piece")
    assert int(piece.get("NumberOfPoints")) == len(run.deformed_vertices)
    assert int(piece.get("NumberOfCells")) == len(run.faces)
    pts = np.array(piece.find("Points/DataArray").text.split(), float).reshape(-1, 3)
    np.testing.assert_allclose(pts, run.deformed_vertices, rtol=1e-15, atol=0)
    arrays = {a.get("Name"): a for a in piece.find("PointData")}
    u = np.array(arrays["displacement"].text.split(), float).reshape(-1, 3)
    np.testing.assert_allclose(u, run.displacements, rtol=1e-15, atol=0)
    conn = np.array(piece.find("Cells/DataArray[@Name='connectivity']").text.split(), int).reshape(-1, 3)
    np.testing.assert_array_equal(conn, run.faces)


def test_strain_energy_density_field_integrates_to_the_energy(good_run):
    """deformed.ply's strain_energy_density [J/m^2] times each vertex's share of the rest area
    (a third of each incident face) sums to the shell's elastic energy (an invariant of the
    vertex lumping), and the field is non-negative."""
    import trimesh

    from graspdef.problem.config import load_problem
    from graspdef.shell.energy import ShellEnergy

    m = trimesh.load(good_run / "deformed.ply", process=False)
    dens = np.asarray(m.metadata["_ply_raw"]["vertex"]["data"]["strain_energy_density"], float)
    assert dens.min() >= 0 and dens.max() > 0
    spec = load_problem(good_run / "problem.toml")
    shell = spec.problem.shell
    z = np.load(good_run / "path_u.npz")
    u = z["u"][-1]
    e = ShellEnergy(shell)
    E, A = e.face_energies(shell.rest_positions + u)
    mesh = shell.mesh
    faces = mesh.faces[: mesh.n_real_faces]
    area = np.zeros(mesh.n_real)
    np.add.at(area, faces, np.repeat(A[: mesh.n_real_faces, None] / 3, 3, axis=1))
    assert float(dens @ area) == pytest.approx(e.energy(shell.rest_positions + u), rel=1e-10)


def test_output_folder_is_checked_before_any_work(tmp_path, capsys):
    """A --out that holds other files, is a file, or cannot be created is refused in one line
    before the problem is even read (so nothing is solved for nothing)."""
    other = tmp_path / "photos"
    other.mkdir()
    (other / "holiday.jpg").write_bytes(b"x")
    afile = tmp_path / "afile"
    afile.write_text("x")
    missing_problem = str(tmp_path / "nope.toml")           # would fail later, if the check came later
    for out, msg in ((other, "not a graspdef run folder"), (afile, "is a file")):
        assert main(["-q", "solve", missing_problem, "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and msg in err[0], err
    assert (other / "holiday.jpg").read_bytes() == b"x"


def test_a_linear_result_beyond_the_thickness_carries_a_warning(tmp_path, capsys):
    """Linear theory with a deflection larger than the thickness: the run is written, its record
    carries the warning, the CLI prints it and the reader shows it among the run's notes."""
    src = tmp_path / "p.toml"
    src.write_text(CANTILEVER_MM.replace('type = "nonlinear"\nmethod = "load"\nsteps = 3', 'type = "linear"')
                   .replace("force = [0.0, 0.0, 0.02]", "force = [0.0, 0.0, 0.2]"))
    assert main(["solve", str(src), "--out", str(tmp_path / "run")]) == 0
    err = capsys.readouterr().err
    assert "graspdef: warning: linear result with a max. displacement" in err
    run = read_run(tmp_path / "run")
    assert run.max_displacement() > 1e-3 and any("use the nonlinear analysis" in n for n in run.notes)
