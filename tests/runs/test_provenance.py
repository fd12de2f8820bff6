"""provenance.json: every run folder records its exact config and the versions it was made with."""
import json

from graspdef.cli import main
from graspdef.runs.provenance import (
    provenance_record,
    read_provenance,
    write_provenance,
)
from graspdef.testing import plate_problem

PLATE = plate_problem("tiny_plate", 4, probe=False)


def test_record_has_versions_command_and_config(tmp_path):
    rec = provenance_record({"answer": 42}, ["graspdef", "solve", "x.toml"])
    assert rec["config"] == {"answer": 42}
    assert rec["command"] == ["graspdef", "solve", "x.toml"]
    assert rec["graspdef"]["version"] and rec["python"].count(".") == 2
    assert rec["packages"]["numpy"] and rec["packages"]["scipy"]
    assert rec["time_utc"].endswith("+00:00")
    write_provenance(tmp_path, {"a": [1, 2]}, ["x"], extra_field="y")
    back = read_provenance(tmp_path)
    assert back["config"] == {"a": [1, 2]} and back["extra_field"] == "y"


def test_solve_run_folder_reproducible_from_itself(tmp_path, capsys):
    """The folder holds the exact problem text; solving that copy again gives the same result."""
    f = tmp_path / "p.toml"
    f.write_text(PLATE)
    assert main(["-q", "solve", str(f), "--out", str(tmp_path / "a")]) == 0
    prov = read_provenance(tmp_path / "a")
    assert prov["config"]["text"] == PLATE
    assert (tmp_path / "a" / "problem.toml").read_text() == PLATE
    assert main(["-q", "solve", str(tmp_path / "a" / "problem.toml"), "--out", str(tmp_path / "b")]) == 0
    ra, rb = (json.loads((tmp_path / d / "result.json").read_text()) for d in "ab")
    assert ra["derived"]["max_displacement"] == rb["derived"]["max_displacement"]
