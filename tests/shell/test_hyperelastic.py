"""Hyperelastic shell materials (``shell.hyperelastic``): incompressible neo-Hookean,
Mooney-Rivlin and exponential laws and a compressible neo-Hookean law, integrated through the
thickness (Kiendl, Hsu, Wu & Reali 2015, "Isogeometric Kirchhoff-Love shell formulations for
general hyperelastic materials", CMAME 291:280), and the material registry."""
import math

import numpy as np
import pytest

from graspdef.errors import ProblemError
from graspdef.geometry.primitives import rectangle
from graspdef.shell.energy import ShellEnergy
from graspdef.shell.hyperelastic import (
    MATERIALS,
    PARAMETERS,
    CompressibleMooneyRivlin,
    CompressibleNeoHookean,
    Exponential,
    MooneyRivlin,
    NeoHookean,
    in_plane_invariants,
    make_material,
)
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell
from shell_helpers import assert_fd_rate

NAN, INF = float("nan"), float("inf")

#: every material, with moduli of order 1 (the tests normalise by the small-strain shear modulus)
ALL = {
    "linear_elastic": LinearElastic(E=2.6, nu=0.3),
    "neo_hookean": NeoHookean(mu=1.0),
    "neo_hookean_2pt": NeoHookean(mu=1.0, n_thickness=2),
    "mooney_rivlin": MooneyRivlin(C1=0.35, C2=0.15),
    "mooney_rivlin_c2_only": MooneyRivlin(C1=0.0, C2=0.5, n_thickness=5),
    "exponential": Exponential(C0=0.625, C1=0.8),
    "compressible_neo_hookean": CompressibleNeoHookean(mu=1.0, lam=1.5),
    "compressible_neo_hookean_nu0": CompressibleNeoHookean(mu=1.0, lam=0.0, n_thickness=4),
    "compressible_mooney_rivlin": CompressibleMooneyRivlin(C1=0.35, C2=0.15, lam=1.5),
    "compressible_mooney_rivlin_nu0": CompressibleMooneyRivlin(C1=0.2, C2=0.3, lam=0.0, n_thickness=4),
    "compressible_mooney_rivlin_c2_only": CompressibleMooneyRivlin(C1=0.0, C2=0.5, lam=20.0),
}
HYPER = {k: v for k, v in ALL.items() if k != "linear_elastic"}
INCOMPRESSIBLE = {k: v for k, v in HYPER.items() if not k.startswith("compressible")}


def _mu(mat):
    """Small-strain shear modulus E / (2 (1 + nu))."""
    return mat.E / (2.0 * (1.0 + mat.nu))


def _inv(A):
    """(A^11, A^22, A^12) of a covariant metric A (..., 2, 2)."""
    Ai = np.linalg.inv(A)
    return np.stack([Ai[..., 0, 0], Ai[..., 1, 1], Ai[..., 0, 1]], -1)


def _voigt(T):
    """(T11, T22, 2 T12) of symmetric 2 x 2 tensors (..., 2, 2)."""
    return np.stack([T[..., 0, 0], T[..., 1, 1], 2.0 * T[..., 0, 1]], -1)


def _random_states(rng, n, e_max=0.3, kt_max=0.3):
    """n random points: rest metric A = L^T L of a random non-orthogonal frame L (tangents a_a =
    L e_a), thickness t0 in [0.02, 0.5], Cartesian membrane strain entries up to e_max and
    curvature change times t0 up to kt_max, pulled back to covariant components (e = L^T e_cart L).
    Draws whose right Cauchy-Green tensor has an eigenvalue below 0.25 anywhere in the thickness
    are redrawn (moderate but far from inversion)."""
    s, inv, t = [], [], []
    while len(s) < n:
        L = np.array([[1.0, 0.0], [0.0, 1.0]]) + 0.5 * rng.uniform(-1, 1, (2, 2))
        if abs(np.linalg.det(L)) < 0.3:
            continue
        t0 = rng.uniform(0.02, 0.5)
        ec = rng.uniform(-e_max, e_max, (2, 2))
        kc = rng.uniform(-kt_max, kt_max, (2, 2)) / t0
        ec, kc = 0.5 * (ec + ec.T), 0.5 * (kc + kc.T)
        if min(np.linalg.eigvalsh(np.eye(2) + 2 * (ec - z * kc)).min() for z in (-t0 / 2, t0 / 2)) < 0.25:
            continue
        s.append(np.concatenate([_voigt(L.T @ ec @ L), _voigt(L.T @ kc @ L)]))
        inv.append(_inv(L.T @ L))
        t.append(t0)
    return np.array(s), np.array(inv), np.array(t)


