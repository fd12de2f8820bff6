"""``graspdef object add``'s pieces: mesh repair (what it fixes and what it refuses, by name), the
grasp line and pose, the units, the memory estimate, and a folder made from a sphere."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
import trimesh

from graspdef.errors import GraspdefError, MeshError, ProblemError
from graspdef.geometry import TriMesh, icosphere, validate_mesh
from graspdef.objects.add import add_object, read_input
from graspdef.objects.data import MaterialSpec
from graspdef.objects.placement import best_antipodal, grasp_along, pose_for
from graspdef.scans.repair import repair_surface
from graspdef.shell.memory import check_memory, memory_estimate
from graspdef.sim.gripper import OPEN


def _soup(mesh: TriMesh) -> tuple[np.ndarray, np.ndarray]:
    """The triangle soup an STL file holds: three vertices of its own per face."""
    v = mesh.vertices[mesh.faces].reshape(-1, 3)
    return v, np.arange(len(v)).reshape(-1, 3)


def test_repair_welds_soup_and_closes_small_holes():
    s = icosphere(0.03, 2)
    r = repair_surface(*_soup(s), "soup.stl")
    assert r.mesh.n_vertices == s.n_vertices and r.mesh.n_faces == s.n_faces
    assert any("welded" in x for x in r.repairs)
    validate_mesh(r.mesh.vertices, r.mesh.faces, "repaired")
    holed = TriMesh(s.vertices, s.faces[1:])                      # one triangle missing: a 3-edge hole
    r = repair_surface(holed.vertices, holed.faces, "holed.ply")
    assert r.repairs == ["closed 1 small hole (1 face added)"]
    t = trimesh.Trimesh(r.mesh.vertices, r.mesh.faces, process=False)
    assert t.is_watertight and t.volume > 0


def test_repair_orients_outward():
    s = icosphere(0.03, 2)
    r = repair_surface(s.vertices, s.faces[:, ::-1], "inside_out.ply")
    assert r.repairs == ["turned the faces' orientation outward"]
    assert trimesh.Trimesh(r.mesh.vertices, r.mesh.faces, process=False).volume > 0


def test_repair_splits_touching_sheets():
    """Two spheres touching along one edge (the welded pinch of a scanned nozzle tip): split, with
    one vertex copy per sheet; the two spheres are then two objects, refused by name."""
    a = trimesh.creation.icosphere(1, 1.0)
    e = a.edges_unique[0]
    b = a.copy()
    b.apply_transform(trimesh.transformations.reflection_matrix(a.vertices[e].mean(axis=0),
                                                               a.vertex_normals[e].mean(axis=0)))
    m = trimesh.util.concatenate([a, b])
    m.merge_vertices()
    with pytest.raises(MeshError, match=r"2 separate objects in one file"):
        repair_surface(m.vertices * 0.01, m.faces, "pinched.stl")


def test_repair_refuses_open_and_non_manifold_by_position():
    s = icosphere(0.03, 2)
    keep = s.vertices[s.faces].mean(axis=1)[:, 2] < 0.02           # the cap above z = 20 mm cut off
    with pytest.raises(MeshError, match=r"open\.ply: the surface is open: 1 hole \(\d+ edges around "
                                        r"\(-?0\.00, -?0\.00, 2\d\.\d\d\) mm\)"):
        repair_surface(s.vertices, s.faces[keep], "open.ply")
    with pytest.raises(MeshError, match="a point cloud"):
        repair_surface(s.vertices, np.zeros((0, 3), int), "cloud.ply")


def test_units_auto(tmp_path):
    s = trimesh.creation.icosphere(2, 30.0)                        # 60 mm across, written in mm
    s.export(tmp_path / "ball.stl")
    v, _, unit, why = read_input(tmp_path / "ball.stl", "auto")
    assert unit == "mm" and "millimetres" in why and np.ptp(v[:, 0]) == pytest.approx(0.06, rel=1e-6)
    s.apply_scale(1e-3)
    s.export(tmp_path / "ball_m.stl")
    assert read_input(tmp_path / "ball_m.stl", "auto")[2] == "m"
    s.apply_scale(1e-6)
    s.export(tmp_path / "dust.stl")
    with pytest.raises(ProblemError, match="give --units"):
        read_input(tmp_path / "dust.stl", "auto")


def test_grasp_along_a_sphere_diameter():
    s = icosphere(0.03, 4)
    g = grasp_along(s, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    assert g.width == pytest.approx(0.06, rel=2e-3)                # the chord is a diameter (facets: < 0.2 %)
    # facet normals: a level-4 icosphere's faces tilt up to ~2.5 deg from the radius at their corners
    assert g.angle_deg < 3.0 and np.allclose(g.centre, 0, atol=1e-4)
    pos, R = pose_for(s, g)
    assert np.allclose(R @ R.T, np.eye(3)) and np.linalg.det(R) == pytest.approx(1.0)
    for p, x in ((g.first, -0.03), (g.second, 0.03)):               # contacts on the fingers' line
        assert np.allclose(R @ p + pos, (x, 0, 0), atol=1e-4)
    with pytest.raises(ProblemError, match="misses the object"):
        grasp_along(s, (0.0, 0.0, 0.05), (1.0, 0.0, 0.0))


def test_best_antipodal_on_an_ellipsoid_goes_through_the_centre():
    """On an ellipsoid the antipodal chords through the centre of mass are its principal axes;
    the semi-axis of 80 mm does not fit the gripper, so the line is along y or z."""
    s = icosphere(1.0, 3)
    e = TriMesh(s.vertices * np.array([0.08, 0.025, 0.035]), s.faces)
    g = best_antipodal(e, np.zeros(3), friction=0.8, max_width=0.126, min_width=0.018)
    assert g.angle_deg < 3.0
    assert np.linalg.norm(np.cross(-g.first, g.axis)) < 1e-3          # the line passes the centre
    assert abs(g.axis[0]) < 0.05                                       # not the 160 mm axis
    pos, R = pose_for(e, g)
    assert np.abs((e.vertices @ R.T + pos)[:, 0]).max() < OPEN


def test_pose_refuses_what_the_gripper_cannot_take():
    big = icosphere(0.1, 3)
    with pytest.raises(ProblemError, match=r"200\.\d mm wide; the gripper takes 18 to 126 mm"):
        pose_for(big, grasp_along(big, (0, 0, 0), (1, 0, 0)))
    s = icosphere(1.0, 3)
    x, y, z = s.vertices.T                     # a bow tie: 40 mm at its waist (z = 0), about 180 mm wide above and below
    bell = TriMesh(np.c_[0.02 * x, y * (0.02 + 0.2 * z ** 2), 0.05 * z], s.faces)
    with pytest.raises(ProblemError, match=r"reaches \d+\.\d mm from the grasp centre along the closing axis, "
                                           "beyond the open fingertips at 66 mm"):
        pose_for(bell, grasp_along(bell, (0, 0, 0), (0, 1, 0)))


def test_memory_estimate_and_guard():
    """The estimate lies above the peaks measured by scripts/memory_estimate.py (MB: 243 at 642
    control vertices, 706 at 10,242, 2,268 at 40,962) and within 2x of them."""
    for n, measured in ((642, 243e6 * 1.048576), (10242, 706e6 * 1.048576), (40962, 2268e6 * 1.048576)):
        assert measured < memory_estimate(n) < 2 * measured
    with pytest.raises(ProblemError, match=r"1,000,000 control vertices need about 56\.3 GiB to solve; "
                                           r"this machine has 8\.0 GiB free"):
        check_memory(1_000_000, "a mesh", available=8 * 2**30)
    assert check_memory(1000, "a mesh", available=8 * 2**30) == memory_estimate(1000)


def test_add_a_sphere(tmp_path):
    """A 60 mm ball in mm through the whole of object add: the folder reads back, its mass is
    the stated wall density x thickness x area, the grasp is a diameter."""
    trimesh.creation.icosphere(4, 30.0).export(tmp_path / "ball.stl")
    mat = MaterialSpec("neo_hookean", 2e6, 0.45, None, "test")
    done = add_object("ball", tmp_path / "ball.stl", tmp_path / "ball", thickness=2e-3, material=mat,
                      density=1100.0, faces=1280)
    r = json.loads((tmp_path / "ball" / "object_add.json").read_text())
    area = 4 * math.pi * 0.03 ** 2
    assert r["mass_kg"] == pytest.approx(1100.0 * 2e-3 * area, rel=0.01)
    assert r["collision"].startswith("convex hull")
    assert r["grasp"]["width_m"] == pytest.approx(0.06, rel=0.01) and r["grasp"]["antipodal_angle_deg"] < 3
    assert done.folder == tmp_path / "ball"
    assert r["control_mesh"]["genus"] == 0 and not any("topology" in line for line in done.summary())
    from graspdef.objects import load_object

    spec = load_object(tmp_path / "ball")
    assert spec.control_mesh.name == "control_mesh.ply" and spec.thickness == 2e-3
    assert spec.material.shell_material("nonlinear").__class__.__name__ == "CompressibleNeoHookean"
    with pytest.raises(GraspdefError, match="not empty"):
        add_object("ball", tmp_path / "ball.stl", tmp_path / "ball", thickness=2e-3, material=mat, density=1100.0)


def test_add_a_torus_reports_its_handle(tmp_path):
    """A torus (R 30 mm, r 10 mm) keeps its one handle through the remeshing: genus 1 (Euler
    characteristic 0) in the record and a summary line with the shortest and median edges [mm]."""
    trimesh.creation.torus(30.0, 10.0).export(tmp_path / "ring.stl")
    mat = MaterialSpec("neo_hookean", 2e6, 0.45, None, "test")
    done = add_object("ring", tmp_path / "ring.stl", tmp_path / "ring", thickness=2e-3, material=mat,
                      density=1100.0, faces=1500)
    cm = done.record["control_mesh"]
    assert (cm["euler"], cm["genus"]) == (0, 1)
    assert 0 < cm["shortest_edge_m"] <= cm["median_edge_m"] < 0.01
    line = [x for x in done.summary() if "topology" in x]
    assert len(line) == 1 and "genus 1 (Euler characteristic 0): 1 handle kept" in line[0]
    assert "scan noise" not in line[0]          # its edges are all of one size (2.6 and 4.3 mm measured)
