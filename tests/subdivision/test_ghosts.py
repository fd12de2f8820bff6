"""Ghost layer around open boundaries (``ghosts.add_ghost_layer``), after Cirak, Ortiz & Schroeder
(2000), Sec. 4.3: every boundary edge a -> b of face (a, b, c) gets a ghost a + b - c, and fans of
lattice-extrapolated vertices close the one-rings of boundary vertices."""
import numpy as np
import pytest

from graspdef.errors import MeshError
from graspdef.geometry.primitives import cylinder, hemisphere, icosphere, rectangle
from graspdef.subdivision.basis import build_basis
from graspdef.subdivision.evaluate import SurfaceEvaluator
from graspdef.subdivision.ghosts import add_ghost_layer
from graspdef.subdivision.halfedge import interior_mask
from graspdef.subdivision.quadrature import triangle_rule
from graspdef.subdivision.rules import limit_matrix
from subdiv_helpers import edge_chart, valences

OPEN = {
    "rectangle": lambda: rectangle(2.0, 1.0, 6, 4),
    "rectangle-1x1": lambda: rectangle(1.0, 1.0, 1, 1),
    "hemisphere": lambda: hemisphere(1.0, 3),
    "hemisphere-hole": lambda: hemisphere(1.0, 5, hole_angle=0.5),
    "cylinder": lambda: cylinder(1.0, 2.0, 8, 3),
    "cylinder-arc": lambda: cylinder(1.0, 2.0, 5, 3, 0.0, 2.0),
}


def boundary_vertices(faces, nv):
    return np.flatnonzero(~interior_mask(faces, nv))


@pytest.mark.parametrize("name", sorted(OPEN))
def test_every_real_vertex_gets_a_closed_one_ring(name):
    """After ghosting, ``interior_mask`` is true for every real vertex (so every real face has a
    complete Loop stencil), real vertices and faces keep their numbers, there is one ghost per
    boundary edge at a + b - c, and the extended mesh is still an oriented 2-manifold (every
    directed edge occurs once; every undirected edge has one or two faces)."""
    m = OPEN[name]()
    x, f = m.vertices, m.faces
    g = add_ghost_layer(x, f)
    nb = len(g.boundary_edges)
    assert nb == len(boundary_vertices(f, len(x))) > 0      # one boundary edge per boundary vertex
    assert g.n_real == len(x) and g.n_real_faces == len(f)
    np.testing.assert_array_equal(g.vertices[: len(x)], x)
    np.testing.assert_array_equal(g.faces[: len(f)], f)
    assert interior_mask(g.faces, g.n_control)[: g.n_real].all()
    # edge ghosts a + b - c, owned by the listed boundary faces
    a, b = g.boundary_edges.T
    c = np.array([next(v for v in f[k] if v != i and v != j)
                  for k, i, j in zip(g.boundary_faces, a, b)])
    np.testing.assert_allclose(g.vertices[g.n_real: g.n_real + nb], x[a] + x[b] - x[c], rtol=0, atol=1e-15)
    for k, i, j in zip(g.boundary_faces, a, b):
        r = list(f[k])
        assert r[(r.index(i) + 1) % 3] == j                  # a -> b is a directed edge of its face
    d = np.stack([g.faces.ravel(), np.roll(g.faces, -1, 1).ravel()], 1)
    assert len(np.unique(d, axis=0)) == len(d)
    _, counts = np.unique(np.sort(d, 1), axis=0, return_counts=True)
    assert set(counts.tolist()) <= {1, 2}


@pytest.mark.parametrize("name", sorted(OPEN))
def test_boundary_vertices_become_valence_six(name):
    """A boundary vertex with k faces has k + 1 real neighbours; the two edge ghosts and the fan
    bring it to valence max(6, k + 3) (module docstring: as many fan triangles as reach valence
    6, one at a straight edge of a regular mesh).  So straight-edge vertices of a grid (k = 3)
    and 90-degree grid corners (k = 1, 2) become regular, and interior valences do not change."""
    m = OPEN[name]()
    x, f = m.vertices, m.faces
    g = add_ghost_layer(x, f)
    bv = boundary_vertices(f, len(x))
    k = np.bincount(f.ravel(), minlength=len(x))
    val0 = valences(f, len(x))
    val1 = valences(g.faces, g.n_control)[: len(x)]
    np.testing.assert_array_equal(val1[bv], np.maximum(6, k[bv] + 3))
    inner = np.setdiff1d(np.arange(len(x)), bv)
    np.testing.assert_array_equal(val1[inner], val0[inner])
    if name.startswith("rectangle"):
        assert (val1 == 6).all()


