import math

import numpy as np
import pytest

from graspdef.errors import ProblemError
from graspdef.geometry.mesh import boundary_loops, is_closed, validate_mesh, vertex_valence
from graspdef.geometry.primitives import (
    cylinder,
    ellipsoid,
    height_field,
    hemisphere,
    icosphere,
    monkey_saddle,
    rectangle,
    sphere,
    square_plate,
)


def face_normals(mesh):
    p = mesh.vertices[mesh.faces]
    return np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])


def face_centroids(mesh):
    return mesh.vertices[mesh.faces].mean(axis=1)


def signed_volume(mesh):
    p = mesh.vertices[mesh.faces]
    return np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() / 6


def interior_mask(mesh):
    mask = np.ones(mesh.n_vertices, dtype=bool)
    for loop in boundary_loops(mesh.faces):
        mask[loop] = False
    return mask


def test_rectangle():
    nx, ny = 5, 3
    mesh = rectangle(2.0, 1.0, nx, ny, center=(1.0, -0.5))
    assert (mesh.n_vertices, mesh.n_faces) == ((nx + 1) * (ny + 1), 2 * nx * ny)
    assert np.allclose(mesh.vertices.min(axis=0), [0, -1, 0])
    assert np.allclose(mesh.vertices.max(axis=0), [2, 0, 0])
    assert np.all(face_normals(mesh)[:, 2] > 0)
    (loop,) = boundary_loops(mesh.faces)
    assert len(loop) == 2 * (nx + ny)
    valence = vertex_valence(mesh.faces, mesh.n_vertices)
    interior = interior_mask(mesh)
    corners = [0, nx, (nx + 1) * ny, (nx + 1) * (ny + 1) - 1]
    edge = ~interior
    edge[corners] = False
    assert np.all(valence[interior] == 6)
    assert np.all(valence[edge] == 4)
    assert sorted(valence[corners]) == [2, 2, 3, 3]


def test_square_plate_is_square_rectangle():
    plate, rect = square_plate(0.3, 4), rectangle(0.3, 0.3, 4, 4)
    np.testing.assert_array_equal(plate.vertices, rect.vertices)
    np.testing.assert_array_equal(plate.faces, rect.faces)


def test_full_cylinder():
    n_theta, n_z, radius = 12, 4, 0.5
    mesh = cylinder(radius, 2.0, n_theta, n_z)
    assert (mesh.n_vertices, mesh.n_faces) == (n_theta * (n_z + 1), 2 * n_theta * n_z)
    np.testing.assert_allclose(np.hypot(*mesh.vertices[:, :2].T), radius, rtol=1e-14)
    assert mesh.vertices[:, 2].min() == 0 and mesh.vertices[:, 2].max() == 2.0
    loops = boundary_loops(mesh.faces)
    assert [len(loop) for loop in loops] == [n_theta, n_theta]
    radial = face_centroids(mesh) * [1, 1, 0]
    assert np.all(np.einsum("ij,ij->i", face_normals(mesh), radial) > 0)
    assert np.all(vertex_valence(mesh.faces, mesh.n_vertices)[interior_mask(mesh)] == 6)


def test_partial_cylinder():
    n_theta, n_z = 6, 3
    mesh = cylinder(1.0, 1.0, n_theta, n_z, theta0=0.25, theta1=1.75)
    assert mesh.n_vertices == (n_theta + 1) * (n_z + 1)
    theta = np.arctan2(mesh.vertices[:, 1], mesh.vertices[:, 0])
    assert np.isclose(theta.min(), 0.25) and np.isclose(theta.max(), 1.75)
    (loop,) = boundary_loops(mesh.faces)
    assert len(loop) == 2 * (n_theta + n_z)
    radial = face_centroids(mesh) * [1, 1, 0]
    assert np.all(np.einsum("ij,ij->i", face_normals(mesh), radial) > 0)


@pytest.mark.parametrize("subdivisions", [0, 2])
def test_icosphere(subdivisions):
    radius = 0.2
    mesh = icosphere(radius, subdivisions)
    assert mesh.n_vertices == 10 * 4**subdivisions + 2
    assert mesh.n_faces == 20 * 4**subdivisions
    np.testing.assert_allclose(np.linalg.norm(mesh.vertices, axis=1), radius, rtol=1e-14)
    assert is_closed(mesh.faces) and boundary_loops(mesh.faces) == []
    assert 0 < signed_volume(mesh) < 4 / 3 * math.pi * radius**3
    assert sphere is icosphere