# ------------------------------------------------------------------------------------------------
# in-plane invariants
# ------------------------------------------------------------------------------------------------
def test_in_plane_invariants_against_matrices():
    """c = tr(A^-1 C) and d = det(C)/det(A) for C = A + 2E, computed with 2 x 2 matrices, equal
    2 + p and 1 + p + q; grad c = 2 (A^11, A^22, A^12).  d is exactly quadratic in
    v = (E11, E22, 2E12), so d(v + w) = d + grad_d . w + w.H.w / 2 to round-off for any w: this
    checks grad_d and the constant Voigt Hessian det(A^-1) [[0, 4, 0], [4, 0, 0], [0, 0, -2]]
    (the -2 on the shear entry because v3 = 2 E12)."""
    rng = np.random.default_rng(0)
    for _ in range(20):
        L = np.eye(2) + 0.5 * rng.uniform(-1, 1, (2, 2))
        A = L.T @ L
        E = rng.uniform(-0.4, 0.4, (2, 2))
        E = 0.5 * (E + E.T)
        ri, v = _inv(A), _voigt(E)
        p, q, gc, gd, Hd = in_plane_invariants(v, ri)
        C = A + 2 * E
        assert 2 + p == pytest.approx(np.trace(np.linalg.solve(A, C)), rel=1e-14, abs=1e-14)
        assert 1 + p + q == pytest.approx(np.linalg.det(C) / np.linalg.det(A), rel=1e-13, abs=1e-14)
        np.testing.assert_allclose(gc, 2 * ri, rtol=1e-15)
        np.testing.assert_array_equal(Hd, Hd.T)
        w = rng.uniform(-0.3, 0.3, 3)
        p2, q2, *_ = in_plane_invariants(v + w, ri)
        taylor = (1 + p + q) + gd @ w + 0.5 * w @ Hd @ w
        assert 1 + p2 + q2 == pytest.approx(taylor, rel=1e-13, abs=1e-14)
        Wm = np.array([[w[0], w[2] / 2], [w[2] / 2, w[1]]])
        assert 0.5 * w @ Hd @ w == pytest.approx(4 * np.linalg.det(Wm) / np.linalg.det(A), rel=1e-12)


# ------------------------------------------------------------------------------------------------
# derivatives
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", list(ALL))
def test_density_derivatives_match_finite_differences(name):
    """dW/ds against central differences of W, d2W/ds2 against central differences of dW/ds, at
    40 random states (membrane strain up to 0.3, curvature change x t0 up to 0.3, random
    non-orthogonal rest metrics and thicknesses).  Variables are normalised so that every entry
    is O(1): strains (e, t0 k), energy W / (mu t0).  Steps h = 2e-3 and h/2: each entry agrees
    to round-off or its error falls by 4 (O(h^2)); a wrong derivative fails.  The Hessian is
    symmetric to round-off."""
    mat = ALL[name]
    rng = np.random.default_rng(1)
    s, ri, t = _random_states(rng, 40)
    sv = np.concatenate([np.ones((len(t), 3)), np.repeat(1.0 / t[:, None], 3, 1)], 1)  # ds per unit of s_hat
    norm = _mu(mat) * t
    W, dW, ddW = mat.density(s, ri, t)
    assert W.shape == (40,) and dW.shape == (40, 6) and ddW.shape == (40, 6, 6)
    assert np.abs(ddW - np.swapaxes(ddW, -1, -2)).max() <= 1e-15 * np.abs(ddW).max()
    g_hat = dW * sv / norm[:, None]
    H_hat = ddW * sv[:, :, None] * sv[:, None, :] / norm[:, None, None]
    fd_g, fd_H = [], []
    for h in (2e-3, 1e-3):
        cols_g, cols_H = [], []
        for j in range(6):
            ds = np.zeros_like(s)
            ds[:, j] = h * sv[:, j]
            Wp, gp, _ = mat.density(s + ds, ri, t)
            Wm, gm, _ = mat.density(s - ds, ri, t)
            cols_g.append((Wp - Wm) / (2 * h) / norm)
            cols_H.append((gp - gm) * sv / (2 * h) / norm[:, None])
        fd_g.append(np.stack(cols_g, -1))
        fd_H.append(np.stack(cols_H, -1))
    assert_fd_rate(g_hat, fd_g[0], fd_g[1], what=f"{name} dW/ds")
    assert_fd_rate(H_hat, fd_H[0], fd_H[1], what=f"{name} d2W/ds2")


@pytest.mark.parametrize("name", list(HYPER))
def test_vectorised_over_faces_and_quadrature_points(name):
    """s (n_faces, n_quad, 6), rest_inv (n_faces, n_quad, 3) and thickness (n_faces, 1), as the
    assembly passes them, give the same numbers as point-by-point evaluation."""
    mat = HYPER[name]
    rng = np.random.default_rng(2)
    s, ri, _ = _random_states(rng, 12)
    t = np.array([[0.1], [0.3], [0.05]])
    W, dW, ddW = mat.density(s.reshape(3, 4, 6), ri.reshape(3, 4, 3), t)
    assert W.shape == (3, 4) and dW.shape == (3, 4, 6) and ddW.shape == (3, 4, 6, 6)
    for f in range(3):
        for q in range(4):
            w1, g1, h1 = mat.density(s[4 * f + q], ri[4 * f + q], t[f, 0])
            assert W[f, q] == pytest.approx(w1, rel=1e-14)
            np.testing.assert_allclose(dW[f, q], g1, rtol=1e-14, atol=1e-16 * np.abs(g1).max())
            np.testing.assert_allclose(ddW[f, q], h1, rtol=1e-14, atol=1e-16 * np.abs(h1).max())


