"""``graspdef rank``: the ranking folder of an object (its table's invariants, the Pareto front,
the rank correlation, the compliance map, the stored shapes), the same ranking on Dask, a
candidate's scene posed for the nonlinear recheck, and the recheck itself (slow)."""
from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from scipy.stats import spearmanr

from graspdef.cli import main
from graspdef.objects.add import add_object
from graspdef.objects.data import MaterialSpec
from graspdef.ranking import rank_object
from graspdef.runs.ranking import read_ranking

FORCE = 5.0


@pytest.fixture(scope="module")
def egg(tmp_path_factory):
    """An ellipsoidal plastic shell (semi-axes 25 x 20 x 40 mm, wall 1 mm, Saint Venant-Kirchhoff
    with E 1 GPa, nu 0.35, 30 g): a made-up test object whose ends are stiffer than its sides."""
    tmp = tmp_path_factory.mktemp("egg")
    m = trimesh.creation.icosphere(4, 1.0)
    m.apply_scale([25.0, 20.0, 40.0])
    m.export(tmp / "egg_mm.stl")
    add_object("egg", tmp / "egg_mm.stl", tmp / "egg", units="mm", thickness=0.001,
               material=MaterialSpec("svk", 1e9, 0.35, None, "test"), mass=0.03, faces=800)
    return tmp / "egg"


@pytest.fixture(scope="module")
def ranked(egg, tmp_path_factory):
    out = tmp_path_factory.mktemp("rank") / "egg_rank"
    rec = rank_object(egg, FORCE, 300, out, strain_limit=0.02)
    return rec, read_ranking(out)


def test_table_is_ranked_by_the_stated_criterion(ranked):
    """Ranks 1..n in order; candidates that hold first, each group by least work; every held row
    keeps its margins (deformed friction margin > 0, weight ratios < 1, strain <= limit)."""
    rec, r = ranked
    t = r.table
    n = r.n
    assert n == rec["n_candidates"] and 100 <= n <= 300
    assert list(t["rank"]) == list(range(1, n + 1))
    assert sorted(t["candidate"]) == list(range(n)) and sorted(t["rigid_rank"]) == list(range(1, n + 1))
    held = t["held"].astype(bool)
    k = int(held.sum())
    assert 0 < k and held[:k].all() and not held[k:].any()
    for part in (slice(0, k), slice(k, n)):
        assert np.all(np.diff(t["work_J"][part]) >= 0)
    h = held
    assert np.all(t["deformed_friction_margin_deg"][h] > 0) and np.all(t["weight_torque_ratio"][h] <= 1 + 1e-9)
    assert np.all(t["weight_slip_ratio"][h] <= 1 + 1e-9) and np.all(t["strain_limit_ratio"][h] <= 1)
    np.testing.assert_allclose(t["strain_limit_ratio"], t["peak_strain"] / 0.02, rtol=1e-8)
    np.testing.assert_allclose(t["work_J"], 0.5 * FORCE * t["closing_m"], rtol=1e-8)
    np.testing.assert_allclose(t["strain_energy_J"], t["work_J"], rtol=1e-7)          # Clapeyron
    np.testing.assert_allclose(t["indentation_per_finger_m"], t["closing_m"] / 2, rtol=1e-8)


def test_pareto_flags_are_the_non_dominated_candidates(ranked):
    """Brute force: a row is on the front iff no other has less (or equal) work and a larger (or
    equal) deformed friction margin, one of them strictly."""
    _, r = ranked
    w, m = r.table["work_J"], r.table["deformed_friction_margin_deg"]
    dominated = np.array([np.any((w <= w[i]) & (m >= m[i]) & ((w < w[i]) | (m > m[i]))) for i in range(r.n)])
    np.testing.assert_array_equal(r.table["pareto"].astype(bool), ~dominated)


