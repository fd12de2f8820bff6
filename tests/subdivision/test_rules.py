"""Loop's subdivision rules (``rules.refine``, ``rules.limit_positions``, ``rules.loop_beta``),
Loop (1987)."""
import functools
import zlib

import numpy as np
import pytest
import scipy.sparse as sp
import trimesh

from graspdef.geometry.primitives import icosphere, rectangle
from graspdef.subdivision.halfedge import interior_mask
from graspdef.subdivision.rules import (
    limit_matrix,
    limit_positions,
    limit_weight,
    loop_beta,
    mesh_edges,
    refine,
)
from subdiv_helpers import bipyramid, random_flips, valences


def euler(faces, nv):
    return nv - len(mesh_edges(faces)[0]) + len(faces)


def closed_mesh(name):
    """Closed test meshes (vertices, faces), randomly perturbed so no symmetry hides an error."""
    x, f = _closed_mesh(name)
    return x.copy(), f.copy()


@functools.lru_cache(maxsize=None)
def _closed_mesh(name):
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    if name.startswith("icosphere"):
        m = icosphere(1.0, int(name[-1]))
        x, f = m.vertices, m.faces
    elif name.startswith("bipyramid"):
        x, f = bipyramid(int(name.split("-")[1]))
    elif name == "flipped":
        m = icosphere(1.0, 1)
        x, f = m.vertices, random_flips(m.vertices, m.faces, np.random.default_rng(1), 600)
    else:
        raise ValueError(name)
    return x + 0.05 * rng.standard_normal(x.shape), np.asarray(f, np.int64)


# valences present: icosphere 5, 6; bipyramid-n: 4 and n; "flipped": 3 .. 16
CLOSED = ["icosphere-0", "icosphere-1", "icosphere-2", "bipyramid-3", "bipyramid-4",
          "bipyramid-8", "bipyramid-12", "flipped"]


def test_flipped_mesh_has_wide_valence_range():
    """Guard for the test meshes: the edge-flipped icosphere has interior vertices of every
    valence 3..8 and some above 12, and the bipyramids have poles of valence n."""
    x, f = closed_mesh("flipped")
    val = valences(f, len(x))
    assert set(range(3, 9)) <= set(val.tolist()) and val.max() > 12
    assert interior_mask(f, len(x)).all()
    x, f = closed_mesh("bipyramid-12")
    assert sorted(valences(f, len(x)).tolist())[-2:] == [12, 12]


@pytest.mark.parametrize("n, beta", [(3, 3 / 16), (4, 31 / 256), (6, 1 / 16)])
def test_loop_beta_known_values(n, beta):
    """Loop's beta(n) = (5/8 - (3/8 + cos(2 pi/n)/4)^2)/n: beta(6) = 1/16 gives the quartic
    box-spline rule, beta(3) = 3/16, beta(4) = 31/256 (cos(pi/2) = 0: (5/8 - 9/64)/4)."""
    assert loop_beta(np.array(n)) == pytest.approx(beta, rel=1e-15)


def test_limit_weight_regular():
    """chi(6) = 1/(3/(8 beta) + 6) = 1/12: the limit mask 1/2, 1/12 x 6 of the box spline."""
    assert limit_weight(np.array(6)) == pytest.approx(1 / 12, rel=1e-15)


@pytest.mark.parametrize("name", CLOSED)
def test_refine_counts_and_topology(name):
    """One Loop step on a closed mesh: V + E new vertices (vertex points keep their numbers),
    4F faces, each row of S an affine combination (sums to 1, weights >= 0), every new directed
    edge has exactly one twin (closed, consistently oriented) and the Euler characteristic is
    kept (the refined mesh is homeomorphic to the old one)."""
    x, f = closed_mesh(name)
    nv = len(x)
    ne = len(mesh_edges(f)[0])
    S, f1 = refine(f, nv)
    assert S.shape == (nv + ne, nv)
    assert f1.shape == (4 * len(f), 3)
    np.testing.assert_allclose(np.asarray(S.sum(axis=1)).ravel(), 1.0, rtol=0, atol=1e-15)
    assert S.data.min() >= 0.0
    assert len(np.unique(f1)) == nv + ne
    assert (f1[:, 0] != f1[:, 1]).all() and (f1[:, 1] != f1[:, 2]).all() and (f1[:, 0] != f1[:, 2]).all()
    d = np.stack([f1.ravel(), np.roll(f1, -1, 1).ravel()], 1)
    key = d[:, 0] * (nv + ne) + d[:, 1]
    twin = d[:, 1] * (nv + ne) + d[:, 0]
    assert len(np.unique(key)) == len(key)
    assert np.isin(twin, key).all()
    assert euler(f1, nv + ne) == euler(f, nv) == 2


