"""The Loop basis of whole control meshes (``basis.build_basis``, ``evaluate.SurfaceEvaluator``):
regular faces through the box-spline patch, faces with extraordinary vertices through exact local
subdivision (Stam 1998, without the eigenbasis).  Limit-point identities follow Loop (1987)."""
import functools

import numpy as np
import pytest

from graspdef.errors import MeshError
from graspdef.geometry.primitives import icosphere, rectangle
from graspdef.subdivision.basis import build_basis
from graspdef.subdivision.evaluate import SurfaceEvaluator, project_point
from graspdef.subdivision.ghosts import add_ghost_layer
from graspdef.subdivision.halfedge import HalfEdges
from graspdef.subdivision.rules import limit_positions, loop_beta
from subdiv_helpers import (
    assert_fd_rate,
    bipyramid,
    dyadic_vertex,
    edge_chart,
    loop_refine,
    random_flips,
    refinement_chain,
    torus,
    valences,
)


@functools.lru_cache(maxsize=None)
def _mesh(name):
    """Control meshes (vertices, faces, active faces or None), randomly perturbed.

    ``bipyramid-n``: poles of valence n, equator of valence 4, every face has three
    extraordinary vertices.  ``bipyramid-n-r``: the same refined once, so the faces at a pole have
    exactly one extraordinary vertex.  Face 0 always has the north pole at chart corner (0, 0)."""
    rng = np.random.default_rng(sum(map(ord, name)))
    active = None
    if name.startswith("bipyramid"):
        parts = name.split("-")
        x, f = bipyramid(int(parts[1]), rng, 0.05)
        if len(parts) == 3:
            x, f = loop_refine(x, f, 1)
    elif name == "icosphere":
        m = icosphere(1.0, 1)
        x, f = m.vertices, m.faces
    elif name == "flipped":
        m = icosphere(1.0, 1)
        x, f = m.vertices, random_flips(m.vertices, m.faces, np.random.default_rng(1), 600)
    elif name == "torus":
        x, f = torus(7, 6)
    elif name == "rectangle":
        r = rectangle(2.0, 1.0, 6, 4)
        g = add_ghost_layer(r.vertices, r.faces)
        x, f, active = g.vertices, g.faces, np.arange(g.n_real_faces)
    else:
        raise ValueError(name)
    x = x + 0.03 * rng.standard_normal(x.shape)
    return x, np.asarray(f, np.int64), active


def mesh(name):
    x, f, a = _mesh(name)
    return x.copy(), f.copy(), a


VALENCES = [3, 4, 5, 7, 8, 10, 12]
POLE_MESHES = [f"bipyramid-{n}" for n in VALENCES] + [f"bipyramid-{n}-r" for n in VALENCES]


def limit_points(ev, x, face, pts):
    st, N, dN, ddN = ev.basis(face, pts)
    X = x[st]
    return N @ X, np.einsum("qsd,sk->qdk", dN, X), np.einsum("qsd,sk->qdk", ddN, X)


# ------------------------------------------------------------------ partition of unity
@pytest.mark.parametrize("name", ["icosphere", "bipyramid-3", "bipyramid-12", "bipyramid-12-r",
                                  "flipped", "rectangle", "torus"])
def test_groups_partition_of_unity(name):
    """In every face group (regular and irregular) sum_s N_s = 1 and the derivatives sum to 0 at
    each quadrature point: the Loop basis is an affine partition of unity, so rigid motions and
    affine maps of the control points move the limit surface the same way.  Tolerance: 1e-14 for
    N, 1e-13 of the largest entry for dN, ddN (sums of <= 30 products through <= 4 levels of
    subdivision).  Also: the regular group (shared 12-function table) holds exactly the faces
    whose three vertices have valence 6, and each irregular stencil is the union of the face's
    three one-rings, with zero weights on the padding."""
    x, f, active = mesh(name)
    act = np.arange(len(f)) if active is None else active
    b = build_basis(f, len(x), active, n_quad=3)
    assert b.n_faces == len(act)
    assert sorted(np.concatenate([g.faces for g in b.groups]).tolist()) == sorted(act.tolist())
    np.testing.assert_allclose(b.qweights.sum(), 0.5, rtol=1e-14)
    val = valences(f, len(x))
    regular = set(act[(val[f[act]] == 6).all(1)].tolist())
    seen_regular = set()
    for g in b.groups:
        N, dN, ddN = g.full("N"), g.full("dN"), g.full("ddN")
        np.testing.assert_allclose(N.sum(-1), 1.0, rtol=0, atol=1e-14)
        np.testing.assert_allclose(dN.sum(-2), 0.0, rtol=0, atol=1e-13 * np.abs(dN).max())
        np.testing.assert_allclose(ddN.sum(-2), 0.0, rtol=0, atol=1e-13 * np.abs(ddN).max())
        if g.N.shape[0] == 1 and g.stencils.shape[1] == 12 and set(g.faces.tolist()) <= regular:
            seen_regular |= set(g.faces.tolist())
            continue
        for k, face in enumerate(g.faces):
            ring = np.unique(f[np.isin(f, f[face]).any(1)])
            n = len(ring)
            np.testing.assert_array_equal(np.sort(g.stencils[k, :n]), ring)
            assert (g.N[k, :, n:] == 0).all() and (g.dN[k, :, n:] == 0).all()
    assert seen_regular == regular
    if name in ("torus", "rectangle"):
        assert len(b.groups) == 1


