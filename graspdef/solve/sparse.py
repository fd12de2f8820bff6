"""Sparse direct solution of the constrained equilibrium (KKT) system

    [K  C^T] [u]   [f]
    [C  0  ] [l] = [0]

K is symmetric positive semi-definite (rigid modes), C removes them, so the KKT matrix is
symmetric indefinite with exactly m negative eigenvalues when K is positive definite on the null
space of C.  Backends: MKL PARDISO through pypardiso (symmetric indefinite LDL^T with inertia; the
default, see README for the measurements) and SciPy's SuperLU (fallback, no inertia).  Backend
"pardiso-ooc" is PARDISO out of core, in a worker process of its own (graspdef.solve.pardiso_ooc:
MKL's out-of-core mode corrupts the memory of the process it runs in, at random): the factor is
written to files in a temporary folder (removed when the system is closed) and only
:data:`OOC_CORE_MB` of it is held in memory at a time -- for
problems whose in-core factor does not fit (the 100k pinched cylinder's is 2.8 GB in double, 1.1 GB
in single precision).  ``precision`` "mixed" (:class:`KKTSystem`): a single-precision factor whose
solves are refined in double to a double solve's backward error.
No regularisation is accepted: PARDISO may perturb tiny pivots of the zero constraint block during
the factorisation, but the solution is then refined iteratively and its residual in the
*unperturbed* system is checked; a wrong inertia (a mechanism) is reported as an error.
"""
from __future__ import annotations

import contextlib
import logging
import math
import os
import shutil
import tempfile
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import SolverError, SupportError
from ..problem.problem import BACKENDS, PRECISIONS
from ..runtime import locate_mkl_rt
from . import pardiso
from .pardiso import new_solver as _new_pardiso
from .pardiso_ooc import OOCPardiso

log = logging.getLogger(__name__)


@dataclass
class KKTResult:
    """Solution of the KKT system.

    Attributes
    ----------
    u : (n,) displacements;  multipliers : (m,) constraint forces (Lagrange multipliers)
    backend : "pardiso", "pardiso-ooc" or "superlu";  n_negative : negative pivots (PARDISO) or None
    seconds_factor, seconds_solve : wall times;  residual : ||K u + C^T l - f|| / ||f||
    precision : "mixed" (a single-precision factor, refined in double) or "double"
    """

    u: np.ndarray
    multipliers: np.ndarray
    backend: str
    n_negative: int | None
    seconds_factor: float
    seconds_solve: float
    residual: float
    precision: str = "double"


def pardiso_available() -> bool:
    locate_mkl_rt()         # else pypardiso's import searches sys.prefix for MKL (its module-level solver)
    try:
        import pypardiso  # noqa: F401  (availability probe)
    except Exception:       # ImportError, or mkl_rt missing
        return False
    return True


def _cnr_threads(solver) -> int:
    """PARDISO's conditional numerical reproducibility (iparm 34 > 0: the number of OpenMP threads
    its factorisation uses, here MKL's own count): the same matrix then gives the same factor and
    the same solutions to the bit in every call and every process with that thread count.  Without
    it neither the parallel factorisation nor the parallel back-substitution is reproducible: on 2
    cores one 10k-ball tangent factorised 6 times gave two different factors at random (single and
    double precision alike), 10 back-substitutions with one factor two different solutions, and a
    path through snaps (the 192 x 96 pinched cylinder) took 230 and 519 factorisations in two runs
    of the same code.  Cost measured 2026-11-28 on that tangent (30,732 unknowns): a factorisation
    0.207 -> 0.229 s single, 0.296 -> 0.312 s double; a back-substitution 5.0 -> 10.7 ms (it runs on
    one thread; PARDISO's parallel-solve settings, iparm 25, change nothing); the sequential ordering
    that the mode needs (iparm 2 = 2) 0.67 -> 0.79 s once per sparsity pattern."""
    try:
        return max(1, int(solver.libmkl.MKL_Get_Max_Threads()))
    except (AttributeError, OSError):             # an MKL without the service function: one thread
        return 1


def _kernel_indices(A: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray]:
    """A's index arrays as the sparse kernels take them: contiguous, both int32 (the ahead-of-time
    build's type, as scipy keeps them) or both int64."""
    ip, ix = A.indptr, A.indices
    if ip.dtype != ix.dtype or ip.dtype not in (np.int32, np.int64):
        ip, ix = ip.astype(np.int64), ix.astype(np.int64)
    return np.ascontiguousarray(ip), np.ascontiguousarray(ix)


@dataclass(frozen=True)
class RowSummary:
    """Per-row numbers of a matrix K that its KKT factorisation needs (:meth:`KKTSystem.factor`:
    the constraint scale and the norm), made where K is summed (:func:`row_summary`) instead of in
    passes of their own: ``abs_sums`` sum_j |K_ij| (as :func:`_abs_row_sums`, to the bit) and
    ``diagonal`` (as ``K.diagonal()``)."""

    abs_sums: np.ndarray
    diagonal: np.ndarray


def row_summary(A: sp.csr_matrix, B: sp.csr_matrix | None = None,
                x: np.ndarray | None = None) -> tuple[sp.csr_matrix, RowSummary, np.ndarray]:
    """H = A (+ B, a CSR matrix on A's own index arrays) with its :class:`RowSummary` and the sums
    sq_i = sum_j H_ij^2 x_j^2 (``x`` flattened; zeros without it), in one parallel pass over H
    (:func:`graspdef.solve._kernels.row_sums`) where numpy and scipy took six (the sum, |H|, its row
    sums, the diagonal, H o H and its product; on the 10k ball's tangents, 3.4 M entries, ~37 ms
    per tangent in the path).  Every number equals what those passes give, to the bit (the row sums
    as numpy's ``add.reduceat`` sums: the kernel's pairwise order, rows of more than 129 entries by
    numpy itself; the products in scipy's order).  H shares A's index arrays and keeps its
    canonical-format flag."""
    from ._kernels import row_sums

    n = A.shape[0]
    ip, ix = _kernel_indices(A)
    a = np.ascontiguousarray(A.data, float)
    b = np.zeros(0) if B is None else np.ascontiguousarray(B.data, float)
    out = np.empty_like(a) if B is not None else np.zeros(0)
    xf = None if x is None else np.asarray(x, float).ravel()
    x2 = np.zeros(n) if xf is None else np.ascontiguousarray(xf * xf)
    abs_sums, sq, diag = np.empty(n), np.empty(n), np.empty(n)
    row_sums(ip, ix, a, b, out, x2, abs_sums, sq, diag)
    data = a if B is None else out
    long_rows = np.flatnonzero(abs_sums < 0)          # numpy's own recursive pairwise sums
    for i in long_rows:
        abs_sums[i] = np.add.reduceat(np.abs(data[ip[i]:ip[i + 1]]), [0])[0]
    H = A if B is None else sp.csr_matrix((out, A.indices, A.indptr), shape=A.shape)
    if B is not None and A.has_canonical_format:          # the same structure as A
        H.has_canonical_format = True
    return H, RowSummary(abs_sums, diag), sq