# ------------------------------------------------------------------------------------------------
# small strain = linear elasticity
# ------------------------------------------------------------------------------------------------
SMALL_STRAIN = [
    (NeoHookean(mu=1.3e6), LinearElastic(E=3 * 1.3e6, nu=0.5)),
    (NeoHookean(mu=1.3e6, n_thickness=2), LinearElastic(E=3 * 1.3e6, nu=0.5)),
    (MooneyRivlin(C1=4e5, C2=1e5), LinearElastic(E=3 * 2 * 5e5, nu=0.5)),
    (MooneyRivlin(C1=4e5, C2=0.0, n_thickness=4), LinearElastic(E=3 * 8e5, nu=0.5)),
    (Exponential(C0=2e5, C1=3.0), LinearElastic(E=3 * 2 * 2e5 * 3.0, nu=0.5)),
    (CompressibleNeoHookean.from_E_nu(2e11, 0.3), LinearElastic(E=2e11, nu=0.3)),
    (CompressibleNeoHookean.from_E_nu(5e6, 0.0), LinearElastic(E=5e6, nu=0.0)),
    (CompressibleNeoHookean.from_E_nu(5e6, 0.49), LinearElastic(E=5e6, nu=0.49)),
    # mu = E / (2 (1 + nu)) = 1, lam = E nu / ((1 + nu)(1 - 2 nu)) = 1.5 <=> E = 2.6, nu = 0.3
    (CompressibleNeoHookean(mu=1.0, lam=1.5), LinearElastic(E=2.6, nu=0.3)),
    (CompressibleMooneyRivlin.from_E_nu(1e6, 0.3, 0.25), LinearElastic(E=1e6, nu=0.3)),
    (CompressibleMooneyRivlin.from_E_nu(1e6, 0.45, 0.1), LinearElastic(E=1e6, nu=0.45)),
    (CompressibleMooneyRivlin.from_E_nu(2e11, 0.0, 1.0, n_thickness=2), LinearElastic(E=2e11, nu=0.0)),
    (CompressibleMooneyRivlin.from_E_nu(5e6, 0.49, 0.0), LinearElastic(E=5e6, nu=0.49)),
    # mu = 2 (C1 + C2) = 1, lam = 1.5 <=> E = 2.6, nu = 0.3 (whatever C2/C1)
    (CompressibleMooneyRivlin(C1=0.35, C2=0.15, lam=1.5), LinearElastic(E=2.6, nu=0.3)),
]


@pytest.mark.parametrize("mat, lin", SMALL_STRAIN, ids=lambda x: repr(x))
def test_small_strain_limit_is_linear_elasticity(mat, lin):
    """At zero strain the energy and dW/ds vanish and d2W/ds2 equals the Koiter tangent
    blockdiag(t H, t^3/12 H) of the linearised law (E = 3 mu, nu = 1/2 for incompressible
    materials; the given E, nu for the compressible one): Gauss-Legendre with >= 2 points
    integrates zeta^0 and zeta^2 exactly.  Checked to 1e-10 relative on non-orthogonal rest
    metrics and several thicknesses; ``tangent`` is the same matrix and (E, nu) the same moduli."""
    rng = np.random.default_rng(3)
    _, ri, _ = _random_states(rng, 6)
    t = np.array([1e-3, 0.01, 0.1, 0.2, 1.0, 2.0])
    W, dW, ddW = mat.density(np.zeros((6, 6)), ri, t)
    ref = lin.tangent(ri, t)
    scale = np.abs(ref).max(axis=(-1, -2))
    assert np.all(W == 0.0)
    assert np.abs(dW).max() <= 1e-15 * scale.max()
    # blockwise relative error: the bending block is t^2/12 smaller than the membrane block
    for blk in (np.s_[..., :3, :3], np.s_[..., 3:, 3:]):
        err = np.abs(ddW[blk] - ref[blk]).max(axis=(-1, -2)) / np.abs(ref[blk]).max(axis=(-1, -2))
        assert err.max() <= 1e-10, err
    assert np.abs(ddW[..., :3, 3:]).max() <= 1e-15 * scale.max()
    np.testing.assert_array_equal(mat.tangent(ri, t), ddW)
    assert mat.E == pytest.approx(lin.E, rel=1e-14) and mat.nu == pytest.approx(lin.nu, rel=1e-14, abs=1e-16)


@pytest.mark.parametrize("name", list(HYPER))
def test_pure_bending_of_a_flat_plate(name):
    """Flat plate (A = I), no membrane strain, curvature change k11 with k t = 1e-4: the energy
    per unit area is the plate value D k^2 / 2 = E t^3 / (24 (1 - nu^2)) k^2 with the small-strain
    moduli (E = 3 mu, nu = 1/2 incompressible), to 1e-6 relative (the nonlinear correction is
    O((k t)^2): odd powers of zeta integrate to zero)."""
    mat = HYPER[name]
    t = 0.02
    k = 1e-4 / t
    W, _, _ = mat.density(np.array([0, 0, 0, k, 0, 0.0]), np.array([1.0, 1.0, 0.0]), t)
    D = mat.E * t ** 3 / (12 * (1 - mat.nu ** 2))
    assert W == pytest.approx(0.5 * D * k ** 2, rel=1e-6)