def test_build_basis_rejects_open_one_ring():
    """A face with a boundary vertex has no complete Loop stencil; build_basis must refuse it
    (MeshError) rather than evaluate a truncated stencil."""
    r = rectangle(1.0, 1.0, 3, 3)
    with pytest.raises(MeshError):
        build_basis(r.faces, len(r.vertices))


# ------------------------------------------------------------------ exactness at dyadic points
DYADIC = [(0.5, 0.0), (0.25, 0.0), (0.25, 0.25), (0.0, 0.5), (0.5, 0.5), (0.125, 0.375),
          (0.0625, 0.0), (0.375, 0.25)]


@functools.lru_cache(maxsize=None)
def _refined_limits(name, levels):
    x, f, _ = _mesh(name)
    xs, fs = refinement_chain(x, f, levels)
    return [limit_positions(a, b) for a, b in zip(xs, fs)], fs


@pytest.mark.parametrize("name", POLE_MESHES)
def test_irregular_evaluation_exact_at_dyadic_points(name):
    """A chart point with dyadic coordinates m/2^k is a control vertex of the k-times refined
    mesh, so its limit point must equal ``limit_positions`` of that mesh there (exact for any
    valence).  Face 0 holds the pole (valence n, at chart (0, 0)): (0.5, 0) is the new vertex on
    the spoke edge after one step, (0.25, 0) and (0.25, 0.25) need two steps, (0.0625, 0) four.
    Agreement is to round-off (< 1e-14 on a unit-size mesh) -- any error in the recursion, the
    child charts or the stencil order shows as O(1e-3) or more."""
    x, f, _ = mesh(name)
    Ls, fs = _refined_limits(name, 4)
    ev = SurfaceEvaluator(f, len(x))
    assert valences(f, len(x))[f[0, 0]] == int(name.split("-")[1])
    P, _, _ = limit_points(ev, x, 0, np.array(DYADIC))
    expect = []
    for p in DYADIC:
        level, vid = dyadic_vertex(fs, 0, p)
        expect.append(Ls[level][vid])
    np.testing.assert_allclose(P, np.array(expect), rtol=0, atol=1e-14)


@pytest.mark.parametrize("name", ["torus", "icosphere"])
def test_regular_patch_exact_at_dyadic_points(name):
    """Same identity on every 7th face of the torus (all valence 6, box-spline patch only) and of
    the icosphere (regular and valence-5 faces): this checks Stam's box-spline table and the
    12-vertex stencil order of ``regular_stencils`` against Loop's subdivision rules,
    independently of ``patch``."""
    x, f, _ = mesh(name)
    Ls, fs = _refined_limits(name, 4)
    ev = SurfaceEvaluator(f, len(x))
    pts = np.array(DYADIC)
    for face in range(0, len(f), 7):
        P, _, _ = limit_points(ev, x, face, pts)
        expect = []
        for p in pts:
            level, vid = dyadic_vertex(fs, face, p)
            expect.append(Ls[level][vid])
        np.testing.assert_allclose(P, np.array(expect), rtol=0, atol=1e-14)


