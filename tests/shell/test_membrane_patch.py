"""Membrane patch test on a flat ghosted rectangle: a homogeneous in-plane deformation of all
control points must produce exactly the homogeneous Green-Lagrange strain at every quadrature
point, no curvature change, and (with exact quadrature) no net force on interior control points.
Cirak, Ortiz & Schroeder (2000), Sec. 5 use this kind of test for subdivision shells."""
import numpy as np
import pytest

from graspdef.geometry.primitives import rectangle
from graspdef.shell.energy import ShellEnergy
from graspdef.shell.kinematics import strains
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell, surface_derivatives
from shell_helpers import random_rotation

NX, NY = 8, 6
E_MOD, NU, T = 3.0, 0.3, 0.02

# in-plane deformation gradients F (2 x 2)
CASES = {
    "isotropic stretch": np.array([[1.1, 0.0], [0.0, 1.1]]),          # x -> (1 + e) x, e = 0.1
    "uniaxial stretch": np.array([[1.25, 0.0], [0.0, 1.0]]),
    "compression + shear": np.array([[0.9, 0.15], [-0.05, 1.05]]),
}


def plate(rotated: bool, n_quad: int = 3):
    """Rectangle 2 x 1 (NX x NY cells), optionally rigidly rotated into a random plane."""
    m = rectangle(2.0, 1.0, NX, NY)
    R = np.eye(3)
    if rotated:
        R = random_rotation(np.random.default_rng(7))
    x = m.vertices @ R.T + (np.array([0.2, -0.4, 0.9]) if rotated else 0.0)
    shell = Shell(x, m.faces, LinearElastic(E_MOD, NU), T, n_quad=n_quad)
    return m, shell, R


def deform(shell, R, F2):
    """Apply the in-plane map x -> c + R F R^T (x - c) (F acting on the plate's own x, y) to
    every control point, ghosts included."""
    F = np.eye(3)
    F[:2, :2] = F2
    c = shell.rest_positions.mean(0)
    return c + (shell.rest_positions - c) @ (R @ F @ R.T).T, R @ F @ R.T


@pytest.mark.parametrize("rotated", [False, True])
@pytest.mark.parametrize("case", sorted(CASES))
def test_homogeneous_strain_is_exact(case, rotated):
    """Loop weights sum to one and ghosts extrapolate affinely, so an affine map of all control
    points maps the limit surface and its derivatives: a_a = F A_a, a_ab = F A_ab.  The membrane
    strain is then e_ab = A_a . E A_b with E = (F^T F - I)/2 at every quadrature point (for the
    isotropic stretch: e_ab = e (1 + e/2) A_ab), and the plate stays flat, so k = 0.
    Tolerance 1e-12 of |A_ab| (round-off; the identities are exact)."""
    _, shell, R = plate(rotated)
    F2 = CASES[case]
    x, F3 = deform(shell, R, F2)
    EGL = 0.5 * (F3.T @ F3 - np.eye(3))
    for g, r in zip(shell.basis.groups, shell.rest):
        Y0 = surface_derivatives(g.stencils, g.dN, g.ddN, shell.rest_positions)
        y = surface_derivatives(g.stencils, g.dN, g.ddN, x)
        s = strains(y, r.rest_a, r.rest_b)
        A1, A2 = Y0[..., 0, :], Y0[..., 1, :]
        e11 = np.einsum("fqi,ij,fqj->fq", A1, EGL, A1)
        e22 = np.einsum("fqi,ij,fqj->fq", A2, EGL, A2)
        e12 = np.einsum("fqi,ij,fqj->fq", A1, EGL, A2)
        scale = np.abs(r.rest_a).max()
        np.testing.assert_allclose(s[..., 0], e11, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(s[..., 1], e22, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(s[..., 2], 2 * e12, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(s[..., 3:], 0.0, rtol=0, atol=1e-12 * scale)
        if case == "isotropic stretch":
            e = F2[0, 0] - 1
            expect = e * (1 + e / 2) * r.rest_a                # (A11, A22, A12) scaled
            np.testing.assert_allclose(s[..., :2], expect[..., :2], rtol=0, atol=1e-12 * scale)
            np.testing.assert_allclose(s[..., 2], 2 * expect[..., 2], rtol=0, atol=1e-12 * scale)


@pytest.mark.parametrize("case", sorted(CASES))
def test_homogeneous_energy_equals_cartesian_density_times_area(case):
    """With a homogeneous strain eps = (F^T F - I)/2 the Koiter density is the same at every
    point, W = t/2 E/(1 - nu^2) [nu tr(eps)^2 + (1 - nu) eps:eps], whatever the chart; so the
    total energy is W times the integrated rest area of the limit surface.  This checks the
    contravariant metric, the Voigt factors and the area weights together (1e-12 relative)."""
    _, shell, R = plate(False)
    x, F3 = deform(shell, R, CASES[case])
    eps = 0.5 * (F3.T @ F3 - np.eye(3))[:2, :2]
    W = 0.5 * T * E_MOD / (1 - NU ** 2) * (NU * np.trace(eps) ** 2 + (1 - NU) * (eps * eps).sum())
    assert ShellEnergy(shell).energy(x) == pytest.approx(W * shell.area(), rel=1e-12)
    assert shell.area() == pytest.approx(2.0, rel=1e-13)      # linear precision: the plate itself


@pytest.mark.parametrize("n_quad", [3, 6, 12])
def test_no_net_force_on_interior_control_points(n_quad):
    """Patch test in the FE sense: under a homogeneous stress n^ab on a flat plate, the internal
    force on control point i is n^ab F A_a . sum_q w_q J dN_i/dtheta^b (q).  On a regular lattice
    N_i is a translate of one box spline M, and summing the quadrature samples over all faces of
    its support is sum_k dM(q + k) over lattice translates k -- the derivative of
    sum_k M(q + k) = 1 (partition of unity of the translates) -- so the sum is zero for any
    quadrature rule, provided the whole support (the 2-ring of i) is integrated.  Hence these
    gradient entries vanish to round-off (1e-12 of the largest force) for 3, 6 and 12 points;
    the control points near the edge carry the boundary traction and must not vanish."""
    _, shell, R = plate(False, n_quad=n_quad)
    x, _ = deform(shell, R, CASES["compression + shear"])
    _, g = ShellEnergy(shell).gradient(x)
    g = g.reshape(-1, 3)
    i, j = np.meshgrid(np.arange(NX + 1), np.arange(NY + 1), indexing="xy")
    idx = (i + j * (NX + 1)).ravel()
    deep = ((i >= 2) & (i <= NX - 2) & (j >= 2) & (j <= NY - 2)).ravel()
    gmax = np.abs(g).max()
    assert np.abs(g[idx[deep]]).max() <= 1e-12 * gmax
    assert np.abs(g[idx[~deep]]).max() > 1e-3 * gmax
