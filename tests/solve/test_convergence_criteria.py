"""Convergence on the problem's own force scale with a round-off floor (issue 17, item 2).

The problem: Sze, Liu & Lo (2004)'s slit annular plate (inner radius 6, outer 10, t = 0.03,
E = 21e6, nu = 0; one lip of the slit clamped, a transverse line force 0.8 (per unit length) on the
other), coarse (20 x 4 cells).  Its membrane stiffness E t = 6.3e5 is huge next to the loads, so
the forces computed from positions of size 10 carry a rounding noise of ~1e-5 of the force scale
at small loads: with a purely relative tolerance of 1e-8 the path stopped at its first step (the
residual stagnated at 6e-6 with corrections of 1e-13).
"""
import numpy as np
import pytest

from graspdef.geometry import rectangle
from graspdef.problem.loads import EdgeLoad
from graspdef.problem.problem import Problem
from graspdef.problem.supports import EdgeSupport
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell
from graspdef.solve.equilibrium import Equilibrium, roundoff_floor
from graspdef.solve.linear import solve_linear
from graspdef.solve.nonlinear import PathOptions, solve_nonlinear

GAP = 1e-6      # [rad] the two lips of the slit, at theta = GAP and 2 pi - GAP


def slit_ring(n_theta=20, n_r=4, force=0.8):
    m = rectangle(2 * np.pi - 2 * GAP, 4.0, n_theta, n_r, center=(np.pi, 8.0))
    th, r = m.vertices[:, 0], m.vertices[:, 1]
    v = np.stack([r * np.cos(th), r * np.sin(th), 0 * r], 1)
    sh = Shell(v, m.faces, LinearElastic(21e6, 0.0), 0.03)
    lip_a = lambda p: (np.abs(p[:, 1]) < 1e-3) & (p[:, 1] > 0) & (p[:, 0] > 0)     # noqa: E731
    lip_b = lambda p: (np.abs(p[:, 1]) < 1e-3) & (p[:, 1] < 0) & (p[:, 0] > 0)     # noqa: E731
    pr = Problem(sh, [EdgeLoad(lip_b, (0.0, 0.0, force))], [EdgeSupport("clamped", lip_a, name="lip a")])
    # the loaded lip's inner corner A: the face of lip b's first cell (theta = 2 pi - GAP)
    pr.probes["A"] = pr.locate((6 * np.cos(-2 * GAP), 6 * np.sin(-2 * GAP), 0.0))
    return pr


@pytest.fixture(scope="module")
def ring():
    return slit_ring()


def test_roundoff_floor_is_the_gradients_rounding_noise(ring):
    """roundoff_floor(H, x) estimates the change of the gradient under perturbations of x of
    rounding size (eps |x_j| with random signs, seeded): the measured change lies within a
    factor 2 of it (an invariant of the estimate's derivation: it is that change's standard
    deviation)."""
    eq = Equilibrium(ring)
    u = np.zeros(eq.n)
    st = eq.evaluate(u, 0.01, 2)
    x = eq.X.ravel()
    floor = roundoff_floor(st.hessian, x)
    rng = np.random.default_rng(3)
    eps = np.finfo(float).eps
    changes = [np.linalg.norm(eq.evaluate(u + eps * np.abs(x) * rng.choice([-1.0, 1.0], x.size), 0.01, 1).gradient
                              - st.gradient) for _ in range(5)]
    ratio = np.median(changes) / floor
    assert 0.5 < ratio < 2.0, ratio
    eq.close()


def test_slit_ring_runs_with_the_default_tolerance(ring):
    """The default settings (tol 1e-8) follow the path: every point converges, by the residual
    test or at the round-off floor (and then with a last correction below tol of |u|); points
    at the floor are recorded as such; and at a small load the nonlinear solution equals the
    linear one to O(load) (W_A at load factor 0.002: within 1 % of the linear W_A x 0.002;
    Sze's S4R curve is still straight there: 1.305 at 0.025)."""
    sol = solve_nonlinear(ring, PathOptions(max_load=0.002, steps=2))
    assert sol.completed
    how = [p.converged_by for p in sol.path[1:]]
    assert [p.extra["at_roundoff_floor"] for p in sol.path[1:]] == [float(h == "round-off floor") for h in how]
    assert set(how) <= {"residual", "round-off floor"} and "round-off floor" in how
    for p in sol.path[1:]:
        assert p.extra["residual_relative"] <= max(1e-8, p.extra["roundoff_floor_relative"])
    w_lin = solve_linear(ring).u
    ev = ring.evaluator
    st, w = ev.values(ring.probes["A"].face, np.asarray(ring.probes["A"].bary))
    wa_lin = float(w @ w_lin[st][:, 2]) * 0.002
    wa = float(sol.path[-1].probes["A"][2])
    assert abs(wa - wa_lin) <= 0.01 * abs(wa_lin)


def test_slit_ring_lifted_to_full_load_with_default_settings():
    """The whole path to P = 0.8 with default settings completes (it stopped at its first step
    before), and W_A at P_max is close to Sze, Liu & Lo (2004)'s S4R reference, problem 3.3
    (13.891 at the loaded lip's inner corner; table transcribed in MBDyn's
    tests/plates/sze2004/sze33/sze33_ref.dat, zanoni-mbdyn/MBDyn): within 5 % at this coarse
    20 x 4 mesh (measured -1.0 % at 40 x 6)."""
    pr = slit_ring()
    sol = solve_nonlinear(pr, PathOptions())
    assert sol.completed
    wa = float(sol.path[-1].probes["A"][2])
    assert abs(wa / 13.891 - 1) < 0.05


@pytest.mark.slow
def test_slit_annular_plate_benchmark_at_sze_mesh():
    """benchmarks/nonlinear/slit_annular_plate.toml (Sze's own 10 x 80 mesh, 1,034 control
    vertices, default settings): every tabulated point of W_A and W_B within the file's 2 % of
    Sze, Liu & Lo (2004)'s S4R values (problem 3.3, MBDyn's sze33_ref.dat).  Before the solves were
    accepted by their backward error, this path crawled in steps of 4e-4 (> 400 steps, stopped at
    a load factor of 0.3)."""
    from pathlib import Path

    from graspdef.bench import run_nonlinear_benchmark

    recs = run_nonlinear_benchmark(Path(__file__).parents[2] / "benchmarks" / "nonlinear" / "slit_annular_plate.toml")
    assert len(recs) == 46
    bad = [(r["name"], r["value"], r["reference"]) for r in recs if not r["passed"]]
    assert not bad, bad
