"""Sparse direct solution of the constrained equilibrium (KKT) system

    [K  C^T] [u]   [f]
    [C  0  ] [l] = [0]

K is symmetric positive semi-definite (rigid modes), C removes them, so the KKT matrix is
symmetric indefinite with exactly m negative eigenvalues when K is positive definite on the null
space of C.  Backends: MKL PARDISO through pypardiso (symmetric indefinite LDL^T with inertia; the
default, see README for the measurements) and SciPy's SuperLU (fallback, no inertia).
No regularisation is accepted: PARDISO may perturb tiny pivots of the zero constraint block during
the factorisation, but the solution is then refined iteratively and its residual in the
*unperturbed* system is checked; a wrong inertia (a mechanism) is reported as an error.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import SolverError, SupportError
from ..problem.problem import BACKENDS

log = logging.getLogger(__name__)


@dataclass
class KKTResult:
    """Solution of the KKT system.

    Attributes
    ----------
    u : (n,) displacements;  multipliers : (m,) constraint forces (Lagrange multipliers)
    backend : "pardiso" or "superlu";  n_negative : negative pivots (PARDISO) or None
    seconds_factor, seconds_solve : wall times;  residual : ||K u + C^T l - f|| / ||f||
    """

    u: np.ndarray
    multipliers: np.ndarray
    backend: str
    n_negative: int | None
    seconds_factor: float
    seconds_solve: float
    residual: float


def pardiso_available() -> bool:
    try:
        import pypardiso  # noqa: F401  (availability probe)
    except Exception:       # ImportError, or mkl_rt missing
        return False
    return True


def constraint_scale(K: sp.spmatrix) -> float:
    """Scale of C in the KKT matrix: the mean |diagonal| of K (balances the two blocks)."""
    d = np.abs(K.diagonal())
    return float(d[d > 0].mean()) if np.any(d > 0) else 1.0


def kkt_matrix(K: sp.spmatrix, C: sp.spmatrix) -> tuple[sp.csr_matrix, float]:
    """Full symmetric KKT matrix with C scaled to the size of K's diagonal; returns (A, scale)."""
    scale = constraint_scale(K)
    A = sp.bmat([[K, scale * C.T], [scale * C, None]], format="csr")
    return A, scale


def kkt_upper(K: sp.spmatrix, C: sp.spmatrix, scale: float) -> sp.csr_matrix:
    """Upper triangle of the KKT matrix with an explicit (zero) diagonal in the constraint block,
    as PARDISO's symmetric modes want it; built without forming the full matrix."""
    K = K.tocsr()
    n, m = K.shape[0], C.shape[0]
    rows = np.repeat(np.arange(n), np.diff(K.indptr))
    up = K.indices >= rows                                   # upper triangle of K, row by row
    Ct = (scale * C.T).tocsr()
    Ct.sort_indices()
    # row i of U: K's upper entries, then C^T's entries (columns n..n+m); then m zero diagonals
    cnt = np.bincount(rows[up], minlength=n) + np.diff(Ct.indptr)
    indptr = np.concatenate([[0], np.cumsum(np.concatenate([cnt, np.ones(m, np.int64)]))])
    indices = np.empty(indptr[-1], np.int64)
    data = np.empty(indptr[-1])
    ku = np.diff(np.concatenate([[0], np.cumsum(np.bincount(rows[up], minlength=n))]))
    start = indptr[:n]
    pos_k = start[rows[up]] + (np.arange(up.sum()) - np.repeat(np.cumsum(ku) - ku, ku))
    indices[pos_k] = K.indices[up]
    data[pos_k] = K.data[up]
    crow = np.repeat(np.arange(n), np.diff(Ct.indptr))
    pos_c = start[crow] + ku[crow] + (np.arange(Ct.nnz) - Ct.indptr[crow])
    indices[pos_c] = n + Ct.indices
    data[pos_c] = Ct.data
    indices[indptr[n:-1]] = n + np.arange(m)
    data[indptr[n:-1]] = 0.0
    return sp.csr_matrix((data, indices, indptr), shape=(n + m, n + m))