def test_refine_open_mesh():
    """On an open rectangle the rows still sum to 1 (midpoint and 1/8-3/4-1/8 boundary masks),
    the Euler characteristic 1 of a disc is kept, and boundary edge and vertex points use only
    boundary neighbours, so every refined boundary point stays on its straight side -- except
    the four corner vertices, which the crease mask without a corner rule moves to
    3/4 c + 1/8 (n1 + n2) (the corner is rounded off)."""
    nx, ny = 4, 3
    m = rectangle(2.0, 1.0, nx, ny)
    x, f = m.vertices, m.faces
    S, f1 = refine(f, len(x))
    np.testing.assert_allclose(np.asarray(S.sum(axis=1)).ravel(), 1.0, rtol=0, atol=1e-15)
    assert euler(f1, S.shape[0]) == euler(f, len(x)) == 1
    x1 = S @ x
    bnd = ~interior_mask(f1, len(x1))
    assert bnd.sum() == 2 * 2 * (nx + ny)
    corners = np.array([0, nx, (nx + 1) * ny, (nx + 1) * (ny + 1) - 1])
    keep = bnd.copy()
    keep[corners] = False
    on_side = (np.abs(np.abs(x1[:, 0]) - 1.0) <= 1e-15) | (np.abs(np.abs(x1[:, 1]) - 0.5) <= 1e-15)
    assert on_side[keep].all()
    hx, hy = 2.0 / nx, 1.0 / ny
    np.testing.assert_allclose(np.abs(x1[corners, :2]), [[1 - hx / 8, 0.5 - hy / 8]] * 4, rtol=0, atol=1e-15)


@pytest.mark.parametrize("name", CLOSED)
def test_limit_positions_are_fixed_under_refinement(name):
    """The limit point of a vertex does not change when the mesh is refined: limit_positions of
    the refined mesh at the old vertices equals limit_positions of the original mesh.  This is an
    exact identity of Loop subdivision (the limit mask is the left eigenvector of eigenvalue 1 of
    the local subdivision matrix), and also holds after a second step."""
    x, f = closed_mesh(name)
    L0 = limit_positions(x, f)
    S, f1 = refine(f, len(x))
    x1 = S @ x
    L1 = limit_positions(x1, f1)
    np.testing.assert_allclose(L1[: len(x)], L0, rtol=0, atol=1e-14)
    S2, f2 = refine(f1, len(x1))
    L2 = limit_positions(S2 @ x1, f2)
    np.testing.assert_allclose(L2[: len(x1)], L1, rtol=0, atol=1e-14)


@pytest.mark.parametrize("name", CLOSED)
def test_vertex_points_contract_to_limit_exactly(name):
    """The one-ring of a vertex is closed under Loop's rules, and its rotation-invariant part
    (centre c, ring mean r) evolves by [[1 - n beta, n beta], [3/8, 5/8]], eigenvalues 1 and
    lambda = 5/8 - n beta; every other Fourier mode vanishes at the centre.  Hence
    c_k - L = lambda^k (c_0 - L) exactly, which ties loop_beta, limit_weight and refine together
    (a wrong limit weight gives a non-geometric sequence)."""
    x, f = closed_mesh(name)
    n = valences(f, len(x))
    lam = 5.0 / 8.0 - n * loop_beta(n)
    L = limit_positions(x, f)
    xk, fk = x, f
    for k in range(1, 4):
        S, fk = refine(fk, len(xk))
        xk = S @ xk
        np.testing.assert_allclose(xk[: len(x)] - L, (lam ** k)[:, None] * (x - L), rtol=0, atol=1e-14)


@pytest.mark.parametrize("name", CLOSED)
def test_limit_matrix_matches_limit_positions(name):
    """``limit_matrix`` (sparse rows of the limit masks) gives the same points as
    ``limit_positions`` for any subset of (interior) vertices, and its rows sum to 1."""
    x, f = closed_mesh(name)
    rows = np.random.default_rng(0).permutation(len(x))[: max(3, len(x) // 2)]
    Lm = limit_matrix(f, len(x), rows)
    assert sp.issparse(Lm) and Lm.shape == (len(rows), len(x))
    np.testing.assert_allclose(Lm @ x, limit_positions(x, f)[rows], rtol=0, atol=1e-15)
    np.testing.assert_allclose(np.asarray(Lm.sum(1)).ravel(), 1.0, rtol=0, atol=1e-15)


def test_limit_positions_nan_on_boundary():
    """Boundary vertices have no closed one-ring, so no interior limit mask: NaN there, finite
    elsewhere."""
    m = rectangle(1.0, 1.0, 3, 3)
    L = limit_positions(m.vertices, m.faces)
    inner = interior_mask(m.faces, len(m.vertices))
    assert np.isnan(L[~inner]).all() and np.isfinite(L[inner]).all()


@pytest.mark.parametrize("name", CLOSED)
def test_matches_trimesh_subdivide_loop(name):
    """trimesh.remesh.subdivide_loop uses the same rules on closed meshes: Loop's original
    beta(n) = (5/8 - (3/8 + cos(2 pi/n)/4)^2)/n (written as (40 - (2 cos + 3)^2)/(64 n)),
    3/8-3/8-1/8-1/8 edge points, old vertices first and then one vertex per edge, and children
    0..2 with our corner order (v0, m01, m20), (m01, v1, m12), (m20, m12, v2).  So the refined
    point sets must agree corner by corner.  (On open meshes trimesh averages every boundary
    neighbour, also those joined by an interior edge, so only closed meshes are compared.)"""
    x, f = closed_mesh(name)
    S, f1 = refine(f, len(x))
    x1 = S @ x
    tv, tf = trimesh.remesh.subdivide_loop(x, f)
    assert len(tv) == len(x1) and len(tf) == len(f1)
    np.testing.assert_allclose(tv[: len(x)], x1[: len(x)], rtol=0, atol=1e-14)
    ours = f1.reshape(-1, 4, 3)[:, :3].reshape(-1, 3)
    theirs = np.asarray(tf).reshape(-1, 4, 3)[:, :3].reshape(-1, 3)
    np.testing.assert_allclose(tv[theirs], x1[ours], rtol=0, atol=1e-14)
