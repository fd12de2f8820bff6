"""``graspdef report``: a self-contained page with the run's numbers, the scan comparison, the
load path and the Table I layout; every bad input is one clear error and leaves nothing behind."""
from __future__ import annotations

import json
import re
import shutil

import numpy as np
import pytest

from graspdef.errors import GraspdefError
from graspdef.report.build import ReportError, build_report
from graspdef.cli import main as graspdef_main


def report_main(argv):
    return graspdef_main(["report", *argv])


def _self_contained(text: str) -> None:
    assert not re.search(r"https?://", text), "the page refers to an external URL"
    for src in re.findall(r'src="([^"]*)"', text):
        assert src.startswith("data:image/png;base64,"), src[:40]
    assert "<script" not in text and "<link" not in text


def test_page_is_self_contained_and_has_the_numbers(scored_report):
    text = (scored_report / "report.html").read_text()
    _self_contained(text)
    rec = json.loads((scored_report / "result.json").read_text())
    md = rec["derived"]["max_displacement"]
    assert re.search(rf"max\. displacement \[mm\]</td><td[^>]*>{md['value'] * 1e3:.4g}<", text)
    uz = rec["probes"]["top"]["displacement"][2] * 1e3
    assert f"{uz:.4g}" in text
    assert "units of the run" in text and "length m" in text
    assert len(re.findall(r"<img ", text)) == 2                        # displacement + scan error
    score = json.loads((scored_report / "score" / "score.json").read_text())
    assert f"{score['prediction']['errors']['rms_mm']:.4g}" in text
    assert f"{score['baseline']['errors']['rms_mm']:.4g}" in text
    # the scan was made 0.3 mm outside the prediction: the score says so
    assert 0.2 < score["prediction"]["errors"]["mean_mm"] < 0.5
    assert score["prediction"]["errors"]["mean_signed_mm"] > 0.2


def test_load_path_plots_and_default_output(cantilever_run, tmp_path):
    d = tmp_path / "cantilever"
    shutil.copytree(cantilever_run, d)
    out = build_report([d])
    assert out == d / "report.html"
    text = out.read_text()
    _self_contained(text)
    assert 'alt="load-deflection"' in text and 'alt="Newton iterations"' in text
    rec = json.loads((d / "result.json").read_text())
    its = rec["convergence"]["newton_iterations"]
    assert f"{len(its)} / {sum(its)}" in text
    assert "consistent units" in text
    assert "table-i-table" not in text                                 # no forces: no Table I


def test_table_i_layout_from_a_table_file(ball_run, cantilever_run, tmp_path):
    (tmp_path / "runs.csv").write_text(f"run,force_N,measured_mm\n{ball_run},10.63,\n{ball_run},21.48,11.0\n")
    out = build_report([], tmp_path / "t.html", table=tmp_path / "runs.csv")
    text = out.read_text()
    table = text[text.index('id="table-i-table"'):]
    table = table[: table.index("</table>")]
    rows = [r for r in re.findall(r"<tr>(.*?)</tr>", table) if "<td" in r]
    assert len(rows) == 2
    cells = [re.findall(r"<td[^>]*>(.*?)</td>", r) for r in rows]
    assert cells[0][0] == "10.63" and cells[0][1] == "2.56"            # the paper's measured value
    assert cells[1][0] == "21.48" and cells[1][1] == "11"              # the file's value
    md = json.loads((ball_run / "result.json").read_text())["derived"]["max_displacement"]["value"] * 1e3   # mm
    assert cells[0][4] == f"{md:.3g}"                                  # linear column
    assert cells[0][5].startswith(f"{abs(md - 2.56):.3g}")             # |predicted - measured|
    assert cells[0][2] == "&ndash;"                                    # no nonlinear run given
    assert cells[0][6] == "0.31" and cells[1][7] == "2.37"             # the paper's errors


def test_flagged_score_is_shown(scored_report, tmp_path):
    d = tmp_path / "ball"
    shutil.copytree(scored_report, d)
    rec = json.loads((d / "score" / "score.json").read_text())
    rec["flags"], rec["ok"] = ["prediction: not_converged"], False
    (d / "score" / "score.json").write_text(json.dumps(rec))
    assert report_main([str(d)]) == 1                    # written, but the exit status says "flagged"
    text = (d / "report.html").read_text()
    assert "flagged score" in text and "not_converged" in text