def csr_product(A: sp.csr_matrix, x: np.ndarray) -> np.ndarray:
    """A x for a CSR matrix A and one column (n,) or a block (n, k), on both cores
    (:func:`graspdef.solve._kernels.csr_products`): scipy's numbers to the bit (each entry summed in
    index order), A read once per block.  On the 10k ball's tangent (3.4 M entries) one column takes
    2.8 ms where scipy's takes 4.3 when A is not in cache -- as between a path's back-substitutions,
    which read the 82 MB factor -- and the same 1.8 ms when it is.  A matrix whose product would run
    serially (graspdef.compiled.SERIAL_MAX) is multiplied by scipy, one column at a time (the
    kernel's call cost more than the product: 224 against 100 us at 1,926 rows)."""
    from ._kernels import csr_products

    if csr_products.serial(A.shape[0]):
        if np.ndim(x) == 1:
            return A @ x
        return np.column_stack([A @ x[:, j] for j in range(x.shape[1])]).reshape(np.shape(x))
    ip, ix = _kernel_indices(A)
    X = np.ascontiguousarray(np.asarray(x, float).reshape(A.shape[1], -1))
    Y = np.empty((A.shape[0], X.shape[1]))
    csr_products(ip, ix, np.ascontiguousarray(A.data, float), X, Y)
    return Y.reshape((A.shape[0],) + np.shape(x)[1:])


def constraint_scale(K: sp.spmatrix, rows: RowSummary | None = None) -> float:
    """Scale of C in the KKT matrix: the mean |diagonal| of K (balances the two blocks)."""
    d = np.abs(K.diagonal() if rows is None else rows.diagonal)
    return float(d[d > 0].mean()) if np.any(d > 0) else 1.0


def kkt_matrix(K: sp.spmatrix, C: sp.spmatrix) -> tuple[sp.csr_matrix, float]:
    """Full symmetric KKT matrix with C scaled to the size of K's diagonal; returns (A, scale)."""
    scale = constraint_scale(K)
    A = sp.bmat([[K, scale * C.T], [scale * C, None]], format="csr")
    return A, scale