@pytest.mark.parametrize("name", ["flipped", "bipyramid-3", "bipyramid-12", "icosphere"])
def test_values_at_vertices_are_limit_positions(name):
    """``SurfaceEvaluator.values`` at a corner (barycentric (1,0,0) etc.) uses the exact limit
    mask (1 - n chi) x + chi sum(ring): it must give ``rules.limit_positions`` for every corner of
    every face, for valences 3 .. 16."""
    x, f, _ = mesh(name)
    ev = SurfaceEvaluator(f, len(x))
    L = limit_positions(x, f)
    for face in range(len(f)):
        for c in range(3):
            bary = np.zeros(3)
            bary[c] = 1.0
            st, w = ev.values(face, bary)
            np.testing.assert_allclose(w.sum(), 1.0, rtol=0, atol=1e-15)
            np.testing.assert_allclose(w @ x[st], L[f[face, c]], rtol=0, atol=1e-15)
            np.testing.assert_allclose(ev.point(x, face, bary), L[f[face, c]], rtol=0, atol=1e-15)


@pytest.mark.parametrize("n", [3, 4, 5, 8, 12])
def test_points_near_vertex_converge_to_limit_position(n):
    """Approaching the pole (valence n) along the spoke edge, the chart point (2^-k, 0) is a
    level-k control vertex and its limit point tends to the pole's limit position
    (continuity at an extraordinary vertex).  The distance is the size of the tangent
    eigencomponent, so it contracts by the subdominant eigenvalue of Loop's subdivision matrix,
    lambda1 = 3/8 + cos(2 pi/n)/4, per step (Stam 1998); the next eigenvalue lambda2 =
    max(3/8 + cos(4 pi/n)/4, 5/8 - n beta, 1/8) pollutes the ratio by O((lambda2/lambda1)^k),
    which is the tolerance used at k = 11 (with one step of slack)."""
    x, f, _ = mesh(f"bipyramid-{n}-r")
    ev = SurfaceEvaluator(f, len(x))
    L = limit_positions(x, f)[f[0, 0]]
    K = 12
    pts = np.array([[2.0 ** -k, 0.0] for k in range(1, K + 1)])
    P, _, _ = limit_points(ev, x, 0, pts)
    d = np.linalg.norm(P - L, axis=1)
    lam1 = 3 / 8 + np.cos(2 * np.pi / n) / 4
    cands = [5 / 8 - n * loop_beta(np.array(n)), 1 / 8]
    if n > 3:
        cands.append(3 / 8 + np.cos(4 * np.pi / n) / 4)
    lam2 = max(cands)
    assert lam2 < lam1
    ratio = d[1:] / d[:-1]
    assert (ratio < 1).all(), d
    assert abs(ratio[-1] / lam1 - 1) < (lam2 / lam1) ** (K - 2), (ratio, lam1, lam2)


# ------------------------------------------------------------------ chart derivatives by FD
def _interior_sample_points(k=4):
    """Centroids of the level-k dyadic sub-triangles of the chart that stay 1/8 away from all three
    corners: the evaluation is one quartic box-spline piece on each of them, so central
    differences with steps <= 1/96 never cross a piece boundary (distance of a centroid to its
    sub-triangle's sides in v, w or v + w is 2^-k / 3 >= 1/48)."""
    s = 2.0 ** -k
    pts = []
    for i in range(2 ** k):
        for j in range(2 ** k - i):
            pts.append(((i + 1 / 3) * s, (j + 1 / 3) * s))            # upward triangles
            if i + j + 2 <= 2 ** k:
                pts.append(((i + 2 / 3) * s, (j + 2 / 3) * s))        # downward triangles
    p = np.array(pts)
    u = 1 - p.sum(1)
    keep = (p.sum(1) > 0.125) & (1 - p[:, 0] > 0.125) & (1 - p[:, 1] > 0.125) & (u < 0.875 + 1e-12)
    return p[keep]


