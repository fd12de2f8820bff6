"""The annulus (structured, optionally slit) and the polygon with holes (Triangle + midpoint
refinement): areas against the analytic ones, topology (Euler characteristic, boundary loops),
orientation, vertex valences and the one-line errors for bad inputs."""
import math

import numpy as np
import pytest

from graspdef.errors import ProblemError
from graspdef.geometry.mesh import boundary_edges, boundary_loops, unique_edges, validate_mesh, vertex_valence
from graspdef.geometry.primitives import POLYGON_MIN_ANGLE_DEG, annulus, midpoint_refined, polygon

SQUARE = [[0.0, 0.0], [4.0, 0.0], [4.0, 3.0], [0.0, 3.0]]
HOLE_SQUARE = [[1.0, 1.0], [2.0, 1.0], [2.0, 2.0], [1.0, 2.0]]
HOLE_TRIANGLE = [[3.0, 1.0], [3.5, 1.5], [3.0, 2.0]]


def signed_areas(mesh):
    p = mesh.vertices[mesh.faces]
    return 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])[:, 2]


def euler(mesh):
    return mesh.n_vertices - len(unique_edges(mesh.faces)) + mesh.n_faces


def faces_per_vertex(mesh):
    return np.bincount(mesh.faces.ravel(), minlength=mesh.n_vertices)


# --- annulus ---------------------------------------------------------------------------------

