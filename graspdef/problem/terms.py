"""The energy-term protocol: every part of the total potential of the nonlinear solver.

    Pi(x, lam) = sum_i Pi_i(x, lam)

Each term is set up completely when it is built (from a shell, by its specification's
``build(shell, evaluator)``, or by its constructor) and then offers:

* ``evaluate(x, lam, order, u)`` -> :class:`TermValue`: value [J], gradient (3n,) [N] (order >= 1),
  Hessian (3n, 3n) [N/m] or None (order 2) and rank-one Hessian parts ``[(c, v)]`` = c v v^T, at
  the control points x (n, 3) = X + u; ``u`` (3n,) is the solver's unknown itself, for terms
  linear in it (no cancellation in x - X);
* ``load(x)``: the generalised force the load factor scales, -d(gradient)/d(lam) (None: none);
* ``commit(x)``: tell a state-tracking term that ``x`` is a converged state;
* ``record(x)``: numbers for the path record (e.g. the enclosed gas's volume and pressure);
* ``internal``: True for the shell's own (elastic and support) forces, which set the force scale
  of the convergence test;
* ``hessian_rows(x, lam, region)`` (optional): the rows of the Hessian at the control vertices of a
  :class:`graspdef.shell.region.Region` -- a CSR matrix (3|R|, 3n) on the region's pattern, or None
  where the term has no Hessian -- and the term's rank-one parts [(c, v)] (v whole); computed on
  the region's faces only, for the path's local corrections (a term without it turns them off);
* ``concurrent()`` (optional, False by default): True when ``evaluate`` may run in a thread beside
  the other terms' -- its work is in code that releases the GIL (graspdef.compiled's ahead-of-time
  kernels), it shares no mutable state with them, and it launches no parallel region of numba's
  (:class:`graspdef.solve.equilibrium.Equilibrium` then evaluates it so: the shell's elastic term);
* ``remedy`` (optional, None by default): for a term that is not convex by itself -- e.g. a Nitsche
  edge term, whose consistency part is bounded only by its penalty -- a sentence naming the
  setting that restores it; a path that stalls on a mode that such a term makes soft says so
  (:meth:`graspdef.solve.nonlinear.PathSolver.soft_terms`).

:class:`graspdef.solve.equilibrium.Equilibrium` sums a list of terms and knows none by name;
:meth:`graspdef.problem.problem.Problem.energy_terms` builds the list of a problem.  A new term
(a load, a support penalty, a contact model) implements this protocol (ARCHITECTURE.md).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np
import scipy.sparse as sp


@dataclass
class TermValue:
    """Value [J], gradient (3n,) [N] or None, Hessian (3n, 3n) [N/m] or None, and rank-one
    Hessian parts [(c, v)] meaning c v v^T."""

    value: float
    gradient: np.ndarray | None
    hessian: sp.csr_matrix | None
    rank_one: list = field(default_factory=list)


@runtime_checkable
class EnergyTerm(Protocol):
    """What :class:`~graspdef.solve.equilibrium.Equilibrium` needs of a term (module docstring)."""

    internal: bool

    def evaluate(self, x: np.ndarray, lam: float, order: int = 2, u: np.ndarray | None = None) -> TermValue: ...

    def load(self, x: np.ndarray) -> np.ndarray | None: ...

    def commit(self, x: np.ndarray) -> None: ...

    def record(self, x: np.ndarray) -> dict: ...


class TermBase:
    """Defaults: an external (not internal) term with no scaled load, no state, nothing to report."""

    internal = False
    remedy: str | None = None

    def load(self, x: np.ndarray) -> np.ndarray | None:
        return None

    def commit(self, x: np.ndarray) -> None:
        pass

    def record(self, x: np.ndarray) -> dict:
        return {}

    def concurrent(self) -> bool:
        return False


#: ``hessian_rows`` of a term without a Hessian (dead loads): no rows, no rank-one parts
NO_ROWS = (None, ())


class ShellElastic(TermBase):
    """The shell's membrane + bending energy at finite deformation (graspdef.shell.energy)."""

    internal = True

    def __init__(self, shell):
        from ..shell.energy import ShellEnergy

        self.energy = ShellEnergy(shell)

    def concurrent(self) -> bool:
        """In a thread of its own when every kernel runs ahead of time (ShellEnergy.concurrent);
        the Hessian's block pattern, shared with other terms, is then built here, before any thread."""
        if not self.energy.concurrent():
            return False
        self.energy.pattern
        return True

    def evaluate(self, x: np.ndarray, lam: float, order: int = 2, u: np.ndarray | None = None) -> TermValue:
        if order == 0:
            return TermValue(self.energy.energy(x), None, None)
        if order == 1:
            return TermValue(*self.energy.gradient(x), None)
        return TermValue(*self.energy.hessian(x))

    def hessian_rows(self, x: np.ndarray, lam: float, region) -> tuple:
        return region.energy.hessian(x)[2], []


class RestQuadratic(TermBase):
    """The linear shell: (1/2) u^T K u with K the Hessian of the shell energy at rest, u = x - X
    (a linear shell on the nonlinear solver's path, e.g. with contact)."""

    internal = True

    def __init__(self, shell):
        from ..shell.energy import ShellEnergy

        self.X = np.asarray(shell.rest_positions, float)
        self.K = ShellEnergy(shell).hessian(self.X)[2].tocsr()

    def evaluate(self, x: np.ndarray, lam: float, order: int = 2, u: np.ndarray | None = None) -> TermValue:
        u = (x - self.X).ravel()
        g = self.K @ u
        E = 0.5 * float(u @ g)
        return TermValue(E, None if order == 0 else g, self.K if order == 2 else None)

    def hessian_rows(self, x: np.ndarray, lam: float, region) -> tuple:
        return self.K[region.dofs], []


class NitscheTerm(TermBase):
    """Nitsche rotation terms of clamped / symmetry edges (graspdef.problem.nitsche)."""

    internal = True

    def __init__(self, nitsche):
        self.nitsche = nitsche
        self.remedy = (f"the Nitsche rotation term of the clamped / symmetry edges: its penalty no longer "
                       f"dominates its edge-moment term there (a spurious mode, not the shell's); raise "
                       f"[solver] nitsche_gamma (now {nitsche.gamma:g})")

    def evaluate(self, x: np.ndarray, lam: float, order: int = 2, u: np.ndarray | None = None) -> TermValue:
        e, g, H = self.nitsche.evaluate(x, order=max(order, 1))
        return TermValue(e, g if order >= 1 else None, H if order == 2 else None)


class DeadLoads(TermBase):
    """Configuration-independent loads f (3n,) [N] scaled by the load factor: -lam f.(x - X)."""

    def __init__(self, f: np.ndarray, X: np.ndarray):
        self.f = np.asarray(f, float)
        self.X = np.asarray(X, float)

    def evaluate(self, x: np.ndarray, lam: float, order: int = 2, u: np.ndarray | None = None) -> TermValue:
        u = (x - self.X).ravel() if u is None else u
        return TermValue(-lam * float(self.f @ u), None if order == 0 else -lam * self.f, None)

    def hessian_rows(self, x: np.ndarray, lam: float, region) -> tuple:
        return NO_ROWS

    def load(self, x: np.ndarray) -> np.ndarray:
        return self.f.copy()
