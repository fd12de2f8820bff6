"""The viewer of a ranking folder (graspdef rank --out), server side without a browser.  The folder is
the synthetic fixture of tests/conftest.py (made-up but consistent numbers, written with
graspdef.runs.ranking.write_ranking)."""
from __future__ import annotations

import shutil

import numpy as np
import pytest

import viser  # noqa: F401  (the viewer extra is part of make test)

from graspdef.cli import main as graspdef_main
from graspdef.runs.ranking import RankingFolderError, read_ranking
from graspdef.viewer import layers
from graspdef.viewer.ranking import RankingViewer, row_markdown
from graspdef.viewer.server import ViewerError


def test_segments_capped_and_coloured_by_rank(synthetic_ranking):
    with RankingViewer(synthetic_ranking, port=0) as v:
        r = v.ranking
        assert r.n == 240 and v.n_drawn == 200                     # the default cap: the best 200
        pts = v.segments_handle.points
        assert pts.shape == (200, 2, 3)
        first, second = r.contacts()                               # rank order, as written
        np.testing.assert_allclose(pts[:, 0], v.to_display(first[:200]), atol=1e-6)
        np.testing.assert_allclose(pts[:, 1], v.to_display(second[:200]), atol=1e-6)
        np.testing.assert_array_equal(v.drawn_ranks, np.arange(1, 201))
        cols = v.segments_handle.colors
        assert cols.shape == (200, 2, 3)
        np.testing.assert_array_equal(cols[0, 0], layers.RANKS[0])     # rank 1: green
        np.testing.assert_array_equal(cols[-1, 1], layers.RANKS[-1])   # rank 200: red
        assert "the best 200 of 240 candidates" in v.segments_note.content
        dots = v.contacts_handle.points                              # both contacts of every drawn candidate
        assert dots.shape == (400, 3)
        np.testing.assert_allclose(dots[:200], pts[:, 0], atol=1e-3)   # float16 on the wire
        v.segments_check.value = False
        assert not v.segments_handle.visible and not v.contacts_handle.visible
        assert v.surface_handle.visible and not v.translucent_handle.visible
        v.surface_dropdown.value = "translucent"                       # the segments inside show
        assert not v.surface_handle.visible and v.translucent_handle.visible
        v.surface_dropdown.value = "hidden"
        assert not v.surface_handle.visible and not v.translucent_handle.visible
    with RankingViewer(synthetic_ranking, port=0, top=40) as v:
        assert v.segments_handle.points.shape == (40, 2, 3)
        assert "the best 40 of 240" in v.segments_note.content
    with RankingViewer(synthetic_ranking, port=0, top=1000) as v:
        assert v.segments_handle.points.shape == (240, 2, 3) and "all 240 candidates" in v.segments_note.content


def test_nan_compliance_is_grey_and_log_scaled(synthetic_ranking):
    with RankingViewer(synthetic_ranking, port=0) as v:
        comp = v.ranking.compliance
        nan = np.isnan(comp)
        assert 0 < nan.sum() < len(comp)                            # the fixture's cap has no pinch
        assert (v.surface_colours[nan] == layers.NAN_GREY).all()
        assert not (v.surface_colours[~nan] == layers.NAN_GREY).all(axis=1).any()
        lo, hi = v.compliance_range                                 # mm/N, the finite range
        assert lo == pytest.approx(np.nanmin(comp) * 1e3) and hi == pytest.approx(np.nanmax(comp) * 1e3)
        i_lo, i_hi = np.nanargmin(comp), np.nanargmax(comp)
        np.testing.assert_array_equal(v.surface_colours[i_lo], layers.VIRIDIS[0])
        np.testing.assert_array_equal(v.surface_colours[i_hi], layers.VIRIDIS[-1])
        mid = np.sqrt(lo * hi)                                      # log scale: the geometric mean is the middle
        np.testing.assert_array_equal(layers.log_colormap(np.array([mid]), lo, hi)[0], layers.VIRIDIS[4])


