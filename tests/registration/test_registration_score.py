"""Scores (mean, RMS, max, Hausdorff, per-vertex errors, transform, undeformed baseline), the
real YCB tennis-ball scan against the undeformed model, and the score run folder."""
import json

import numpy as np
import pytest

from graspdef.errors import GraspdefError
from graspdef.geometry import TriMesh, icosphere, save_ply
from graspdef.registration import RegistrationError, score, score_cli, score_surface
from graspdef.scans import NEXTENGINE_SIGMA, Scanner, control_mesh, load_scan, scan_surface
from graspdef.scans.manifest import ply_units, read_surface


@pytest.fixture(scope="module")
def ball():
    return load_scan("ycb_056_tennis_ball")


def test_tennis_ball_scan_against_the_sphere_model(ball):
    """Acceptance (issue 6): the real YCB tennis-ball scan (8,194 vertices, SOURCES.md) against
    the undeformed tennis-ball model, a sphere of the ball's outer radius (least-squares fit to
    the scan: 33.39 mm; ITF ball diameters 65.4-68.6 mm).  The error is the felt and the
    ball's out-of-roundness, well under a millimetre.  Measured: mean 0.165 mm, RMS 0.228 mm,
    max 0.79 mm (the RMS equals the radial scatter about the fitted sphere, 0.228 mm)."""
    pts = ball.vertices
    a = np.c_[2 * pts, np.ones(len(pts))]
    x = np.linalg.lstsq(a, (pts**2).sum(axis=1), rcond=None)[0]
    radius = np.sqrt(x[3] + x[:3] @ x[:3])
    np.testing.assert_allclose(radius, 33.39e-3, atol=0.01e-3)
    result = score_surface(pts, icosphere(radius, 5))  # chord error 0.005 mm
    s = result.stats
    assert s["rms"] < 0.3e-3 and s["max"] < 1.0e-3
    radial = np.linalg.norm(pts - x[:3], axis=1) - radius
    np.testing.assert_allclose(s["rms"], np.sqrt(np.mean(radial**2)), rtol=0.02)
    assert result.registration.fitness == 1.0 and s["coverage"] > 0.95


def test_tennis_ball_scan_against_its_control_mesh(ball):
    """The simulation's undeformed model built from the scan (5,120-face projected control
    mesh): measured mean 0.047 mm, RMS 0.061 mm, max 0.44 mm (the felt between vertices
    4 mm apart)."""
    mesh, report = control_mesh(ball, 5120, "project")
    s = score_surface(ball.vertices, mesh).stats
    assert s["rms"] < 0.1e-3 and s["max"] < 0.6e-3
    # registration did not move it off the identity it was built in: same as the direct check
    np.testing.assert_allclose(s["rms"], report.scan_to_mesh_rms, rtol=0.05)


def _dent(mesh: TriMesh, depth: float) -> TriMesh:
    x = mesh.vertices[:, 0]
    d = depth * np.clip((x - 0.02) / 0.02, 0, 1) ** 2
    c = mesh.vertices.mean(axis=0)
    inward = (mesh.vertices - c) / np.linalg.norm(mesh.vertices - c, axis=1)[:, None]
    return TriMesh(mesh.vertices - d[:, None] * inward, mesh.faces)


@pytest.fixture(scope="module")
def case(egg, tmp_path_factory):
    """A dented egg (the 'truth'), scanned; a perfect prediction and the undeformed egg, written
    in mm; the scan written in m."""
    root = tmp_path_factory.mktemp("score")
    truth = _dent(egg, 3e-3)
    scan = scan_surface(truth, Scanner(n_points=20_000), seed=5)
    save_ply(root / "deformed.ply", truth.vertices, truth.faces, units="mm")
    save_ply(root / "undeformed.ply", egg.vertices, egg.faces, units="mm")
    save_ply(root / "scan.ply", scan.points, np.empty((0, 3), dtype=np.int64), units="m")
    return root, scan, truth


def test_score_cli_writes_the_run_folder(case):
    """The prediction (the true dented shape) scores the scanner noise; the undeformed baseline
    is worse; every file states its units.  Measured: RMS 0.128 mm (max 0.52 mm) against the
    baseline's 0.48 mm (max 3.00 mm, the dent)."""
    root, scan, truth = case
    rec = score_cli(root / "deformed.ply", root / "scan.ply", root / "out")
    saved = json.loads((root / "out" / "score.json").read_text())
    assert saved == json.loads(json.dumps(rec))
    assert rec["units"]["length"] == "mm" and rec["inputs"]["scan_units"] == "m"
    assert rec["inputs"]["prediction_units"] == "mm" and rec["ok"] and rec["flags"] == []
    pe, be = rec["prediction"]["errors"], rec["baseline"]["errors"]
    assert abs(pe["rms_mm"] / (NEXTENGINE_SIGMA * 1e3) - 1) < 0.10
    assert be["rms_mm"] > 3 * pe["rms_mm"] and be["max_mm"] > 2.0
    assert pe["max_mm"] <= pe["hausdorff_mm"] and pe["mean_mm"] <= pe["rms_mm"] <= pe["max_mm"]
    assert "from " in rec["summary"] and f"{pe['mean_mm']:.3f} mm" in rec["summary"]
    reg = rec["prediction"]["registration"]
    found = np.array(reg["transform_scan_to_surface"])
    found[:3, 3] /= 1e3
    err = found @ scan.pose
    assert np.degrees(np.arccos(min(1, (np.trace(err[:3, :3]) - 1) / 2))) < 0.1
    np.testing.assert_allclose(reg["translation_mm"], found[:3, 3] * 1e3)
    # per-vertex errors, in the files' own units
    pts, faces = read_surface(root / "out" / "scan_errors.ply", "m")
    np.testing.assert_allclose(pts, scan.points, rtol=1e-15)
    import trimesh
    props = trimesh.load(root / "out" / "scan_errors.ply", process=False).metadata["_ply_raw"][
        "vertex"]["data"]
    assert np.sqrt(np.mean(props["error_mm"] ** 2)) == pytest.approx(pe["rms_mm"], rel=1e-12)
    assert np.abs(props["baseline_error_mm"]).max() == pytest.approx(be["max_mm"], rel=1e-12)
    for name in ("prediction_errors.ply", "undeformed_errors.ply"):
        assert ply_units(root / "out" / name) == "mm"