# ------------------------------------------------------------------------------------------------
# finite strain: exact homogeneous states (../shared/BENCHMARKS.md section 4.1)
# ------------------------------------------------------------------------------------------------
def _uniaxial(mat, lam, t0):
    """Flat sheet (A = I) stretched by lam in direction 1, direction 2 free: e11 = (lam^2 - 1)/2,
    e22 from dW/de22 = 0 (Newton with the material's own d2W/de22^2, to round-off).  Returns the
    lateral stretch and the force per unit reference width N = dW/dlam = lam dW/de11 [N/m].
    Newton steps are halved while they would invert the sheet (infinite energy)."""
    ri = np.array([1.0, 1.0, 0.0])
    s = np.array([(lam ** 2 - 1) / 2, 0.0, 0.0, 0.0, 0.0, 0.0])
    for _ in range(60):
        _, g, H = mat.density(s, ri, t0)
        step = -g[1] / H[1, 1]
        while not np.isfinite(mat.density(s + step * np.eye(6)[1], ri, t0)[0]):
            step /= 2
        s[1] += step
        if abs(step) <= 1e-16:
            break
    _, g, _ = mat.density(s, ri, t0)
    assert abs(g[1]) <= 1e-13 * abs(g[0])
    return math.sqrt(1 + 2 * s[1]), lam * g[0]


MU_GSMO = 1.5e6      # G+Smo gsThinShellAssembler_test UAT: mu = 1.5e6, t = 0.001, lambda = 2, MR ratio 7


@pytest.mark.parametrize("mat, cauchy", [
    (NeoHookean(mu=MU_GSMO), lambda l: MU_GSMO * (l ** 2 - 1 / l)),
    (MooneyRivlin(C1=7 / 8 * MU_GSMO / 2, C2=1 / 8 * MU_GSMO / 2),
     lambda l: 2 * (l ** 2 - 1 / l) * (7 / 8 * MU_GSMO / 2 + 1 / 8 * MU_GSMO / 2 / l)),
    # exponential: sigma = 2 (lam^2 - 1/lam) dW/dI1 with dW/dI1 = C0 C1 exp(C1 (I1 - 3)),
    # I1 = lam^2 + 2/lam on the uniaxial path
    (Exponential(C0=2e5, C1=0.7),
     lambda l: 2 * (l ** 2 - 1 / l) * 2e5 * 0.7 * math.exp(0.7 * (l ** 2 + 2 / l - 3))),
], ids=["neo_hookean", "mooney_rivlin", "exponential"])
@pytest.mark.parametrize("lam", [2.0, 1.3, 0.7])
def test_uniaxial_tension_exact(mat, cauchy, lam):
    """Incompressible uniaxial tension (BENCHMARKS.md 4.1; G+Smo gsKLShell UAT_analytical): lateral
    stretch 1/sqrt(lam), deformed thickness t0/sqrt(lam), Cauchy stress sigma(lam) (NH
    mu (lam^2 - 1/lam), MR 2 (lam^2 - 1/lam)(C1 + C2/lam)).  The membrane force per unit reference
    width is sigma x deformed thickness x lateral stretch = sigma t0 / lam; it equals
    dW/dlam = lam dW/de11 (equivalently t0 S11 with S11 = sigma / lam^2).  Homogeneous, no
    curvature: exact up to round-off (1e-9 relative)."""
    t0 = 1e-3
    lat, N = _uniaxial(mat, lam, t0)
    assert lat == pytest.approx(1 / math.sqrt(lam), rel=1e-9)
    thick = t0 * mat.thickness_stretch(np.array([(lam ** 2 - 1) / 2, (lat ** 2 - 1) / 2, 0, 0, 0, 0]),
                                       np.array([1.0, 1.0, 0.0]))
    assert thick == pytest.approx(t0 / math.sqrt(lam), rel=1e-9)
    assert N == pytest.approx(cauchy(lam) * thick * lat, rel=1e-9)


@pytest.mark.parametrize("name", list(INCOMPRESSIBLE))
@pytest.mark.parametrize("skew", [False, True])
def test_equibiaxial_thickness_stretch(name, skew):
    """Equibiaxial stretch lam of an incompressible sheet, C_ab = lam^2 A_ab (e = (lam^2 - 1)/2 A,
    any rest metric): the thickness stretch is 1/lam^2."""
    mat = INCOMPRESSIBLE[name]
    A = np.array([[1.3, 0.4], [0.4, 0.8]]) if skew else np.eye(2)
    lam = np.array([0.6, 1.0, 1.5, 2.0, 3.0])
    e = (lam[:, None, None] ** 2 - 1) / 2 * A
    s = np.concatenate([_voigt(e), np.zeros((5, 3))], 1)
    np.testing.assert_allclose(mat.thickness_stretch(s, _inv(A)), 1 / lam ** 2, rtol=1e-14)


