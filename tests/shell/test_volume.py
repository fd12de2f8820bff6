"""The enclosed-volume functional: the compiled kernel agrees with the numpy reference path, the
value is exact for a sphere's limit surface to quadrature accuracy, and the derivatives match
finite differences."""
import numpy as np

from graspdef.geometry import sphere
from graspdef.shell.hyperelastic import NeoHookean
from graspdef.shell.model import Shell
from graspdef.shell.volume import EnclosedVolume
from graspdef.testing import assert_fd_rate


def _deformed():
    m = sphere(1.0, 2)
    sh = Shell(m.vertices, m.faces, NeoHookean(1e5), 0.01)
    X = sh.rest_positions
    rng = np.random.default_rng(7)
    x = X + 0.05 * np.sin(2 * X[:, [2, 0, 1]]) + 0.01 * rng.standard_normal(X.shape)
    return EnclosedVolume(sh), x


def test_compiled_volume_terms_equal_the_reference_path():
    """Value, gradient and Hessian of the fused kernel equal the einsum reference to round-off
    (irregular and regular face groups, a deformed state); the Hessian shares the shell
    energy's CSR structure so the two add entry by entry."""
    vol, x = _deformed()
    V, g, H = vol.hessian(x)
    Vr, gr, Hr = vol._hessian_reference(x)
    assert abs(V - Vr) <= 1e-13 * abs(Vr)
    assert abs(vol.value(x) - Vr) <= 1e-13 * abs(Vr)
    assert np.abs(g - gr).max() <= 1e-12 * np.abs(gr).max()
    assert np.abs(vol.gradient(x)[1] - gr).max() <= 1e-12 * np.abs(gr).max()
    assert abs(H - Hr).max() <= 1e-12 * abs(Hr).max()
    from graspdef.shell.energy import ShellEnergy
    Hs = ShellEnergy(vol.shell).hessian(x)[2]
    assert np.array_equal(Hs.indptr, H.indptr) and np.array_equal(Hs.indices, H.indices)


def test_volume_of_a_sphere_and_its_derivatives():
    """V of the Loop limit surface of the unit icosphere (level 2; the limit surface lies slightly
    inside the sphere) is within 2 % of 4 pi / 3; dV/dx and d2V/dx2 match central differences
    at the O(h^2) rate."""
    vol, x = _deformed()
    V0 = vol.value(vol.shell.rest_positions)
    assert abs(V0 / (4 * np.pi / 3) - 1) < 0.02
    d = np.random.default_rng(1).standard_normal(x.shape)
    _, g, H = vol.hessian(x)
    h = 1e-4

    def fd(fun, step):
        return (fun(x + step * d) - fun(x - step * d)) / (2 * step)
    assert_fd_rate(float(g @ d.ravel()), fd(vol.value, h), fd(vol.value, h / 2), what="dV/dx")
    G = lambda v: vol.gradient(v)[1]  # noqa: E731
    assert_fd_rate(H @ d.ravel(), fd(G, h), fd(G, h / 2), what="d2V/dx2")