def test_score_cli_refuses_bad_input_and_writes_nothing(case, tmp_path):
    root, scan, _ = case
    save_ply(tmp_path / "scan_mm_as_m.ply", scan.points * 1e3, np.empty((0, 3), np.int64),
             units="m")  # millimetre numbers in a file that says metres
    with pytest.raises(RegistrationError, match="unit mismatch.*mm declared as m"):
        score_cli(root / "deformed.ply", tmp_path / "scan_mm_as_m.ply", tmp_path / "o1")
    with pytest.raises(RegistrationError, match="states units 'm' but 'mm' was given"):
        score_cli(root / "deformed.ply", root / "scan.ply", tmp_path / "o2", scan_units="mm")
    (tmp_path / "lonely").mkdir()
    save_ply(tmp_path / "lonely" / "p.ply", *_mesh(root / "deformed.ply"), units="mm")
    with pytest.raises(RegistrationError, match="no undeformed shape"):
        score_cli(tmp_path / "lonely" / "p.ply", root / "scan.ply", tmp_path / "o3")
    save_ply(tmp_path / "empty.ply", np.empty((0, 3)), np.empty((0, 3), np.int64), units="m")
    with pytest.raises(GraspdefError, match="empty"):
        score_cli(root / "deformed.ply", tmp_path / "empty.ply", tmp_path / "o4")
    assert not any((tmp_path / f"o{i}").exists() for i in range(1, 5))
    assert not list(tmp_path.glob(".o*"))


def _mesh(path):
    return read_surface(path, "mm")


def test_flags_reach_the_score(egg, case):
    """A registration that did not converge makes the score flagged, never silently 'ok'."""
    _, scan, truth = case
    res = score(scan.points, truth, egg, init=np.linalg.inv(scan.pose) @ _turn(20),
                coarse=False, iterations=1, max_distance=10e-3)
    assert "prediction: not_converged" in res["flags"]


def _turn(deg):
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def test_mid_surface_prediction_is_offset_to_the_scanned_side(egg):
    """A shell prediction is a mid-surface; the scanner sees the outer side.  With
    surface_offset = t/2 the outer surface is compared (residual = the noise); without it the
    scan lies about t/2 outside (mean signed error measured +1.06 mm for t = 2 mm: the scan is
    partial, so the rigid fit shifts it a little towards the unseen side)."""
    from graspdef.scans import mid_surface

    t = 2e-3
    mid = mid_surface(egg, t)
    scan = scan_surface(egg, Scanner(n_points=20_000), seed=9)
    with_offset = score(scan.points, mid, mid, surface_offset=t / 2)["prediction"].stats
    assert abs(with_offset["rms"] / NEXTENGINE_SIGMA - 1) < 0.10
    without = score_surface(scan.points, mid).stats
    np.testing.assert_allclose(without["mean_signed"], t / 2, rtol=0.10)
    assert without["rms"] > 5 * with_offset["rms"]


def test_score_cli_takes_a_manifest_scan_id(ball, tmp_path):
    """A real scan named by its manifest id is read in place with the manifest's units; a
    prediction equal to the undeformed shape scores exactly like its baseline."""
    mesh, report = control_mesh(ball, 1280, "project")
    save_ply(tmp_path / "deformed.ply", mesh.vertices, mesh.faces, units="mm")
    save_ply(tmp_path / "undeformed.ply", mesh.vertices, mesh.faces, units="mm")
    rec = score_cli(tmp_path / "deformed.ply", "ycb_056_tennis_ball", tmp_path / "out")
    assert rec["inputs"]["scan_units"] == "m" and rec["inputs"]["scan_is_mesh"]
    assert rec["inputs"]["n_scan_points"] == 8194
    # (equal up to open3d's multithreaded summation order)
    assert rec["prediction"]["errors"] == pytest.approx(rec["baseline"]["errors"], rel=1e-9)
    assert rec["prediction"]["errors"]["rms_mm"] == pytest.approx(
        report.scan_to_mesh_rms * 1e3, rel=0.05)