def _membrane_states(rng, n):
    s, ri, _ = _random_states(rng, n, e_max=0.6, kt_max=0.0)
    return s, ri


def test_neo_hookean_stress_is_the_plane_stress_3d_stress():
    """Incompressible neo-Hookean, homogeneous membrane state (k = 0): dW/de equals t0 times the
    2nd Piola-Kirchhoff stress S^ab = mu (A^ab - C33 C^ab) with C33 = 1/d (S = mu I - p C^-1,
    p fixed by S^33 = 0; cf. Kiendl et al. 2015), C^ab the inverse of C_ab, on non-orthogonal
    rest metrics (Voigt: dW/d(2 e12) = t0 S^12)."""
    rng = np.random.default_rng(4)
    mu, t0 = 2.0, 0.1
    mat = NeoHookean(mu)
    s, ri = _membrane_states(rng, 20)
    _, dW, _ = mat.density(s, ri, t0)
    for si, r, g in zip(s, ri, dW):
        Ainv = np.array([[r[0], r[2]], [r[2], r[1]]])
        A = np.linalg.inv(Ainv)
        C = A + 2 * np.array([[si[0], si[2] / 2], [si[2] / 2, si[1]]])
        c33 = np.linalg.det(A) / np.linalg.det(C)
        S = mu * (Ainv - c33 * np.linalg.inv(C))
        np.testing.assert_allclose(g[:3], t0 * np.array([S[0, 0], S[1, 1], S[0, 1]]), rtol=1e-12,
                                   atol=1e-14 * mu * t0)
        assert mat.thickness_stretch(si, r) == pytest.approx(math.sqrt(c33), rel=1e-14)


@pytest.mark.parametrize("mu, lam", [(1.0, 1.5), (1.0, 0.0), (1.0, 49.0), (3e5, 2e7)])
def test_compressible_neo_hookean_is_the_plane_stress_3d_law(mu, lam):
    """Compressible neo-Hookean (Bonet & Wood: S = mu (G^-1 - C^-1) + lam ln J C^-1), homogeneous
    membrane states with in-plane stretches up to ~1.5: the solved C33 = thickness_stretch^2
    makes S^33 = mu (1 - 1/C33) + lam ln J / C33 vanish (plane stress, to round-off), and dW/de
    equals t0 S^ab (in-plane block of the 3D stress, with J^2 = C33 det C_ab / det A_ab)."""
    rng = np.random.default_rng(5)
    t0 = 0.05
    mat = CompressibleNeoHookean(mu, lam)
    s, ri = _membrane_states(rng, 20)
    _, dW, _ = mat.density(s, ri, t0)
    c33 = mat.thickness_stretch(s, ri) ** 2
    for si, r, g, C33 in zip(s, ri, dW, c33):
        Ainv = np.array([[r[0], r[2]], [r[2], r[1]]])
        A = np.linalg.inv(Ainv)
        C = A + 2 * np.array([[si[0], si[2] / 2], [si[2] / 2, si[1]]])
        lnJ = 0.5 * math.log(C33 * np.linalg.det(C) / np.linalg.det(A))
        S33 = mu * (1 - 1 / C33) + lam * lnJ / C33
        assert abs(S33) <= 1e-14 * (mu + lam)
        S = mu * (Ainv - np.linalg.inv(C)) + lam * lnJ * np.linalg.inv(C)
        np.testing.assert_allclose(g[:3], t0 * np.array([S[0, 0], S[1, 1], S[0, 1]]), rtol=1e-11,
                                   atol=1e-14 * (mu + lam) * t0)


@pytest.mark.parametrize("C1, C2, lam", [(0.35, 0.15, 1.5), (0.5, 0.0, 1.5), (0.0, 0.5, 0.0), (0.1, 0.4, 49.0),
                                         (3e5, 1e5, 2e7)])
