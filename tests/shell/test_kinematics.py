"""Kirchhoff-Love kinematics at a point (``kinematics.strains``, ``strain_jacobian``,
``strain_hessian_contract``), Cirak, Ortiz & Schroeder (2000), Sec. 2: membrane strain
e = (a - A)/2, curvature change k = b - B with b_ab = a_ab . n."""
import numpy as np
import pytest

from graspdef.shell.kinematics import (
    fundamental_forms,
    normal,
    skew,
    strain_hessian_contract,
    strain_jacobian,
    strains,
)
from shell_helpers import assert_fd_rate, random_rotation


def random_state(rng, n):
    """n random surface-derivative sets y = (a1, a2, a11, a22, a12) with well-separated tangents
    (|a1 x a2| bounded below), rest forms and stress weights."""
    y = rng.standard_normal((n, 5, 3))
    y[:, 0] += np.array([1.5, 0.0, 0.0])
    y[:, 1] += np.array([0.0, 1.5, 0.0])
    rest_a = rng.standard_normal((n, 3))
    rest_b = rng.standard_normal((n, 3))
    sig = rng.standard_normal((n, 6))
    return y, rest_a, rest_b, sig


def fd_wrt_y(fun, y, h):
    """Central differences of fun (returning (n, ...)) w.r.t. each of the 15 entries of y;
    result (n, ..., 5, 3)."""
    cols = []
    for K in range(5):
        for a in range(3):
            e = np.zeros_like(y)
            e[:, K, a] = h
            cols.append((fun(y + e) - fun(y - e)) / (2 * h))
    out = np.stack(cols, -1)
    return out.reshape(out.shape[:-1] + (5, 3))


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("h", [1e-2, 1e-3])
def test_strain_jacobian_fd(seed, h):
    """ds/dy against central differences at h and h/2.  Membrane rows are quadratic in y (FD exact
    up to round-off); curvature rows are rational (through n = a1 x a2 / |a1 x a2|) and their FD
    error must drop by 4 when h halves."""
    y, ra, rb, _ = random_state(np.random.default_rng(seed), 64)
    J = strain_jacobian(y)
    assert J.shape == (64, 6, 5, 3)
    f = lambda z: strains(z, ra, rb)                               # noqa: E731
    rel, n_ratio = assert_fd_rate(J, fd_wrt_y(f, y, h), fd_wrt_y(f, y, h / 2), what="ds/dy")
    assert n_ratio > 0 or rel < 1e-9        # the rate test really ran (or FD is already exact)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("h", [1e-2, 1e-3])
def test_strain_hessian_contract_fd(seed, h):
    """sum_i sig_i d2 s_i/dy2 against central differences of sum_i sig_i ds_i/dy at h and h/2
    (O(h^2) with ratio 4), for random weights sig, so all six strain Hessians are covered."""
    y, _, _, sig = random_state(np.random.default_rng(10 + seed), 64)
    H = strain_hessian_contract(y, sig)
    assert H.shape == (64, 5, 3, 5, 3)
    g = lambda z: np.einsum("ni,nika->nka", sig, strain_jacobian(z))   # noqa: E731
    assert_fd_rate(H, fd_wrt_y(g, y, h), fd_wrt_y(g, y, h / 2), what="d2s/dy2")


def test_strain_hessian_symmetric():
    """Second derivatives commute: H[K, a, L, b] = H[L, b, K, a] (to round-off, 1e-13 of max|H|:
    the two triangles are built by separate matrix products)."""
    y, _, _, sig = random_state(np.random.default_rng(20), 128)
    H = strain_hessian_contract(y, sig)
    np.testing.assert_allclose(H, H.transpose(0, 3, 4, 1, 2), rtol=0, atol=1e-13 * np.abs(H).max())