def same_array(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two arrays are views of the same memory with the same layout (hence equal); the
    cheap test that two sparse matrices share their index arrays."""
    return a is b or (a.shape == b.shape and a.dtype == b.dtype and a.strides == b.strides
                      and a.ctypes.data == b.ctypes.data)


class _UpperMap:
    """Where K's upper-triangle entries and C^T's entries go in :func:`kkt_upper`'s matrix, for
    one sparsity pattern of K: later matrices on the same pattern (Newton iterations) only
    gather their values.  The pattern is built by a compiled kernel
    (:func:`graspdef.solve._kernels.kkt_upper_pattern`: 10k pinched cylinder, 3.3 M non-zeros of
    K, 0.25 s in numpy before)."""

    def __init__(self, K: sp.csr_matrix, C: sp.spmatrix):
        from graspdef.solve._kernels import kkt_upper_pattern

        self.indptr, self.indices = K.indptr, K.indices
        n, m = K.shape[0], C.shape[0]
        Ct = C.T.tocsr()
        Ct.sort_indices()
        self.shape = (n + m, n + m)
        indptr, indices, self.src = kkt_upper_pattern(
            K.indptr.astype(np.int64, copy=False), K.indices.astype(np.int64, copy=False),
            Ct.indptr.astype(np.int64, copy=False), Ct.indices.astype(np.int64, copy=False), n, m)
        if indices.size >= 2**31:
            raise SolverError(f"the KKT matrix has {indices.size:,} non-zeros in its upper triangle: beyond "
                              "PARDISO's 32-bit interface (2^31)")
        if not np.diff(indptr).all():
            raise SolverError("the KKT matrix has an empty row: the stiffness is singular (a degree of "
                              "freedom without stiffness)")
        # 32-bit and zero-based, as PARDISO reads them (iparm 35 = 1): passed without a copy per call
        self.U_indptr, self.U_indices = indptr.astype(np.int32), indices.astype(np.int32)
        self.ct_data = np.asarray(Ct.data, float)

    def matches(self, K: sp.csr_matrix) -> bool:
        return (same_array(K.indptr, self.indptr) and same_array(K.indices, self.indices)) or (
            K.nnz == self.indices.size and np.array_equal(K.indptr, self.indptr)
            and np.array_equal(K.indices, self.indices))

    def upper(self, K: sp.csr_matrix, scale: float, dtype=np.float64) -> sp.csr_matrix:
        from graspdef.solve._kernels import kkt_upper_values

        data = kkt_upper_values(self.src, np.asarray(K.data, float), self.ct_data, float(scale))
        if dtype != np.float64:
            data = data.astype(dtype)
        return sp.csr_matrix((data, self.U_indices, self.U_indptr), shape=self.shape, copy=False)


def kkt_upper(K: sp.spmatrix, C: sp.spmatrix, scale: float) -> sp.csr_matrix:
    """Upper triangle of the KKT matrix with an explicit (zero) diagonal in the constraint block,
    as PARDISO's symmetric modes want it; built without forming the full matrix."""
    K = K.tocsr()
    return _UpperMap(K, C).upper(K, scale)


class KKTSystem:
    """Factorisations of KKT matrices [[K, s C^T], [s C, 0]] for one constraint matrix C.

    Repeated factorisations (Newton iterations) reuse PARDISO's analysis (ordering, matching)
    while K's sparsity pattern is unchanged; every solution is refined and its residual in the
    unperturbed system checked.  ``n_negative`` is the number of negative pivots of the last
    factorisation (PARDISO) -- the inertia that decides stability -- or None (SuperLU).
    Use as a context manager or call :meth:`close` to free PARDISO's memory.

    ``precision`` "mixed" (in-core PARDISO only; see :data:`PRECISIONS`; "auto": mixed from
    :data:`MIXED_MIN_UNKNOWNS` unknowns on): the factor is computed in
    single precision -- half the memory and ~0.6 x the time of the double one -- and every solve
    is refined with residuals in double down to :data:`MIXED_FLOOR` (or until a step no longer
    halves its backward error) and accepted at :data:`MIXED_BACKWARD_TOL`; when a check fails (a
    solve that does not refine to it, or an inertia other than the expected one) the system
    refactors in double and goes on as "double".
    ``single`` says whether the last factor is a single-precision one.
    """

    def __init__(self, C: sp.spmatrix, backend: str = "auto", precision: str = "double"):
        if backend not in BACKENDS:
            raise SolverError(f"unknown linear solver backend '{backend}' (valid: {', '.join(BACKENDS)})")
        if precision not in PRECISIONS:
            raise SolverError(f"unknown factorisation precision '{precision}' (valid: {', '.join(PRECISIONS)})")
        if backend == "auto":
            backend = "pardiso" if pardiso_available() else "superlu"
        if backend == "pardiso-ooc" and not pardiso_available():
            raise SolverError("backend 'pardiso-ooc' needs PARDISO (pypardiso with MKL), which is not available here")
        self.backend = backend
        self._pardiso = backend in ("pardiso", "pardiso-ooc")
        # mixed: PARDISO factorises in single precision (in core only), every solve is refined in
        # double until its backward error is a double solve's; a failed check refactors in double
        # ("auto": mixed from MIXED_MIN_UNKNOWNS unknowns on, decided at the first factorisation)
        self.precision = precision
        self.single = precision in ("mixed", "auto") and backend == "pardiso"
        self._ooc_dir: str | None = None  # pardiso-ooc: the folder of PARDISO's factor files
        self.ooc_core_mb = OOC_CORE_MB    # pardiso-ooc: the factor's part held in memory [MB]
        self.C = C.tocsr()
        self.m = self.C.shape[0]
        self._solver = None
        self._map: _UpperMap | None = None                 # K's pattern, analysed by PARDISO
        self._lu = None
        self.n_negative: int | None = None
        self.perturbed = 0
        self.variant = 0                  # PARDISO settings in use: 0 the defaults, k the k-th of _PARDISO_FALLBACKS
        self._tried: set[int] = set()     # variants tried on the current matrix (see retry_robust)
        self.scale = 1.0
        self.seconds_factor = 0.0
        self.seconds_solve = 0.0
        self.norm = 0.0                   # infinity norm of the last factorised KKT matrix
        self.n_back = 0                   # back-substitutions (each right-hand side counted)
        self.n_back_calls = 0             # back-substitution calls (a block of right-hand sides is one)
        self.n_factor = 0                 # numerical factorisations (robust retries included)
        self.certificates = 0             # inertia certificates of single-precision factors (certify_inertia)
        self.n_single = 0                 # of the factorisations, single-precision ones

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        if self._solver is not None:
            self._solver.free_memory(everything=True)     # out of core: its worker process ends
            self._solver = None
            self._map = None                                # a new solver needs a new analysis
        if self._ooc_dir is not None:
            shutil.rmtree(self._ooc_dir, ignore_errors=True)
            self._ooc_dir = None

    def _ooc_env(self) -> dict[str, str]:
        """pardiso-ooc: MKL's out-of-core settings, which it reads from the environment of the worker
        process (graspdef.solve.pardiso_ooc) at every call: the factor files' folder, the factor's
        part held in memory [MB], and no files kept.

        The folder is given **without a trailing separator**: MKL 2026.2 appends "/mkl_pardiso" to
        the path itself, and for a path that ends in "/" its configuration reader
        (``mkl_pds_lp64_pardiso_ooc_read_cfg_file``, in ``mkl_serv_sprintf_s``) writes one byte past
        a heap buffer -- found with valgrind's memcheck (an "Invalid write of size 1", 7 bytes after
        a 56-byte block) on a 900-unknown system; with the path "/tmp/x/" the same, with
        "/tmp/x" or any path without the final "/" none."""
        return {"MKL_PARDISO_OOC_PATH": ooc_path(self._ooc_dir),
                "MKL_PARDISO_OOC_MAX_CORE_SIZE": str(self.ooc_core_mb),
                "MKL_PARDISO_OOC_KEEP_FILE": "0"}

    def factor(self, K: sp.spmatrix, analyse: bool = False, rows: RowSummary | None = None) -> None:
        """Factor the KKT matrix of ``K``; ``analyse`` forces a fresh ordering/matching; ``rows``:
        K's :class:`RowSummary`, if made with K (else computed here).  A
        factorisation that fails a check is redone by :meth:`retry_robust` (the callers' and
        :meth:`solve`'s second chance)."""
        t0 = time.perf_counter()
        self._tried = {self.variant}
        self.K = K.tocsr()
        self.n = self.K.shape[0]
        self.scale = constraint_scale(self.K, rows)
        self.norm = kkt_norm(self.K, self.C, self.scale, rows)
        if self.precision == "auto" and self.n_factor == 0:
            self.single = self.single and self.n + self.m >= MIXED_MIN_UNKNOWNS
        if self._pardiso:
            self._factor_pardiso(analyse)
        else:
            A, _ = kkt_matrix(self.K, self.C)
            try:
                self._lu = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A")
                self.n_factor += 1
            except RuntimeError as exc:
                raise SupportError(f"the constrained stiffness is singular ({exc}): a mechanism is free") from exc
            self.n_negative = None
        self.seconds_factor += time.perf_counter() - t0

    def _factor_pardiso(self, analyse: bool) -> None:
        K = self.K
        if not K.has_sorted_indices:
            K = K.sorted_indices()
        new_pattern = self._map is None or not self._map.matches(K)
        upper_map = _UpperMap(K, self.C) if new_pattern else self._map
        # single precision (iparm 28 = 1): PARDISO reads the values and right-hand sides as float32
        dtype = np.float32 if self.single else np.float64
        U = upper_map.upper(K, self.scale, dtype)
        if self.backend == "pardiso-ooc" and self._solver is not None and new_pattern:
            # out of core a second analysis is a fresh worker's (graspdef.solve.pardiso_ooc; a second
            # analysis on one handle crashed the process): a pattern inside the analysed one -- a
            # Newton tangent with an exact zero more -- is factorised on it (its missing entries zero)
            inside = self._on_analysed_pattern(K)
            if inside is not None:
                K, upper_map, new_pattern = inside, self._map, False
                U = upper_map.upper(K, self.scale, dtype)
            else:
                self._solver.free_memory(everything=True)
                self._solver = None
        if self._solver is None:
            ooc = self.backend == "pardiso-ooc"
            if ooc and self._ooc_dir is None:
                self._ooc_dir = ooc_folder()
            # out of core: a worker process on MKL's sequential layer (one thread)
            solver = OOCPardiso(-2) if ooc else _new_pardiso(-2)
            self._solver = solver
            for k, v in {**_PARDISO_IPARM, **self._variant_iparm(), **({60: 2} if ooc else {}), 28: int(self.single),
                         34: 1 if ooc else _cnr_threads(solver)}.items():
                self._solver.set_iparm(k, v)
        s = self._solver
        self._U = U
        z = np.zeros((U.shape[0], 1), dtype)
        try:
            if analyse or new_pattern:
                self._call(11, z)                       # analysis (matching, ordering)
                self._map = upper_map                   # kept once PARDISO has analysed it
                if self._ooc_dir is not None:
                    self._fit_ooc_core(int(s.get_iparm(61)))
            self._call(22, z)                           # numerical factorisation
        except Exception as exc:
            if self._ooc_dir is None or getattr(exc, "value", None) != -9:
                raise
            # -9: the in-memory part allowed is below what PARDISO's out-of-core mode needs for this
            # matrix although its analysis said otherwise (_fit_ooc_core; not seen since 2026-11-27)
            raise SolverError(f"PARDISO out of core: {self.ooc_core_mb} MB in memory were too few for this "
                              "matrix's factorisation (error -9) although its analysis asked for no more; "
                              "raise graspdef.solve.sparse.OOC_CORE_MB and run again") from None
        self.n_factor += 1
        self.n_single += self.single
        self.perturbed = int(s.get_iparm(14))
        self.n_negative = int(s.get_iparm(23))

    def _on_analysed_pattern(self, K: sp.csr_matrix) -> sp.csr_matrix | None:
        """pardiso-ooc: ``K`` on the analysed pattern (its entries there, explicit zeros elsewhere),
        or None if K has an entry outside it."""
        a = self._map
        ref = sp.csr_matrix((np.zeros(a.indices.size), a.indices, a.indptr), shape=K.shape)
        union = union_sum(K, ref)
        if not a.matches(union):
            log.info("PARDISO out of core: the pattern changed (%d analysed non-zeros, %d now): a fresh worker "
                     "analyses it", a.indices.size, union.nnz)
            return None
        return union

    def _fit_ooc_core(self, need_kb: int) -> None:
        """pardiso-ooc, after an analysis: raise the factor's part held in memory to what PARDISO's
        out-of-core factorisation needs for this matrix, as its analysis reports it (iparm 61, in KB)
        with OOC_CORE_MARGIN, so that the factorisation does not fail with error -9.  Measured, the
        least size that factorises (in MB) is that number rounded up: 40 x 40 plate 12,465 KB, 12 MB
        fails, 13 MB factorises; the 10k pinched cylinder 68,840 KB, 67 MB fails, 68 MB factorises
        (iparm 62, 9,429 and 43,260 KB, is not it).  Before 2026-11-27 the error itself was the
        signal: the system was closed, the memory doubled and the matrix analysed again -- and a
        solver re-created after that failure came out wrong in 3 of 260 processes (a solution 1 %
        off SuperLU's at a residual of 1e-12, a solve failing its check, a process ending without
        output), against 0 of 120 without the failure (docs/speed.md, "Out of core")."""
        need_mb = math.ceil(need_kb * OOC_CORE_MARGIN / 1024)
        if need_kb <= 0 or self.ooc_core_mb >= need_mb:
            return
        have = _available_mb()
        if have is not None and need_mb > have:
            raise SolverError(f"PARDISO out of core needs {need_mb} MB of memory for this matrix and {have} MB "
                              "are free: the problem is too large for this machine")
        log.info("PARDISO out of core: %d MB in memory (PARDISO's minimum for this matrix: %d KB)", need_mb, need_kb)
        self.ooc_core_mb = need_mb

    @property
    def robust(self) -> bool:
        """Whether PARDISO runs with settings other than the defaults (a fallback, see
        :meth:`retry_robust`)."""
        return self.variant != 0

    def _variant_iparm(self) -> dict:
        return dict(_PARDISO_FALLBACKS[self.variant - 1]) if self.variant else {}

    def negative_pivots(self, expected: int) -> int | None:
        """The last factorisation's number of negative pivots; when it is not ``expected``, after a
        refactorisation in double precision if the factor was a single one, and when the default
        settings are in use, after one refactorisation with the first fallback settings
        (:meth:`retry_robust`; an unstable state is so confirmed once per system, not at every
        unstable point of a path).  None: no inertia (SuperLU)."""
        if self.n_negative is not None and self.n_negative != expected and self.single:
            self.retry_robust()                         # a single factor's inertia is confirmed in double first
        if self.n_negative is not None and self.n_negative != expected and not self.robust and self.retry_robust():
            log.info("KKT: %d negative pivots for %d expected with the robust settings", self.n_negative, expected)
        return self.n_negative

    def certify_inertia(self) -> bool:
        """Whether a single-precision factor's inertia is the matrix's; a factor that cannot show
        it is replaced by a double one (False is then returned; ``n_negative`` is the double
        factor's).  Nothing to do for a double factor (True).  See :meth:`certify_inertia_along`."""
        return self.certify_inertia_along(None)[0]

    def certify_inertia_along(self, along: np.ndarray | None,
                              g: np.ndarray | None = None) -> tuple[bool, np.ndarray | None]:
        """:meth:`certify_inertia`, returning (its answer, start): ``start`` is None unless
        ``along`` is given (see below) and the factor was kept.

        With M the single factor's matrix and A the KKT matrix, G = I - M^-1 A: if A and M had
        different inertias, M + t (A - M) = M (I - t G) would be singular for some t in (0, 1], so
        G would have a real eigenvalue mu = 1/t >= 1.  The certificate is the homogeneous
        iteration y <- G y = y - M^-1 (A y) (A in double, M^-1 a single back-substitution) from a
        fixed pseudo-random y_0 ~ N(0, I): with u a unit left eigenvector of such an eigenvalue,
        u.y_k = mu^k u.y_0, so |y_k| >= |u.y_0|: |y_k| can fall to c = :data:`CERTIFICATE_MISS`
        sqrt(pi / 2) only if |u.y_0|, a standard normal, is below c, which has the probability
        erf(c / sqrt(2)) < c sqrt(2 / pi) = CERTIFICATE_MISS (1e-7) for any number of unknowns N
        (|y_0| ~ sqrt(N): a reduction of |y| by ~1.25e-7 / sqrt(N); until 2026-12-07 by 1e-10 at every N,
        the bound at a million unknowns, which on the 10k ball, 30,732 unknowns, asked 7 of its 9
        certificates for a third step).  The iteration is
        required to reach that within :data:`MIXED_REFINEMENTS` steps, each at least halving |y|.
        It watches the error, not the residual: near a critical point the matrix has an eigenvalue
        far below single precision's rounding of it, where a residual shows nothing (one of 1e-12
        of the largest: the residual test passed on a factor whose inertia was a coin toss) but
        G's eigenvalue is ~1 and |y| stalls; that factor is then replaced by a double one.
        Costs 2 back-substitutions and products on the 10k ball's tangents (|y| shrinks by ~1e-5 per
        step, to 0.8-3.0e-10 |y_0| after two, against 7.2e-10 asked).

        ``along`` (n,) or (n, k), ``g`` (m,) or (m, k) (zero if None): right-hand sides [f; g] of the
        KKT system whose plain refinement steps x <- x - M^-1 (A x - [f; g]) from x = 0 ride in the
        certificate's back-substitutions
        (one call of several columns: PARDISO's back-substitution reads the factor once per call,
        and on the 10k ball's tangent, 30,732 unknowns, one column took 12.4 ms, two 14.3 and four
        14.1); ``start`` is then their iterates, (n + m,) or (n + m, k), a start for :meth:`solve`
        (the Woodbury vectors of a rank-one part and the Newton step and load tangent on a factor
        that gives a stability: graspdef.solve.equilibrium.Equilibrium.factor)."""
        if not self.single or not self._pardiso:
            return True, None
        N = self.n + self.m
        y = np.random.default_rng(CERTIFICATE_SEED).standard_normal(N)
        size0 = size = float(np.linalg.norm(y))
        B = X = None
        if along is not None:
            f = np.asarray(along, float)
            k = f.size // self.n
            G = np.zeros((self.m, k)) if g is None else np.asarray(g, float).reshape(self.m, k)
            B = np.concatenate([f.reshape(self.n, -1), self.scale * G])
            X = np.zeros_like(B)
        ok = False
        for k in range(MIXED_REFINEMENTS):
            if B is None:
                y = y - self._back(self._apply(y))
            else:
                AY = self._apply(np.column_stack([y, X]))      # one pass over K for the block
                AY[:, 1:] -= B
                Z = self._back(AY)
                y, X = y - Z[:, 0], X - Z[:, 1:]
            new = float(np.linalg.norm(y))
            if not np.isfinite(new) or not new <= 0.5 * size:
                break
            size = new
            if size <= CERTIFICATE_MISS * math.sqrt(math.pi / 2):
                ok = True
                break
        self.certificates += 1
        log.debug("KKT certificate: %s, |y| reduced to %.1e in %d steps", ok, size / size0, k + 1)
        if ok:
            return True, None if X is None else X.reshape((N,) + np.shape(along)[1:])
        log.info("KKT: the single-precision factor's error operator contracts to %.1e only: its inertia "
                 "is not certain, refactoring in double", size / size0)
        self.retry_robust()
        return False, None

    def _apply(self, x: np.ndarray) -> np.ndarray:
        """The (scaled) KKT matrix of the last factorisation times x (one column or a block), in double."""
        n, s = self.n, self.scale
        Kx = csr_product(self.K, x[:n])                # both cores, K read once per block
        return np.concatenate([Kx + s * (self.C.T @ x[n:]), s * (self.C @ x[:n])])

    def retry_robust(self) -> bool:
        """Refactor the last matrix with the next PARDISO settings not yet tried on it -- the
        defaults and each of :data:`_PARDISO_FALLBACKS`, in turn from the ones in use -- and keep
        them for the next factorisations; returns whether it did (False: every variant has been
        tried on this matrix).  The callers' second (and third) chance when an inertia or a solve
        check fails.  Every variant is tried, the defaults included, because no one of them is
        backward-stable on every matrix: on a quarter half-can's path (scripts/can_half_study.py)
        the standard matching, switched to at one point, solved a later tangent to a residual of
        1e-2 that the defaults solve to 3e-12."""
        if not self._pardiso or self._solver is None:
            return False
        if self.single:
            # a single-precision factor failed a check: the same settings in double precision first
            t0 = time.perf_counter()
            log.info("KKT: refactoring in double precision after the single-precision factor failed a check")
            self.single = False
            self._solver.free_memory(everything=True)
            self._solver = None
            self._factor_pardiso(True)
            self.seconds_factor += time.perf_counter() - t0
            return True
        n_var = 1 + len(_PARDISO_FALLBACKS)
        nxt = next(((self.variant + k) % n_var for k in range(1, n_var) if (self.variant + k) % n_var not in self._tried), None)
        if nxt is None:
            return False
        t0 = time.perf_counter()
        log.info("KKT: refactoring with PARDISO settings %s after a failed check", _PARDISO_FALLBACKS[nxt - 1] if nxt else "(defaults)")
        self._tried.add(nxt)
        self.variant = nxt
        self._solver.free_memory(everything=True)          # a fresh solver: every iparm from the variant
        self._solver = None
        self._factor_pardiso(True)
        self.seconds_factor += time.perf_counter() - t0
        return True

    def back(self, f: np.ndarray) -> np.ndarray:
        """The displacement part of one raw back-substitution of [f; 0] with the last factorisation
        (no refinement, no residual check): a preconditioner, not a solve."""
        t0 = time.perf_counter()
        f = np.asarray(f, float)
        x = self._back(np.concatenate([f, np.zeros((self.m,) + f.shape[1:])]))[:self.n]
        self.seconds_solve += time.perf_counter() - t0
        return x

    def _back(self, b: np.ndarray) -> np.ndarray:
        self.n_back += 1 if b.ndim == 1 else b.shape[1]
        self.n_back_calls += 1
        if self._pardiso:
            if self._U.dtype == np.float32:
                # each column scaled to a largest entry of 1 in single precision: a residual's
                # entries far below 1e-38 [SI] would otherwise be flushed to zero (and above 3e38 overflow)
                b2 = b.reshape(b.shape[0], -1)
                beta = np.abs(b2).max(axis=0)
                beta[~(beta > 0) | ~np.isfinite(beta)] = 1.0
                x = self._call(33, np.asfortranarray(b2 / beta, np.float32))
                return (np.asarray(x, float) * beta).reshape(b.shape)
            x = self._call(33, np.asfortranarray(b, self._U.dtype))
            return np.ascontiguousarray(x, float).reshape(b.shape)
        return self._lu.solve(b)

    def _gmres_refine(self, apply, rhs: np.ndarray, sol: np.ndarray, res: np.ndarray, eta: float):
        """GMRES-based iterative refinement (Carson & Higham, SIAM J. Sci. Comput. 39 (2017)
        A2834 and 40 (2018) A817): where plain refinement with the single factor contracts slowly
        (a condition number near 1 / single precision) and has left a backward error above
        :data:`MIXED_BACKWARD_TOL`, each correction A d = -r is solved by GMRES in double,
        right-preconditioned by the single factor (:func:`graspdef.solve.krylov.gmres`, at most
        :data:`MIXED_GMRES` iterations of one back-substitution and one product each), down to
        :data:`MIXED_FLOOR`; at most two such corrections.  Returns (sol, res, eta), the best
        found; the caller's acceptance decides (and refactors in double if it fails)."""
        from .krylov import gmres

        cols = sol.ndim == 1
        X, R, B = (a.reshape(a.shape[0], -1) for a in (sol, res, rhs))
        X, R = X.copy(), R.copy()
        for _ in range(2):
            for j in range(X.shape[1]):
                # MIXED_FLOOR in the 2-norm GMRES minimises (so at most that in the infinity norm of
                # the backward error); where round-off keeps it above, GMRES stops at MIXED_GMRES
                # iterations with the best correction it found (hemisphere with a hole, 26,910
                # vertices: 12 iterations after 4 plain steps, backward error 2.7e-8 -> 1.2e-17 / 1.6e-17)
                size = self.norm * float(np.abs(X[:, j]).max()) + float(np.abs(B[:, j]).max())
                atol = 0.5 * MIXED_FLOOR * size
                d, _, _, _ = gmres(apply, -R[:, j], atol, MIXED_GMRES, precondition=self._back)
                new = X[:, j] + d
                new_r = apply(new) - B[:, j]
                if backward_error(self.norm, new, new_r, B[:, j]) < backward_error(self.norm, X[:, j], R[:, j], B[:, j]):
                    X[:, j], R[:, j] = new, new_r
            new_eta = backward_error(self.norm, X, R, B)
            improved = new_eta < 0.5 * eta
            eta = min(eta, new_eta)
            if eta <= MIXED_FLOOR or not improved:
                break
        if cols:
            X, R = X[:, 0], R[:, 0]
        return X, R, eta

    def _call(self, phase: int, b: np.ndarray) -> np.ndarray:
        """One PARDISO phase on the last KKT upper triangle (``self._U``) with right-hand sides ``b``
        (Fortran order, U's dtype): :func:`graspdef.solve.pardiso.call` in this process, or out of
        core in the system's worker process (:class:`graspdef.solve.pardiso_ooc.OOCPardiso`)."""
        U = self._U
        if self.backend == "pardiso-ooc":
            return self._solver.call(phase, U, b, self._ooc_env())
        return pardiso.call(self._solver, phase, U.data, U.indptr, U.indices, b)

    def solve(self, f: np.ndarray, g: np.ndarray | None = None, rtol: float = 1e-8,
              refinements: int = 3, exact: bool = True,
              start: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, float]:
        """Solve K u + C^T l = f, C u = g for one (n,) or several (n, k) right-hand sides.

        Returns (u, l, relative residual |r| / |rhs|, the largest over the columns: each column is
        its own solve).  The solution is refined (at most
        ``refinements`` back-substitutions of the residual) and accepted when its relative residual
        is at most ``rtol`` **or** its normwise backward error (:func:`backward_error`) is at most
        :data:`BACKWARD_TOL` and the system does not amplify the right-hand side by more than
        :data:`MAX_AMPLIFICATION` (|A| |x| / |b|, a lower bound of the condition number): it is
        then the exact solution of a system within round-off of this one, and the system is not
        numerically singular (a singular one, solved backward-stably, has eta ~ eps too, but
        |x| ~ |b| / (eps |A|)).  The second test matters for thin, stiff shells: their tangents' condition numbers
        reach 1e10 (a slit ring, t/R = 0.005), the residual of an exact-to-round-off solution is
        eps |A| |x| >> rtol |rhs|, and a residual test alone rejected solves whose backward error
        was 3e-17.  Raises SolverError when neither holds (singular or not solved).

        ``start``: an iterate of the whole system, (n + m,) or (n + m, k), made with the current
        factorisation (:meth:`certify_inertia`'s), refined instead of a first back-substitution."""
        t0 = time.perf_counter()
        n, m = self.n, self.m
        f = np.asarray(f, float)
        g_in = g
        g = np.zeros((m,) + f.shape[1:]) if g is None else np.asarray(g, float).reshape((m,) + f.shape[1:])
        s = self.scale
        rhs = np.concatenate([f, s * g])
        apply = self._apply                             # the KKT matrix times x, in double

        def residual(x):
            return apply(x) - rhs

        # each column of several right-hand sides is its own solve: its residual relative to its
        # own right-hand side (as the backward error is each column's), not the block's norm, which
        # a column of larger size would dominate
        bn = np.maximum(np.linalg.norm(rhs.reshape(rhs.shape[0], -1), axis=0), 1e-300)

        def relative(r):
            return float((np.linalg.norm(r.reshape(r.shape[0], -1), axis=0) / bn).max())

        sol = self._back(rhs) if start is None else np.asarray(start, float).reshape(rhs.shape)
        res = residual(sol)
        eta = backward_error(self.norm, sol, res, rhs)
        single = self.single
        loose = single and not exact                    # an inexact Newton step's solve: rtol is enough
        for _ in range(MIXED_REFINEMENTS if single else refinements):
            if not np.all(np.isfinite(sol)) or eta <= (MIXED_FLOOR if single else 0.01 * BACKWARD_TOL):
                break
            if (not single or loose) and relative(res) <= (1.0 if loose else 0.01) * rtol:
                break
            new = sol - self._back(res)
            new_res = residual(new)
            new_eta = backward_error(self.norm, new, new_res, rhs)
            if not new_eta < eta:                       # refinement at its round-off limit
                break
            slow = new_eta > 0.5 * eta
            sol, res, eta = new, new_res, new_eta
            if single and slow:                         # a single factor's refinement at its limit
                break
        met = loose and bool(np.all(np.isfinite(sol))) and relative(res) <= rtol
        if single and not met and eta > MIXED_BACKWARD_TOL and np.all(np.isfinite(sol)):
            sol, res, eta = self._gmres_refine(apply, rhs, sol, res, eta)
        self.seconds_solve += time.perf_counter() - t0
        finite = bool(np.all(np.isfinite(sol)))
        if finite:
            rel = relative(res)
            amp = self.norm * float(np.abs(sol).max()) / max(float(np.abs(rhs).max()), 1e-300)
        failed = not finite or rel > rtol and not (eta <= BACKWARD_TOL and amp <= MAX_AMPLIFICATION)
        if (failed or single and eta > MIXED_BACKWARD_TOL and not met) and self.retry_robust():
            return self.solve(f, g_in, rtol=rtol, refinements=refinements, exact=exact)
        if not finite:
            raise SolverError("the linear solve produced non-finite values (singular system)")
        if rel > rtol and not (eta <= BACKWARD_TOL and amp <= MAX_AMPLIFICATION):
            raise SolverError(f"linear solve residual {rel:.2e} exceeds {rtol:.0e} and its backward error "
                              f"{eta:.1e} exceeds {BACKWARD_TOL:.0e} (singular or too ill-conditioned)")
        return sol[:n], s * sol[n:], rel


#: Largest normwise backward error of an accepted solve (see :meth:`KKTSystem.solve`): ~1e4
#: machine epsilons, above a stable factorisation's (measured: 3e-17 on a slit ring whose tangent
#: has condition number 9e9) and far below what an unrefined perturbed pivot or a singular
#: system leaves (PARDISO perturbs tiny pivots by 1e-8 of the matrix norm).
BACKWARD_TOL = 1e-12

# Factorisation precisions of KKTSystem (PRECISIONS, defined with the problem's BACKENDS): "double",
# or "mixed" -- a single-precision PARDISO factor whose solves are refined with double residuals
# (Wilkinson's iterative refinement; Higham, *Accuracy and Stability of Numerical Algorithms*,
# ch. 12; Langou et al. 2006), in core only.  Measured on the pinched cylinder (README, "Mixed
# precision"): the factor's memory halved, its time ~0.6 x, 4-8 refinement steps.

#: "auto" precision: mixed from this many unknowns (displacements and constraints) on, double below.
#: The factor's time and memory matter from about the 10k pinched cylinder's 31,693 on; below, a
#: double factor takes milliseconds and its answers stay the same to the bit as before mixed
#: precision existed (and the 288-cell cylinder, whose nearly dependent support rows make its
#: single factor's inertia wrong, 188 for 185, does not pay for a single factor it then replaces)
MIXED_MIN_UNKNOWNS = 20_000

#: Largest backward error of an accepted mixed-precision solve (:class:`KKTSystem`): above it the
#: single factor is replaced by a double one.  The refinement goes on below it, to
#: :data:`MIXED_FLOOR` or until a step no longer halves the backward error, so that the answer is a
#: double solve's to round-off times the condition number: on the 1/8 soda can (t/R = 0.003) a
#: double factor's solve has 2.6e-17, the mixed one's steps 2.1e-8, 9.8e-11, 1.2e-12, 7.5e-15, ...
MIXED_BACKWARD_TOL = 1e-14

#: Backward error at which a mixed-precision solve's refinement stops (about the double rounding
#: of a residual)
MIXED_FLOOR = 1e-16

#: Most refinement steps of a mixed-precision solve: a single factor that has not refined a solve to
#: MIXED_BACKWARD_TOL after them (a contraction slower than ~8 per step, i.e. a condition number
#: approaching 1 / single precision's 6e-8) is replaced by a double one
MIXED_REFINEMENTS = 12

#: Seed of the pseudo-random start of :meth:`KKTSystem.certify_inertia` (fixed: the same path takes
#: the same decisions in every run)
CERTIFICATE_SEED = 20261127

#: The largest probability that :meth:`KKTSystem.certify_inertia` passes a single factor whose
#: inertia differs from the matrix's: its iteration must bring |y| (from y_0 ~ N(0, I)) below
#: CERTIFICATE_MISS sqrt(pi / 2), whatever the number of unknowns
CERTIFICATE_MISS = 1e-7

#: Most GMRES iterations of a mixed-precision solve's correction (:meth:`KKTSystem._gmres_refine`):
#: each costs a single-precision back-substitution, below a double factorisation's cost by ~50x at
#: 10k-100k unknowns
MIXED_GMRES = 30

#: Largest |A| |x| / |b| (infinity norms) of a solve accepted by its backward error: beyond it
#: (a condition number above 1e12, ~1e-4 / eps) the system is taken as singular.  The slit ring's
#: tangent solves have 9e8.
MAX_AMPLIFICATION = 1e12


def kkt_norm(K: sp.csr_matrix, C: sp.spmatrix, scale: float, summary: RowSummary | None = None) -> float:
    """Infinity norm (largest absolute row sum) of the KKT matrix [[K, s C^T], [s C, 0]]
    (K's row sums from ``summary`` when given)."""
    rows = _abs_row_sums(K) if summary is None else summary.abs_sums
    if C.shape[0]:
        rows = rows + scale * np.asarray(abs(C).sum(axis=0)).ravel()
        rows = np.concatenate([rows, scale * np.asarray(abs(C).sum(axis=1)).ravel()])
    return float(rows.max()) if rows.size else 0.0


def _abs_row_sums(A: sp.spmatrix) -> np.ndarray:
    """sum_j |A_ij| per row, without the copy of the whole matrix that ``abs(A)`` makes (the 100k
    cylinder's K: 0.4 GB and 0.75 s per factorisation)."""
    A = A.tocsr()
    out = np.zeros(A.shape[0])
    nz = np.flatnonzero(np.diff(A.indptr))
    if nz.size:
        out[nz] = np.add.reduceat(np.abs(A.data), A.indptr[nz])
    return out


def backward_error(norm: float, x: np.ndarray, r: np.ndarray, b: np.ndarray) -> float:
    """Normwise backward error |r| / (|A| |x| + |b|) (infinity norms; Rigal & Gaches 1967,
    Higham, *Accuracy and Stability of Numerical Algorithms*, Thm 7.1) of a solution x of A x = b
    with residual r = A x - b; the largest over the columns of several right-hand sides.  A solve
    with backward error eta is the exact solution of a system whose matrix and right-hand side
    are within relative eta of the given ones."""
    x, r, b = (np.asarray(a, float).reshape(a.shape[0], -1) for a in (x, r, b))
    den = norm * np.abs(x).max(axis=0) + np.abs(b).max(axis=0)
    num = np.abs(r).max(axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        eta = np.where(den > 0, num / np.where(den > 0, den, 1.0), np.where(num > 0, np.inf, 0.0))
    return float(eta.max()) if eta.size else 0.0


def union_sum(A: sp.spmatrix, B: sp.spmatrix) -> sp.csr_matrix:
    """A + B on the union of their patterns, explicit zeros kept (scipy's sum drops them), with
    sorted indices."""
    a, b = A.tocoo(), B.tocoo()
    out = sp.coo_matrix((np.concatenate([a.data, b.data]), (np.concatenate([a.row, b.row]), np.concatenate([a.col, b.col]))),
                        shape=A.shape).tocsr()
    out.sum_duplicates()
    return out


def ooc_path(folder: str) -> str:
    """MKL_PARDISO_OOC_PATH for a folder: the folder itself, without a trailing separator (MKL adds
    "/mkl_pardiso"; a path ending in a separator makes MKL 2026.2 write one byte past a heap buffer,
    KKTSystem._ooc_env)."""
    path = folder.rstrip(os.sep)
    if not path:
        raise SolverError(f"PARDISO out of core needs a folder other than the file system's root, got {folder!r}")
    return path


#: prefix of the out-of-core factor folders in the temporary directory; the creating process's id follows
OOC_PREFIX = "graspdef_pardiso_ooc_"

#: an out-of-core folder of a process that no longer runs is removed once untouched this long [s]
OOC_STALE_S = 3600.0


def ooc_folder(parent: str | None = None) -> str:
    """A new folder for PARDISO's out-of-core factor files, named after this process
    (``graspdef_pardiso_ooc_<pid>_<random>`` in ``parent``, default the temporary directory); first
    the folders of processes that no longer run, untouched for ``OOC_STALE_S``, are removed.  A
    KKTSystem removes its folder when it closes, but a process killed during a solve cannot, and
    its factor files stay: 2.3 GB for the 100k pinched cylinder.  A folder whose process id runs
    again (reused by another process) is left alone, as are folders named otherwise and recent ones
    (a process in another PID namespace sharing the folder would look dead here)."""
    parent = tempfile.gettempdir() if parent is None else parent
    now = time.time()
    with contextlib.suppress(OSError):
        for entry in os.scandir(parent):
            pid = entry.name[len(OOC_PREFIX):].split("_", 1)[0] if entry.name.startswith(OOC_PREFIX) else ""
            if not (pid.isdigit() and entry.is_dir(follow_symlinks=False)) or _process_runs(int(pid)):
                continue
            with contextlib.suppress(OSError):
                files = [f.stat() for f in os.scandir(entry.path) if f.is_file(follow_symlinks=False)]
                if now - max([entry.stat().st_mtime] + [f.st_mtime for f in files]) < OOC_STALE_S:
                    continue
                size = sum(f.st_size for f in files)
                shutil.rmtree(entry.path)
                log.info("removed %s (%.0f MB): out-of-core factor files of process %s, which no longer runs",
                         entry.path, size / 1e6, pid)
    return tempfile.mkdtemp(prefix=f"{OOC_PREFIX}{os.getpid()}_", dir=parent)


def _process_runs(pid: int) -> bool:
    """Whether a process with this id (> 0) exists (of any user)."""
    if pid <= 0:
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:             # e.g. another user's process: it exists
        return True
    return True


#: pardiso-ooc: the part of the factor PARDISO keeps in memory [MB] (MKL_PARDISO_OOC_MAX_CORE_SIZE;
#: MKL's default is 2000).  Doubled while PARDISO reports too little (error -9; the 100k pinched
#: cylinder needs 700-800).
OOC_CORE_MB = 1000

#: The factor's part held in memory out of core is at least this multiple of PARDISO's own minimum
#: for the matrix (:meth:`KKTSystem._fit_ooc_core`).
OOC_CORE_MARGIN = 1.1


def _available_mb() -> int | None:
    from ..shell.memory import available_memory

    have = available_memory()
    return None if have is None else int(have / 2**20)


#: PARDISO settings (1-based iparm): see the README's solver section
_PARDISO_IPARM = {
    1: 1,       # use the values below, not the defaults
    2: 2,       # METIS nested-dissection ordering, the sequential one: the parallel one (3)
                # rules out PARDISO's reproducible mode (iparm 34, set per solver: _cnr_threads)
    8: 0,       # no automatic iterative refinement: KKTSystem.solve refines while the residual in
                # the unperturbed system is too large (PARDISO's two automatic steps tripled the
                # cost of every Newton back-substitution at 10k: 0.12 s vs 0.04 s)
    10: 8,      # pivot perturbation 1e-8 (then refined; the true residual is checked)
    11: 1,      # symmetric scaling
    13: 2,      # weighted matching, improved variant (saddle-point systems)
    21: 0,      # 1x1 diagonal pivots (the constraint rows' zero pivots are static-pivoted and
                # then refined; Bunch-Kaufman 2x2 pivots, 21 = 1, are the first fallback): the 10k
                # ball's single-precision factor 0.21-0.23 s against 0.30-0.33 s with them, the same
                # inertia (docs/speed.md, "1×1 pivots")
    35: 1,      # zero-based indices (KKTSystem._call passes scipy's own)
}

#: PARDISO settings of a second factorisation when the first fails a check (a solve's residual and
#: backward error, or an inertia other than the one expected): Bunch-Kaufman 1x1 and 2x2 pivots
#: instead of 1x1 pivots only (Bunch-Kaufman was the default until 2026-11-28).  Then, with
#: Bunch-Kaufman pivots, the standard weighted matching instead of the improved one, and then the
#: minimum-degree ordering instead of METIS.  The improved matching is faster (10k pinched
#: cylinder: 1.95 vs 2.26 s per factorisation, medians of 5), but its static pivoting is not
#: backward-stable on every matrix: the 1/8 soda can at 96 x 96 cells with two collocation points per edge, with its
#: nearly dependent support rows re-based into one orthonormal basis (as they then were), perturbs one pivot, counts
#: 961 negative pivots for 960 constraints and solves to a residual of 1e-3, while another
#: orthonormal basis of the same rows (what OpenBLAS's LAPACK returns with two threads instead of
#: one) factors exactly; SuperLU solves both to 1.5e-11 with the same displacements, so the
#: matrices are regular.  The 100k pinched cylinder likewise.  The standard matching factors every
#: such case here (tests/solve/test_kkt_robust.py).  Perturbed pivots alone do not trigger it: the fast
#: settings perturb tiny pivots of the zero constraint block routinely (the pinched cylinder, the
#: patch model) and the refined solution then passes its check.
#: The settings tried after the defaults when a check fails, in this order (:meth:`KKTSystem.retry_robust`):
#: Bunch-Kaufman pivots, then with them the standard weighted matching (above), then the
#: minimum-degree ordering instead of METIS (which factored the soda can's and the half-can's
#: failing tangents exactly as well).
_PARDISO_ROBUST = {21: 1}
_PARDISO_FALLBACKS = (_PARDISO_ROBUST, {21: 1, 13: 1}, {21: 1, 2: 0})


def solve_kkt(K: sp.spmatrix, C: sp.spmatrix, f: np.ndarray, backend: str = "auto",
              rtol: float = 1e-8, refinements: int = 3, g: np.ndarray | None = None,
              precision: str = "double") -> KKTResult:
    """Solve K u + C^T l = f, C u = g (default g = 0); raise SupportError/SolverError on singular
    or unbalanced systems.  ``precision``: see :class:`KKTSystem`."""
    with KKTSystem(C, backend, precision) as kkt:
        kkt.factor(K)
        m = kkt.m
        neg = kkt.negative_pivots(m)
        if neg is not None and neg != m:
            raise SupportError(
                f"the constrained stiffness is singular or indefinite: the KKT matrix has {neg} "
                f"negative pivots for {m} constraints (expected {m}; {kkt.perturbed} pivots perturbed). A "
                "mechanism is free (a part without supports, or redundant/conflicting supports).")
        u, lam, rel = kkt.solve(f, g, rtol=rtol, refinements=refinements)
    log.info("KKT %s (%s): n=%d m=%d factor %.3fs solve %.3fs residual %.1e", kkt.backend,
             "mixed" if kkt.single else "double", len(f), m,
             kkt.seconds_factor, kkt.seconds_solve, rel)
    return KKTResult(u, lam, kkt.backend, kkt.n_negative, kkt.seconds_factor, kkt.seconds_solve, rel,
                     "mixed" if kkt.single else "double")
