"""Reading run folders and building what the viewer draws (no server, no browser)."""
from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from graspdef.errors import GraspdefError
from graspdef.viewer import layers
from graspdef.runs.pathfile import read_path_u, write_path_u
from graspdef.runs.read import RunFolderError, read_run


def test_linear_run_in_mm(plate_run):
    run = read_run(plate_run)
    # the problem file is in mm; the run folder is SI and displays mm
    assert run.analysis == "linear" and run.length_unit == "m" and run.display_unit == "mm"
    assert run.rest_vertices.shape == run.deformed_vertices.shape == (121, 3)
    assert run.faces.shape == (200, 3)
    # SI inside: the plate is 0.1 m wide; the centre moves down (load -z)
    assert np.ptp(run.rest_vertices[:, 0]) == pytest.approx(0.1, rel=0.05)
    w = run.displacements[:, 2].min()
    assert w < 0 and -w == pytest.approx(run.max_displacement(), rel=1e-9)
    md = run.record.derived["max_displacement"]
    assert md["unit"] == "m" and md["surface"] == "mid" and not md["rigid_motion_removed"]
    assert np.linalg.norm(run.displacements, axis=1).max() == md["value"]         # the stored field defines it
    assert run.problem_file is not None and run.path_table is None


def test_contacts_and_scan_overlay(plate_run):
    run = read_run(plate_run)
    c = run.contacts
    assert [f["name"] for f in c.fingers] == ["top_pad", "bottom_pad"]
    np.testing.assert_allclose(c.points[0], [0, 0, 0.5e-3])
    np.testing.assert_allclose(c.forces[:, 2], [-2.0, 1.0])
    np.testing.assert_allclose(c.fingers[1]["wxyz"], [1, 0, 0, 0])            # default orientation
    s = run.scan                                                              # found in run/score/
    assert s.points.shape == (100, 3) and s.errors_mm.shape == (100,)
    np.testing.assert_allclose(s.points[:, 2], 0.0, atol=1e-12)              # 10 mm scan, t = -10 mm
    assert s.stats_mm["mean_mm"] == 0.25 and s.baseline_stats_mm["max_mm"] == 1.0


def test_nonlinear_run_with_path_u(cantilever_run):
    run = read_run(cantilever_run)
    t = run.path_table
    assert run.analysis == "nonlinear" and t.load_factors[0] == 0 and t.load_factors[-1] == 1
    assert set(t.probes) == {"tip"} and t.probes["tip"].shape == (len(t.load_factors), 3)
    u, lf, L = run.path_u
    assert u.shape[0] == len(lf) and L.shape == (len(run.rest_vertices), u.shape[1])
    np.testing.assert_allclose(run.path_displacements(len(lf) - 1), run.displacements, atol=1e-9)
    np.testing.assert_allclose(run.path_displacements(0), 0.0, atol=1e-15)


def test_path_u_roundtrip(tmp_path):
    import scipy.sparse as sp

    rng = np.random.default_rng(0)
    u = rng.normal(size=(3, 5, 3))
    L = sp.random(4, 5, density=0.5, random_state=1, format="csr")
    write_path_u(tmp_path, u, [0.0, 0.5, 1.0], L)
    u2, lf, L2 = read_path_u(tmp_path / "path_u.npz")
    np.testing.assert_array_equal(u, u2)
    np.testing.assert_array_equal((L - L2).toarray(), 0.0)
    with pytest.raises(ValueError, match="inconsistent"):
        write_path_u(tmp_path, u, [0.0, 1.0], L)


@pytest.mark.parametrize("damage, message", [
    ("missing", "does not exist"),
    ("no_result", "incomplete: missing result.json"),
    ("no_deformed", "incomplete: missing deformed.ply"),
    ("bad_json", "result.json is not valid JSON"),
    ("no_path_csv", "a nonlinear run needs path.csv"),
    ("mismatch", "do not match"),
    ("units", "states units 'm' but result.json says 'consistent'"),
    ("bad_path_u", "path_u.npz does not match"),
    ("bad_contacts", "contacts.json: contacts\\[0\\].force must be 3 finite numbers"),
])
def test_bad_run_folders(cantilever_run, plate_run, tmp_path, damage, message):
    d = tmp_path / "run"
    shutil.copytree(cantilever_run, d)
    if damage == "missing":
        d = tmp_path / "nowhere"
    elif damage == "no_result":
        (d / "result.json").unlink()
    elif damage == "no_deformed":
        (d / "deformed.ply").unlink()
    elif damage == "bad_json":
        (d / "result.json").write_text("{ not json")
    elif damage == "no_path_csv":
        (d / "path.csv").unlink()
    elif damage == "mismatch":
        from graspdef.geometry.io import save_ply

        save_ply(d / "undeformed.ply", np.eye(3), np.array([[0, 1, 2]]), units="consistent")
    elif damage == "units":
        shutil.copy(plate_run / "undeformed.ply", d / "undeformed.ply")
    elif damage == "bad_path_u":
        rows = (d / "path.csv").read_text().splitlines()
        (d / "path.csv").write_text("\n".join(rows[:-1]) + "\n")
    elif damage == "bad_contacts":
        (d / "contacts.json").write_text(json.dumps({"contacts": [{"position": [0, 0, 0], "force": [1, 2]}]}))
    with pytest.raises(RunFolderError, match=message) as info:
        read_run(d)
    assert isinstance(info.value, GraspdefError) and "\n" not in str(info.value)