def test_compressible_mooney_rivlin_is_the_plane_stress_3d_law(C1, C2, lam):
    """Compressible Mooney-Rivlin, psi = C1 (I1 - 3 - 2 ln J) + C2 (tr C^-1 - 3 + 2 ln J) + lam/2 (ln J)^2, so
    S = 2 C1 (G^-1 - C^-1) + 2 C2 (C^-1 - C^-1 G C^-1) + lam ln J C^-1; homogeneous membrane states with in-plane
    stretches up to ~1.5: the solved C33 = thickness_stretch^2 makes S^33 = 2 C1 (1 - 1/C33) + 2 C2 (1/C33 -
    1/C33^2) + lam ln J / C33 vanish (plane stress, to round-off), and dW/de equals t0 S^ab (in-plane block of the
    3D stress, J^2 = C33 det C_ab / det A_ab).  C2 = 0 is the compressible neo-Hookean law with mu = 2 C1."""
    rng = np.random.default_rng(5)
    t0 = 0.05
    mat = CompressibleMooneyRivlin(C1, C2, lam)
    s, ri = _membrane_states(rng, 20)
    _, dW, _ = mat.density(s, ri, t0)
    c33 = mat.thickness_stretch(s, ri) ** 2
    scale = C1 + C2 + lam
    for si, r, g, C33 in zip(s, ri, dW, c33):
        Ainv = np.array([[r[0], r[2]], [r[2], r[1]]])
        A = np.linalg.inv(Ainv)
        C = A + 2 * np.array([[si[0], si[2] / 2], [si[2] / 2, si[1]]])
        Ci = np.linalg.inv(C)
        lnJ = 0.5 * math.log(C33 * np.linalg.det(C) / np.linalg.det(A))
        S33 = 2 * C1 * (1 - 1 / C33) + 2 * C2 * (1 / C33 - 1 / C33 ** 2) + lam * lnJ / C33
        assert abs(S33) <= 1e-14 * scale
        S = 2 * C1 * (Ainv - Ci) + 2 * C2 * (Ci - Ci @ A @ Ci) + lam * lnJ * Ci
        np.testing.assert_allclose(g[:3], t0 * np.array([S[0, 0], S[1, 1], S[0, 1]]), rtol=1e-11,
                                   atol=1e-14 * scale * t0)
    if C2 == 0.0:
        ref = CompressibleNeoHookean(2 * C1, lam).density(s, ri, t0)
        for a, b in zip(mat.density(s, ri, t0), ref):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-14 * np.abs(b).max())


def test_compressible_mooney_rivlin_extreme_stretches():
    """The safeguarded plane-stress Newton solve converges from d = 1e-6 to 1e6 (equibiaxial), also for C1 = 0 and
    for nearly incompressible lam/mu = 1e6 (C33 -> 1/d); at lam = 0 the root is C33 = 1 (f(0) = lam ln d)."""
    d = np.logspace(-6, 6, 25)
    e = (np.sqrt(d) - 1) / 2
    s = np.stack([e, e] + [np.zeros_like(d)] * 4, -1)
    ri = np.array([1.0, 1.0, 0.0])
    for C1, C2, lam in ((0.4, 0.1, 0.0), (0.4, 0.1, 1.0), (0.0, 0.5, 3.0), (0.4, 0.1, 1e6)):
        mat = CompressibleMooneyRivlin(C1, C2, lam)
        C33 = mat.thickness_stretch(s, ri) ** 2
        p, q, *_ = in_plane_invariants(s[:, :3], ri)
        ln_c33, ln_d = np.log(C33), np.log1p(p + q)
        r = 4 * C1 * (C33 - 1) + 4 * C2 * (1 - 1 / C33) + lam * (ln_c33 + ln_d)
        assert np.all(np.abs(r) <= 1e-14 * (4 * C1 * C33 + 4 * C2 / C33 + lam * (1 + np.abs(ln_c33) + np.abs(ln_d)))), r
        if lam == 0.0:
            np.testing.assert_array_equal(C33, 1.0)
        if lam == 1e6:
            mid = (d >= 1e-2) & (d <= 1e2)
            np.testing.assert_allclose(C33[mid], 1 / d[mid], rtol=2.5e-4)


def test_compressible_neo_hookean_extreme_stretches():
    """The plane-stress Newton solve converges (C33 S^33 = 0 to round-off) from strong compression
    (d = 1e-6) to strong stretch (d = 1e6) and for nearly incompressible lam/mu = 1e6, where the
    thickness stretch tends to the incompressible 1/sqrt(d) (relative deviation ~ 2 C33 mu/lam,
    <= 2e-4 for 1e-2 <= d <= 1e2)."""
    for lam in (0.0, 1.0, 1e6):
        mat = CompressibleNeoHookean(1.0, lam)
        d = np.logspace(-6, 6, 25)
        e = (np.sqrt(d) - 1) / 2                      # equibiaxial, A = I: C = sqrt(d) I
        s = np.stack([e, e] + [np.zeros_like(d)] * 4, -1)
        C33 = mat.thickness_stretch(s, np.array([1.0, 1.0, 0.0])) ** 2
        # d as the material evaluates it from the strain (1 + p + q): at d = 1e-6 the strain
        # components carry only ~1e-10 relative information about d
        p, q, *_ = in_plane_invariants(s[:, :3], np.array([1.0, 1.0, 0.0]))
        assert np.allclose(1 + p + q, d, rtol=1e-9)
        ln_c33, ln_d = np.log(C33), np.log(1 + p + q)
        # C33 S^33 / mu = C33 - 1 + lam/mu ln J with ln J = (ln C33 + ln d)/2: zero to the
        # round-off of its terms (ln C33 is known to a few eps absolute, amplified by lam)
        r = C33 - 1 + lam * 0.5 * (ln_c33 + ln_d)
        assert np.all(np.abs(r) <= 1e-14 * (1 + C33 + lam * (1 + np.abs(ln_c33) + np.abs(ln_d)))), r
        if lam == 1e6:     # ln(C33 d) = -2 (C33 - 1)/lam -> 0: incompressible while C33 << lam/mu
            mid = (d >= 1e-2) & (d <= 1e2)
            np.testing.assert_allclose(C33[mid], 1 / d[mid], rtol=2.5e-4)


