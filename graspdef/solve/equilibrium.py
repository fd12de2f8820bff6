"""The discrete equilibrium problem of the nonlinear solvers.

Total potential energy of the control points x = X + u at load factor lam::

    Pi(x, lam) = E(x) + Pi_N(x) - lam f.u + sum_i Pi_i(x, lam)

with the shell's elastic energy E, the Nitsche rotation terms Pi_N of clamped/symmetry edges
(``graspdef.problem.nitsche``: consistent at finite deformation), the dead loads f and the
configuration-dependent loads Pi_i (``graspdef.problem.potentials``).  Supports are the linear
constraints C u = lam g (g non-zero for prescribed displacements); rigid-body modes of a free
body are removed by a statically determinate 3-2-1 point support (exact at finite rotation).  The load direction is
q(x) = -d(grad Pi)/d lam = f + sum_i load_i(x).

Each linearised step solves the KKT system of the Hessian H (+ rank-one parts, by the Woodbury
identity) and reports its inertia: the equilibrium is stable when the KKT matrix has exactly
m negative eigenvalues (m constraints), i.e. H is positive definite on the null space of C.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import SolverError
from ..problem.nitsche import NitscheRotation
from ..problem.problem import Problem
from ..shell.energy import ShellEnergy
from .sparse import KKTSystem, same_array


def _add(A: sp.spmatrix, B: sp.spmatrix) -> sp.csr_matrix:
    """A + B (a new matrix: the terms may hand out cached matrices); entry by entry when both
    are CSR on the same index arrays (the shell's shared pattern) or an equal structure."""
    if sp.isspmatrix_csr(A) and sp.isspmatrix_csr(B) and (
            (same_array(A.indices, B.indices) and same_array(A.indptr, B.indptr))
            or (A.nnz == B.nnz and A.has_sorted_indices and B.has_sorted_indices
                and np.array_equal(A.indptr, B.indptr) and np.array_equal(A.indices, B.indices))):
        return sp.csr_matrix((A.data + B.data, A.indices, A.indptr), shape=A.shape)
    return (A + B).tocsr()


@dataclass
class State:
    """Energy, gradient, Hessian and load direction at (x, lam)."""

    energy: float
    gradient: np.ndarray
    hessian: sp.csr_matrix | None
    rank_one: list
    load: np.ndarray
    internal: np.ndarray | None = None      # elastic forces dE/dx + dPi_N/dx (the force scale)


class Equilibrium:
    """Energy, residual and tangent solves of a :class:`Problem` (see the module docstring)."""

    def __init__(self, problem: Problem, backend: str = "auto"):
        self.problem = problem
        shell = problem.shell
        self.X = shell.rest_positions.copy()
        self.n = shell.n_dofs
        self.energy_fn = ShellEnergy(shell)
        self.nitsche = NitscheRotation(shell, problem.supports, problem.evaluator)
        self.f = problem.dead_load_vector()
        self.potentials = problem.potentials()
        self.C, self.labels, self.g = problem.constraints(with_targets=True, rigid="three_point")
        self.m = self.C.shape[0]
        self.kkt = KKTSystem(self.C, backend)
        self._CCt = spla.splu((self.C @ self.C.T).tocsc()) if self.m else None
        self.n_factorisations = 0

    def close(self) -> None:
        self.kkt.close()

    # ---- energy and derivatives -------------------------------------------------------------
    def evaluate(self, u: np.ndarray, lam: float, order: int = 2) -> State:
        """Pi, grad Pi, Hessian (order 2) and q at displacement u (3n,) and load factor lam."""
        x = self.X + u.reshape(-1, 3)
        if order == 0:
            E = self.energy_fn.energy(x)
            grad = None
        elif order == 1:
            E, grad = self.energy_fn.gradient(x)
            H = None
        else:
            E, grad, H = self.energy_fn.hessian(x)
        if self.nitsche:
            en, gn, Hn = self.nitsche.evaluate(x, order=max(order, 1))
            E += en
        E -= lam * float(self.f @ u)
        rank_one: list = []
        q = self.f.copy()
        internal = None
        if order >= 1:
            if self.nitsche:
                grad = grad + gn
            internal = grad
            grad = grad - lam * self.f
            if order == 2 and self.nitsche:
                H = _add(H, Hn)
        for pot in self.potentials:
            t = pot.evaluate(x, lam, order=order)
            E += t.value
            if order >= 1:
                grad = grad + t.gradient
                q = q + pot.load(x)
            if order == 2:
                if t.hessian is not None:
                    H = _add(H, t.hessian)
                rank_one += t.rank_one
        return State(float(E), grad, H if order == 2 else None, rank_one, q, internal)

    def energy(self, u: np.ndarray, lam: float) -> float:
        return self.evaluate(u, lam, order=0).energy

    def commit(self, u: np.ndarray) -> None:
        """Tell the state-tracking loads (edge rotations) that ``u`` is converged."""
        x = self.X + u.reshape(-1, 3)
        for pot in self.potentials:
            pot.commit(x)

    # ---- residuals ----------------------------------------------------------------------------
    def projected_residual(self, grad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Residual grad + C^T mu with least-squares reactions mu (what equilibrium leaves)."""
        if not self.m:
            return grad, np.zeros(0)
        mu = -self._CCt.solve(self.C @ grad)
        return grad + self.C.T @ mu, mu

    def constraint_residual(self, u: np.ndarray, lam: float) -> np.ndarray:
        """lam g - C u: what the next step must add to satisfy the supports."""
        return lam * self.g - self.C @ u if self.m else np.zeros(0)

    # ---- tangent solves ------------------------------------------------------------------------
    def factor(self, state: State) -> int | None:
        """Factor the KKT matrix of the state's Hessian; returns the inertia excess (negative
        eigenvalues of H on the constraint null space; 0 = stable) or None (no inertia)."""
        self.kkt.factor(state.hessian)
        self.n_factorisations += 1
        self._lowrank = None
        neg = self.kkt.n_negative
        if state.rank_one:
            V = np.stack([v for _, v in state.rank_one], axis=1)             # (n, k)
            c = np.array([c for c, _ in state.rank_one])
            W, _, _ = self.kkt.solve(V)                                       # A^-1 [V; 0]
            S = np.diag(1.0 / c) + V.T @ W                                    # C^-1 + V^T A^-1 V
            self._lowrank = (V, W, S)
            if neg is not None:
                # Haynsworth: neg(A + V C V^T) = neg(A) + neg(-S) - neg(-C^-1); negative c
                # (e.g. a force-controlled contact's condensed DOF) adds no negative pivot
                neg = neg + int((np.linalg.eigvalsh(-S) < 0).sum()) - int((c > 0).sum())
        return None if neg is None else neg - self.m

    def solve(self, rhs: np.ndarray, g: np.ndarray | None = None) -> np.ndarray:
        """Solve (H + sum c v v^T) du + C^T l = rhs, C du = g with the last factorisation;
        ``rhs`` (n,) or (n, k)."""
        du, _, _ = self.kkt.solve(rhs, g)
        if self._lowrank is not None:
            V, W, S = self._lowrank
            du = du - W @ np.linalg.solve(S, V.T @ du)
        if not np.all(np.isfinite(du)):
            raise SolverError("the tangent solve produced non-finite values")
        return du
