"""Material law (``materials.LinearElastic``, ``plane_stress_tensor``) and input validation of
``materials.LinearElastic`` and ``model.Shell``."""
import numpy as np
import pytest

from graspdef.errors import ProblemError
from graspdef.geometry.primitives import rectangle
from graspdef.shell.materials import LinearElastic, plane_stress_tensor
from graspdef.shell.model import Shell

NAN, INF = float("nan"), float("inf")


@pytest.mark.parametrize("E, nu", [
    (0.0, 0.3), (-1.0, 0.3), (NAN, 0.3), (INF, 0.3), (-INF, 0.3),
    (1.0, -0.1), (1.0, 0.5000001), (1.0, 0.7), (1.0, NAN), (1.0, INF), (1.0, -INF),
])
def test_linear_elastic_rejects_invalid_parameters(E, nu):
    """E must be positive and finite; plane-stress nu must lie in [0, 0.5] (the class's
    documented range) and be finite.  Anything else is a ProblemError, not a silent NaN later."""
    with pytest.raises(ProblemError):
        LinearElastic(E=E, nu=nu)


@pytest.mark.parametrize("E, nu", [(1.0, 0.0), (2e11, 0.3), (1e-3, 0.5)])
def test_linear_elastic_accepts_valid_parameters(E, nu):
    """The closed range ends nu = 0 and nu = 0.5 (incompressible in plane stress) are valid."""
    mat = LinearElastic(E=E, nu=nu)
    assert mat.E == E and mat.nu == nu


@pytest.mark.parametrize("thickness", [0.0, -0.01, NAN, INF, np.array([0.1] * 47 + [0.0]),
                                       np.array([0.1] * 47 + [NAN])])
def test_shell_rejects_non_positive_thickness(thickness):
    """Thickness (scalar or one value per face) must be positive and finite: ProblemError."""
    m = rectangle(1.0, 1.0, 6, 4)
    with pytest.raises(ProblemError):
        Shell(m.vertices, m.faces, LinearElastic(1.0, 0.3), thickness)


def test_shell_rejects_thickness_of_wrong_length():
    """A per-face thickness array must have one entry per face."""
    m = rectangle(1.0, 1.0, 6, 4)
    with pytest.raises(ProblemError):
        Shell(m.vertices, m.faces, LinearElastic(1.0, 0.3), np.full(len(m.faces) - 1, 0.1))


def test_per_face_thickness_scales_membrane_and_bending():
    """With thickness t_f per face, the rest tangent of face f is blockdiag(t_f H, t_f^3/12 H)
    (Koiter: membrane ~ t, bending ~ t^3/12).  A per-face array equal to a scalar reproduces the
    scalar shell's rest data exactly."""
    m = rectangle(1.0, 1.0, 6, 4)
    mat = LinearElastic(1.0, 0.3)
    a = Shell(m.vertices, m.faces, mat, 0.02)
    b = Shell(m.vertices, m.faces, mat, np.full(len(m.faces), 0.02))
    for ra, rb in zip(a.rest, b.rest):
        np.testing.assert_array_equal(ra.thickness, rb.thickness)
        np.testing.assert_array_equal(ra.weights, rb.weights)
    t = np.linspace(0.01, 0.05, len(m.faces))
    c = Shell(m.vertices, m.faces, mat, t)
    for g, r in zip(c.basis.groups, c.rest):
        np.testing.assert_array_equal(r.thickness[:, 0], t[g.faces])
        D = mat.tangent(r.rest_inv, r.thickness)
        H = plane_stress_tensor(mat.E, mat.nu, r.rest_inv)
        tt = r.thickness[..., None, None]
        np.testing.assert_allclose(D[..., :3, :3], tt * H, rtol=1e-15)
        np.testing.assert_allclose(D[..., 3:, 3:], tt ** 3 / 12 * H, rtol=1e-15)
        np.testing.assert_array_equal(D[..., :3, 3:], 0.0)


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.5])
def test_plane_stress_tensor_cartesian(nu):
    """With an orthonormal rest metric (A^ab = delta) the Voigt matrix acting on
    (e11, e22, 2 e12) is the textbook plane-stress matrix E/(1 - nu^2) [[1, nu, 0], [nu, 1, 0],
    [0, 0, (1 - nu)/2]]."""
    E = 3.0
    H = plane_stress_tensor(E, nu, np.array([1.0, 1.0, 0.0]))
    ref = E / (1 - nu ** 2) * np.array([[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]])
    np.testing.assert_allclose(H, ref, rtol=1e-15, atol=1e-15)


def test_plane_stress_tensor_is_tensorial():
    """For a skew rest metric A_ab = F^T F (tangents a_a = F e_a), the density
    1/2 e_ab C^abcd e_cd computed with the contravariant metric equals the Cartesian density of
    the same strain tensor pushed forward, eps = F^-T e F^-1 (coordinate invariance)."""
    rng = np.random.default_rng(0)
    E, nu = 2.0, 0.25
    F = np.eye(2) + 0.4 * rng.standard_normal((2, 2))
    A = F.T @ F
    Ainv = np.linalg.inv(A)
    H = plane_stress_tensor(E, nu, np.array([Ainv[0, 0], Ainv[1, 1], Ainv[0, 1]]))
    e = rng.standard_normal((2, 2))
    e = e + e.T
    s = np.array([e[0, 0], e[1, 1], 2 * e[0, 1]])
    eps = np.linalg.inv(F).T @ e @ np.linalg.inv(F)
    W_cart = 0.5 * E / (1 - nu ** 2) * (nu * np.trace(eps) ** 2 + (1 - nu) * (eps * eps).sum())
    assert 0.5 * s @ H @ s == pytest.approx(W_cart, rel=1e-13)


def test_density_derivatives():
    """W = 1/2 s.D s, dW/ds = D s, d2W/ds2 = D (exact for the quadratic density), and D is
    symmetric positive definite for 0 <= nu < 0.5 (positive semi-definite limit at 0.5 is not
    needed: all eigenvalues are > 0 here)."""
    rng = np.random.default_rng(1)
    mat = LinearElastic(5.0, 0.3)
    F = np.eye(2) + 0.3 * rng.standard_normal((2, 2))
    Ainv = np.linalg.inv(F.T @ F)
    inv = np.array([Ainv[0, 0], Ainv[1, 1], Ainv[0, 1]])
    s = rng.standard_normal(6)
    W, dW, D = mat.density(s, inv, np.array(0.1))
    np.testing.assert_allclose(D, D.T, rtol=0, atol=1e-15 * np.abs(D).max())
    assert np.linalg.eigvalsh(D).min() > 0
    np.testing.assert_allclose(dW, D @ s, rtol=1e-14)
    assert W == pytest.approx(0.5 * s @ D @ s, rel=1e-14)


def test_one_point_quadrature_is_refused():
    """One Gauss point per face leaves spurious zero-energy modes (8 instead of 6 zero
    eigenvalues on a ghosted 6 x 4 rectangle), so Shell refuses it."""
    import pytest as _pytest

    from graspdef.errors import ProblemError
    from graspdef.geometry import rectangle
    from graspdef.shell.materials import LinearElastic
    from graspdef.shell.model import Shell

    m = rectangle(1.0, 1.0, 4, 4)
    with _pytest.raises(ProblemError, match="zero-energy"):
        Shell(m.vertices, m.faces, LinearElastic(1.0, 0.3), 0.01, n_quad=1)
