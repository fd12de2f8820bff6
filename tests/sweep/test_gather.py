"""Gathering and resuming without a cluster: a sweep folder whose cases are all final is
re-gathered by ``graspdef sweep DIR`` (no cluster started, nothing recomputed)."""
import csv
import json

from graspdef.cli import main
from graspdef.sweep import parse_spec
from graspdef.sweep.run import CASES, COLUMNS

SPEC = """
[sweep]
name = "g"
[grid]
scenes = ["tennis_ball"]
forces_N = [5.0, 10.0]
materials = ["linear"]
control_faces = [320]
"""


def _fake_folder(tmp_path):
    spec = parse_spec(SPEC, "g.toml")
    out = tmp_path / "sw"
    (out / CASES).mkdir(parents=True)
    (out / "spec.toml").write_text(SPEC)
    done, failed = spec.cases
    (out / CASES / done.id).mkdir()
    (out / CASES / done.id / "case.json").write_text(json.dumps({
        "case": done.record(), "status": "done", "attempts": 1, "error": None, "seconds": 2.5,
        "results": {"max_displacement_m": 0.0090093, "indentation_m": 0.0089316, "completed": True,
                    "load_factor": 1.0, "control_vertices": 162, "control_faces": 320, "E_Pa": 1e6,
                    "gas_p0_Pa": 0.0, "normal_force_N": {"left": 4.99, "right": 5.0},
                    "net_force_residual_N": 6e-14}}))
    (out / CASES / failed.id).mkdir()
    (out / CASES / failed.id / "case.json").write_text(json.dumps({
        "case": failed.record(), "status": "failed", "attempts": 2, "error": "SimError: boom", "seconds": None,
        "results": None}))
    (out / CASES / f".{done.id}.tmp123").mkdir()           # a killed worker's leftover
    return spec, out


def test_regather_without_cluster(tmp_path, capsys):
    spec, out = _fake_folder(tmp_path)
    assert main(["sweep", str(out)]) == 1                   # one case failed
    captured = capsys.readouterr()
    assert "all 2 cases already final" in captured.err and "starting a local cluster" not in captured.err
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert list(rows[0]) == COLUMNS
    assert [r["status"] for r in rows] == ["done", "failed"]
    assert float(rows[0]["max_displacement_mm"]) == 0.0090093 * 1e3
    assert rows[1]["error"] == "SimError: boom" and rows[1]["attempts"] == "2"
    summary = (out / "summary.md").read_text()
    assert "**1 done**, **1 failed**" in summary and "SimError: boom" in summary
    assert not [p for p in (out / CASES).iterdir() if p.name.startswith(".") and p.name != ".running"]
    assert json.loads((out / "provenance.json").read_text())["config"]["text"] == SPEC
    assert len((out / "runs.jsonl").read_text().splitlines()) == 1