def _factor_pardiso(U: sp.csr_matrix):
    import pypardiso

    solver = pypardiso.PyPardisoSolver(mtype=-2)
    solver.set_iparm(1, 1)      # use the values below, not the defaults
    solver.set_iparm(2, 3)      # parallel METIS nested-dissection ordering
    solver.set_iparm(8, 2)      # up to two steps of iterative refinement
    solver.set_iparm(10, 8)     # pivot perturbation 1e-8 (then refined; the true residual is checked)
    solver.set_iparm(11, 1)     # symmetric scaling
    solver.set_iparm(13, 2)     # weighted matching, improved variant (saddle-point systems)
    solver.set_iparm(21, 1)     # Bunch-Kaufman pivoting
    # call the phases directly: pypardiso's factorize()/solve() copy and compare the matrix
    solver._check_A(U)
    z = np.zeros((U.shape[0], 1))
    solver.set_phase(11)                                    # analysis (matching, ordering)
    solver._call_pardiso(U, z)
    solver.set_phase(22)                                    # numerical factorisation
    solver._call_pardiso(U, z)
    perturbed = int(solver.get_iparm(14))
    n_neg = int(solver.get_iparm(23))
    return solver, U, perturbed, n_neg


def solve_kkt(K: sp.spmatrix, C: sp.spmatrix, f: np.ndarray, backend: str = "auto",
              rtol: float = 1e-8, refinements: int = 3) -> KKTResult:
    """Solve the KKT system; raise SupportError/SolverError on singular or unbalanced systems."""
    if backend not in BACKENDS:
        raise SolverError(f"unknown linear solver backend '{backend}' (valid: {', '.join(BACKENDS)})")
    if backend == "auto":
        backend = "pardiso" if pardiso_available() else "superlu"
    n, m = K.shape[0], C.shape[0]
    K = K.tocsr()
    C = C.tocsr()
    scale = constraint_scale(K)
    rhs = np.concatenate([f, np.zeros(m)])
    t0 = time.perf_counter()
    n_neg = None
    if backend == "pardiso":
        solver, U, perturbed, n_neg = _factor_pardiso(kkt_upper(K, C, scale))
        t1 = time.perf_counter()
        if n_neg != m:
            raise SupportError(
                f"the constrained stiffness is singular or indefinite: the KKT matrix has {n_neg} negative "
                f"pivots for {m} constraints (expected {m}; {perturbed} pivots perturbed). A mechanism is "
                "free (a part without supports, or redundant/conflicting supports).")
        log.info("PARDISO: %d perturbed pivots (removed by iterative refinement; residual checked)", perturbed)
        solver.set_phase(33)                                # solve with iterative refinement
        back = lambda b: solver._call_pardiso(U, np.asfortranarray(b)).ravel()  # noqa: E731
    else:
        A, _ = kkt_matrix(K, C)
        try:
            lu = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A")
        except RuntimeError as exc:
            raise SupportError(f"the constrained stiffness is singular ({exc}): a mechanism is free") from exc
        t1 = time.perf_counter()
        back = lu.solve

    def residual(x: np.ndarray) -> np.ndarray:
        return np.concatenate([K @ x[:n] + scale * (C.T @ x[n:]), scale * (C @ x[:n])]) - rhs

    fn = max(np.linalg.norm(f), 1e-300)
    try:
        sol = back(rhs)
        res = residual(sol)
        for _ in range(refinements):                        # a few more steps on ill-conditioned systems
            if not np.all(np.isfinite(sol)) or np.linalg.norm(res) <= 0.01 * rtol * fn:
                break
            sol = sol - back(res)
            res = residual(sol)
    finally:
        if backend == "pardiso":
            solver.free_memory(everything=True)
    t2 = time.perf_counter()
    if not np.all(np.isfinite(sol)):
        raise SolverError("the linear solve produced non-finite values (singular system)")
    u, lam = sol[:n], sol[n:]
    rel = float(np.linalg.norm(res) / fn)
    if rel > rtol:
        raise SolverError(f"linear solve residual {rel:.2e} exceeds {rtol:.0e} (ill-conditioned or singular)")
    log.info("KKT %s: n=%d m=%d factor %.3fs solve %.3fs residual %.1e", backend, n, m, t1 - t0, t2 - t1, rel)
    return KKTResult(u, scale * lam, backend, n_neg, t1 - t0, t2 - t1, rel)
