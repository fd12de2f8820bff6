"""The report of a ranking folder (graspdef rank --out).  The folder is the synthetic fixture of
tests/conftest.py (made-up but consistent numbers, written with graspdef.runs.ranking.write_ranking)."""
from __future__ import annotations

import base64
import re
import shutil

import numpy as np
import pytest

from graspdef.cli import main as graspdef_main
from graspdef.report import build_report
from graspdef.report.ranking import FIGURES, figures
from graspdef.runs.ranking import read_ranking

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def ranking_report(synthetic_ranking, tmp_path_factory):
    out = tmp_path_factory.mktemp("ranking_report") / "rank.html"
    assert graspdef_main(["-q", "report", str(synthetic_ranking), "--out", str(out)]) == 0
    return out


def _section(text: str, anchor: str) -> str:
    """The page from the heading ``id=anchor`` to the next h2."""
    start = text.index(f'id="{anchor}"')
    end = text.find("<h2", start)
    return text[start:] if end < 0 else text[start:end]


def test_every_section_and_figure(ranking_report, synthetic_ranking):
    text = ranking_report.read_text()
    r = read_ranking(synthetic_ranking)
    rec = r.record
    for anchor in ("summary", "top", "compliance", "pareto", "rigid", "recheck"):
        assert f'id="{anchor}"' in text, anchor
    summary = _section(text, "summary")
    for label, value in (("object", "fixture_icosphere"), ("force per finger [N]", "5"),
                         ("friction coefficient", "0.5"), ("material", "linear_elastic, E = 5 MPa, nu = 0.45"),
                         ("wall thickness [mm]", "2"), ("control vertices", "162"), ("candidates", "240"),
                         ("candidates per minute", f"{rec['candidates_per_minute']:.4g}"),
                         ("criterion", rec["ranking"])):
        assert f'<td class="l">{label}</td><td class="l">{value}</td>' in summary, label
    # the top ten: ranks 1..10 with their candidate numbers, as written in ranking.csv
    top = _section(text, "top")
    rows = re.findall(r"<tr><td>(\d+)</td><td>(\d+)</td>", top)
    assert [(int(a), int(b)) for a, b in rows] == list(zip(range(1, 11), r.table["candidate"][:10].tolist()))
    assert f"<td>{r.table['work_J'][0] * 1e3:.4g}</td>" in top
    # the rigid-vs-deformable correlation and the recheck's, from the record
    assert f"ρ = {rec['rank_correlation']['rigid_vs_deformable_spearman']:.3g}" in _section(text, "rigid")
    recheck = _section(text, "recheck")
    assert "nonlinear closing [mm]" in recheck and f"<b>{rec['recheck_spearman']:.3g}</b>" in recheck
    assert recheck.count("<tr>") == 1 + len(rec["recheck"])
    # pictures: inline (self-contained, as every report) and as files beside the page
    inline = re.findall(r'src="data:image/png;base64,([^"]+)"', text)
    assert len(inline) == len(FIGURES) == 3
    folder = ranking_report.parent / "rank_figures"
    assert sorted(p.name for p in folder.iterdir()) == sorted(FIGURES)
    for name, data in zip(FIGURES, inline):                         # the same pictures, in page order
        assert (folder / name).read_bytes()[:8] == PNG and base64.b64decode(data) == (folder / name).read_bytes()
    assert "http://" not in text and "https://" not in text


def test_pareto_front_is_the_flagged_rows(synthetic_ranking):
    r = read_ranking(synthetic_ranking)
    _, front = figures(r, views=("iso",))
    flagged = r.table["pareto"] == 1
    want = np.c_[r.table["work_J"][flagged] * 1e3, r.table["deformed_friction_margin_deg"][flagged]]
    assert 2 <= len(front) < r.n
    np.testing.assert_allclose(front, want[np.argsort(want[:, 0], kind="stable")])


def test_without_recheck_and_default_output(ranking_writer, tmp_path):
    d = ranking_writer(tmp_path / "rank", n_candidates=30, recheck=False)
    out = build_report([d])
    assert out == d / "report.html" and (d / "report_figures" / "pareto.png").is_file()
    text = out.read_text()
    assert 'id="recheck"' not in text and 'id="pareto"' in text
    assert "<h2 id=\"top\">Top 10</h2>" in text


@pytest.mark.parametrize("how, message", [("no_shapes", "shapes.npz is missing"),
                                          ("columns", "ranking.csv: columns")])
def test_damaged_ranking_folder_one_line_exit_2(synthetic_ranking, tmp_path, capsys, how, message):
    d = tmp_path / how
    shutil.copytree(synthetic_ranking, d)
    if how == "no_shapes":
        (d / "shapes.npz").unlink()
    else:
        lines = (d / "ranking.csv").read_text().splitlines()
        lines[0] = lines[0].replace("held", "grasped")
        (d / "ranking.csv").write_text("\n".join(lines) + "\n")
    assert graspdef_main(["report", str(d)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("graspdef: error: ") and message in err and err.count("\n") == 1
    assert not (d / "report.html").exists() and not (d / "report_figures").exists()     # nothing written


def test_ranking_is_reported_on_its_own(synthetic_ranking, tmp_path, capsys):
    assert graspdef_main(["report", str(synthetic_ranking), str(tmp_path), "--out", str(tmp_path / "x.html")]) == 2
    err = capsys.readouterr().err
    assert "is a ranking folder: report it on its own" in err and err.count("\n") == 1
    assert not (tmp_path / "x.html").exists()