@pytest.mark.parametrize("name", list(HYPER))
def test_inverted_material_has_infinite_energy(name):
    """A state with d = det C / det A <= 0 at a Gauss point (here e11 = -0.6: C11 = -0.2) has
    energy +inf and NaN derivatives (a line search backtracks); other points are unaffected."""
    mat = HYPER[name]
    s = np.array([[-0.6, 0.0, 0, 0, 0, 0], [0.1, 0.0, 0, 0, 0, 0]])
    W, dW, ddW = mat.density(s, np.array([1.0, 1.0, 0.0]), 0.1)
    assert W[0] == INF and np.isnan(dW[0]).all() and np.isnan(ddW[0]).all()
    assert np.isfinite(W[1]) and np.isfinite(dW[1]).all() and np.isfinite(ddW[1]).all()


# ------------------------------------------------------------------------------------------------
# in a shell
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["neo_hookean", "compressible_neo_hookean", "mooney_rivlin_c2_only",
                                  "compressible_mooney_rivlin"])
def test_in_shell_energy(name):
    """ShellEnergy on a ghosted 6 x 4 rectangle with a hyperelastic material: zero energy and
    gradient at rest and after a rigid rotation (objectivity); gradient and Hessian-vector
    products agree with central differences at O(h^2) under a 5 % random perturbation."""
    mat = ALL[name]
    m = rectangle(2.0, 1.0, 6, 4)
    en = ShellEnergy(Shell(m.vertices, m.faces, mat, thickness=0.05))
    x0 = en.shell.rest_positions.copy()
    R = np.linalg.qr(np.random.default_rng(6).standard_normal((3, 3)))[0]
    for x in (x0, x0 @ R.T + 0.3):
        E, g = en.gradient(x)
        assert abs(E) <= 1e-14 and np.abs(g).max() <= 1e-13
    rng = np.random.default_rng(7)
    x = x0 + 0.05 * rng.standard_normal(x0.shape)
    E, g, H = en.hessian(x)
    D = rng.standard_normal((3,) + x.shape)
    fds = [np.array([(en.energy(x + h * d) - en.energy(x - h * d)) / (2 * h) for d in D]) for h in (1e-3, 5e-4)]
    scale = np.linalg.norm(g) * np.linalg.norm(D.reshape(3, -1), axis=1).max()
    assert_fd_rate(D.reshape(3, -1) @ g, fds[0], fds[1], scale=scale, what="gradient")
    d = D[0]
    fds = [(en.gradient(x + h * d)[1] - en.gradient(x - h * d)[1]) / (2 * h) for h in (1e-3, 5e-4)]
    assert_fd_rate(H @ d.ravel(), fds[0], fds[1], what="Hessian-vector")


# ------------------------------------------------------------------------------------------------
# parameter validation and registry
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("make, match", [
    (lambda: NeoHookean(0.0), "mu must be positive"),
    (lambda: NeoHookean(-1.0), "mu must be positive"),
    (lambda: NeoHookean(NAN), "mu must be finite"),
    (lambda: NeoHookean(INF), "mu must be finite"),
    (lambda: NeoHookean("1e6"), "mu must be a number"),
    (lambda: NeoHookean(True), "mu must be a number"),
    (lambda: NeoHookean(1.0, n_thickness=1), "n_thickness .* integer >= 2"),
    (lambda: NeoHookean(1.0, n_thickness=0), "n_thickness .* integer >= 2"),
    (lambda: NeoHookean(1.0, n_thickness=2.5), "n_thickness .* integer >= 2"),
    (lambda: NeoHookean(1.0, n_thickness=True), "n_thickness .* integer >= 2"),
    (lambda: MooneyRivlin(-1.0, 2.0), "C1 must be >= 0"),
    (lambda: MooneyRivlin(1.0, -0.5), "C2 must be >= 0"),
    (lambda: MooneyRivlin(0.0, 0.0), r"C1 \+ C2 > 0"),
    (lambda: MooneyRivlin(NAN, 1.0), "C1 must be finite"),
    (lambda: MooneyRivlin(1.0, -INF), "C2 must be finite"),
    (lambda: Exponential(0.0, 1.0), "C0 must be positive"),
    (lambda: Exponential(1.0, 0.0), "C1 must be positive"),
    (lambda: Exponential(1.0, -2.0), "C1 must be positive"),
    (lambda: Exponential(INF, 1.0), "C0 must be finite"),
    (lambda: CompressibleNeoHookean(0.0, 1.0), "mu must be positive"),
    (lambda: CompressibleNeoHookean(1.0, -0.1), "lam .* must be >= 0"),
    (lambda: CompressibleNeoHookean(1.0, NAN), "lam .* must be finite"),
    (lambda: CompressibleNeoHookean.from_E_nu(1.0, 0.5), r"nu must lie in \[0, 0.5\)"),
    (lambda: CompressibleNeoHookean.from_E_nu(1.0, -0.1), r"nu must lie in \[0, 0.5\)"),
    (lambda: CompressibleNeoHookean.from_E_nu(-1.0, 0.3), "E must be positive"),
    (lambda: CompressibleNeoHookean.from_E_nu(1.0, NAN), "nu must be finite"),
    (lambda: CompressibleMooneyRivlin(-1.0, 1.0, 1.0), "C1 must be >= 0"),
    (lambda: CompressibleMooneyRivlin(0.0, 0.0, 1.0), r"C1 \+ C2 > 0"),
    (lambda: CompressibleMooneyRivlin(1.0, 1.0, -0.1), "lam .* must be >= 0"),
    (lambda: CompressibleMooneyRivlin(1.0, NAN, 1.0), "C2 must be finite"),
    (lambda: CompressibleMooneyRivlin.from_E_nu(1.0, 0.5, 0.1), r"nu must lie in \[0, 0.5\).*use mooney_rivlin"),
    (lambda: CompressibleMooneyRivlin.from_E_nu(1.0, 0.3, -0.1), "C2/C1 must be >= 0"),
    (lambda: CompressibleMooneyRivlin.from_E_nu(0.0, 0.3, 0.1), "E must be positive"),
])
def test_invalid_parameters_are_rejected(make, match):
    """Non-positive or non-finite moduli, negative Mooney-Rivlin constants or C1 + C2 = 0,
    nu outside [0, 1/2) for the compressible law, fewer than two thickness points, and
    non-numbers: ProblemError naming the parameter, not a NaN later."""
    with pytest.raises(ProblemError, match=match):
        make()