def test_ellipsoid():
    a, b, c = 1.0, 2.0, 3.0
    mesh = ellipsoid(a, b, c, 2)
    x, y, z = mesh.vertices.T
    np.testing.assert_allclose((x / a) ** 2 + (y / b) ** 2 + (z / c) ** 2, 1.0, rtol=1e-13)
    assert is_closed(mesh.faces) and signed_volume(mesh) > 0


def check_hemisphere(mesh, radius):
    np.testing.assert_allclose(np.linalg.norm(mesh.vertices, axis=1), radius, rtol=1e-14)
    assert mesh.vertices[:, 2].min() == 0.0
    assert np.all(np.einsum("ij,ij->i", face_normals(mesh), face_centroids(mesh)) > 0)
    assert np.all(vertex_valence(mesh.faces, mesh.n_vertices)[interior_mask(mesh)] == 6)


@pytest.mark.parametrize("n", [1, 2, 5])
def test_hemisphere(n):
    mesh = hemisphere(0.1, n)
    assert (mesh.n_vertices, mesh.n_faces) == (3 * n * (n + 1) + 1, 6 * n**2)
    check_hemisphere(mesh, 0.1)
    (loop,) = boundary_loops(mesh.faces)
    assert len(loop) == 6 * n
    assert np.all(mesh.vertices[loop, 2] == 0.0)
    np.testing.assert_array_equal(mesh.vertices[0], [0, 0, 0.1])


def test_hemisphere_with_hole():
    n, hole = 8, 0.4
    mesh = hemisphere(1.0, n, hole_angle=hole)
    k0 = max(1, round(n * hole / (math.pi / 2)))
    assert mesh.n_vertices == 3 * n * (n + 1) - 3 * k0 * (k0 - 1)
    assert mesh.n_faces == 6 * (n**2 - k0**2)
    check_hemisphere(mesh, 1.0)
    inner, outer = sorted(boundary_loops(mesh.faces), key=len)
    assert (len(inner), len(outer)) == (6 * k0, 6 * n)
    np.testing.assert_allclose(np.arccos(mesh.vertices[inner, 2]), hole, rtol=1e-12)
    assert np.all(mesh.vertices[outer, 2] == 0.0)


def test_monkey_saddle():
    n, h, scale = 8, 50.0, 5000.0
    mesh = monkey_saddle(h, n, scale)
    x, y, z = mesh.vertices.T
    assert mesh.n_vertices == (n + 1) ** 2
    np.testing.assert_allclose(x**3 - 3 * x * y**2, scale * z, atol=1e-9)
    assert np.abs(x).max() == h and np.abs(y).max() == h
    assert np.all(face_normals(mesh)[:, 2] > 0)


def test_height_field():
    mesh = height_field(lambda x, y: x * y, (0, 1), (0, 2), 3, 4)
    assert mesh.n_vertices == 4 * 5
    np.testing.assert_allclose(mesh.vertices[:, 2], mesh.vertices[:, 0] * mesh.vertices[:, 1])
    with pytest.raises(ProblemError, match="shape"):
        height_field(lambda x, y: 0.0, (0, 1), (0, 1), 2, 2)


@pytest.mark.parametrize("build", [
    lambda: rectangle(0.0, 1.0, 2, 2),
    lambda: rectangle(1.0, 1.0, 0, 2),
    lambda: rectangle(1.0, 1.0, 2.5, 2),
    lambda: square_plate(-1.0, 2),
    lambda: cylinder(1.0, 1.0, 2, 2),
    lambda: cylinder(1.0, 1.0, 4, 2, theta0=1.0, theta1=1.0),
    lambda: cylinder(1.0, 1.0, 4, 2, theta1=7.0),
    lambda: icosphere(float("nan"), 1),
    lambda: icosphere(1.0, -1),
    lambda: ellipsoid(1.0, 0.0, 1.0, 1),
    lambda: hemisphere(1.0, 0),
    lambda: hemisphere(1.0, 4, hole_angle=math.pi / 2),
    lambda: hemisphere(1.0, 2, hole_angle=1.2),
    lambda: height_field(np.add, (1, 0), (0, 1), 2, 2),
    lambda: monkey_saddle(scale=0.0),
])
def test_bad_arguments(build):
    with pytest.raises(ProblemError):
        build()


def test_primitives_are_valid_meshes():
    for mesh in [rectangle(1, 1, 1, 1), cylinder(1, 1, 1, 1, 0, 1), cylinder(1, 1, 3, 1),
                 hemisphere(1, 1), hemisphere(1, 2, 0.1)]:
        validate_mesh(mesh.vertices, mesh.faces)