def test_rank_correlation_is_the_tables(ranked):
    rec, r = ranked
    rho = spearmanr(r.table["rank"], r.table["rigid_rank"]).statistic
    assert rec["rank_correlation"]["rigid_vs_deformable_spearman"] == pytest.approx(rho, abs=1e-12)
    assert r.record["rank_correlation"]["rigid_vs_deformable_spearman"] == pytest.approx(rho, abs=1e-12)


def test_compliance_map_and_shapes(ranked):
    """The map: positive compliance at most vertices (NaN only where the normal line finds no far
    side), stiffness its inverse; the ends of the egg (|z| > 30 mm) stiffer than its waist
    (|z| < 10 mm).  The stored shapes are the best candidates' displacements: their largest
    magnitude is at most the row's max displacement and at least half the indentation."""
    _, r = ranked
    c = r.compliance
    ok = np.isfinite(c)
    assert ok.mean() > 0.9 and np.all(c[ok] > 0)
    np.testing.assert_allclose(r.stiffness[ok], 1.0 / c[ok], rtol=1e-12)
    z = r.vertices[:, 2]
    assert np.nanmedian(c[np.abs(z) > 0.030]) < np.nanmedian(c[np.abs(z) < 0.010])
    assert len(r.shape_candidates) == min(50, r.n)
    np.testing.assert_array_equal(r.shape_candidates, r.table["candidate"][: len(r.shape_candidates)])
    for i in range(3):
        row = r.row(i)
        u = np.linalg.norm(r.displacement_of(row["candidate"]), axis=1).max()
        assert 0.5 * row["indentation_per_finger_m"] <= u <= row["max_displacement_m"] * (1 + 1e-6)


def test_force_range_ranks_each_candidate_at_its_least_holding_force(egg, ranked, tmp_path):
    """--force-range A B: each candidate at max(A, its least holding force) -- slip m g / (2 mu)
    and twist m g off / (2 torsional friction) -- or B when that exceeds B; linear theory, so
    every candidate's compliance (closing / force) equals the fixed-force ranking's (to 1e-7: the
    CSV's 9 significant digits); the
    held ones sit at ratios of at most 1, with one of them exactly 1 unless the force is A."""
    from graspdef.ranking.run import TORSIONAL_FRICTION, G

    _, fixed = ranked
    rec = rank_object(egg, None, 300, tmp_path / "fr", force_range=(0.5, 8.0), strain_limit=0.02, with_map=False)
    r = read_ranking(tmp_path / "fr")
    t = r.table
    assert rec["force_range_N"] == [0.5, 8.0] and np.all((t["force_N"] >= 0.5) & (t["force_N"] <= 8.0))
    p, q = r.contacts()
    d = (q - p) / np.linalg.norm(q - p, axis=1, keepdims=True)
    off = np.linalg.norm(np.cross(np.array(rec["centre_of_mass_m"]) - p, d), axis=1)
    need = np.maximum(rec["mass_kg"] * G / (2 * rec["friction"]), rec["mass_kg"] * G * off / (2 * TORSIONAL_FRICTION))
    np.testing.assert_allclose(t["force_N"], np.clip(need, 0.5, 8.0), rtol=1e-6)
    np.testing.assert_allclose(t["work_J"], 0.5 * t["force_N"] * t["closing_m"], rtol=1e-8)
    by = {c: k for k, c in enumerate(fixed.table["candidate"])}
    k = np.array([by[c] for c in t["candidate"]])
    np.testing.assert_allclose(t["closing_m"] / t["force_N"], fixed.table["closing_m"][k] / FORCE, rtol=1e-7)
    h = t["held"] == 1
    assert h.sum() > 0
    top = np.maximum(t["weight_torque_ratio"], t["weight_slip_ratio"])
    assert np.all(top[h] <= 1 + 1e-9)
    at_limit = h & (t["force_N"] > 0.5)
    np.testing.assert_allclose(top[at_limit], 1.0, rtol=1e-6)


