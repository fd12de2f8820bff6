"""Loads keep force and moment exactly; supports constrain the limit surface; rigid-body modes
left free are reported; symmetry planes reproduce the full model."""
import numpy as np
import pytest

from graspdef.errors import SupportError
from graspdef.geometry import hemisphere, icosphere, rectangle
from graspdef.problem.loads import BodyForce, PointLoad, Pressure
from graspdef.problem.problem import Problem, locate
from graspdef.problem.supports import EdgeSupport, PointSupport, RigidModes
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell
from graspdef.solve.linear import solve_linear


def _plate(n=8, a=1.0, center=(0.0, 0.0)):
    m = rectangle(a, a, n, n, center=center)
    return Shell(m.vertices, m.faces, LinearElastic(1e6, 0.3), 0.01)


@pytest.mark.parametrize("bary", [(1.0, 0.0, 0.0), (0.2, 0.3, 0.5), (0.0, 0.5, 0.5)])
@pytest.mark.parametrize("kind", ["plate", "sphere"])
def test_point_load_keeps_force_and_moment(kind, bary):
    """sum_i N_i F = F and sum_i x_i x N_i F = x x F, since sum N_i = 1 and sum N_i x_i = x
    (partition of unity and the limit point); exact also next to extraordinary vertices."""
    if kind == "plate":
        sh = _plate()
    else:
        m = icosphere(1.0, 1)
        sh = Shell(m.vertices, m.faces, LinearElastic(1.0, 0.3), 0.01)
    pr = Problem(sh, [], [RigidModes()])
    F = np.array([0.3, -1.2, 2.0])
    face = 5
    f = PointLoad(face, bary, tuple(F)).vector(sh, pr.evaluator)
    x = sh.rest_positions
    point = pr.evaluator.point(x, face, np.array(bary))
    np.testing.assert_allclose(f.sum(0), F, atol=1e-14)
    np.testing.assert_allclose(np.cross(x, f).sum(0), np.cross(point, F), atol=1e-13)


def test_pressure_resultant_on_hemisphere():
    """Uniform pressure p on a hemisphere of radius R has the resultant p pi R^2 along its axis
    (../shared/BENCHMARKS.md 2.3); the limit surface of the 24-ring mesh converges to it."""
    m = hemisphere(2.0, 24)
    sh = Shell(m.vertices, m.faces, LinearElastic(1.0, 0.3), 0.01)
    pr = Problem(sh, [], [RigidModes()])
    f = Pressure(3.0).vector(sh, pr.evaluator)
    total = f.sum(0)
    assert total[2] == pytest.approx(3.0 * np.pi * 4.0, rel=2e-3)
    assert np.abs(total[:2]).max() < 1e-10


def test_pressure_on_closed_sphere_is_self_equilibrated():
    m = icosphere(1.0, 2)
    sh = Shell(m.vertices, m.faces, LinearElastic(1.0, 0.3), 0.01)
    f = Pressure(1.0).vector(sh, Problem(sh, [], [RigidModes()]).evaluator)
    assert np.abs(f.sum(0)).max() < 1e-12


def test_body_force_total_is_weight():
    """Gravity on a flat plate: total force = rho g t A.  The ghost layer continues the grid's
    lattice around the corners, so by linear precision the limit surface of the real faces is
    exactly the square, A = a^2."""
    sh = _plate(n=6, a=2.0)
    f = BodyForce(1000.0, (0.0, 0.0, -9.81)).vector(sh, Problem(sh, [], [RigidModes()]).evaluator)
    np.testing.assert_allclose(f.sum(0), [0.0, 0.0, -1000.0 * 9.81 * 0.01 * 4.0], rtol=1e-12)


def _edges(a=1.0):
    return lambda p: (np.abs(np.abs(p[:, 0]) - a / 2) < 1e-9) | (np.abs(np.abs(p[:, 1]) - a / 2) < 1e-9)