def test_colormap_and_legend():
    c = layers.colormap(np.array([0.0, 0.5, 1.0, 2.0, np.nan]), 0.0, 1.0)
    assert c.shape == (5, 3) and c.dtype == np.uint8
    np.testing.assert_array_equal(c[0], layers.VIRIDIS[0])
    np.testing.assert_array_equal(c[2], layers.VIRIDIS[-1])
    np.testing.assert_array_equal(c[3], c[2])                                 # clipped
    assert np.all(layers.colormap(np.ones(3), 1.0, 1.0) == layers.VIRIDIS[0])  # zero range
    html = layers.legend_html("displacement |u|", "mm", 0.0, 1.27)
    assert "[mm]" in html and "linear-gradient" in html
    assert layers.nice_ticks(0.0, 1.27) == [0.0, 0.5, 1.0]
    assert layers.nice_ticks(0.0, 7.46) == [0.0, 2.0, 4.0, 6.0]


def test_force_arrows_proportional():
    p = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    f = np.array([[0.0, 0, -2.0], [0.0, 0, 1.0]])
    seg = layers.force_arrows(p, f, 0.3)
    assert seg.shape == (2, 2, 3)
    np.testing.assert_allclose(seg[:, 1], p)                                  # heads at the contacts
    np.testing.assert_allclose(np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1), [0.3, 0.15])
    np.testing.assert_allclose(seg[0, 1] - seg[0, 0], [0, 0, -0.3])           # along the force


def test_chart_svg():
    svg = layers.chart_svg(np.array([0.0, 1.0, 2.0]), np.array([0.0, 0.5, 1.0]), 1, "tip uz [mm]", "load factor",
                           extra=(1.5, 0.7))
    assert svg.startswith("<svg") and svg.count("<circle") == 5 and "tip uz [mm]" in svg


def test_grasp_pipeline_contacts_in_world_frame(plate_run, tmp_path):
    """The grasp pipeline's contacts.json (issue 5): world-frame records and the object pose;
    the viewer moves them into the object frame of the surfaces."""
    d = tmp_path / "grasp"
    shutil.copytree(plate_run, d)
    c, s = np.cos(0.3), np.sin(0.3)
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])                       # object -> world
    t = np.array([0.1, 0.2, 0.3])
    p_obj, f_obj = np.array([0.0, 0.0, 0.0005]), np.array([0.0, 1.0, -2.0])
    doc = {"frame": "world", "object_pose": {"position_m": t.tolist(), "quat_wxyz": [np.cos(0.15), 0, 0, np.sin(0.15)],
                                             "rotation": R.tolist()},
           "contacts": [{"finger": "left", "position_m": (R @ p_obj + t).tolist(), "force_N": (R @ f_obj).tolist(),
                         "normal": [0, 0, 1], "normal_force_N": 2.0, "friction_force_N": 1.0}],
           "per_finger": {"left": {"point_m": (R @ p_obj + t).tolist(), "force_N": (R @ f_obj).tolist()}}}
    (d / "contacts.json").write_text(json.dumps(doc))
    for pose in (doc["object_pose"], {k: v for k, v in doc["object_pose"].items() if k != "rotation"}):
        (d / "contacts.json").write_text(json.dumps(dict(doc, object_pose=pose)))
        run = read_run(d)
        np.testing.assert_allclose(run.contacts.points[0], p_obj, atol=1e-12)
        np.testing.assert_allclose(run.contacts.forces[0], f_obj, atol=1e-12)
        assert run.contacts.fingers[0]["name"] == "left"
        np.testing.assert_allclose(run.contacts.fingers[0]["position"], p_obj, atol=1e-12)
