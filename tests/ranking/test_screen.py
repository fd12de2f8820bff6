"""The linear screen of grasp pairs (graspdef.ranking.screen): symmetry, an independent solve,
Reissner's point-loaded sphere, Clapeyron, convergence, and a can's stiff ends."""
import math

import numpy as np
import pytest
import trimesh

from graspdef.geometry import TriMesh, hemisphere, icosphere
from graspdef.problem.loads import PointLoad
from graspdef.problem.problem import Problem
from graspdef.problem.supports import RigidModes
from graspdef.ranking.screen import LinearScreen
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell
from graspdef.solve.linear import solve_linear

R, T, E, NU = 0.03, 0.0003, 1e9, 0.3           # R/t = 100


def reissner_closing(F: float, R: float, t: float, E: float, nu: float) -> float:
    """Approach of two opposite point forces F on a sphere: twice Reissner's apex deflection
    sqrt(3 (1 - nu^2)) F R / (4 E t^2) (../shared/BENCHMARKS.md 2.4; R/t >~ 50)."""
    return 2.0 * math.sqrt(3 * (1 - nu ** 2)) * F * R / (4 * E * t ** 2)


@pytest.fixture(scope="module")
def ico3():
    m = icosphere(R, 3)
    sc = LinearScreen(Shell(m.vertices, m.faces, LinearElastic(E, NU), T), E, NU)
    yield m, sc
    sc.close()


def _antipodes(sc, idx):
    _, j = sc.tree.query(-sc.P[idx])
    return j


def test_sphere_candidates_related_by_symmetry_are_equal(ico3):
    """Issue 18: on a sphere every candidate is equivalent.  On an icosphere mesh, candidates that
    the mesh's icosahedral symmetry maps onto each other must give the same figures to 1e-6
    relative (measured: 3e-14): the 6 antipodal pairs of the 12 valence-5 vertices, and the 15
    pairs of the 30 vertices at the icosahedron's edge midpoints."""
    m, sc = ico3
    n = sc.n_control
    val = np.bincount(m.faces.ravel(), minlength=n)
    v5 = np.flatnonzero(val == 5)
    assert len(v5) == 12
    d = np.linalg.norm(m.vertices[v5][:, None] - m.vertices[v5][None], axis=2)
    edge = d[d > 0].min()
    a, b = np.nonzero(np.triu(np.isclose(d, edge, rtol=1e-9)))
    mid = m.vertices[v5[a]] + m.vertices[v5[b]]
    mid = R * mid / np.linalg.norm(mid, axis=1, keepdims=True)
    _, v30 = trimesh.proximity.ProximityQuery(trimesh.Trimesh(m.vertices, m.faces)).vertex(mid)
    assert len(a) == 30 and len(set(v30.tolist())) == 30
    for orbit in (v5, v30):
        i1 = orbit[m.vertices[orbit] @ [0.3, 0.5, 0.7] > 0]
        i2 = _antipodes(sc, i1)
        fig = sc.evaluate(i1, i2, 5.0)
        for name in ("closing_m", "work_J", "strain_energy_J", "max_displacement_m", "peak_strain",
                     "peak_von_mises_Pa", "contact_area_m2"):
            v = getattr(fig, name)
            assert np.ptp(v) <= 1e-6 * abs(v.mean()), (name, v)
        for name in ("deformed_angle_deg", "rest_angle_deg"):
            assert np.ptp(getattr(fig, name)) <= 1e-6, name


def test_screen_equals_an_independent_linear_solve(ico3):
    """The screen (sample weights, one factorisation, blocks of back-substitutions) against the
    ordinary linear solve of the same problem (loads located by projection, a fresh KKT solve):
    the closing displacement and the displacement field agree to 1e-6."""
    m, sc = ico3
    rng = np.random.default_rng(7)
    i1 = rng.integers(0, sc.samples.n, 3)
    i2 = _antipodes(sc, i1)
    U, B, d = sc.solve(i1, i2, 2.0)
    fig = sc.evaluate(i1, i2, 2.0)
    shell = sc.shell
    free = Problem(shell, [], [RigidModes()])
    for k in range(3):
        p, q = free.locate(sc.P[i1[k]], "p"), free.locate(sc.P[i2[k]], "q")
        prob = Problem(shell, [PointLoad(p.face, p.bary, tuple(2.0 * d[k])), PointLoad(q.face, q.bary, tuple(-2.0 * d[k]))],
                       [RigidModes()], {"p": p, "q": q})
        sol = solve_linear(prob)
        closing = float((sol.probe("p") - sol.probe("q")) @ d[k])
        assert closing == pytest.approx(fig.closing_m[k], rel=1e-6)
        np.testing.assert_allclose(sol.u.ravel(), U[:, k], atol=1e-6 * np.abs(U[:, k]).max())


def test_work_equals_strain_energy_clapeyron(ico3):
    """Linear theory: the fingers' work F delta / 2 equals the strain energy u.K u / 2 (computed
    separately from the stiffness), to 1e-9."""
    m, sc = ico3
    i1 = np.arange(0, sc.samples.n, 997)
    fig = sc.evaluate(i1, _antipodes(sc, i1), 3.0)
    np.testing.assert_allclose(fig.strain_energy_J, fig.work_J, rtol=1e-9)
    np.testing.assert_allclose(fig.stiffness_N_per_m * fig.closing_m, 3.0, rtol=1e-12)


