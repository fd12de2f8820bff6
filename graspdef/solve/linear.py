"""The linear problem: K0 u = f with K0 the Hessian of the shell energy at rest."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..problem.problem import Problem
from ..shell.energy import ShellEnergy
from .result import DisplacementField
from .sparse import KKTResult, KKTSystem, solve_kkt


@dataclass
class LinearSolution(DisplacementField):
    """Control-point displacements of a linear solve and what is derived from them.

    Attributes
    ----------
    problem : Problem
    u : (n_control, 3) control-point displacements [m]
    kkt : KKTResult
    timings : dict of seconds (assembly, constraints, factor, solve)
    """

    problem: Problem
    u: np.ndarray
    kkt: KKTResult
    timings: dict = field(default_factory=dict)
    load: np.ndarray | None = None

    @property
    def strain_energy(self) -> float:
        """(1/2) f.u [J] (equal to the elastic energy at equilibrium of a linear problem)."""
        return 0.5 * float(self.load @ self.u.ravel())

    def net_load(self) -> tuple[np.ndarray, np.ndarray]:
        """Net force [N] and moment about the origin [N m] of the applied loads."""
        f = self.load.reshape(-1, 3)
        x = self.problem.shell.rest_positions
        return f.sum(0), np.cross(x, f).sum(0)


def rest_stiffness(problem: Problem):
    """K0: the Hessian of the shell energy at rest plus the Nitsche terms of rotation-fixed edges."""
    shell = problem.shell
    _, _, K = ShellEnergy(shell).hessian(shell.rest_positions)
    Kb = problem.boundary_stiffness()
    if Kb.nnz:
        K = (K + Kb).tocsr()
    return K


class LinearResponse:
    """The factorised linear problem, for many scalings of its loads and moduli (the viewer's live
    re-solves): u = (load scale / modulus scale) u_f + u_g, exact in linear theory.

    ``u_f`` (n_control, 3): the response to the loads at scale 1; ``u_g``: to the prescribed
    displacements."""

    def __init__(self, problem: Problem, backend: str = "auto", precision: str = "auto"):
        K = rest_stiffness(problem)
        f = problem.load_vector()
        C, _, g = problem.constraints(with_targets=True)
        self.kkt = KKTSystem(C, backend, precision)
        self.kkt.factor(K)
        uf, _, _ = self.kkt.solve(f)
        self.u_f = uf.reshape(-1, 3)
        self.u_g = self.kkt.solve(np.zeros_like(f), g)[0].reshape(-1, 3) if np.any(g) else np.zeros_like(self.u_f)

    def displacements(self, load_scale: float, modulus_scale: float) -> np.ndarray:
        """Control-point displacements (n_control, 3) [m] at the scaled loads and moduli."""
        return load_scale / modulus_scale * self.u_f + self.u_g

    def close(self) -> None:
        self.kkt.close()


def solve_linear(problem: Problem, backend: str = "auto", precision: str = "auto") -> LinearSolution:
    """Assemble K0 (Hessian at rest), the load vector and the support constraints, and solve.
    ``precision`` "mixed": a single-precision factor refined in double to a double solve's
    backward error, refactored in double if it does not get there
    (:class:`graspdef.solve.sparse.KKTSystem`); "double": a double factor; "auto" (default): mixed
    from 20,000 unknowns on (:data:`graspdef.solve.sparse.MIXED_MIN_UNKNOWNS`)."""
    t0 = time.perf_counter()
    shell = problem.shell
    built = shell.has_block_pattern
    K = rest_stiffness(problem)
    if not built:
        # one Hessian only: the pattern's element maps (built for it, 2.3 x K's index array) are not
        # needed again, and at 100k they are 0.3 GB of the process's peak beside the factor (K keeps
        # the pattern's index arrays it shares)
        shell.release_block_pattern()
    t1 = time.perf_counter()
    f = problem.load_vector()
    C, _, g = problem.constraints(with_targets=True)
    t2 = time.perf_counter()
    kkt = solve_kkt(K, C, f, backend=backend, g=g, precision=precision)
    timings = {"assembly": t1 - t0, "loads_constraints": t2 - t1, "factor": kkt.seconds_factor,
               "solve": kkt.seconds_solve}
    return LinearSolution(problem, kkt.u.reshape(-1, 3), kkt, timings, f)