def test_same_ranking_on_dask(egg, ranked, tmp_path):
    """The screen spread over Dask workers in chunks gives the local screen's figures (to 1e-9)
    and so the same ranking."""
    pytest.importorskip("distributed")
    from graspdef.sweep.rank import rank_on_dask

    rec = rank_on_dask(egg, FORCE, 300, tmp_path / "dask", workers=1, chunks=3, strain_limit=0.02, with_map=False)
    d = read_ranking(tmp_path / "dask")
    _, r = ranked
    assert rec["dask"]["chunks"] == 3
    np.testing.assert_array_equal(d.table["candidate"], r.table["candidate"])
    np.testing.assert_allclose(d.table["work_J"], r.table["work_J"], rtol=1e-9)
    np.testing.assert_allclose(d.table["deformed_friction_margin_deg"], r.table["deformed_friction_margin_deg"],
                               atol=1e-9)


def test_posed_scene_puts_the_candidate_on_the_gripper_axis(egg, ranked, tmp_path):
    """The recheck's scene for the best candidate compiles in MuJoCo and places the candidate's
    contacts on the world x axis (the fingers' closing line), symmetric about the origin."""
    from graspdef.objects import load_object
    from graspdef.objects.build import outer_surface
    from graspdef.objects.placement import Grasp
    from graspdef.ranking.recheck import posed_scene
    from graspdef.sim.scene import load_scene

    _, r = ranked
    row = r.row(0)
    p = np.array([row["first_x_m"], row["first_y_m"], row["first_z_m"]])
    q = np.array([row["second_x_m"], row["second_y_m"], row["second_z_m"]])
    spec = load_object(egg)
    outer, _ = outer_surface(spec)
    xml = posed_scene(egg, "egg", Grasp(p, q, (q - p) / np.linalg.norm(q - p), 0.0, "test"), outer, tmp_path / "c")
    sc = load_scene(xml, "egg")
    import mujoco

    mujoco.mj_forward(sc.model, sc.data)
    R = sc.data.xmat[sc.object_body].reshape(3, 3)
    x = sc.data.xpos[sc.object_body]
    w = np.array([R @ p + x, R @ q + x])
    np.testing.assert_allclose(w[:, 1:], 0.0, atol=1e-6)
    assert w[0, 0] == pytest.approx(-w[1, 0], abs=1e-6)


def test_cli_rank_prints_the_table(egg, tmp_path, capsys):
    code = main(["-q", "rank", str(egg), "--force", "5N", "--candidates", "40", "--no-map", "--out",
                 str(tmp_path / "r")])
    out = capsys.readouterr().out
    assert code == 0 and "40 candidates at 5 N per finger" in out and "rigid vs deformable" in out
    assert (tmp_path / "r" / "ranking.csv").read_text().count("\n") == 41
    # a ranking folder is replaced by the next ranking
    assert main(["-q", "rank", str(egg), "--force", "5N", "--candidates", "20", "--no-map", "--out",
                 str(tmp_path / "r")]) == 0
    assert (tmp_path / "r" / "ranking.csv").read_text().count("\n") == 21


@pytest.mark.slow
def test_recheck_runs_the_best_candidates_nonlinear(egg, tmp_path):
    """The best two candidates grasped by the whole nonlinear chain (pads, MuJoCo friction, its
    contact forces as loads) at 60 N (linear indentation ~0.3 mm, a third of the wall): both run and
    close the fingers; the pads spread the force, so the closing is at most the linear point-load
    screen's plus 50 %.  (What the README reports is the rank correlation of the tutorial bottle's
    best 10.)"""
    rec = rank_object(egg, 60.0, 100, tmp_path / "r", recheck=2, with_map=False)
    assert len(rec["recheck"]) == 2
    for e in rec["recheck"]:
        assert e["status"] == "ok", e
        assert 0 < e["nonlinear_closing_m"] <= 1.5 * e["linear_closing_m"], e
    assert math.isnan(rec["recheck_spearman"])             # fewer than 3 candidates: no correlation