def test_closed_mesh_unchanged():
    """A closed mesh has no boundary: add_ghost_layer returns it unchanged, with no ghosts and an
    identity extension map."""
    m = icosphere(1.0, 1)
    g = add_ghost_layer(m.vertices, m.faces)
    np.testing.assert_array_equal(g.vertices, m.vertices)
    np.testing.assert_array_equal(g.faces, m.faces)
    assert g.n_control == g.n_real == len(m.vertices) and g.n_real_faces == len(m.faces)
    assert len(g.boundary_edges) == 0 and len(g.boundary_faces) == 0
    E = getattr(g, "extension_map", None)
    if E is not None:
        np.testing.assert_array_equal(E.toarray(), np.eye(len(m.vertices)))


def test_non_manifold_boundary_vertex_rejected():
    """Two triangles touching at one vertex (a bow tie) put that vertex on two boundary loops;
    there is no single fan to close, so add_ghost_layer raises MeshError."""
    x = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]], float)
    f = np.array([[0, 1, 2], [0, 3, 4]])
    with pytest.raises(MeshError):
        add_ghost_layer(x, f)


@pytest.mark.parametrize("name", sorted(OPEN))
def test_extension_map_is_affine(name):
    """Ghost positions are fixed linear combinations of real vertices (``extension_map``) with
    weights summing to 1 (a + b - c, and parallelogram-rule fan vertices r1 - r0 + b), so the
    ghosting commutes with any affine map of the real vertices: ghosts of A x + t are
    A (ghosts of x) + t."""
    m = OPEN[name]()
    x, f = m.vertices, m.faces
    g = add_ghost_layer(x, f)
    E = g.extension_map
    assert E.shape == (g.n_control, g.n_real)
    np.testing.assert_allclose(E @ x, g.vertices, rtol=0, atol=1e-14)
    np.testing.assert_allclose(np.asarray(E.sum(1)).ravel(), 1.0, rtol=0, atol=1e-14)
    rng = np.random.default_rng(0)
    A, t = rng.standard_normal((3, 3)), rng.standard_normal(3)
    g2 = add_ghost_layer(x @ A.T + t, f)
    np.testing.assert_allclose(g2.vertices, g.vertices @ A.T + t, rtol=0, atol=1e-13)


# ------------------------------------------------------------------ linear precision on a plate
def _plate(rotate: bool):
    m = rectangle(2.0, 1.0, 6, 4)
    x = m.vertices.copy()
    R = np.eye(3)
    if rotate:
        q, _ = np.linalg.qr(np.random.default_rng(5).standard_normal((3, 3)))
        R = q * np.sign(np.linalg.det(q))
        x = x @ R.T + np.array([0.3, -0.2, 0.7])
    return m, x, R


@pytest.mark.parametrize("rotate", [False, True])
def test_flat_plate_limit_surface_is_the_plate(rotate):
    """A regular grid extended by lattice ghosts is an affine image of the triangular lattice, and
    the box spline has linear precision (Stam 1998): the limit surface at every quadrature point
    of every real face is x = A + v (B - A) + w (C - A) exactly, with a1 = B - A, a2 = C - A and
    zero second derivatives.  In particular it lies in the plate's plane (z = 0, or the rotated
    plane), up to round-off."""
    m, x, R = _plate(rotate)
    g = add_ghost_layer(x, m.faces)
    b = build_basis(g.faces, g.n_control, np.arange(g.n_real_faces), n_quad=6)
    qp = b.qpoints
    for grp in b.groups:
        X = g.vertices[grp.stencils]
        P = np.einsum("fqs,fsd->fqd", grp.full("N"), X)
        d1 = np.einsum("fqsk,fsd->fqkd", grp.full("dN"), X)
        d2 = np.einsum("fqsk,fsd->fqkd", grp.full("ddN"), X)
        A, B, C = (x[m.faces[grp.faces, k]] for k in range(3))
        expect = A[:, None] + qp[None, :, 0:1] * (B - A)[:, None] + qp[None, :, 1:2] * (C - A)[:, None]
        np.testing.assert_allclose(P, expect, rtol=0, atol=1e-14)
        np.testing.assert_allclose(d1[:, :, 0], np.broadcast_to((B - A)[:, None], P.shape),
                                   rtol=0, atol=1e-13)
        np.testing.assert_allclose(d1[:, :, 1], np.broadcast_to((C - A)[:, None], P.shape),
                                   rtol=0, atol=1e-13)
        np.testing.assert_allclose(d2, 0.0, rtol=0, atol=1e-12)
        height = (P - x[0]) @ R[:, 2]               # distance from the plate's plane
        np.testing.assert_allclose(height, 0.0, rtol=0, atol=1e-14)