def lattice_sphere(radius: float, n: int) -> TriMesh:
    """A closed sphere of two ``hemisphere(radius, n)`` lattices glued at the equator (a regular
    valence-6 lattice around both poles), as in tests/objects/test_poisson_sphere.py."""
    h = hemisphere(radius, n)
    v, f = h.vertices, h.faces
    lower = np.abs(v[:, 2]) >= 1e-12 * radius
    index = np.arange(len(v))
    index[lower] = len(v) + np.arange(lower.sum())
    return TriMesh(np.vstack([v, v[lower] * [1.0, 1.0, -1.0]]), np.vstack([f, index[f][:, ::-1]]))


def test_pinched_sphere_matches_reissner():
    """The poles' pair of a sphere at R/t = 100 against Reissner's closing displacement
    2 sqrt(3 (1 - nu^2)) F R / (4 E t^2) (../shared/BENCHMARKS.md 2.4), within the linear
    benchmark's 3 % (measured on the 6,146-vertex lattice sphere, samples at level 2: -0.55 %)."""
    m = lattice_sphere(R, 32)
    sc = LinearScreen(Shell(m.vertices, m.faces, LinearElastic(E, NU), T), E, NU, level=2)
    try:
        _, i = sc.tree.query([[0, 0, R], [0, 0, -R]])
        fig = sc.evaluate(i[:1], i[1:], 1.0)
    finally:
        sc.close()
    assert fig.closing_m[0] == pytest.approx(reissner_closing(1.0, R, T, E, NU), rel=0.03)


def test_sphere_candidates_converge_to_one_value(ico3):
    """Away from symmetric points, candidates on a sphere differ only by discretisation: the
    spread (max - min) / mean of 200 random antipodal pairs shrinks with refinement -- measured
    32 % at 642 vertices, 13 % at 2,562 -- and their mean approaches Reissner (0.57 -> 0.90)."""
    rng = np.random.default_rng(0)
    spread, mean = [], []
    for sc in (ico3[1], None):
        own = sc is None
        if own:
            m = icosphere(R, 4)
            sc = LinearScreen(Shell(m.vertices, m.faces, LinearElastic(E, NU), T), E, NU, level=3)
        i1 = rng.integers(0, sc.samples.n, 200)
        c = sc.evaluate(i1, _antipodes(sc, i1), 1.0).closing_m
        spread.append(np.ptp(c) / c.mean())
        mean.append(c.mean() / reissner_closing(1.0, R, T, E, NU))
        if own:
            sc.close()
    assert spread[1] < 0.5 * spread[0]
    assert abs(1 - mean[1]) < 0.5 * abs(1 - mean[0])


def capped_cylinder(faces: int) -> TriMesh:
    """A closed can (radius 33 mm, height 122 mm: a soda can), isotropically remeshed."""
    from graspdef.scans.remesh import control_mesh

    raw = trimesh.creation.cylinder(radius=0.033, height=0.122, sections=96)
    raw.apply_translation([0, 0, 0.061])
    cm, _ = control_mesh(TriMesh(raw.vertices, raw.faces), faces, "isotropic")
    return cm


def test_can_is_stiffer_near_its_ends_than_in_the_middle():
    """Issue 18: on a can, grasps near the stiff ends against the soft middle.  Diametral pinches
    at 10 ... 50 % of the height: the screen (1,500 faces) orders them as an independent linear
    solve on a twice finer mesh does (closing displacement increasing towards the middle,
    rank correlation 1).  Aluminium wall, t = 0.3 mm."""
    pytest.importorskip("pymeshlab")
    H, Rc, t, Ea, nua = 0.122, 0.033, 0.0003, 69e9, 0.33
    z = np.array([0.1, 0.2, 0.3, 0.4, 0.5]) * H
    first = np.c_[np.full(5, Rc), np.zeros(5), z]
    second = np.c_[np.full(5, -Rc), np.zeros(5), z]
    m = capped_cylinder(1500)
    sc = LinearScreen(Shell(m.vertices, m.faces, LinearElastic(Ea, nua), t), Ea, nua)
    try:
        screen = sc.evaluate(sc.locate(first)[0], sc.locate(second)[0], 10.0).closing_m
    finally:
        sc.close()
    fine = Shell(*(lambda c: (c.vertices, c.faces))(capped_cylinder(3000)), LinearElastic(Ea, nua), t)
    free = Problem(fine, [], [RigidModes()])
    full = []
    for p0, q0 in zip(first, second):
        p, q = free.locate(p0 - [t / 2, 0, 0], "p"), free.locate(q0 + [t / 2, 0, 0], "q")
        prob = Problem(fine, [PointLoad(p.face, p.bary, (-10.0, 0, 0)), PointLoad(q.face, q.bary, (10.0, 0, 0))],
                       [RigidModes()], {"p": p, "q": q})
        sol = solve_linear(prob)
        full.append(float(sol.probe("q")[0] - sol.probe("p")[0]))
    full = np.array(full)
    assert np.all(np.diff(screen) > 0), screen
    assert np.all(np.diff(full) > 0), full
    assert full[0] < 0.7 * full[-1] and screen[0] < 0.7 * screen[-1]