@pytest.mark.parametrize("name", ["bipyramid-3", "bipyramid-5-r", "bipyramid-12", "flipped"])
def test_irregular_chart_derivatives_fd(name):
    """dN and ddN of faces with extraordinary vertices against central differences of N and dN
    (evaluated at p +- h and p +- h/2, h = 2e-3): within one polynomial piece the error is exactly
    (h^2/6) times a third derivative and drops by 4 when h halves.  The chain factors 2 s (first)
    and 4 (second derivatives) of the child charts, including the flipped centre child (s = -1),
    are what is tested."""
    x, f, _ = mesh(name)
    ev = SurfaceEvaluator(f, len(x))
    val = valences(f, len(x))
    faces = [i for i in range(len(f)) if (val[f[i]] != 6).any()][:2]
    p = _interior_sample_points()
    q = len(p)
    h = 2e-3
    shifts = [s * step * e for step in (h, h / 2) for e in np.eye(2) for s in (1, -1)]
    for face in faces:
        # one call: p, then p + h e_v, p - h e_v, p + h e_w, ..., p - h/2 e_w
        st, N, dN, ddN = ev.basis(face, np.concatenate([p] + [p + s for s in shifts]))
        Ns = N[q:].reshape(8, q, -1)
        dNs = dN[q:].reshape(8, q, -1, 2)
        N, dN, ddN = N[:q], dN[:q], ddN[:q]
        fd1, fd2 = [], []
        for lvl, step in enumerate((h, h / 2)):
            o = 4 * lvl
            c1 = [(Ns[o + 2 * d] - Ns[o + 2 * d + 1]) / (2 * step) for d in range(2)]
            c2 = [(dNs[o + 2 * d] - dNs[o + 2 * d + 1]) / (2 * step) for d in range(2)]
            fd1.append(np.stack(c1, -1))
            # (N_vv, N_ww, N_vw as d/dw N_v, N_vw as d/dv N_w)
            fd2.append(np.stack([c2[0][..., 0], c2[1][..., 1], c2[1][..., 0], c2[0][..., 1]], -1))
        assert_fd_rate(dN, fd1[0], fd1[1], what=f"{name} face {face} dN")
        assert_fd_rate(np.concatenate([ddN, ddN[..., 2:3]], -1), fd2[0], fd2[1],
                       what=f"{name} face {face} ddN")


# ------------------------------------------------------------------ C1 continuity
def _edge_jumps(x, f, ev, he, fa, a, b, t):
    """Position and unit-normal jump between the two faces sharing edge a-b at parameters t."""
    fb = int(he.face_of(np.array([b]), np.array([a]))[0])
    assert fb >= 0 and fb != fa
    out = []
    for F in (fa, fb):
        P, d1, _ = limit_points(ev, x, F, edge_chart(f[F], a, b, t))
        n = np.cross(d1[:, 0], d1[:, 1])
        out.append((P, n / np.linalg.norm(n, axis=1)[:, None]))
    return (np.linalg.norm(out[0][0] - out[1][0], axis=1).max(),
            np.linalg.norm(out[0][1] - out[1][1], axis=1).max())


@pytest.mark.parametrize("name", POLE_MESHES + ["flipped", "torus"])
def test_c1_continuity_across_edges(name):
    """The Loop limit surface is C1 at and around extraordinary vertices (Stam 1998; Loop 1987).
    Along the shared edge of two faces (all three edges of face 0: the two spokes at the pole
    and the rim edge opposite it; for the flipped mesh the spokes and rims of four faces at its
    highest-valence vertex, valence 16) the limit point
    and the unit normal evaluated from either face must coincide.  The edge parameter t (from a
    to b) is mapped into each face's own chart; both charts are orientation-preserving, so the
    normals a1 x a2 agree in sign.  Measured jumps: positions <= 9e-16, normals <= 3e-13 (round-off
    amplified by the 2^depth chain factor of points near the extraordinary vertex, depth <= 6 for
    t >= 0.03); the bound 1e-12 is the brief's, a C0/C1 defect would be O(1e-3) or more."""
    x, f, _ = mesh(name)
    ev = SurfaceEvaluator(f, len(x))
    he = HalfEdges.build(f, len(x))
    t = np.array([0.03, 0.1, 0.27, 0.5, 0.71, 0.9, 0.97])
    if name == "flipped":
        v = int(np.argmax(valences(f, len(x))))
        fa_list = np.flatnonzero((f == v).any(1))[:4]
        edges = []
        for fa in fa_list:
            k = int(np.flatnonzero(f[fa] == v)[0])
            edges.append((fa, v, f[fa, (k + 1) % 3]))
            edges.append((fa, f[fa, (k + 1) % 3], f[fa, (k + 2) % 3]))
    else:
        edges = [(0, f[0, 0], f[0, 1]), (0, f[0, 1], f[0, 2]), (0, f[0, 2], f[0, 0])]
    report = []
    for fa, a, b in edges:
        dp, dn = _edge_jumps(x, f, ev, he, int(fa), int(a), int(b), t)
        report.append((dp, dn))
    dp = max(r[0] for r in report)
    dn = max(r[1] for r in report)
    assert dp < 1e-12 and dn < 1e-12, f"position jump {dp:.2e}, normal jump {dn:.2e}"


# ------------------------------------------------------------------ area convergence
def _limit_area(x, f, n_quad=12):
    b = build_basis(f, len(x), n_quad=n_quad)
    area = 0.0
    for g in b.groups:
        X = x[g.stencils]
        d = np.einsum("fqsk,fsd->fqkd", g.full("dN"), X)
        area += (np.linalg.norm(np.cross(d[..., 0, :], d[..., 1, :]), axis=-1) * b.qweights).sum()
    return area