def test_strains_vanish_at_rest_and_are_rotation_invariant():
    """s(y; A(y), B(y)) = 0 exactly at the rest state, and the strains are invariant under a
    rotation Q of all five vectors (a_a.a_b, a_ab.n are scalars), so J(Q y) = J(y) Q^T."""
    rng = np.random.default_rng(3)
    y, _, _, _ = random_state(rng, 32)
    A, B = fundamental_forms(y)
    np.testing.assert_array_equal(strains(y, A, B), 0.0)
    ra, rb = rng.standard_normal((32, 3)), rng.standard_normal((32, 3))
    Q = random_rotation(rng)
    yq = y @ Q.T
    np.testing.assert_allclose(strains(yq, ra, rb), strains(y, ra, rb), rtol=0, atol=1e-13)
    np.testing.assert_allclose(strain_jacobian(yq), strain_jacobian(y) @ Q.T, rtol=0, atol=1e-13)


def test_strain_voigt_layout():
    """s = (e11, e22, 2 e12, k11, k22, 2 k12): shearing a1 by d a2 changes only a12, so only
    entry 2 moves, by 2 * (a1 . a2 change)/2; bending a11 along n changes only k11."""
    y = np.zeros((1, 5, 3))
    y[0, 0] = [1.0, 0.0, 0.0]
    y[0, 1] = [0.0, 1.0, 0.0]
    A, B = fundamental_forms(y)
    z = y.copy()
    z[0, 0] = [1.0, 0.25, 0.0]                     # a1.a2 = 0.25, a11 += 0.0625
    s = strains(z, A, B)[0]
    np.testing.assert_allclose(s, [0.5 * 0.0625, 0.0, 0.25, 0.0, 0.0, 0.0], rtol=0, atol=1e-16)
    z = y.copy()
    z[0, 2] = [0.0, 0.0, 0.3]                       # a_11 . n = 0.3, n = e_z
    z[0, 4] = [0.0, 0.0, 0.1]                       # a_12 . n = 0.1
    np.testing.assert_allclose(strains(z, A, B)[0], [0, 0, 0, 0.3, 0.0, 0.2], rtol=0, atol=1e-16)


@pytest.mark.parametrize("R, u, v", [(1.0, 0.3, 0.2), (2.5, -1.0, 0.7), (0.4, 2.0, -1.1)])
def test_fundamental_forms_of_a_sphere(R, u, v):
    """For the sphere x = R (cos u cos v, sin u cos v, sin v) the metric is diag(R^2 cos^2 v, R^2)
    and, with n = a1 x a2/|a1 x a2| = x/R (outward), b = -a / R: the second fundamental form of
    a sphere is proportional to the first (umbilic), and j = |a1 x a2| = R^2 cos v."""
    cu, su, cv, sv = np.cos(u), np.sin(u), np.cos(v), np.sin(v)
    x = R * np.array([cu * cv, su * cv, sv])
    y = R * np.array([[[-su * cv, cu * cv, 0.0],              # x_u
                       [-cu * sv, -su * sv, cv],              # x_v
                       [-cu * cv, -su * cv, 0.0],             # x_uu
                       [-cu * cv, -su * cv, -sv],             # x_vv
                       [su * sv, -cu * sv, 0.0]]])            # x_uv
    n, j = normal(y)
    np.testing.assert_allclose(n[0], x / R, rtol=0, atol=1e-15)
    np.testing.assert_allclose(j[0], R * R * cv, rtol=1e-14)
    a, b = fundamental_forms(y)
    np.testing.assert_allclose(a[0], [R * R * cv * cv, R * R, 0.0], rtol=0, atol=1e-14 * R * R)
    np.testing.assert_allclose(b[0], -a[0] / R, rtol=0, atol=1e-14 * R)


def test_skew_is_cross_product():
    """skew(v) @ w = v x w for random vectors (used in the curvature Hessian)."""
    rng = np.random.default_rng(4)
    v, w = rng.standard_normal((2, 20, 3))
    np.testing.assert_allclose(np.einsum("nij,nj->ni", skew(v), w), np.cross(v, w), rtol=0, atol=1e-14)
