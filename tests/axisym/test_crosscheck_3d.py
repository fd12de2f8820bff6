"""Cross-check: the axisymmetric shell solver (graspdef.axisym, the thesis method) against the 3-D
Loop-subdivision Kirchhoff-Love nonlinear solver on the same axisymmetric problems, same
incompressible Mooney-Rivlin material (C2/C1 = 0.1).  Problems, numbers and discussion:
docs/crosscheck.md; the code is scripts/crosscheck_axisym_3d.py.

What is compared, and why two axisymmetric columns:

* pinched: a sphere (R = 1) squeezed by two opposite total forces F spread over a ring of radius
  a = 0.2 R around each pole; pole displacement at F/(C1 t^2) below the limit load.
* inflation: the same sphere under a follower pressure; mid-surface stretch.
* The two solvers integrate the hyperelastic law through the thickness differently: the thesis
  phi = t0 [W + (1/24) d2W/dzeta0^2] with exact layer stretches, the 3-D solver Gauss points with
  E(zeta) = e - zeta k (covariant k = b - B, mid-surface metric for every layer; Kiendl et al.
  2015).  These are different first-approximation shell theories: they differ at O(t/R) in
  bending-dominated states (the membrane-bending coupling of the curved shell's energy) and at
  O((t/R)^2) in inflation.  The script therefore also runs the axisymmetric solver with the 3-D
  solver's thickness model ("same energy"); that comparison checks the two *solvers* (to 1 %),
  the other quantifies the *model* difference (about 2 % at R/t = 10, 1 % at R/t = 20).
"""
import importlib.util
from pathlib import Path

import numpy as np
import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "crosscheck_axisym_3d.py"