def test_registry_builds_every_material():
    """Every registry name builds its class from SI parameters; saint_venant_kirchhoff is an
    alias of linear_elastic; compressible_neo_hookean takes (mu, lam) or (E, nu);
    n_thickness is optional and passed through."""
    assert make_material("linear_elastic", {"E": 2.0, "nu": 0.3}) == LinearElastic(2.0, 0.3)
    assert make_material("saint_venant_kirchhoff", {"E": 2.0, "nu": 0.3}) == LinearElastic(2.0, 0.3)
    assert make_material("neo_hookean", {"mu": 1e6}) == NeoHookean(1e6)
    assert make_material("neo_hookean", {"mu": 1e6, "n_thickness": 5}).n_thickness == 5
    assert make_material("mooney_rivlin", {"C1": 1.0, "C2": 2.0}) == MooneyRivlin(1.0, 2.0)
    assert make_material("exponential", {"C0": 1.0, "C1": 2.0}) == Exponential(1.0, 2.0)
    assert make_material("compressible_neo_hookean", {"mu": 1.0, "lam": 2.0}) == CompressibleNeoHookean(1.0, 2.0)
    assert (make_material("compressible_neo_hookean", {"E": 2.6, "nu": 0.3})
            == CompressibleNeoHookean.from_E_nu(2.6, 0.3))
    assert (make_material("compressible_mooney_rivlin", {"C1": 1.0, "C2": 2.0, "lam": 3.0})
            == CompressibleMooneyRivlin(1.0, 2.0, 3.0))
    assert set(MATERIALS) == set(PARAMETERS)


@pytest.mark.parametrize("name, params, match", [
    ("neo_hokean", {"mu": 1.0}, r"unknown material 'neo_hokean' \(did you mean 'neo_hookean'\?\)"),
    ("rubber", {"mu": 1.0}, "accepted: compressible_mooney_rivlin, compressible_neo_hookean, exponential, linear_elastic"),
    ("neo_hookean", {"mue": 1.0}, r"unknown parameter 'mue' \(did you mean 'mu'\?\)"),
    ("neo_hookean", {}, "missing parameter.* mu"),
    ("mooney_rivlin", {"C1": 1.0}, "missing parameter.* C2"),
    ("mooney_rivlin", {"C1": 1.0, "C3": 1.0}, "unknown parameter 'C3'.*accepted: C1, C2, n_thickness"),
    ("compressible_mooney_rivlin", {"C1": 1.0, "C2": 1.0}, "missing parameter.* lam"),
    ("linear_elastic", {"E": 1.0}, "missing parameter.* nu"),
    ("compressible_neo_hookean", {"mu": 1.0, "nu": 0.3}, "either .mu, lam. or .E, nu., not both"),
    ("compressible_neo_hookean", {"E": 1.0}, "missing parameter.* nu"),
    ("compressible_neo_hookean", {"lambda": 1.0}, "did you mean 'lam'"),
    ("exponential", {"C0": 1.0, "C1": -1.0}, "C1 must be positive"),
    ("neo_hookean", [("mu", 1.0)], "parameters must be a table"),
])
def test_registry_rejects_bad_input(name, params, match):
    """Unknown names and keys (with a did-you-mean), missing keys and invalid values raise
    ProblemError with a message that names them and lists the valid choices."""
    with pytest.raises(ProblemError, match=match):
        make_material(name, params)
