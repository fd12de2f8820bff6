"""The scanner model: visibility, holes, Gaussian noise (0.127 mm, Tian & Jia 2010 Sec. IX:
NextEngine desktop scanner), unknown rigid pose, provenance written next to the scan."""
import json

import numpy as np
import pytest

from graspdef.errors import ProblemError
from graspdef.geometry import TriMesh, icosphere, rectangle
from graspdef.scans import (NEXTENGINE_SIGMA, Scanner, generate_scan, load_generated_scan,
                            read_surface, scan_surface)
from graspdef.scans.manifest import ply_units
from graspdef.scans.scanner import write_scan

R = 0.03


@pytest.fixture(scope="module")
def sphere():
    return icosphere(R, 6)  # chord error 0.0016 mm, negligible against the noise


def _unposed(scan):
    pose = scan.pose
    return (scan.points - pose[:3, 3]) @ pose[:3, :3]


def test_isotropic_noise_and_pose(sphere):
    """After undoing the recorded pose, the radial error (the normal component of per-axis
    noise) has mean 0 and standard deviation sigma (n = 20,000: sampling error 0.5 %)."""
    scan = scan_surface(sphere, Scanner(n_points=20_000), seed=3)
    assert scan.points.shape == (20_000, 3)
    rot = scan.pose[:3, :3]
    np.testing.assert_allclose(rot @ rot.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(rot) > 0 and np.degrees(np.arccos((np.trace(rot) - 1) / 2)) > 1
    radial = np.linalg.norm(_unposed(scan), axis=1) - R
    assert abs(radial.mean()) < 3 * NEXTENGINE_SIGMA / np.sqrt(20_000)
    np.testing.assert_allclose(radial.std(), NEXTENGINE_SIGMA, rtol=0.02)
    # the pose is unknown to the user: the scan is moved as a whole
    assert np.linalg.norm(scan.points.mean(axis=0)) > 1e-3


def test_ray_noise_is_along_the_line_of_sight(sphere):
    """noise='ray': the radial error is sigma * cos(incidence) per point."""
    scanner = Scanner(n_points=20_000, noise="ray", random_pose=False)
    scan = scan_surface(sphere, scanner, seed=4)
    cams = np.asarray(scan.provenance["camera_positions_m"])[scan.view]
    radial = np.linalg.norm(scan.points, axis=1) - R
    unit = scan.points / np.linalg.norm(scan.points, axis=1, keepdims=True)
    sight = cams - scan.points
    cos = np.einsum("ij,ij->i", unit, sight / np.linalg.norm(sight, axis=1, keepdims=True))
    np.testing.assert_allclose(np.sqrt(np.mean(radial**2)),
                               NEXTENGINE_SIGMA * np.sqrt(np.mean(cos**2)), rtol=0.03)


def test_visibility_holes_and_occlusion():
    """One camera on +x: only points facing it within 80 degrees are seen, none in the holes,
    and a sphere hidden behind another is seen only around the edge of its shadow."""
    front, back = icosphere(0.02, 5), icosphere(0.02, 5)
    mesh = TriMesh(np.vstack([front.vertices, back.vertices - [0.06, 0, 0]]),
                   np.vstack([front.faces, back.faces + front.n_vertices]))
    scanner = Scanner(n_points=5000, n_views=1, elevations_deg=(0.0,), sigma=0.0, n_holes=3,
                      hole_radius=4e-3, random_pose=False)
    scan = scan_surface(mesh, scanner, seed=5)
    p = scan.points
    cam = np.asarray(scan.provenance["camera_positions_m"][0])
    on_front = p[:, 0] > -0.03
    normal = np.where(on_front[:, None], p, p + [0.06, 0, 0]) / 0.02
    sight = cam - p
    cos = np.einsum("ij,ij->i", normal, sight) / np.linalg.norm(sight, axis=1)
    # the scanner uses facet normals: allow the largest facet-to-radial angle of the mesh
    tri = mesh.vertices[mesh.faces]
    fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    fn /= np.linalg.norm(fn, axis=1, keepdims=True)
    centre = np.where(tri[:, :1, 0] > -0.03, 0.0, -0.06)
    radial = tri - np.stack([centre, 0 * centre, 0 * centre], axis=-1)
    radial /= np.linalg.norm(radial, axis=2, keepdims=True)
    facet = np.arccos(np.einsum("fj,fij->fi", fn, radial).min())
    assert np.degrees(facet) < 1.5
    assert np.arccos(cos.min()) < np.radians(80) + facet
    holes = np.asarray(scan.provenance["hole_centres_m"])
    assert holes.shape == (3, 3)
    assert np.linalg.norm(p[:, None] - holes[None], axis=2).min() > 4e-3
    behind = p[~on_front]
    # shadow of the front sphere seen from 0.4 m: radius about 0.02 m at the back sphere
    assert np.all(np.hypot(behind[:, 1], behind[:, 2]) > 0.017)


def test_same_seed_same_scan_and_provenance_written(tmp_path, sphere):
    a = scan_surface(sphere, Scanner(n_points=2000), seed=7, source="icosphere r=30 mm")
    b = scan_surface(sphere, Scanner(n_points=2000), seed=7)
    np.testing.assert_array_equal(a.points, b.points)
    path = write_scan(a, tmp_path / "s.ply", units="mm")
    assert ply_units(path) == "mm"
    points, faces = read_surface(path, "mm")
    np.testing.assert_allclose(points, a.points, rtol=1e-15, atol=1e-18)
    assert faces.shape == (0, 3)
    prov = json.loads((tmp_path / "s.provenance.json").read_text())
    assert prov["units"] == "m" and prov["file_units"] == "mm" and prov["seed"] == 7
    assert prov["source"] == "icosphere r=30 mm"
    assert prov["scanner"]["sigma"] == NEXTENGINE_SIGMA
    np.testing.assert_array_equal(prov["pose_source_to_scan"], a.pose)


def test_generate_from_manifest_recipe(tmp_path):
    path = generate_scan("ellipsoid_6views", out_dir=tmp_path)
    assert path == tmp_path / "ellipsoid_6views.ply"
    prov = json.loads(path.with_suffix(".provenance.json").read_text())
    points, again = load_generated_scan("ellipsoid_6views", out_dir=tmp_path)  # not remade
    assert again == prov and points.shape == (50_000, 3)
    pose = np.asarray(prov["pose_source_to_scan"])
    local = (points - pose[:3, 3]) @ pose[:3, :3]
    # on the ellipsoid x^2/a^2 + y^2/b^2 + z^2/c^2 = 1 (mm semi-axes 40, 30, 20), up to noise
    # and the 4-subdivision facets
    level = np.sqrt(((local / [0.04, 0.03, 0.02]) ** 2).sum(axis=1))
    assert np.abs(level - 1).max() < 0.05
    assert prov["source"] == "ellipsoid:40,30,20" and prov["seed"] == 2
    assert prov["n_points"] == 50_000 and prov["scanner"]["hole_radius"] == 3e-3


def test_bad_settings():
    with pytest.raises(ProblemError, match="noise"):
        Scanner(noise="speckle")
    with pytest.raises(ProblemError, match="sees only 0 points"):  # a plate seen edge-on
        scan_surface(rectangle(0.05, 0.05, 4, 4), Scanner(n_points=100, elevations_deg=(0.0,)))


def test_range_image_mesh(sphere, tmp_path):
    """triangulate=True: each view's points meshed in its image plane; triangles never join
    two views, face their camera (outward on a sphere), form no non-manifold edge, and cover
    the sphere except the holes and the seams between views (measured: 96.8 % of 4 pi R^2)."""
    import trimesh

    scanner = Scanner(n_points=20_000, sigma=0.0, random_pose=False)
    scan = scan_surface(sphere, scanner, seed=1, triangulate=True)
    f = scan.faces
    assert f.shape[0] > 1.8 * 20_000 and np.all(scan.view[f] == scan.view[f][:, :1])
    tm = trimesh.Trimesh(scan.points, f, process=False)
    assert np.all(np.einsum("ij,ij->i", tm.face_normals, tm.triangles_center) > 0)
    assert np.bincount(tm.edges_unique_inverse).max() <= 2
    assert 0.93 < tm.area / (4 * np.pi * R**2) < 1.0
    path = write_scan(scan, tmp_path / "mesh.ply")
    points, faces = read_surface(path, "m")
    np.testing.assert_array_equal(faces, f)