def test_annulus_area_converges_at_second_order():
    """The control mesh is the inscribed 2n-gon ring: its area is exactly
    n/2 sin(2 pi / n) (b^2 - a^2) and its error against pi (b^2 - a^2) falls as n^-2."""
    a, b = 0.5, 1.0
    exact = math.pi * (b * b - a * a)
    errors = []
    for n in (24, 48, 96):
        m = annulus(a, b, n, n // 8)
        area = signed_areas(m).sum()
        assert area == pytest.approx(n / 2 * math.sin(2 * math.pi / n) * (b * b - a * a), rel=1e-13)
        errors.append(exact - area)
    rates = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all(np.abs(rates - 2.0) < 0.02), rates


@pytest.mark.parametrize("slit", [None, 0.0, math.radians(30.0)])
def test_annulus_topology_orientation_and_valence(slit):
    """Closed ring: Euler characteristic 0, two boundary loops; slit ring: a disk (1, one loop).
    All faces counter-clockwise seen from +z, interior vertices valence 6, boundary valence 4
    (the slit's four corners: 1 or 2 faces, like rectangle corners)."""
    n_theta, n_r = 40, 5
    m = annulus(6.0, 10.0, n_theta, n_r, slit=slit)
    validate_mesh(m.vertices, m.faces)
    assert m.n_faces == 2 * n_theta * n_r
    assert np.all(signed_areas(m) > 0)
    loops = boundary_loops(m.faces)
    r = np.hypot(*m.vertices[:, :2].T)
    on_circle = np.isclose(r, 6.0, atol=1e-12) | np.isclose(r, 10.0, atol=1e-12)
    boundary = np.zeros(m.n_vertices, bool)
    boundary[np.concatenate(loops)] = True
    valence = vertex_valence(m.faces, m.n_vertices)
    assert np.all(valence[~boundary] == 6)
    if slit is None:
        assert euler(m) == 0 and len(loops) == 2
        assert np.array_equal(boundary, on_circle)
        assert np.all(valence[boundary] == 4)
    else:
        assert euler(m) == 1 and len(loops) == 1
        assert boundary.sum() == 2 * (n_theta + 1) + 2 * (n_r - 1)    # both circles and both lips
        corners = np.flatnonzero(faces_per_vertex(m) < 3)
        assert len(corners) == 4 and np.all(on_circle[corners])
        assert np.all(valence[boundary & ~np.isin(np.arange(m.n_vertices), corners)] == 4)


def test_slit_lips_coincide_but_are_separate_boundary_edges():
    """The cut duplicates the vertex column on the ray theta = slit with bit-identical positions;
    the two lips share no vertex, so each lip's n_r edges are boundary edges of one face."""
    n_theta, n_r = 24, 4
    slit = math.radians(90.0)
    m = annulus(1.0, 2.0, n_theta, n_r, slit=slit)
    row = n_theta + 1
    first, last = np.arange(n_r + 1) * row, np.arange(n_r + 1) * row + n_theta
    assert np.array_equal(m.vertices[first], m.vertices[last])
    assert np.allclose(np.arctan2(m.vertices[first, 1], m.vertices[first, 0]), slit, atol=1e-15)
    used_by = [set(np.flatnonzero(np.isin(m.faces, col).any(axis=1))) for col in (first, last)]
    assert not used_by[0] & used_by[1]
    loop = boundary_loops(m.faces)[0]
    for col in (first, last):
        assert np.isin(col, loop).all()


@pytest.mark.parametrize("args, message", [
    ((2.0, 1.0, 16, 2), "r_inner must be smaller than r_outer"),
    ((1.0, 1.0, 16, 2), "r_inner must be smaller than r_outer"),
    ((0.0, 1.0, 16, 2), "r_inner must be a positive"),
    ((0.5, 1.0, 2, 2), "n_theta must be >= 3"),
    ((0.5, 1.0, 16, 0), "n_r must be >= 1"),
    ((0.5, 1.0, 3, 1, 0.0), "n_theta must be >= 4"),
    ((0.5, 1.0, 8, 1, float("nan")), "slit must be a finite angle"),
])
def test_annulus_bad_inputs(args, message):
    with pytest.raises(ProblemError, match=message) as err:
        annulus(*args)
    assert "\n" not in str(err.value)


# --- polygon ---------------------------------------------------------------------------------

def distance_to_polygon(points, poly):
    poly = np.asarray(poly, float)
    a, b = poly, np.roll(poly, -1, axis=0)
    d = b - a
    t = np.clip(np.einsum("pkj,kj->pk", points[:, None, :] - a[None], d) / np.einsum("kj,kj->k", d, d), 0, 1)
    nearest = a[None] + t[..., None] * d[None]
    return np.linalg.norm(points[:, None, :] - nearest, axis=-1).min(axis=1)


@pytest.mark.parametrize("holes", [[], [HOLE_SQUARE], [HOLE_SQUARE, HOLE_TRIANGLE[::-1]]])
def test_polygon_area_topology_orientation_quality(holes):
    """The mesh covers the polygon exactly (area = shoelace area to rounding), has Euler
    characteristic 1 - holes and 1 + holes boundary loops, every face counter-clockwise from +z,
    every boundary vertex on the given boundary, and no angle below Triangle's bound (midpoint
    refinement keeps the angles: each child is similar to its parent)."""
    def shoelace(q):
        q = np.asarray(q, float)
        return 0.5 * abs(np.sum(q[:, 0] * np.roll(q[:, 1], -1) - np.roll(q[:, 0], -1) * q[:, 1]))

    hole_area = sum(shoelace(h) for h in holes)
    m = polygon(SQUARE, holes, edge_length=0.2, refinements=1)
    validate_mesh(m.vertices, m.faces)
    assert np.all(signed_areas(m) > 0)
    assert signed_areas(m).sum() == pytest.approx(12.0 - hole_area, rel=1e-12)
    loops = boundary_loops(m.faces)
    assert euler(m) == 1 - len(holes) and len(loops) == 1 + len(holes)
    bnd = m.vertices[np.concatenate(loops), :2]
    dist = np.min([distance_to_polygon(bnd, q) for q in [SQUARE] + holes], axis=0)
    assert dist.max() < 1e-12
    p = m.vertices[m.faces]
    e = [p[:, (i + 1) % 3] - p[:, i] for i in range(3)]
    cos = [np.einsum("ij,ij->i", -e[i - 1], e[i]) / np.linalg.norm(e[i - 1], axis=1) / np.linalg.norm(e[i], axis=1)
           for i in range(3)]
    assert np.degrees(np.arccos(np.clip(cos, -1, 1))).min() >= POLYGON_MIN_ANGLE_DEG - 1e-6


def test_polygon_refinement_isolates_irregular_vertices():
    """Midpoint refinement of a fixed coarse mesh adds only regular vertices (valence 6 inside,
    three faces on a straight boundary), so the irregular ones are the coarse mesh's alone: their
    number stays the same while the vertex count grows about four-fold per level."""
    counts = []
    for k in (0, 1, 2):
        m = polygon(SQUARE, [HOLE_SQUARE], edge_length=0.6 / 2 ** k, refinements=k)
        boundary = np.zeros(m.n_vertices, bool)
        boundary[np.concatenate(boundary_loops(m.faces))] = True
        val = vertex_valence(m.faces, m.n_vertices)
        irregular = (~boundary & (val != 6)) | (boundary & (faces_per_vertex(m) != 3))
        counts.append((m.n_vertices, int(irregular.sum())))
    (n0, i0), (n1, i1), (n2, i2) = counts
    assert i0 == i1 == i2 > 0
    assert n1 > 3.5 * n0 and n2 > 3.5 * n1


def test_midpoint_refined_keeps_vertices_and_quadruples_faces():
    m = annulus(1.0, 2.0, 8, 2)
    r = midpoint_refined(m, 2)
    assert r.n_faces == 16 * m.n_faces
    assert np.array_equal(r.vertices[: m.n_vertices], m.vertices)
    assert signed_areas(r).sum() == pytest.approx(signed_areas(m).sum(), rel=1e-13)
    assert euler(r) == euler(m) and len(boundary_loops(r.faces)) == 2


@pytest.mark.parametrize("outer, holes, kwargs, message", [
    ([[0, 0], [1, 1], [1, 0], [0, 1]], [], {}, "outer polygon is self-intersecting"),
    (SQUARE[::-1], [], {}, "outer polygon is clockwise"),
    ([[0, 0], [1, 0], [2, 0]], [], {}, "outer polygon is self-intersecting"),
    ([[0, 0], [2, 0], [1, 0], [1, 1]], [], {}, "outer polygon is self-intersecting"),
    ([[0, 0], [1, 0], [1, 0], [0, 1]], [], {}, "outer polygon repeats point 2"),
    ([[0, 0], [1, 0]], [], {}, "outer polygon needs at least 3 points"),
    ([[0, 0], [1, 0], [0, float("inf")]], [], {}, "non-finite"),
    (SQUARE, [[[3, 1], [5, 1], [5, 2]]], {}, "hole 1 is not strictly inside the outer polygon"),
    (SQUARE, [[[5, 1], [6, 1], [6, 2]]], {}, "hole 1 is not strictly inside the outer polygon"),
    (SQUARE, [HOLE_SQUARE, [[1.5, 1.5], [2.5, 1.5], [2.5, 2.5]]], {}, "holes 1 and 2 overlap"),
    (SQUARE, [HOLE_SQUARE, [[1.2, 1.2], [1.8, 1.2], [1.8, 1.8]]], {}, "holes 1 and 2 overlap"),
    (SQUARE, [[[1, 1], [2, 2], [2, 1], [1, 2]]], {}, "hole 1 is self-intersecting"),
    (SQUARE, [], {"edge_length": 2.0, "refinements": 2}, "too few cells"),
    (SQUARE, [], {"edge_length": -1.0}, "edge_length must be a positive"),
    (SQUARE, [], {"edge_length": 1e-4}, "would need about"),
])
def test_polygon_bad_inputs(outer, holes, kwargs, message):
    kwargs = {"edge_length": 0.5, "refinements": 0} | kwargs
    with pytest.raises(ProblemError, match=message) as err:
        polygon(outer, holes, **kwargs)
    assert "\n" not in str(err.value)


def test_disk_boundary_on_the_circle_and_problem_file(tmp_path):
    """``disk``: every boundary vertex on the circle at every refinement, area -> pi R^2, and the
    problem-file type."""
    from graspdef.geometry.primitives import disk
    from graspdef.problem.config import load_problem

    areas = []
    for k in range(3):
        m = disk(2.0, 0.8 / 2 ** k, k, center=(1.0, -1.0))
        b = np.unique(boundary_edges(m.faces))
        r = np.hypot(m.vertices[b, 0] - 1.0, m.vertices[b, 1] + 1.0)
        np.testing.assert_allclose(r, 2.0, rtol=0, atol=1e-12)
        e1 = m.vertices[m.faces[:, 1]] - m.vertices[m.faces[:, 0]]
        e2 = m.vertices[m.faces[:, 2]] - m.vertices[m.faces[:, 0]]
        cz = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
        assert np.all(cz > 0)
        areas.append(0.5 * cz.sum())
    err = np.abs(np.array(areas) - np.pi * 4.0)
    assert err[0] > err[1] > err[2]
    f = tmp_path / "disk.toml"
    f.write_text('[units]\nlength = "consistent"\nforce = "consistent"\n[geometry]\ntype = "disk"\nradius = 2.0\nedge_length = 0.4\nrefinements = 1\n'
                 '[material]\nE = 1000.0\nnu = 0.3\n[shell]\nthickness = 0.1\n'
                 '[regions]\nrim = "abs(sqrt(x*x + y*y) - 2) < 1e-9"\n'
                 '[[supports]]\nkind = "simply_supported"\nregion = "rim"\n')
    pr = load_problem(f).problem
    assert pr.shell.mesh.boundary_edges.shape[0] > 0