@pytest.fixture(scope="module")
def cc():
    spec = importlib.util.spec_from_file_location("crosscheck_axisym_3d", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


LOADS = (0.5, 1.0)          # F/(C1 t^2) at R/t = 10: apex displacement 2.1 % and 4.8 % of R (limit at 2.05)


@pytest.fixture(scope="module")
def pinched10(cc):
    ax = cc.axisym_pinched(10.0, LOADS)
    ax3 = cc.axisym_pinched(10.0, LOADS, energy="3d")
    d = {s: cc.shell3d_pinched(s, 10.0, LOADS)[0] for s in (2, 3)}
    return ax, ax3, d


def test_shell3d_thickness_model_in_axisym_variables_has_the_small_strain_shell_stiffness(cc):
    """The diagnostic energy (the 3-D solver's thickness model in the axisymmetric variables) is
    stress-free at rest and has the incompressible (nu = 1/2) linear shell's stiffness on a flat
    shell, as the thesis's phi: membrane 4 mu [[1, 1/2], [1/2, 1]], bending (mu/3) [[1, 1/2], [1/2, 1]]
    with mu = 2 (1 + gamma) (C1 = 1, t0 = 1); its gradient and Hessian match central differences."""
    mat3, matT = cc.axisym_material("3d"), cc.axisym_material("thesis")
    one, zero = np.ones(1), np.zeros(1)
    phi, g, H = mat3.shell_energy(one, one, zero, zero, zero, zero)
    _, _, HT = matT.shell_energy(one, one, zero, zero, zero, zero)
    assert abs(phi[0]) < 1e-14 and np.abs(g).max() < 1e-14
    assert np.allclose(H[..., 0], HT[..., 0], rtol=1e-12, atol=1e-12)
    mu = 2 * (1 + cc.GAMMA)
    assert np.allclose(H[:2, :2, 0], 4 * mu * np.array([[1, .5], [.5, 1]]))
    assert np.allclose(H[2:, 2:, 0], mu / 3 * np.array([[1, .5], [.5, 1]]))
    x = np.array([1.1, 0.95, -0.12, -0.08])
    k = (-0.1, -0.1)
    f = lambda y: mat3.shell_energy(*[np.array([v]) for v in (*y, *k)])  # noqa: E731
    _, g, H = f(x)
    h = 1e-6
    for i in range(4):
        e = np.zeros(4)
        e[i] = h
        assert abs((f(x + e)[0] - f(x - e)[0])[0] / (2 * h) - g[i, 0]) < 1e-7
        assert np.allclose((f(x + e)[1] - f(x - e)[1])[:, 0] / (2 * h), H[:, i, 0], atol=1e-6)


def test_pinched_sphere_same_energy_within_one_percent_and_converging(pinched10):
    """Pinched sphere R/t = 10, ring a = 0.2 R, F/(C1 t^2) = 0.5 and 1.0 (apex 2-5 % of R): with the
    same shell energy, the 3-D pole displacement on 642 control vertices is within 1 % of the
    axisymmetric one (measured -0.7 %, -0.8 %; 10,242 vertices: -0.1 %, docs/crosscheck.md) and
    the difference shrinks from 162 to 642 vertices (-1.1 % -> -0.7 %, -2.3 % -> -0.8 %); the
    3-D shell approaches from the stiff side."""
    _, ax3, d = pinched10
    e2, e3 = d[2] / ax3 - 1, d[3] / ax3 - 1
    assert np.all(np.abs(e3) < 0.01), e3
    assert np.all(np.abs(e3) < np.abs(e2)), (e2, e3)
    assert np.all(e3 < 0) and np.all(e2 < 0)


def test_pinched_sphere_thesis_energy_differs_by_the_thickness_model(pinched10):
    """Against the thesis's energy (graspdef.axisym as is) the 3-D solution at R/t = 10 is stiffer
    by 1.8-2.3 % on 642 vertices (converged, 10,242 vertices: 1.7 % and 1.1 %).  That is *not*
    within the 1 % target: it is the O(t/R) difference between the two thickness models (2 % at
    R/t = 10, 1 % at R/t = 20), which the same-energy axisymmetric run reproduces: 3-D minus
    thesis equals (axisym with the 3-D model) minus thesis to within the discretisation error
    (< 1 %) asserted above."""
    ax, ax3, d = pinched10
    model = ax3 / ax - 1
    assert np.all((model < -0.005) & (model > -0.03)), model      # the 3-D model is stiffer here
    diff = d[3] / ax - 1
    assert np.all(np.abs(diff - model) < 0.01), (diff, model)
    assert np.all(np.abs(diff) < 0.03), diff


def test_inflated_sphere_both_solvers_match_their_closed_forms(cc):
    """Inflation, R/t = 10, p R/(C1 t) = 1, 2, 2.5 (stretch 1.045-1.19): each solver reproduces the
    closed-form uniform-inflation solution of its own shell energy (axisym, thesis phi, to 1e-4 of
    stretch - 1; 3-D on 162 vertices, Gauss-point model, to 1e-3) and with the same energy they
    agree to 1e-3; the two energies differ by 1.6-1.8 % of stretch - 1 (0.07-0.28 % of the stretch), the
    O((t/R)^2) bending correction, while the 3-D model stays within 0.1 % of the membrane curve."""
    loads = cc.INFLATION_LOADS
    ax = cc.axisym_inflated(10.0, loads)
    ax3 = cc.axisym_inflated(10.0, loads, energy="3d")
    d, _ = cc.shell3d_inflated(2, 10.0, loads)
    thesis_cf = np.array([cc.stretch_of(cc.thesis_pressure, p, 10.0) for p in loads])
    shell_cf = np.array([cc.stretch_of(cc.kiendl_pressure, p, 10.0) for p in loads])
    membrane = np.array([cc.stretch_of(cc.membrane_pressure, p) for p in loads])
    assert np.all(np.abs(ax / thesis_cf - 1) < 1e-4 * (thesis_cf - 1))
    assert np.all(np.abs(ax3 - shell_cf) < 1e-4 * (shell_cf - 1))
    assert np.all(np.abs(d - shell_cf) < 1e-3 * (shell_cf - 1))
    assert np.all(np.abs(d - ax3) < 1e-3 * (ax3 - 1))
    rel = (d - 1) / (ax - 1) - 1
    rel_cf = (shell_cf - 1) / (thesis_cf - 1) - 1           # the same ratio of the two closed forms
    assert np.all(np.abs(rel - rel_cf) < 2e-3), (rel, rel_cf)
    assert np.all(np.abs(shell_cf - membrane) < 1e-3 * (membrane - 1))


@pytest.mark.slow
@pytest.mark.parametrize("R_over_t", [10.0, 20.0])
def test_pinched_sphere_fine_mesh_same_energy_within_one_percent(cc, R_over_t):
    """10,242 control vertices, all load levels below the limit load (apex up to 11.7 % of R at
    R/t = 10, 4.6 % at R/t = 20): 3-D within 1 % of the axisymmetric solver with the same energy
    (measured <= 0.4 %, the largest next to the limit point where the curve flattens), and the
    2,562-vertex result already within 1 %."""
    loads = cc.PINCH_LOADS[R_over_t][1:]
    ax3 = cc.axisym_pinched(R_over_t, loads, energy="3d")
    for s in (4, 5):
        v, _ = cc.shell3d_pinched(s, R_over_t, loads)
        assert np.all(np.abs(v / ax3 - 1) < 0.01), (s, v / ax3 - 1)
