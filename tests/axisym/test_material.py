"""Shell energy of the thesis (2.73) from the 3-D strain energies: small-strain limit and derivatives."""
import numpy as np
import pytest

from graspdef.axisym import AxisymMaterial
from graspdef.errors import ProblemError


@pytest.mark.parametrize("kind,gamma,mu", [("mooney_rivlin", 0.1, 2.2), ("mooney_rivlin", 0.0, 2.0),
                                           ("exponential", 0.5, 2.0)])
@pytest.mark.parametrize("k", [0.0, -0.1])
def test_small_strain_limit_is_linear_incompressible_shell(kind, gamma, mu, k):
    """At the undeformed state the Hessian is the linear shell's with nu = 1/2 (E = 3 mu, nondimensional by C1,
    t0): membrane E t/(1 - nu^2) [[1, nu], [nu, 1]] = 4 mu [[1, 1/2], ...], bending E t^3/(12 (1 - nu^2)) = mu/3
    (textbook Kirchhoff-Love values); exact for a flat plate, within O((t0 k)^2) for a curved shell."""
    m = AxisymMaterial(kind, 1.0, gamma)
    phi, g, H = m.shell_energy(1.0, 1.0, k, k, k, k)
    rel = 1e-12 + 4 * k * k
    assert abs(phi) < 1e-14 and np.max(np.abs(g)) < 1e-13
    assert H[0, 0] == pytest.approx(4 * mu, rel=rel) and H[0, 1] == pytest.approx(2 * mu, rel=rel)
    assert H[2, 2] == pytest.approx(mu / 3, rel=rel) and H[2, 3] == pytest.approx(mu / 6, rel=rel)
    assert abs(H[0, 2]) < 1e-12 + 2 * mu * abs(k)


@pytest.mark.parametrize("kind,volume", [("mooney_rivlin", False), ("mooney_rivlin", True), ("exponential", False)])
def test_generated_gradient_and_hessian_match_finite_differences(kind, volume):
    m = AxisymMaterial(kind, 1.0, 0.3, volume_factor=volume)
    x = np.array([1.13, 0.91, 0.27, -0.08])
    k1, k2 = -0.1, -0.07
    f = lambda z: m.shell_energy(*z, k1, k2)
    _, g, H = f(x)
    eps = 1e-6
    for i in range(4):
        e = np.zeros(4)
        e[i] = eps
        assert (f(x + e)[0] - f(x - e)[0]) / (2 * eps) == pytest.approx(g[i], rel=1e-7, abs=1e-9)
        assert (f(x + e)[1] - f(x - e)[1]) / (2 * eps) == pytest.approx(H[:, i], rel=1e-6, abs=1e-8)


def test_membrane_part_is_the_3d_energy_at_the_midsurface():
    """With no curvature the shell energy is w(I1, I2) of the plane-stress incompressible stretch state."""
    m = AxisymMaterial("mooney_rivlin", 1.0, 0.1)
    l1, l2 = 1.3, 0.8
    l3 = 1 / (l1 * l2)
    I1, I2 = l1**2 + l2**2 + l3**2, l1**-2 + l2**-2 + l3**-2
    assert m.shell_energy(l1, l2, 0.0, 0.0, 0.0, 0.0)[0] == pytest.approx(m.w3d(I1, I2), rel=1e-13)


def test_constitutive_inversion_round_trip():
    m = AxisymMaterial("mooney_rivlin", 1.0, 0.1)
    l1, l2, c1, c2 = np.array([1.1, 0.95]), np.array([1.05, 1.2]), np.array([0.2, -0.3]), np.array([0.05, 0.0])
    _, g, _ = m.shell_energy(l1, l2, c1, c2, -0.1, -0.1)
    a, c, *_ = m.invert(g[0], g[2], l2, c2, -0.1, -0.1, np.array([np.ones(2), np.zeros(2)]))
    assert np.allclose(a, l1, atol=1e-12) and np.allclose(c, c1, atol=1e-12)


def test_bad_material():
    with pytest.raises(ProblemError, match="kind"):
        AxisymMaterial("ogden")
    with pytest.raises(ProblemError, match="C1"):
        AxisymMaterial("mooney_rivlin", C1=-1.0)
