"""The regular Loop patch (``patch.regular_basis``): the 12 quartic box-spline functions of
Stam (1998), Appendix, on the chart A = (0, 0), B = (1, 0), C = (0, 1)."""
import numpy as np
import pytest

from graspdef.subdivision.patch import LATTICE, regular_basis
from subdiv_helpers import assert_fd_rate


def triangle_points(n, rng, closed=True):
    """``n`` uniform random points of the reference triangle plus (if ``closed``) its corners and
    edge midpoints, where sign and symmetry errors show first."""
    r = rng.random((n, 2))
    flip = r.sum(1) > 1
    r[flip] = 1 - r[flip]
    if closed:
        r = np.vstack([r, [[0, 0], [1, 0], [0, 1], [0.5, 0], [0.5, 0.5], [0, 0.5]]])
    return r


def lattice_index(points):
    """Index in LATTICE of each integer point (asserts it is in the stencil)."""
    idx = [int(np.flatnonzero((LATTICE == p).all(1))[0]) for p in np.asarray(points, np.int64)]
    return np.array(idx)


def test_partition_of_unity():
    """sum_i N_i = 1 everywhere (Loop/box-spline basis, Stam 1998): needed for affine invariance.
    The functions are degree-4 polynomials with coefficients k/12, so the sum is exact up to
    round-off of 15-term dot products (< 1e-14)."""
    p = triangle_points(200, np.random.default_rng(0))
    N, dN, ddN = regular_basis(p)
    assert N.shape == (len(p), 12) and dN.shape == (len(p), 12, 2) and ddN.shape == (len(p), 12, 3)
    np.testing.assert_allclose(N.sum(-1), 1.0, rtol=0, atol=1e-14)
    np.testing.assert_allclose(dN.sum(-2), 0.0, rtol=0, atol=1e-13)
    np.testing.assert_allclose(ddN.sum(-2), 0.0, rtol=0, atol=1e-13)


def test_linear_precision():
    """sum_i N_i(v, w) LATTICE_i = (v, w): the box spline reproduces linear functions, so the
    control points placed on the lattice give back the chart map itself; its chart Jacobian is the
    identity and its second derivatives vanish."""
    p = triangle_points(200, np.random.default_rng(1))
    N, dN, ddN = regular_basis(p)
    L = LATTICE.astype(float)
    np.testing.assert_allclose(N @ L, p, rtol=0, atol=1e-14)
    np.testing.assert_allclose(np.einsum("qsd,sk->qkd", dN, L), np.broadcast_to(np.eye(2), (len(p), 2, 2)),
                               rtol=0, atol=1e-13)
    np.testing.assert_allclose(np.einsum("qsd,sk->qkd", ddN, L), 0.0, rtol=0, atol=1e-13)


def test_nonnegative_inside_triangle():
    """Box splines are non-negative (convex-hull property, Loop 1987); on a fine grid of the
    closed triangle no function dips below -1e-15 (round-off of exact zeros, e.g. function 5 and
    8 vanish on whole edges)."""
    g = np.linspace(0.0, 1.0, 41)
    v, w = np.meshgrid(g, g)
    keep = v + w <= 1.0 + 1e-15
    p = np.stack([v[keep], w[keep]], 1)
    N, _, _ = regular_basis(p)
    assert N.min() >= -1e-15, N.min()


def test_corner_values_are_loop_limit_mask():
    """At the chart corners the patch reproduces the Loop limit mask of a valence-6 vertex:
    1/2 at the vertex, 1/12 = chi(6) at each of its six lattice neighbours, 0 elsewhere
    (Loop 1987; chi(n) = 1/(3/(8 beta) + n) with beta(6) = 1/16)."""
    N, _, _ = regular_basis(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]))
    ring = np.array([[1, 0], [0, 1], [-1, 1], [-1, 0], [0, -1], [1, -1]])
    for k, corner in enumerate([(0, 0), (1, 0), (0, 1)]):
        expect = np.zeros(12)
        expect[lattice_index([corner])] = 0.5
        expect[lattice_index(ring + np.array(corner))] = 1.0 / 12.0
        np.testing.assert_allclose(N[k], expect, rtol=0, atol=1e-15)