@pytest.mark.parametrize("case, msg", [
    ("missing", "does not exist"),
    ("not_a_run", "incomplete: missing result.json"),
    ("out_is_dir", "is a folder"),
    ("bad_table", "needs a header line with a 'run' column"),
    ("consistent_scan", "consistent units"),
    ("empty_scan", "scan"),
])
def test_bad_input_is_one_line_and_writes_nothing(case, msg, ball_run, cantilever_run, tmp_path, capsys):
    d = tmp_path / "ball"
    shutil.copytree(ball_run, d)
    args = {"missing": [str(tmp_path / "nowhere")],
            "not_a_run": [str(tmp_path)],
            "out_is_dir": [str(d), "--out", str(tmp_path)],
            "bad_table": ["--table", str(tmp_path / "t.csv"), "--out", str(tmp_path / "r.html")],
            "consistent_scan": [str(cantilever_run), "--scan", str(d / "deformed.ply"), "--out", str(tmp_path / "r.html")],
            "empty_scan": [str(d), "--scan", str(tmp_path / "empty.ply")]}[case]
    (tmp_path / "t.csv").write_text("folder\nx\n")
    (tmp_path / "empty.ply").write_text("ply\nformat ascii 1.0\ncomment units mm\nelement vertex 0\n"
                                        "property float x\nproperty float y\nproperty float z\nend_header\n")
    before = sorted(p.name for p in tmp_path.rglob("*"))
    assert report_main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("graspdef: error:") and msg in err[-1], err
    assert sorted(p.name for p in tmp_path.rglob("*")) == before          # nothing written


@pytest.mark.parametrize("case, msg", [("plane", "overlap"), ("mm_as_m", "mm")])
def test_wrong_scan_is_refused(case, msg, ball_run, ball_scan, tmp_path):
    """A scan of something else (a wavy patch of the ball's size) cannot be registered; a scan in
    mm declared as metres is caught by its size.  Nothing is written."""
    import trimesh

    from graspdef.geometry.io import save_ply

    d = tmp_path / "ball"
    shutil.copytree(ball_run, d)
    if case == "plane":
        g = np.linspace(-0.03, 0.03, 60)
        x, y = np.meshgrid(g, g)
        pts = np.c_[x.ravel(), y.ravel(), 0.01 * np.sin(150 * x.ravel()) * np.cos(120 * y.ravel())]
    else:
        pts = np.asarray(trimesh.load(ball_scan, process=False).vertices) * 1e3
    save_ply(tmp_path / "scan.ply", pts, np.zeros((0, 3), int), units="m")
    with pytest.raises(GraspdefError, match=msg):
        build_report([d], scan=str(tmp_path / "scan.ply"))
    assert not (d / "report.html").exists() and not (d / "score").exists()


def test_wired_into_graspdef_cli(capsys):
    from graspdef.cli import main

    assert main(["report", "/nonexistent/run"]) == 2
    assert "run folder /nonexistent/run does not exist" in capsys.readouterr().err


def test_failed_report_keeps_the_previous_one(ball_run, tmp_path):
    d = tmp_path / "ball"
    shutil.copytree(ball_run, d)
    out = build_report([d])
    old = out.read_bytes()
    (tmp_path / "t.csv").write_text("run\nnowhere\n")
    with pytest.raises(GraspdefError):
        build_report([d], table=tmp_path / "t.csv")
    assert out.read_bytes() == old
    assert sorted(p.name for p in d.iterdir() if p.name.startswith(".report-")) == []
    with pytest.raises(ReportError, match="no run folders"):
        build_report([])


def test_paper_values_only_for_the_tennis_ball_forces():
    from graspdef.report.build import paper_row

    assert paper_row(10.63, "tennis_ball")["measured_max_mm"] == 2.56
    assert paper_row(21.47, None)["measured_max_mm"] == 10.27           # within 0.05 N
    assert paper_row(10.63, "duck") is None
    assert paper_row(10.75, "tennis_ball") is None and paper_row(None) is None


def test_a_stopped_path_is_marked_and_gets_no_error(cantilever_run, tmp_path):
    d = tmp_path / "stopped"
    shutil.copytree(cantilever_run, d)
    rec = json.loads((d / "result.json").read_text())
    rec["convergence"].update(completed=False, stop_reason="Newton did not converge (test)", load_factor=0.5)
    (d / "result.json").write_text(json.dumps(rec))
    (tmp_path / "runs.csv").write_text("run,force_N\nstopped,10.63\n")
    text = build_report([], tmp_path / "r.html", table=tmp_path / "runs.csv").read_text()
    row = re.findall(r"<tr>(<td.*?)</tr>", text[text.index('id="table-i-table"'):])[0]
    cells = re.findall(r"<td[^>]*>(.*?)</td>", row)
    assert "path stopped at load factor 0.5" in cells[2] and cells[3] == "&ndash;"
    assert "Newton did not converge (test)" in text and "the load path stopped" in text


def test_no_measurement_no_comparison_table(ball_run, tmp_path):
    """Measured vs predicted appears only where a measurement exists: the same run listed at a
    force the paper did not measure (and no measured_mm) gets no Table I; with a measured value
    in the table file it does."""
    (tmp_path / "runs.csv").write_text(f"run,force_N\n{ball_run},7.0\n{ball_run},8.0\n")
    text = build_report([], tmp_path / "t.html", table=tmp_path / "runs.csv").read_text()
    assert "table-i-table" not in text and "Table I" not in text
    (tmp_path / "runs.csv").write_text(f"run,force_N,measured_mm\n{ball_run},7.0,1.5\n{ball_run},8.0,\n")
    text = build_report([], tmp_path / "t2.html", table=tmp_path / "runs.csv").read_text()
    assert "table-i-table" in text
