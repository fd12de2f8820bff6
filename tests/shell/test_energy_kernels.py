"""Compiled paths of the shell energy against their numpy references.

* ``ShellEnergy.energy / gradient / hessian`` (``_kernels.point_strains``,
  ``_kernels.assemble_elements``: per point Hessian with respect to y, contracted with the basis
  derivatives, blocks written straight into the pattern) against ``ShellEnergy._*_reference``
  (``kinematics.strain_jacobian`` / ``strain_hessian_contract`` with numpy einsums and
  ``_kernels.material_hessian_blocks``);
* ``_ThicknessIntegrated.density`` (``_kernels.density_points``) against ``_density_numpy``;
* the parallel schedule (blocks of one colour share no control vertex) and its consequence: the
  assembled matrices do not depend on the number of threads.
"""
import functools

import numba
import numpy as np
import pytest

from graspdef.geometry.primitives import hemisphere, icosphere, rectangle
from graspdef.shell.energy import ShellEnergy
from graspdef.shell.hyperelastic import CompressibleNeoHookean, Exponential, MooneyRivlin, NeoHookean
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell

MATERIALS = {
    "linear": LinearElastic(E=1.0, nu=0.3),
    "neo_hookean": NeoHookean(1.0 / 3.0),
    "compressible": CompressibleNeoHookean(mu=0.4, lam=0.6),
    "mooney_rivlin": MooneyRivlin(0.2, 0.05, n_thickness=4),
}
CASES = [("icosphere", "neo_hookean", 3), ("icosphere", "linear", 6), ("rectangle", "compressible", 3),
         ("hemisphere", "mooney_rivlin", 3), ("hemisphere", "neo_hookean", 12)]


@functools.lru_cache(maxsize=None)
def setup(mesh, material, n_quad):
    """Energy on a closed sphere (regular and irregular groups), an open ghosted rectangle or an
    open hemisphere, and a state near rest with strains of ~1 % (membrane and bending, so that the
    geometric stiffness is active and no point is inverted)."""
    if mesh == "icosphere":
        m = icosphere(1.0, 2)
    elif mesh == "hemisphere":
        m = hemisphere(1.0, 3)
    else:
        m = rectangle(2.0, 1.0, 6, 4)
    shell = Shell(m.vertices, m.faces, MATERIALS[material], thickness=0.05, n_quad=n_quad)
    en = ShellEnergy(shell)
    x0 = shell.rest_positions.copy()
    rng = np.random.default_rng(7)
    x = 1.01 * x0 + 0.01 * rng.standard_normal(x0.shape)
    return en, x0, x


@pytest.mark.parametrize("mesh,material,n_quad", CASES)
def test_compiled_energy_gradient_hessian_match_numpy_reference(mesh, material, n_quad):
    """Same sums in a different order: energy to 1e-13 relative, gradient and Hessian to 1e-12 of
    their largest entry, at rest and at the deformed state; the Hessian has the reference's
    sparsity structure and is exactly symmetric (off-diagonal blocks are mirrored, diagonal
    blocks symmetrised)."""
    en, x0, x = setup(mesh, material, n_quad)
    for state in (x0, x):
        E, g, H = en.hessian(state)
        Er, gr, Hr = en._hessian_reference(state)
        scale_e = max(abs(Er), 1e-300)
        assert abs(E - Er) <= 1e-13 * scale_e + 1e-300
        assert abs(en.energy(state) - Er) <= 1e-13 * scale_e + 1e-300
        assert abs(en._energy_reference(state) - Er) <= 1e-13 * scale_e + 1e-300
        E1, g1 = en.gradient(state)
        np.testing.assert_array_equal(g1, g)
        assert E1 == E
        gs = max(np.abs(gr).max(), 1e-300)
        np.testing.assert_allclose(g, gr, rtol=0, atol=1e-12 * gs)
        np.testing.assert_allclose(en._gradient_reference(state)[1], gr, rtol=0, atol=1e-12 * gs)
        np.testing.assert_array_equal(H.indptr, Hr.indptr)
        np.testing.assert_array_equal(H.indices, Hr.indices)
        np.testing.assert_allclose(H.data, Hr.data, rtol=0, atol=1e-12 * np.abs(Hr.data).max())
        assert abs(H - H.T).max() == 0.0