@pytest.mark.parametrize("name, T, shift", [
    # rotation A->B->C relabels the chart: new coordinates (w, 1 - v - w)
    ("rotation", np.array([[0, 1], [-1, -1]]), np.array([0, 1])),
    # reflection swapping B and C: new coordinates (w, v)
    ("reflection", np.array([[0, 1], [1, 0]]), np.array([0, 0])),
])
def test_symmetry_of_the_stencil(name, T, shift):
    """The patch has the symmetries of the triangle: relabelling the corners maps the chart by an
    integer affine map p -> T p + shift that permutes the 12 lattice points, and each function
    must follow its control point: N_i(p) = N_{pi(i)}(T p + shift).  This checks all 180
    coefficients of Stam's table against each other (a single wrong entry breaks it)."""
    perm = lattice_index(LATTICE @ T.T + shift)
    p = triangle_points(50, np.random.default_rng(2))
    N, dN, _ = regular_basis(p)
    Nt, dNt, _ = regular_basis(p @ T.T + shift)
    np.testing.assert_allclose(N, Nt[:, perm], rtol=0, atol=1e-14)
    # chain rule: grad_p N_i = T^T grad N_pi(i)
    np.testing.assert_allclose(dN, np.einsum("qsk,kd->qsd", dNt[:, perm], T), rtol=0, atol=1e-13)


@pytest.mark.parametrize("h", [1e-2, 1e-3])
def test_first_derivatives_fd(h):
    """dN/dv, dN/dw against central differences at h and h/2: the functions are quartic
    polynomials, so the central-difference error is exactly (h^2/6) f''' and drops by 4."""
    p = triangle_points(40, np.random.default_rng(3), closed=False)
    _, dN, _ = regular_basis(p)
    fd = []
    for step in (h, h / 2):
        cols = []
        for d in range(2):
            e = np.zeros(2)
            e[d] = step
            cols.append((regular_basis(p + e)[0] - regular_basis(p - e)[0]) / (2 * step))
        fd.append(np.stack(cols, -1))
    assert_fd_rate(dN, fd[0], fd[1], what="dN")


@pytest.mark.parametrize("h", [1e-2, 1e-3])
def test_second_derivatives_fd(h):
    """ddN = (N_vv, N_ww, N_vw) against central differences of dN at h and h/2 (error O(h^2),
    ratio 4); N_vw is checked both as d/dw of N_v and d/dv of N_w (symmetry of mixed partials)."""
    p = triangle_points(40, np.random.default_rng(4), closed=False)
    _, _, ddN = regular_basis(p)
    ev, ew = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    fd = []
    for step in (h, h / 2):
        dv = (regular_basis(p + step * ev)[1] - regular_basis(p - step * ev)[1]) / (2 * step)
        dw = (regular_basis(p + step * ew)[1] - regular_basis(p - step * ew)[1]) / (2 * step)
        fd.append(np.stack([dv[..., 0], dw[..., 1], dw[..., 0], dv[..., 1]], -1))
    exact = np.concatenate([ddN, ddN[..., 2:3]], -1)
    assert_fd_rate(exact, fd[0], fd[1], what="ddN")


def test_broadcasting_shape():
    """Points of any leading shape (..., 2) give (..., 12) etc. with the same values as flat."""
    p = triangle_points(12, np.random.default_rng(5), closed=False)
    N, dN, ddN = regular_basis(p.reshape(3, 4, 2))
    N0, dN0, ddN0 = regular_basis(p)
    assert N.shape == (3, 4, 12) and dN.shape == (3, 4, 12, 2) and ddN.shape == (3, 4, 12, 3)
    np.testing.assert_array_equal(N.reshape(12, 12), N0)
    np.testing.assert_array_equal(ddN.reshape(12, 12, 3), ddN0)