def test_limit_boundary_is_the_straight_edge():
    """Along every boundary edge of the flat rectangle (straight sides and corner edges alike)
    the limit curve is the edge itself: the limit point at parameter t is (1 - t) a + t b
    (linear precision of the lattice extension; Cirak et al. 2000 need this so that the limit
    boundary is the prescribed plate edge).  At edge midpoints of the straight sides, away from
    corners, this is the brief's requirement; corners are included because the fan makes them
    regular too."""
    m = rectangle(2.0, 1.0, 6, 4)
    g = add_ghost_layer(m.vertices, m.faces)
    ev = SurfaceEvaluator(g.faces, g.n_control)
    t = np.array([0.1, 0.3, 0.5, 0.7, 0.9])
    for (a, b), face in zip(g.boundary_edges, g.boundary_faces):
        st, N, _, _ = ev.basis(int(face), edge_chart(g.faces[face], a, b, t))
        P = N @ g.vertices[st]
        expect = (1 - t)[:, None] * m.vertices[a] + t[:, None] * m.vertices[b]
        np.testing.assert_allclose(P, expect, rtol=0, atol=1e-15)


def test_limit_boundary_of_straight_sides_away_from_corners():
    """The brief's weaker statement, stated on its own so it still holds if corners get another
    treatment: at midpoints of boundary edges whose both ends are straight-side (non-corner)
    vertices, the limit point lies on the side's line (y = -0.5 etc.) at the edge midpoint."""
    nx, ny = 6, 4
    m = rectangle(2.0, 1.0, nx, ny)
    g = add_ghost_layer(m.vertices, m.faces)
    ev = SurfaceEvaluator(g.faces, g.n_control)
    corners = {0, nx, (nx + 1) * ny, (nx + 1) * (ny + 1) - 1}
    n_checked = 0
    for (a, b), face in zip(g.boundary_edges, g.boundary_faces):
        if a in corners or b in corners:
            continue
        P = ev.point(g.vertices, int(face), np.where(np.isin(g.faces[face], [a, b]), 0.5, 0.0))
        np.testing.assert_allclose(P, 0.5 * (m.vertices[a] + m.vertices[b]), rtol=0, atol=1e-15)
        n_checked += 1
    assert n_checked == 2 * (nx + ny) - 8


@pytest.mark.parametrize("name", ["rectangle", "hemisphere", "cylinder"])
def test_interpolating_limit_points_hit_the_vertices(name):
    """``GhostedMesh.interpolating()`` solves L E X = P so that the limit point of every real
    vertex is the given vertex (Loop limit masks L, ghost extension E); ghosts are re-extrapolated
    with the same E.  Checked with ``limit_matrix`` on the returned mesh (residual at round-off
    of a diagonally dominant sparse solve)."""
    m = OPEN[name]()
    g = add_ghost_layer(m.vertices, m.faces)
    gi = g.interpolating()
    L = limit_matrix(gi.faces, gi.n_control, np.arange(gi.n_real))
    np.testing.assert_allclose(L @ gi.vertices, m.vertices, rtol=0, atol=1e-13)
    np.testing.assert_allclose(gi.extension_map @ gi.vertices[: gi.n_real], gi.vertices, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(gi.faces, g.faces)


def test_triangle_rule_exactness():
    """The Gauss rules integrate every monomial v^a w^b up to their stated degree exactly:
    int_T v^a w^b = a! b! / (a + b + 2)! on the reference triangle (weights sum to 1/2).  Used by
    every area and energy integral; a mistyped point or weight breaks some monomial."""
    from math import factorial
    for n, deg in [(1, 1), (3, 2), (6, 4), (12, 6)]:
        p, w = triangle_rule(n)
        assert p.shape == (n, 2) and w.shape == (n,)
        assert (p > 0).all() and (p.sum(1) < 1).all()
        for a in range(deg + 1):
            for bb in range(deg + 1 - a):
                exact = factorial(a) * factorial(bb) / factorial(a + bb + 2)
                assert abs((w * p[:, 0] ** a * p[:, 1] ** bb).sum() - exact) < 1e-14, (n, a, bb)
    with pytest.raises(ValueError):
        triangle_rule(4)