def test_schedule_blocks_of_one_colour_share_no_vertex():
    """Every face is scheduled once; two blocks of one colour touch disjoint control points, so
    their element matrices are written without races."""
    en, _, _ = setup("icosphere", "neo_hookean", 3)
    for gd in en._groups:
        sc = gd.schedule
        assert np.array_equal(np.sort(sc.order), np.arange(len(gd.stencils)))
        assert np.array_equal(np.sort(sc.cblocks), np.arange(len(sc.bstart) - 1))
        for c in range(sc.n_colours):
            seen = set()
            for b in sc.cblocks[sc.cstart[c]:sc.cstart[c + 1]]:
                verts = set(gd.stencils[sc.order[sc.bstart[b]:sc.bstart[b + 1]]].ravel().tolist())
                assert not (verts & seen)
                seen |= verts


def test_assembly_independent_of_thread_count():
    """The colouring fixes the order of every sum, so gradient and Hessian are bitwise the same
    with one thread as with all (here on a sphere with several colours)."""
    m = icosphere(1.0, 4)
    shell = Shell(m.vertices, m.faces, NeoHookean(1.0), thickness=0.02)
    en = ShellEnergy(shell)
    assert max(gd.schedule.n_colours for gd in en._groups) > 1
    x = 1.02 * shell.rest_positions
    nt = numba.get_num_threads()
    E, g, H = en.hessian(x)
    try:
        numba.set_num_threads(1)
        E1, g1, H1 = en.hessian(x)
    finally:
        numba.set_num_threads(nt)
    assert E1 == E
    np.testing.assert_array_equal(g1, g)
    np.testing.assert_array_equal(H1.data, H.data)


DENSITY_MATERIALS = [NeoHookean(1.0 / 3.0), NeoHookean(2.0, n_thickness=2), MooneyRivlin(0.3, 0.1),
                     MooneyRivlin(0.0, 0.5, n_thickness=5), Exponential(0.2, 0.8),
                     CompressibleNeoHookean(mu=1.0, lam=3.0), CompressibleNeoHookean(mu=1.0, lam=0.0, n_thickness=4)]


@pytest.mark.parametrize("mat", DENSITY_MATERIALS, ids=lambda m: f"{type(m).__name__}-{m.n_thickness}")
def test_compiled_density_matches_numpy(mat):
    """``density`` (compiled, per point) against ``_density_numpy`` (vectorised): W, dW, ddW to
    1e-13 of their largest entry for strains up to ~30 % and curvatures up to ~3/t, skew rest
    metrics and per-face thickness broadcast against (faces, points); an inverted point gives
    +inf and NaN in both."""
    rng = np.random.default_rng(11)
    nf, nq = 40, 3
    F = np.eye(2) + 0.3 * rng.standard_normal((nf, nq, 2, 2))
    A = np.einsum("...ki,...kj->...ij", F, F)                     # SPD rest metrics
    det = A[..., 0, 0] * A[..., 1, 1] - A[..., 0, 1] ** 2
    ri = np.stack([A[..., 1, 1] / det, A[..., 0, 0] / det, -A[..., 0, 1] / det], -1)
    t = rng.uniform(0.01, 0.05, (nf, 1))
    s = np.concatenate([0.1 * rng.standard_normal((nf, nq, 3)),
                        rng.standard_normal((nf, nq, 3)) / t[..., None]], -1) * 0.3
    ri[0, 0] = [1.0, 1.0, 0.0]
    s[0, 0] = [-0.6, 0.1, 0.0, 0.0, 0.0, 0.0]                # inverted: d = 1 - 1.0 - 0.24 < 0
    W, dW, ddW = mat.density(s, ri, t)
    Wr, dWr, ddWr = mat._density_numpy(s, ri, t)
    for a, b in ((W, Wr), (dW, dWr), (ddW, ddWr)):
        assert a.shape == b.shape
        fin = np.isfinite(b)
        np.testing.assert_array_equal(np.isfinite(a), fin)
        np.testing.assert_allclose(a[fin], b[fin], rtol=0, atol=1e-13 * np.abs(b[fin]).max())
    assert W[0, 0] == np.inf and np.isnan(dW[0, 0]).all() and np.isnan(ddW[0, 0]).all()
    # a single point with scalar thickness, and the zero-strain tangent
    W1, dW1, ddW1 = mat.density(s[3, 1], ri[3, 1], 0.02)
    W1r, dW1r, ddW1r = mat._density_numpy(s[3, 1], ri[3, 1], 0.02)
    assert W1.shape == () and dW1.shape == (6,) and ddW1.shape == (6, 6)
    np.testing.assert_allclose(ddW1, ddW1r, rtol=0, atol=1e-13 * np.abs(ddW1r).max())
    np.testing.assert_allclose(dW1, dW1r, rtol=0, atol=1e-13 * np.abs(dW1r).max())
    assert W1 == pytest.approx(float(W1r), rel=1e-13)
