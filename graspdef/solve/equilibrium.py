"""The discrete equilibrium problem of the nonlinear solvers.

Total potential energy of the control points x = X + u at load factor lam: the sum of a list of
energy terms (:mod:`graspdef.problem.terms`; :meth:`Problem.energy_terms` builds them)::

    Pi(x, lam) = sum_i Pi_i(x, lam)

-- typically the shell's elastic energy, the Nitsche rotation terms of clamped/symmetry edges
(``graspdef.problem.nitsche``: consistent at finite deformation), the dead loads -lam f.u and
the configuration-dependent loads (``graspdef.problem.potentials``, finger contact).  The sum
knows no term by name.  Supports are the linear
constraints C u = lam g (g non-zero for prescribed displacements); rigid-body modes of a free
body are removed by six rows on the surface's mean displacement and mean rotation
(:class:`graspdef.problem.supports.RigidModes`: no vertex picked, symmetric, numbering-invariant).  The load direction is
q(x) = -d(grad Pi)/d lam = sum_i load_i(x); the force scale of the convergence test is the
gradient of the internal terms (the shell's own elastic and support forces).

Each linearised step solves the KKT system of the Hessian H (+ rank-one parts, by the Woodbury
identity) and reports its inertia: the equilibrium is stable when the KKT matrix has exactly
m negative eigenvalues (m constraints), i.e. H is positive definite on the null space of C.

Local corrections (:meth:`Equilibrium.local_region`, :meth:`Equilibrium.local_step`): a step on a
factorised tangent from elsewhere, preceded by an exact Newton step in a region R of control
vertices -- d_R = -H_RR^-1 r_R with the current Hessian's rows of R only
(:class:`graspdef.shell.region.Region`), then the factorised tangent's step for the residual that
leaves, r + H_{:,R} d_R (one multiplicative Schwarz cycle of the exact local and the reused global
tangent, linearised).  Where the tangent changed only in R (a point load's dimple) this contracts
as a fresh tangent does at a few per cent of its cost.

``precision`` "mixed" (or "auto" from 20,000 unknowns): the tangents are factorised in single
precision (about 0.6 x the time and half the memory of a double factor); a factor whose inertia
is reported is first certified (:meth:`graspdef.solve.sparse.KKTSystem.certify_inertia`: else it is
refactorised in double), and the solves are refined only to what the caller needs (a predictor's
or the Woodbury vectors' relative residual 1e-8, the acceptance of a double solve; a Newton
step's forcing tolerance, ``PathSolver.newton``), not to a double solve's backward error.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .. import compiled
from ..errors import SolverError
from ..problem.problem import Problem
from ..problem.terms import EnergyTerm
from ..shell.region import Region, vertex_rings
from .krylov import gmres
from .sparse import KKTSystem, RowSummary, row_summary, same_array, union_sum


#: a term that may (``concurrent()``) is evaluated in a thread beside the others from this many control
#: vertices on (the tennis ball's 642: a tangent 28 -> 18 ms, a gradient 6.1 -> 5.5 ms; a thread's
#: start and join cost ~0.1 ms, which a smaller shell's overlap does not repay)
CONCURRENT_MIN_VERTICES = 256


def _add(A: sp.spmatrix, B: sp.spmatrix) -> sp.csr_matrix:
    """A + B (a new matrix: the terms may hand out cached matrices); entry by entry when both
    are CSR on the same index arrays (the shell's shared pattern) or an equal structure; a matrix
    with no stored entries (a term that is zero, e.g. friction with mu = 0) leaves the other's
    structure as it is (scipy's sum would drop its explicit zeros).  Two different structures are
    summed on their union with explicit zeros kept as well: a flat shell's Hessian at rest has exact
    zeros where a bent one has none (the cantilever: 31,203 against 55,359 non-zeros), and dropping
    them changed the tangent's pattern after the first step -- a second PARDISO analysis (in core,
    and out of core a fresh worker process: graspdef.solve.pardiso_ooc)."""
    if B.nnz == 0 or A.nnz == 0:
        C = (A if B.nnz == 0 else B).tocsr()
        return sp.csr_matrix((C.data.copy(), C.indices, C.indptr), shape=C.shape)
    if sp.isspmatrix_csr(A) and sp.isspmatrix_csr(B) and (
            (same_array(A.indices, B.indices) and same_array(A.indptr, B.indptr))
            or (A.nnz == B.nnz and A.has_sorted_indices and B.has_sorted_indices
                and np.array_equal(A.indptr, B.indptr) and np.array_equal(A.indices, B.indices))):
        return sp.csr_matrix((A.data + B.data, A.indices, A.indptr), shape=A.shape)
    return union_sum(A, B)


@dataclass
class State:
    """Energy, gradient, Hessian and load direction at (x, lam)."""

    energy: float
    gradient: np.ndarray
    hessian: sp.csr_matrix | None
    rank_one: list
    load: np.ndarray
    internal: np.ndarray | None = None      # elastic forces dE/dx + dPi_N/dx (the force scale)
    floor: float | None = None               # round-off level of |gradient| (order 2 only), see roundoff_floor
    rows: RowSummary | None = None           # the Hessian's row numbers for its factorisation (tangent_sum)
    terms: list | None = None                # each term's TermValue, in order (``keep_terms`` only)


#: Factor of :func:`roundoff_floor`: its estimate is the standard deviation of the gradient's
#: change under perturbations of x of eps |x| (rounding errors are at most half that); measured on
#: the slit ring, Newton's residual stagnates at 0.4 of it.
ROUNDOFF_FACTOR = 1.0


def roundoff_floor(H: sp.csr_matrix, x: np.ndarray) -> float:
    """The level below which |grad Pi| is round-off [N]: ``ROUNDOFF_FACTOR`` times
    eps || sqrt((H o H) x^2) ||_2 (o: entry-wise product; x = X + u, flattened).

    The forces are computed from the absolute positions x, whose every component carries a
    rounding error of about eps |x_j|; independent errors of that size move the gradient by H dx,
    whose standard deviation is the expression above (checked against the gradient's actual
    change under such perturbations: 1.94e-8 vs 1.99e-8 N on the slit ring below).  For a thin,
    stiff shell at small loads (a slit ring lifted at one lip: t = 0.03, E t = 6.3e5, line load
    0.8e-3) this level is ~1e-5 of the force scale, and a relative tolerance of 1e-8 could only
    be met by luck."""
    if H is None:
        return 0.0
    x = np.asarray(x, float).ravel()
    H = H.tocsr()
    if not H.has_canonical_format:                 # entry-wise squares need each entry once
        H = H.copy()
        H.sum_duplicates()
    H2 = sp.csr_matrix((H.data * H.data, H.indices, H.indptr), shape=H.shape)    # H o H on H's structure
    return _floor(H2 @ (x * x))


def _floor(sq: np.ndarray) -> float:
    """:func:`roundoff_floor` from the row sums sq_i = sum_j H_ij^2 x_j^2."""
    return float(ROUNDOFF_FACTOR * np.finfo(float).eps * np.linalg.norm(np.sqrt(sq)))


def tangent_sum(hessians: list, x: np.ndarray) -> tuple[sp.csr_matrix | None, RowSummary | None, float]:
    """The sum of the terms' Hessians (in their order, as :func:`_add` sums them), its
    :class:`~graspdef.solve.sparse.RowSummary` (None where it is not made) and its
    :func:`roundoff_floor`.  Where the last two share their index arrays (the shell's pattern) and
    the sum is in canonical format, the last sum, the floor's products and the factorisation's row
    numbers are one pass (:func:`graspdef.solve.sparse.row_summary`), with the same numbers to the bit."""
    if not hessians:
        return None, None, 0.0
    H = hessians[0]
    for B in hessians[1:-1]:
        H = _add(H, B)
    B = hessians[-1] if len(hessians) > 1 else None
    if not (sp.isspmatrix_csr(H) and H.nnz and (B is None or (
            sp.isspmatrix_csr(B) and B.nnz and same_array(H.indices, B.indices) and same_array(H.indptr, B.indptr)))
            and H.has_canonical_format):
        H = H if B is None else _add(H, B)
        return H, None, roundoff_floor(H, x)
    H, rows, sq = row_summary(H, B, x)
    return H, rows, _floor(sq)


class Equilibrium:
    """Energy, residual and tangent solves of a :class:`Problem` (see the module docstring)."""

    def __init__(self, problem: Problem, backend: str = "auto", terms: list[EnergyTerm] | None = None,
                 precision: str = "double"):
        """``terms``: the energy terms to sum (default ``problem.energy_terms()``); ``precision``:
        the tangents' factorisation (:class:`graspdef.solve.sparse.KKTSystem`; a single-precision
        factor's inertia is certified before it is reported, :meth:`factor`)."""
        self.problem = problem
        shell = problem.shell
        compiled.prepare(len(shell.faces))   # a large shell's JIT kernels load beside the first evaluations
        self.X = shell.rest_positions.copy()
        self.n = shell.n_dofs
        self.terms = list(problem.energy_terms() if terms is None else terms)
        self.C, self.labels, self.g = problem.constraints(with_targets=True)
        self.m = self.C.shape[0]
        self.kkt = KKTSystem(self.C, backend, precision)
        self._CCt = spla.splu((self.C @ self.C.T).tocsc()) if self.m else None
        self.n_hessians = 0           # order-2 evaluations
        self.n_krylov = 0             # GMRES iterations of inexact Newton steps (one back-substitution each)
        self.last_krylov = 0          # GMRES iterations of the last inexact step
        self.floor = 0.0              # round-off level of |grad Pi| at the latest Hessian [N]
        self._lowrank = None          # the rank-one terms' Woodbury parts on the last factor
        self._ahead = None            # a next solve's right-hand sides and their iterates (factor)
        self.n_local = 0              # local corrections (local_step)
        # the term evaluated in a thread beside the others (EnergyTerm.concurrent), or None
        self.concurrent = None
        if len(self.terms) > 1 and shell.n_control >= CONCURRENT_MIN_VERTICES:
            self.concurrent = next((i for i, t in enumerate(self.terms)
                                    if getattr(t, "concurrent", None) is not None and t.concurrent()), None)
        # vertices in support rows of their own (not the dense surface-mean rows): never in a region
        self._held = np.zeros(problem.shell.n_control, bool)
        if self.m:
            Cc = self.C.tocsr()
            own = np.flatnonzero(np.diff(Cc.indptr) < problem.shell.n_control // 2)
            if len(own):
                self._held[np.unique(Cc[own].indices // 3)] = True

    @property
    def n_factorisations(self) -> int:
        """Tangent factorisations so far (the KKT system's count, robust retries included)."""
        return self.kkt.n_factor

    def close(self) -> None:
        self.kkt.close()

    # ---- energy and derivatives -------------------------------------------------------------
    def evaluate(self, u: np.ndarray, lam: float, order: int = 2, keep_terms: bool = False) -> State:
        """Pi, grad Pi, Hessian (order 2) and q at displacement u (3n,) and load factor lam: the
        sums over the terms, in their order (``keep_terms``: each term's part too, ``State.terms``)."""
        x = self.X + u.reshape(-1, 3)
        E = None
        grad = internal = None
        hessians: list = []
        rank_one: list = []
        q = np.zeros(self.n)
        parts = [] if keep_terms else None
        for t, v in zip(self.terms, self._values(x, lam, order, u)):
            if parts is not None:
                parts.append(v)
            E = v.value if E is None else E + v.value
            if order >= 1:
                grad = v.gradient if grad is None else grad + v.gradient
                if t.internal:
                    internal = grad
                load = t.load(x)
                if load is not None:
                    q = q + load
            if order == 2:
                if v.hessian is not None:
                    hessians.append(v.hessian)
                rank_one += v.rank_one
        H = rows = floor = None
        if order == 2:
            H, rows, floor = tangent_sum(hessians, x)
            self.floor = floor
        self.n_hessians += order == 2
        return State(float(E), grad, H, rank_one, q, internal, floor, rows=rows, terms=parts)

    def _values(self, x: np.ndarray, lam: float, order: int, u: np.ndarray) -> list:
        """Every term's TermValue, in the terms' order; the :attr:`concurrent` term's from a thread
        of its own while this one evaluates the others (its kernels release the GIL), joined before
        anything returns or raises.  The values and their sum in :meth:`evaluate` are the same to
        the bit either way: each term computes alone, and the sum keeps the terms' order."""
        c = self.concurrent
        if c is None:
            return [t.evaluate(x, lam, order, u) for t in self.terms]
        out: dict = {}

        def run():
            try:
                out["value"] = self.terms[c].evaluate(x, lam, order, u)
            except BaseException as exc:                 # (re-raised by the calling thread)
                out["error"] = exc

        worker = threading.Thread(target=run, name="graspdef-term", daemon=True)
        worker.start()
        try:
            vals = [None if i == c else t.evaluate(x, lam, order, u) for i, t in enumerate(self.terms)]
        finally:
            worker.join()
        if "error" in out:
            raise out["error"]
        vals[c] = out["value"]
        return vals

    def commit(self, u: np.ndarray) -> None:
        """Tell the state-tracking terms (edge rotations) that ``u`` is converged."""
        x = self.X + u.reshape(-1, 3)
        for t in self.terms:
            t.commit(x)

    def records(self, u: np.ndarray) -> list[tuple[EnergyTerm, dict]]:
        """Each term with its numbers for the path record (terms with none left out)."""
        x = self.X + u.reshape(-1, 3)
        return [(t, r) for t in self.terms if (r := t.record(x))]

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
    def factor(self, state: State, inertia: bool = True,
               ahead: tuple[np.ndarray, np.ndarray] | None = None) -> int | None:
        """Factor the KKT matrix of the state's Hessian; returns the inertia excess (negative
        eigenvalues of H on the constraint null space; 0 = stable) or None (no inertia).
        ``inertia=False``: the caller will not report this factor's inertia (a Newton iterate far
        from equilibrium), so a single-precision factor's is neither certified nor returned (None).

        ``ahead`` = (rhs (n, j), g (m, j)): the right-hand sides of the caller's next :meth:`solve`
        on this factor, known now (the Newton step and load tangent on a factor that gives a
        stability): with a single factor whose inertia is certified, their refinement steps ride in
        the certificate's back-substitutions, and that solve starts from them (on the 10k ball two
        back-substitution calls fewer per point)."""
        self.kkt.factor(state.hessian, rows=state.rows)
        self._lowrank = None
        self._ahead = None
        V = c = start = None
        k = 0
        if state.rank_one:
            V = np.stack([v for _, v in state.rank_one], axis=1)             # (n, k)
            c = np.array([c for c, _ in state.rank_one])
            k = V.shape[1]
        deferred = self.kkt.single and not inertia
        if not deferred:
            # a single factor's inertia, or a double factor; the Woodbury vectors' first
            # refinement steps (and those of the solve ``ahead``) ride in the certificate's
            # back-substitutions
            along, g_along = V, None
            if ahead is not None and self.kkt.single:
                F, G = (np.asarray(a, float) for a in ahead)
                along = F if V is None else np.column_stack([V, F])
                g_along = G if V is None else np.column_stack([np.zeros((self.m, k)), G])
            made = self.kkt.n_factor
            _, start = self.kkt.certify_inertia_along(along, g_along)
            neg = self.kkt.negative_pivots(self.m)  # an unexpected inertia is checked once robustly
            if self.kkt.n_factor != made:           # refactorised: the iterates are another factor's
                start = None
            if start is not None and along is not V:
                self._ahead = (F, G, start[:, k:])
                start = start[:, :k] if V is not None else None
        else:
            neg = None
        if V is not None:
            if deferred:
                # no inertia asked of a single factor: W = A^-1 [V; 0] is solved with the next
                # solve's right-hand sides, in the same back-substitutions (:meth:`solve`)
                self._lowrank = (V, None, c)
                return None
            self._lowrank = self._woodbury(V, c, self.kkt.solve(V, exact=False, start=start)[0])
            S = self._lowrank[2]
            if neg is not None:
                # Haynsworth: neg(A + V C V^T) = neg(A) + neg(-S) - neg(-C^-1); negative c
                # (e.g. a force-controlled contact's condensed DOF) adds no negative pivot
                neg = neg + int((np.linalg.eigvalsh(-S) < 0).sum()) - int((c > 0).sum())
        return None if neg is None else neg - self.m

    def solve(self, rhs: np.ndarray, g: np.ndarray | None = None, rtol: float = 1e-8,
              exact: bool = False) -> np.ndarray:
        """Solve (H + sum c v v^T) du + C^T l = rhs, C du = g with the last factorisation;
        ``rhs`` (n,) or (n, k); ``rtol``: the largest relative residual accepted (a nearly singular
        tangent, at a critical point, needs a looser one for inverse iteration).  A single-precision
        factor's solve stops refining once its relative residual is ``rtol`` -- what a double
        factor's solve is accepted at, and all that a path's predictors and Newton steps need --
        unless ``exact`` (then it goes on to a double solve's backward error,
        :meth:`graspdef.solve.sparse.KKTSystem.solve`); a double factor's solve is the same either way.

        The Woodbury vectors W = A^-1 [V; 0] still due from a :meth:`factor` that gave no inertia
        are solved with ``rhs`` as one block (each column refined to its own tolerance, the vectors
        to the tighter of ``rtol`` and the 1e-8 they need): a block costs the back-substitutions of
        one column (graspdef.solve.sparse.KKTSystem.certify_inertia_along)."""
        if self._lowrank is not None and self._lowrank[1] is None:
            V, _, c = self._lowrank
            k = V.shape[1]
            R = np.asarray(rhs, float)
            G = np.zeros((self.m,) + R.shape[1:]) if g is None else np.asarray(g, float).reshape((self.m,) + R.shape[1:])
            X, _, _ = self.kkt.solve(np.column_stack([V, R.reshape(self.n, -1)]),
                                     np.column_stack([np.zeros((self.m, k)), G.reshape(self.m, -1)]),
                                     rtol=min(rtol, 1e-8), exact=exact)
            self._lowrank = self._woodbury(V, c, X[:, :k])
            du = X[:, k:].reshape(R.shape)
        else:
            start, self._ahead = self._ahead, None
            if start is not None:
                # the right-hand sides given to :meth:`factor` as ``ahead``: start from their iterates
                F, G, X = start
                R = np.asarray(rhs, float)
                GG = np.zeros((self.m,) + R.shape[1:]) if g is None else np.asarray(g, float)
                start = X.reshape((X.shape[0],) + R.shape[1:]) if (
                    R.shape == F.shape and GG.shape == G.shape and np.array_equal(R, F) and np.array_equal(GG, G)) else None
            du, _, _ = self.kkt.solve(rhs, g, rtol=rtol, exact=exact, start=start)
        if self._lowrank is not None:
            V, W, S = self._lowrank
            du = du - W @ np.linalg.solve(S, V.T @ du)
        if not exact and self.m and self.kkt.single:
            # an inexact solve meets the supports only to its tolerance: the least-squares
            # correction onto C du = g (what the Newton loop's feasibility test and the energy
            # line search assume; without it they were skipped, on the 10k ball one more factorisation)
            gg = np.zeros((self.m,) + du.shape[1:]) if g is None else np.asarray(g, float).reshape((self.m,) + du.shape[1:])
            du = du + self.C.T @ self._CCt.solve(gg - self.C @ du)
        if not np.all(np.isfinite(du)):
            raise SolverError("the tangent solve produced non-finite values")
        return du

    @staticmethod
    def _woodbury(V: np.ndarray, c: np.ndarray, W: np.ndarray) -> tuple:
        """(V, W, S) of the Woodbury identity for A + V diag(c) V^T, W = A^-1 [V; 0]."""
        return V, W, np.diag(1.0 / c) + V.T @ W                           # C^-1 + V^T A^-1 V

    def precondition(self, r: np.ndarray) -> np.ndarray:
        """The displacement part of the last factorisation's inverse applied to [r; 0] (one raw
        back-substitution, the rank-one parts by Woodbury): it maps into the null space of C and
        ignores the range of C^T."""
        if self._lowrank is not None and self._lowrank[1] is None:
            V, _, c = self._lowrank
            self._lowrank = self._woodbury(V, c, self.kkt.solve(V, exact=False)[0])
        du = self.kkt.back(r)
        if self._lowrank is not None:
            V, W, S = self._lowrank
            du = du - W @ np.linalg.solve(S, V.T @ du)
        return du

    # ---- local corrections ---------------------------------------------------------------------
    def local_region(self, residual: np.ndarray, rings: int, share: float = 0.99,
                     max_share: float = 0.25) -> Region | None:
        """The region of :meth:`local_step` for a residual (3n,): the fewest control vertices that
        hold ``share`` of its square, grown by ``rings`` edges of the control mesh, without the
        vertices of their own support rows; None when a term has no ``hessian_rows`` or the region
        would hold more than ``max_share`` of the control vertices (the residual is not local)."""
        if not all(hasattr(t, "hessian_rows") for t in self.terms):
            return None
        shell = self.problem.shell
        w = (np.asarray(residual, float).reshape(-1, 3) ** 2).sum(1)
        total = float(w.sum())
        if not np.isfinite(total) or total <= 0:
            return None
        order = np.argsort(-w, kind="stable")
        k = int(np.searchsorted(np.cumsum(w[order]), share * total)) + 1
        if k > max_share * shell.n_control:
            return None
        mask = vertex_rings(shell, order[:k], rings) & ~self._held
        if not mask.any() or mask.sum() > max_share * shell.n_control:
            return None
        return Region(shell, mask)

    def local_step(self, u: np.ndarray, lam: float, state: State, g: np.ndarray, region: Region,
                   rtol: float = 1e-8) -> np.ndarray | None:
        """A local correction and the last factorisation's step after it (the module docstring):
        d = d_R + A^-1 [-(grad + H_{:,R} d_R); g - C d_R] with H_RR d_R = -r_R (r = grad + C^T mu,
        the projected residual; the rank-one parts by the Woodbury identity, locally and in the
        product).  None if the local block is singular or the step not finite."""
        x = self.X + u.reshape(-1, 3)
        rows, rank_one = None, []
        for t in self.terms:
            M, r1 = t.hessian_rows(x, lam, region)
            rank_one += r1
            if M is not None:
                rows = M if rows is None else _add(rows, M)
        if rows is None:
            return None
        dofs = region.dofs
        r, _ = self.projected_residual(state.gradient)
        pat = region.view.block_pattern
        A = region.own_block(rows) if (same_array(rows.indices, pat.scalar_indices)
                                       and same_array(rows.indptr, pat.scalar_indptr)) else rows[:, dofs]
        B = np.column_stack([-r[dofs]] + [v[dofs] for _, v in rank_one])
        try:
            Y = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A").solve(B)
        except RuntimeError:                           # SuperLU: the block is exactly singular
            return None
        dR = Y[:, 0]
        if rank_one:
            V, W, S = self._woodbury(B[:, 1:], np.array([c for c, _ in rank_one]), Y[:, 1:])
            dR = dR - W @ np.linalg.solve(S, V.T @ dR)
        d = np.zeros(self.n)
        d[dofs] = dR
        g2 = state.gradient + rows.T @ dR
        for c, v in rank_one:
            g2 = g2 + (c * float(v[dofs] @ dR)) * v
        self.n_local += 1
        step = d + self.solve(-g2, (g - self.C @ d) if self.m else None, rtol=rtol)
        return step if np.all(np.isfinite(step)) else None

    def project(self, v: np.ndarray) -> np.ndarray:
        """v less its least-squares part in the range of C^T (the orthogonal projection onto the
        null space of C)."""
        return v - self.C.T @ self._CCt.solve(self.C @ v) if self.m else v

    def inexact_step(self, u: np.ndarray, lam: float, state: State, rhs: np.ndarray, du0: np.ndarray,
                     rtol: float, maxiter: int) -> np.ndarray | None:
        """The Newton step at (u, lam) by GMRES preconditioned by the last factorisation (that of an
        earlier tangent): du with A du + C^T l = rhs, C du = g, where A is the tangent at u and
        ``du0`` -- the last factorisation's solution of the same system -- already satisfies
        C du0 = g.  The correction d = du - du0 lies in the null space of C: with R the orthogonal
        projection onto it and P = :meth:`precondition` (which maps into it), GMRES on R A P y =
        R (rhs - A du0), d = P y, until the true projected residual |R (rhs - A du)| is at most
        ``rtol`` |R rhs| (the inexact Newton condition |F + J s| <= eta |F|, Eisenstat & Walker
        1996).  A v is the state's Hessian (with its rank-one parts) times v if ``state`` has one,
        else a forward difference of the gradient (``state.gradient`` at u), (grad(u + h v) -
        grad(u)) / h with h |v| = sqrt(eps) |X + u| (Jacobian-free Newton-Krylov, Knoll & Keyes
        2004: a gradient costs a fraction of a Hessian; its relative error, ~1e-7 on the ball, is
        far below any ``rtol`` used).  Returns du, or None when GMRES needs more than ``maxiter``
        iterations (the tangent is too far from the factorised one: factorise it).  The accuracy
        of this step only decides how fast Newton converges, never where: the convergence test
        is on the true residual."""
        H, r1 = state.hessian, state.rank_one
        size = np.sqrt(np.finfo(float).eps) * float(np.linalg.norm(self.X.ravel() + u))

        def tangent(d):
            if H is None:
                dn = float(np.linalg.norm(d))
                if dn == 0:
                    return np.zeros_like(d)
                h = size / dn
                y = (self.evaluate(u + h * d, lam, 1).gradient - state.gradient) / h
                if not np.all(np.isfinite(y)):             # e.g. across a barrier: no inexact step
                    raise FloatingPointError("non-finite tangent product")
                return y
            y = H @ d
            for c, v in r1:
                y = y + (c * float(v @ d)) * v
            return y

        try:
            b = self.project(rhs - tangent(du0))
            d, k, _, ok = gmres(lambda v: self.project(tangent(v)), b,
                                rtol * float(np.linalg.norm(self.project(rhs))), maxiter, self.precondition)
        except (FloatingPointError, np.linalg.LinAlgError):
            return None
        self.n_krylov += k
        self.last_krylov = k
        if not ok:
            return None
        du = du0 + self.project(d)                       # back onto C d = 0 exactly
        if not np.all(np.isfinite(du)):
            return None
        return du
