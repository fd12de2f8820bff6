"""What a load-controlled path does not compute twice (issue 17, speed).

* A load step that fails before any factorisation (its predicted state has non-finite energy, or
  Newton gives up on the reused tangent) leaves the current point's factorisation and its load
  tangent du/dlam as they were: the halved step reuses both instead of factorising the same
  point again (``PathSolver._tangent``).  One that did factorise elsewhere refactors here.
* The energy test of a Newton step evaluates the gradient at the whole step as well, and that
  state is the next iterate's when the whole step is taken: no state (u, lam) is evaluated twice.

Both change what is computed, not the equilibria: the injected failures end at the clean path's
final state (every path converged to the default tolerance).
"""
import numpy as np
import pytest

from graspdef.solve import nonlinear as nl
from graspdef.solve.equilibrium import Equilibrium
from graspdef.solve.nonlinear import PathOptions, solve_nonlinear
from test_inexact_newton import _ball       # the bench's air-filled neo-Hookean ball pinched at its poles


def _spy_tangent(monkeypatch):
    calls = []
    orig = nl.PathSolver._tangent

    def tangent(self, u, lam):
        calls.append(float(lam))
        return orig(self, u, lam)

    monkeypatch.setattr(nl.PathSolver, "_tangent", tangent)
    return calls


@pytest.mark.parametrize("factorise", [False, True])
def test_a_failed_step_keeps_the_points_factorisation_unless_it_made_another(monkeypatch, factorise):
    """The 642-vertex air-filled ball pinched to 20 N; the first attempt beyond load factor 0.3
    fails on purpose.  Without a factorisation of its own (``factorise`` False, as when the
    predicted state is not finite) the point's factorisation is kept: no tangent is factorised
    again; after one at the predicted state (True) the point's tangent is factorised once more.
    Both paths end where the clean one does, to 1e-8 of the pole's displacement."""
    clean = solve_nonlinear(_ball(3, 20.0), PathOptions(steps=10))
    calls = _spy_tangent(monkeypatch)
    orig = nl.PathSolver.newton
    failed = []

    def newton(self, u0, lam, *a, **k):
        if lam > 0.3 and not failed:
            failed.append(lam)
            if factorise:
                self.eq.factor(self.eq.evaluate(u0, lam, 2), inertia=False)
            raise nl._Failed(f"non-finite energy or forces at load factor {lam:.6g} (injected)")
        return orig(self, u0, lam, *a, **k)

    monkeypatch.setattr(nl.PathSolver, "newton", newton)
    sol = solve_nonlinear(_ball(3, 20.0), PathOptions(steps=10))
    assert failed and sol.completed and all(p.stable for p in sol.path)
    assert any(e["action"] == "load step halved" and "injected" in e["reason"] for e in sol.events)
    assert len(calls) == (1 if factorise else 0)
    top, ref = sol.probe("top"), clean.probe("top")
    assert np.linalg.norm(top - ref) <= 1e-8 * np.linalg.norm(ref)


@pytest.mark.parametrize("sub", [3, 4])
def test_no_state_is_evaluated_twice(monkeypatch, sub):
    """Along the air-filled ball's pinch -- 642 control vertices (Anderson steps on the reused
    tangent, energy tests, fresh tangents) and 2,562 (local corrections as well) -- no energy or
    gradient is evaluated at a state (u, lam) that was evaluated before; a Hessian may follow a
    gradient at the same state (the tangent is factorised there).  Before the energy test's state
    was kept, the end of every Newton step with an energy test was evaluated twice (its energy,
    then its gradient)."""
    seen: dict = {}
    repeats = []
    orig = Equilibrium.evaluate

    def evaluate(self, u, lam, order=2, keep_terms=False):
        key = (np.asarray(u, float).tobytes(), float(lam))
        if key in seen and order <= 1:
            repeats.append((float(lam), seen[key], order))
        seen[key] = max(seen.get(key, -1), order)
        return orig(self, u, lam, order, keep_terms)

    monkeypatch.setattr(Equilibrium, "evaluate", evaluate)
    sol = solve_nonlinear(_ball(sub, 20.0), PathOptions(steps=10))
    assert sol.completed and len(seen) > 20 and (sol.n_local > 0) == (sub == 4)
    assert repeats == []


def test_the_gas_rows_follow_their_own_state():
    """The enclosed gas's Hessian rows take the volume and its gradient from the term's last
    evaluation only when that was at the same positions: after an evaluation elsewhere its rows
    at x are still those of a fresh term at x (bit for bit), and after one at x as well."""
    from graspdef.shell.region import Region, vertex_rings

    pr = _ball(3, 20.0)
    eq = Equilibrium(pr)
    try:
        gas = next(t for t in eq.terms if type(t).__name__ == "EnclosedGas")
        fresh = next(t for t in Equilibrium(pr).terms if type(t).__name__ == "EnclosedGas")
        reg = Region(pr.shell, vertex_rings(pr.shell, [int(np.argmax(eq.X[:, 2]))], 2))
        x = eq.X * np.array([1.05, 1.05, 0.9])
        want_M, ((want_c, want_g),) = fresh.hessian_rows(x, 0.5, reg)
        for at in (eq.X * 1.02, x):                 # the last evaluation elsewhere, then at x
            gas.evaluate(at, 0.5, 1)
            M, ((c, g),) = gas.hessian_rows(x, 0.5, reg)
            assert np.array_equal(M.data, want_M.data) and c == want_c and np.array_equal(g, want_g)
    finally:
        eq.close()