def _polygon_area(x, f):
    p = x[f]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()


def test_limit_area_converges():
    """Area of the limit surface of a (radially perturbed) icosphere(1) control mesh (valence 5
    and 6 vertices) three ways:

    * polygon areas P_k of the k-times refined control mesh converge to it at O(4^-k): the ratio
      of successive differences lies in (3, 5) for k >= 1 (measured 4.1, 4.03, 4.006);
    * the integrated limit area (12-point rule) of the original control mesh agrees with the
      5-times refined polygon to 1e-3 (the brief's bound; measured 1.4e-4) and with the Richardson
      limit P_inf = P_5 + (P_5 - P_4)/3 to 1e-3 (measured 2.4e-4);
    * integrating the same limit surface from its once-refined control mesh (an identical
      surface with four times smaller irregular patches) cuts the remaining (quadrature) error by
      more than 3 (measured 4.8): the error lives on the non-polynomial irregular patches, whose
      area shrinks by 4 per level.
    """
    m = icosphere(1.0, 1)
    x = m.vertices * (1 + 0.05 * np.random.default_rng(3).standard_normal((len(m.vertices), 1)))
    xs, fs = refinement_chain(x, m.faces, 5)
    P = np.array([_polygon_area(a, b) for a, b in zip(xs, fs)])
    d = np.diff(P)
    ratios = d[:-1] / d[1:]
    assert ((ratios[1:] > 3) & (ratios[1:] < 5)).all(), ratios
    P_inf = P[5] + (P[5] - P[4]) / 3
    A = np.array([_limit_area(xs[k], fs[k]) for k in range(2)])
    assert abs(A[0] / P[5] - 1) < 1e-3, (A[0], P[5])
    err = np.abs(A - P_inf)
    assert err[0] / P_inf < 1e-3, err
    assert err[0] / err[1] > 3, err


# ------------------------------------------------------------------ closest point
@pytest.mark.parametrize("name", ["flipped", "torus"])
def test_project_point_recovers_limit_points(name):
    """``project_point`` (Gauss-Newton in the chart) applied to a limit point of a face must
    return that face, the same barycentric coordinates and distance ~0 (the residual is
    linear in the chart step near the solution, so Newton converges to round-off)."""
    x, f, _ = mesh(name)
    ev = SurfaceEvaluator(f, len(x))
    rng = np.random.default_rng(11)
    for face in rng.choice(len(f), 4, replace=False):
        bary = rng.dirichlet([3.0, 3.0, 3.0])
        target = ev.point(x, int(face), bary)
        got_face, got_bary, dist = project_point(ev, x, target, np.array([face]))
        assert got_face == face
        assert dist < 1e-12
        np.testing.assert_allclose(got_bary, bary, rtol=0, atol=1e-10)


def test_irregular_basis_cache_is_exact():
    """Faces whose local patches are the same up to the numbering of their vertices share one local
    subdivision (``irregular_basis(..., cache)``, the set-up of Delaunay meshes: 1944 of 2240 faces
    irregular on a 256-gon disk, 39 distinct patches among 430 faces on the 64-gon below); the
    cached basis equals the uncached one to round-off and keeps the stencil order."""
    from graspdef.geometry.primitives import polygon
    from graspdef.subdivision.basis import irregular_basis, vertex_faces
    from graspdef.subdivision.halfedge import face_counts, interior_mask
    from graspdef.subdivision.quadrature import triangle_rule

    th = 2 * np.pi * np.arange(64) / 64
    m = polygon(np.c_[50 * np.cos(th), 50 * np.sin(th)], edge_length=8, refinements=0)
    g = add_ghost_layer(m.vertices, m.faces)
    f, n = g.faces, g.n_control
    counts, inner = face_counts(f, n), interior_mask(f, n)
    act = np.arange(g.n_real_faces)
    irr = act[~np.all((counts[f[act]] == 6) & inner[f[act]], axis=1)]
    vf = vertex_faces(f, n)
    qp, _ = triangle_rule(6)
    cache = {}
    for i in irr[:120]:
        s0, *a = irregular_basis(f, vf, int(i), qp)
        s1, *b = irregular_basis(f, vf, int(i), qp, cache)
        assert np.array_equal(s0, s1)
        for x, y in zip(a, b):
            np.testing.assert_allclose(y, x, rtol=0, atol=1e-13)
    assert len(cache) < 60