def test_pick_stored_candidate_shows_rest_plus_displacement(synthetic_ranking):
    with RankingViewer(synthetic_ranking, port=0) as v:
        r = v.ranking
        assert [rk for rk, _ in v.stored] == [1, 2, 3, 4, 5, 6]    # shapes.npz holds the best 6
        best = v.stored[0][1]
        assert v.candidate == best and "**rank 1**" in v.row_panel.content
        rest_plus = lambda c, m=1.0: v.to_display(r.vertices + m * r.displacement_of(c), v.offset)  # noqa: E731
        np.testing.assert_allclose(v.displayed, rest_plus(best), atol=1e-6)
        rank3, cand3 = v.stored[2]
        v.pick_dropdown.value = f"rank {rank3} · candidate {cand3}"     # what the dropdown does
        assert v.candidate == cand3
        np.testing.assert_allclose(v.displayed, rest_plus(cand3), atol=1e-6)
        u = r.displacement_of(cand3)
        assert np.abs(v.displayed - v.to_display(r.vertices, v.offset)).max() > 0.5 * np.abs(u).max() / v.lref
        v.set_magnification(10.0)
        np.testing.assert_allclose(v.displayed, rest_plus(cand3, 10.0), atol=1e-6)
        v.set_magnification(0.0)
        np.testing.assert_allclose(v.displayed, v.to_display(r.vertices, v.offset), atol=1e-6)
        text = v.show_candidate(v.stored[1][1])                    # programmatic pick, by candidate number
        row = r.row(1)
        assert v.pick_dropdown.value == f"rank 2 · candidate {row['candidate']}"
        assert f"{row['work_J'] * 1e3:.4g} mJ" in text and f"{row['grasp_stiffness_N_per_m'] * 1e-3:.4g} N/mm" in text
        assert f"{row['indentation_per_finger_m'] * 1e3:.4g} mm" in text and f"{row['peak_strain'] * 100:.4g} %" in text
        assert f"{row['deformed_friction_margin_deg']:.4g} °" in text and "| held | yes |" in text
        with pytest.raises(ViewerError, match="no stored shape"):
            v.show_candidate(int(r.table["candidate"][-1]))


def test_row_markdown_units():
    row = {"rank": 3, "rigid_rank": 7, "candidate": 11, "width_m": 0.05, "indentation_per_finger_m": 0.001,
           "closing_m": 0.002, "work_J": 0.004, "grasp_stiffness_N_per_m": 2500.0, "max_displacement_m": 0.003,
           "peak_strain": 0.015, "peak_von_mises_Pa": 2e5, "strain_limit_ratio": float("nan"),
           "contact_area_m2": 1e-4, "friction_margin_deg": 10.0, "deformed_friction_margin_deg": -1.5,
           "weight_torque_ratio": 0.5, "weight_slip_ratio": 0.2, "held": 0, "pareto": 1}
    md = row_markdown(row)
    for s in ("| indentation per finger | 1 mm |", "| work | 4 mJ |", "| grasp stiffness | 2.5 N/mm |",
              "| peak strain | 1.5 % |", "| strain limit ratio | – |", "| contact area per finger | 100 mm² |",
              "| friction margin, deformed | -1.5 ° |", "| held | no |", "| on the Pareto front | yes |"):
        assert s in md, s


def _damaged(src, dst, how):
    shutil.copytree(src, dst)
    if how == "no_shapes":
        (dst / "shapes.npz").unlink()
    elif how == "columns":
        lines = (dst / "ranking.csv").read_text().splitlines()
        lines[0] = lines[0].replace("work_J", "work_mJ")
        (dst / "ranking.csv").write_text("\n".join(lines) + "\n")
    return dst


@pytest.mark.parametrize("how, message", [("no_shapes", "shapes.npz is missing"),
                                          ("columns", "ranking.csv: columns")])
def test_damaged_ranking_folder_one_line_exit_2(synthetic_ranking, tmp_path, capsys, how, message):
    d = _damaged(synthetic_ranking, tmp_path / how, how)
    with pytest.raises(RankingFolderError, match=message):
        read_ranking(d)
    assert graspdef_main(["view", str(d), "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("graspdef: error: ") and message in err and err.count("\n") == 1


def test_cli_refuses_mixing_ranking_with_runs(synthetic_ranking, tmp_path, capsys):
    assert graspdef_main(["view", str(synthetic_ranking), str(tmp_path), "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert "is a ranking folder: view it on its own" in err and err.count("\n") == 1
    assert graspdef_main(["view", str(tmp_path), "--top", "5", "--port", "0"]) == 2
    assert "--top is for a ranking folder" in capsys.readouterr().err


def test_cli_serves_a_ranking_folder(synthetic_ranking, monkeypatch, capsys):
    seen = {}

    def no_wait(self):                                          # instead of blocking until Ctrl-C
        seen.update(host=self.host, drawn=self.n_drawn, url=self.url)

    monkeypatch.setattr(RankingViewer, "wait", no_wait)
    assert graspdef_main(["view", str(synthetic_ranking), "--port", "0", "--top", "10"]) == 0
    assert seen["host"] == "127.0.0.1" and seen["drawn"] == 10           # this machine only, by default
    assert f"viewer at {seen['url']} (ranking " in capsys.readouterr().err
