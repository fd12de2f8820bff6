import numpy as np
import pytest

from graspdef.errors import MeshError
from graspdef.geometry.mesh import (
    TriMesh,
    boundary_edges,
    boundary_loops,
    edge_face_counts,
    is_closed,
    unique_edges,
    validate_mesh,
    vertex_valence,
)

SQUARE_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]])
TETRA_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
TETRA_F = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])


def test_valid_meshes_pass():
    validate_mesh(SQUARE_V, SQUARE_F)
    validate_mesh(TETRA_V, TETRA_F)
    mesh = TriMesh(SQUARE_V, SQUARE_F.astype(np.int32)).validated()
    assert mesh.faces.dtype == np.int64 and mesh.vertices.dtype == np.float64
    assert (mesh.n_vertices, mesh.n_faces) == (4, 2)


def bowtie():
    """Two triangles touching only at vertex 0 (two open fans)."""
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0]], dtype=float)
    return v, np.array([[0, 1, 2], [0, 3, 4]])


def double_tetra():
    """Two closed tetrahedra sharing vertex 0 (two closed fans)."""
    v = np.vstack([TETRA_V, -TETRA_V[1:]])
    mirrored = np.where(TETRA_F == 0, 0, TETRA_F + 3)[:, ::-1]
    return v, np.vstack([TETRA_F, mirrored])


def three_wings():
    """Three triangles on edge (0, 1)."""
    v = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0], [0.5, 0, 1]], dtype=float)
    return v, np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])


@pytest.mark.parametrize("vertices, faces, message", [
    (SQUARE_V, np.array([[0, 1, 2, 3]]), "faces must be triangles"),
    (SQUARE_V[:, :2], SQUARE_F, r"vertices must have shape \(n, 3\)"),
    (SQUARE_V, SQUARE_F.astype(float), "integer"),
    (np.zeros((0, 3)), np.zeros((0, 3), dtype=int), "empty"),
    (np.where(np.arange(4)[:, None] == 2, np.nan, SQUARE_V), SQUARE_F, "non-finite.*vertices 2"),
    (SQUARE_V, np.array([[0, 1, 2], [0, 2, 4]]), r"out of range \[0, 4\) in faces 1"),
    (SQUARE_V, np.array([[0, 1, 2], [0, -1, 3]]), "out of range.*faces 1"),
    (SQUARE_V, np.array([[0, 1, 1], [0, 2, 3]]), "repeated vertex in faces 0"),
    (np.vstack([SQUARE_V, [[5, 5, 5]]]), SQUARE_F, "unreferenced vertices 4"),
    (np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], dtype=float), np.array([[0, 1, 2]]),
     "degenerate.*faces 0"),
    (*three_wings(), r"non-manifold edges.*\(0, 1\)"),
    (SQUARE_V, np.array([[0, 1, 2], [0, 3, 2]]), r"inconsistent face orientation.*\(0, 2\)"),
    (*bowtie(), "non-manifold vertices.*0"),
    (*double_tetra(), "non-manifold vertices.*0"),
])
def test_validation_errors(vertices, faces, message):
    with pytest.raises(MeshError, match=message):
        validate_mesh(vertices, faces, name="part")
    with pytest.raises(MeshError, match="^part: "):
        TriMesh(vertices, faces).validated("part")


def test_error_lists_first_few_and_total():
    v = np.vstack([SQUARE_V, np.zeros((10, 3))])
    with pytest.raises(MeshError, match=r"4, 5, 6, 7, 8, \.\.\. \(10 in total\)"):
        validate_mesh(v, SQUARE_F)


def test_edges_and_counts():
    edges, counts = edge_face_counts(SQUARE_F)
    np.testing.assert_array_equal(edges, [[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]])
    np.testing.assert_array_equal(counts, [1, 2, 1, 1, 1])
    np.testing.assert_array_equal(unique_edges(SQUARE_F), edges)
    np.testing.assert_array_equal(vertex_valence(SQUARE_F, 4), [3, 2, 3, 2])


def test_boundary_edges_keep_face_on_the_left():
    np.testing.assert_array_equal(boundary_edges(SQUARE_F), [[0, 1], [1, 2], [2, 3], [3, 0]])
    (loop,) = boundary_loops(SQUARE_F)
    np.testing.assert_array_equal(loop, [0, 1, 2, 3])


def test_closed_surface():
    assert is_closed(TETRA_F) and not is_closed(SQUARE_F)
    assert boundary_loops(TETRA_F) == []
    assert boundary_edges(TETRA_F).shape == (0, 2)