def _boundary_residual(n, kind):
    """Max |u| on the limit boundary (9 points per edge) / max |u|, on edges next to corners
    and elsewhere."""
    m = rectangle(1.0, 1.0, n, n)
    sh = Shell(m.vertices, m.faces, LinearElastic(1e6, 0.3), 0.01)
    pr = Problem(sh, [Pressure(1.0)], [EdgeSupport(kind, _edges())])
    sol = solve_linear(pr)
    mesh, ev = sh.mesh, pr.evaluator
    xy = np.abs(m.vertices[:, :2])
    corner = set(np.flatnonzero(np.all(np.abs(xy - 0.5) < 1e-9, axis=1)).tolist())
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    worst = {True: 0.0, False: 0.0}
    for e, (a, b) in enumerate(mesh.boundary_edges):
        f = int(mesh.boundary_faces[e])
        i = int(np.flatnonzero(mesh.faces[f] == a)[0])
        near = int(a) in corner or int(b) in corner
        for tau in np.linspace(0.03, 0.97, 9):
            pt = (1 - tau) * corners[i] + tau * corners[(i + 1) % 3]
            st, N, _, _ = ev.basis(f, pt[None])
            worst[near] = max(worst[near], np.abs(N[0] @ sol.u[st]).max())
    return worst[True] / sol.max_displacement(), worst[False] / sol.max_displacement()


@pytest.mark.parametrize("kind", ["simply_supported", "clamped"])
def test_support_residual_on_the_limit_boundary_converges(kind):
    """Supports are imposed at two collocation points per edge of the limit curve; between them
    the residual must be small and vanish at high order under refinement (measured order 3-4;
    asserted: > 2.5 from 8 x 8 to 16 x 16 cells, and < 1 % / 0.05 % of the maximum
    displacement at 8 x 8 on edges next to corners / elsewhere)."""
    c8, o8 = _boundary_residual(8, kind)
    c16, o16 = _boundary_residual(16, kind)
    assert c8 < 1e-2 and o8 < 5e-4
    assert np.log2(c8 / c16) > 2.5
    assert np.log2(o8 / o16) > 2.5


def test_under_supported_body_is_reported():
    """A plate held on one straight edge only by a symmetry condition keeps rigid motions free;
    the error names them."""
    sh = _plate(n=4)
    left = lambda p: np.abs(p[:, 0] + 0.5) < 1e-9
    pr = Problem(sh, [Pressure(1.0)], [EdgeSupport("symmetry", left, normal=(1.0, 0.0, 0.0))])
    with pytest.raises(SupportError, match="under-supported.*translation"):
        solve_linear(pr)


def test_unsupported_body_without_rigid_modes_is_refused():
    m = icosphere(1.0, 1)
    sh = Shell(m.vertices, m.faces, LinearElastic(1.0, 0.3), 0.01)
    x = m.vertices[0]
    pr0 = Problem(sh, [], [RigidModes()])
    pt, _ = locate(sh, pr0.evaluator, x, "p")
    pr = Problem(sh, [Pressure(1.0)], [PointSupport(pt.face, pt.bary)])
    with pytest.raises(SupportError, match="rotation"):
        solve_linear(pr)


def test_symmetry_planes_reproduce_full_plate():
    """A quarter of a simply supported plate with two symmetry planes gives the full plate's
    centre deflection (same element size): symmetry = u.n = 0 (collocation) + zero rotation
    (Nitsche).  The two discretisations differ, so agreement is to discretisation error, which
    is itself < 1 % of the Kirchhoff value here; we ask for 0.5 % between them."""
    full = _plate(n=24, a=1.0)
    pr = Problem(full, [Pressure(1.0)], [EdgeSupport("simply_supported", _edges())])
    c, _ = locate(full, pr.evaluator, [0.0, 0.0, 0.0], "c")
    w_full = solve_linear(Problem(full, [Pressure(1.0)], pr.supports, {"c": c})).probe("c")[2]

    q = rectangle(0.5, 0.5, 12, 12, center=(0.25, 0.25))
    sh = Shell(q.vertices, q.faces, LinearElastic(1e6, 0.3), 0.01)
    outer = lambda p: (np.abs(p[:, 0] - 0.5) < 1e-9) | (np.abs(p[:, 1] - 0.5) < 1e-9)
    sup = [EdgeSupport("simply_supported", outer),
           EdgeSupport("symmetry", lambda p: np.abs(p[:, 0]) < 1e-9, normal=(1, 0, 0)),
           EdgeSupport("symmetry", lambda p: np.abs(p[:, 1]) < 1e-9, normal=(0, 1, 0))]
    pr_q = Problem(sh, [Pressure(1.0)], sup)
    cq, _ = locate(sh, pr_q.evaluator, [0.0, 0.0, 0.0], "c")
    w_q = solve_linear(Problem(sh, [Pressure(1.0)], sup, {"c": cq})).probe("c")[2]
    D = 1e6 * 0.01 ** 3 / (12 * (1 - 0.09))
    assert w_q == pytest.approx(w_full, rel=5e-3)
    assert w_q == pytest.approx(0.00406235 / D, rel=1e-2)
