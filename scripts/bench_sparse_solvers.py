#!/usr/bin/env python
"""Benchmark sparse direct solvers on the real linear shell systems of graspdef.

What is measured
----------------
The test case is the pinched cylinder, full model (R = 300, L = 600, t = 3, E = 3e6, nu = 0.3,
rigid diaphragms at z = 0 and z = L, unit inward point loads at (+-R, 0, L/2), one axial point
support at (0, R, L/2) that removes the last rigid mode), meshed with ``cylinder(R, L, 2 n_z, n_z)``
(about 2 n_z^2 control vertices: n_z = 70 -> ~10k, n_z = 224 -> ~100k).  Two systems are solved:

``kkt``  the production system of ``graspdef.solve.sparse``: [[K, s C^T], [s C, 0]] built by
         ``kkt_matrix`` (symmetric indefinite, m negative eigenvalues).
``spd``  an SPD system of the same size and sparsity character for Cholesky solvers: the rows and
         columns of K for the DOFs that no constraint row touches (the DOFs with a non-zero in C
         are treated as fixed), with the matching part of f.  This is a *different* boundary
         value problem (it clamps the boundary ring), so its u_A does not match the reference.

Solvers (each one is skipped, not crashed, if its package is missing):

  kkt: ``pardiso`` (MKL PARDISO via pypardiso, mtype -2, the iparm settings that
       ``graspdef.solve.sparse._factor_pardiso`` uses, read from it at run time; phases
       11 / 22 / 33 timed separately),
       ``solve_kkt`` (the production ``graspdef.solve.sparse.solve_kkt`` end to end, including
       building the KKT matrix, its upper triangle and the residual check),
       ``superlu-colamd`` and ``superlu-mmd_at_plus_a`` (``scipy.sparse.linalg.splu``; its
       analysis is not separable, so it counts as factorisation), ``mumps`` (pymumps, sym = 2,
       LDL^T with pivoting, jobs 1 / 2 / 3), ``qdldl`` (LDL^T without pivoting, AMD ordering),
       ``qdldl-regularised`` (zero block -> -1e-8 s I, then iterative refinement, as OSQP does).
  spd: ``cholespy`` (its bundled CHOLMOD; analysis + factorisation happen in one constructor),
       ``cholmod`` (scikit-sparse, the system's SuiteSparse and whatever BLAS ``libblas.so.3``
       resolves to), ``cholmod-refblas`` (the same with Debian's reference BLAS/LAPACK put first
       on LD_LIBRARY_PATH, if installed), ``pardiso-spd`` (mtype 2, the production ordering
       option iparm(2), other values MKL's defaults), ``mumps-spd``
       (sym = 1), ``superlu-mmd_at_plus_a-spd``, ``qdldl-spd``.

How
---
1. For each size a subprocess builds the problem and times: the Shell, ``ShellEnergy(shell).hessian``
   (first call in a fresh process, which includes loading the numba cache, and a warm repeat
   with a new ``ShellEnergy``), ``Problem.boundary_stiffness`` and ``load_vector`` +
   ``constraints`` (first call and warm repeat).  It saves K, C, f and the probe weights at A
   under ``out/bench_sparse_cache/``.
2. Every (size, solver) run is a fresh subprocess: it loads the matrices, prepares the input
   format the solver wants (not timed: CSR upper triangle with explicit diagonal for PARDISO,
   CSC for SuperLU/CHOLMOD, ...), then times analysis / factorisation / solve with
   ``time.perf_counter``.  Its peak resident set (VmHWM of /proc/self/status) is read after the
   solve; ``rss_before_MB`` is VmHWM just before the solver starts (matrices loaded and
   converted), so ``peak - before`` is what the solver itself added at its peak.
3. Checks: relative residual ||A x - b|| / ||b|| in the unperturbed system; the radial
   displacement at A, ``-(w @ u[stencil])[0]`` (reference 1.8248e-5 for the KKT system); and the
   relative difference of each solution to the reference solver's (``pardiso`` / ``pardiso-spd``).
4. Times are medians over the runs (``--repeats`` for sizes below 50k vertices,
   ``--repeats-large`` above); a run that exceeds ``--timeout`` seconds is killed and reported,
   and that solver is not tried at larger sizes.  A solver whose time at a smaller size,
   scaled by (n_dofs ratio)^1.5, exceeds the timeout is skipped with that prediction as the
   reason (measured here: the real growth from 10k to 100k vertices was 1.2-1.5x steeper).
   The 1-minute load average at the start of each run is recorded: the machine has 2 cores.

Usage::

    python scripts/bench_sparse_solvers.py [--sizes 70 224] [--repeats 3] [--repeats-large 1]
        [--timeout 600] [--solvers pardiso mumps ...] [--skip superlu-colamd ...]
        [--reuse-build] [--out out/bench_sparse_solvers.json]

Optional packages: pypardiso (+ mkl), python-mumps is not usable on Python 3.11, so MUMPS is
``pymumps`` built against Debian's ``libmumps-dev`` (+ ``mpi4py``); ``scikit-sparse==0.4.16``
needs ``libsuitesparse-dev``; ``qdldl``; ``cholespy`` (bundles a reference BLAS).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CACHE = ROOT / "out" / "bench_sparse_cache"
U_A_REFERENCE = 1.8248e-5
LARGE_VERTICES = 50_000
REF_BLAS_DIRS = ("/usr/lib/x86_64-linux-gnu/blas", "/usr/lib/x86_64-linux-gnu/lapack")

# (name, system, module that must import, extra environment)
SOLVERS = [
    ("pardiso", "kkt", "pypardiso", {}),
    ("solve_kkt", "kkt", "pypardiso", {}),
    ("mumps", "kkt", "mumps", {}),
    ("superlu-colamd", "kkt", "scipy", {}),
    ("superlu-mmd_at_plus_a", "kkt", "scipy", {}),
    ("qdldl", "kkt", "qdldl", {}),
    ("qdldl-regularised", "kkt", "qdldl", {}),
    ("pardiso-spd", "spd", "pypardiso", {}),
    ("cholmod", "spd", "sksparse.cholmod", {}),
    ("mumps-spd", "spd", "mumps", {}),
    ("cholmod-refblas", "spd", "sksparse.cholmod", {"LD_LIBRARY_PATH": ":".join(REF_BLAS_DIRS)}),
    ("cholespy", "spd", "cholespy", {}),
    ("superlu-mmd_at_plus_a-spd", "spd", "scipy", {}),
    ("qdldl-spd", "spd", "qdldl", {}),
]
REFERENCE = {"kkt": "pardiso", "spd": "pardiso-spd"}


# --------------------------------------------------------------------------------------------
# helpers used in the subprocesses
# --------------------------------------------------------------------------------------------

def _status_kb(field: str) -> float:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(field + ":"):
                return float(line.split()[1])
    return float("nan")


def _peak_mb() -> float:
    return _status_kb("VmHWM") / 1024.0


def _loaded_blas() -> str:
    """The BLAS/LAPACK/MKL shared objects mapped into this process (what the solvers really use)."""
    libs = set()
    with open("/proc/self/maps") as fh:
        for line in fh:
            path = os.path.realpath(line.split()[-1])
            name = os.path.basename(path)
            if name.startswith("lib") and any(k in name for k in ("blas", "lapack", "mkl_core")) \
                    and "scalapack" not in name and "numpy.libs" not in path:
                libs.add(f"{os.path.basename(os.path.dirname(path))}/{name}")
    return ", ".join(sorted(libs))


def build_case(nz: int, out_dir: Path) -> dict:
    """Build the pinched cylinder, time assembly and constraints, save the matrices."""
    import scipy.sparse as sp

    t_import = time.perf_counter()
    from graspdef.geometry import cylinder
    from graspdef.problem.loads import PointLoad
    from graspdef.problem.problem import Problem, locate
    from graspdef.problem.supports import EdgeSupport, PointSupport
    from graspdef.shell.energy import ShellEnergy
    from graspdef.shell.materials import LinearElastic
    from graspdef.shell.model import Shell
    times = {"import_s": time.perf_counter() - t_import}

    R, L = 300.0, 600.0
    t = time.perf_counter()
    m = cylinder(R, L, 2 * nz, nz)
    shell = Shell(m.vertices, m.faces, LinearElastic(3e6, 0.3), 3.0)
    times["shell_s"] = time.perf_counter() - t

    t = time.perf_counter()
    ends = lambda p: (np.abs(p[:, 2]) < 1e-6) | (np.abs(p[:, 2] - L) < 1e-6)  # noqa: E731
    sup = [EdgeSupport("diaphragm", ends, normal=(0, 0, 1))]
    pr0 = Problem(shell, [], sup)
    A, _ = locate(shell, pr0.evaluator, [R, 0, L / 2], "A")
    B, _ = locate(shell, pr0.evaluator, [-R, 0, L / 2], "B")
    C, _ = locate(shell, pr0.evaluator, [0, R, L / 2], "C")
    pr = Problem(shell, [PointLoad(A.face, A.bary, (-1, 0, 0)), PointLoad(B.face, B.bary, (1, 0, 0))],
                 sup + [PointSupport(C.face, C.bary, ((0, 0, 1),))], probes={"A": A})
    times["problem_s"] = time.perf_counter() - t

    for key in ("hessian_first_s", "hessian_warm_s"):
        t = time.perf_counter()
        _, _, K = ShellEnergy(shell).hessian(shell.rest_positions)
        times[key] = time.perf_counter() - t
    t = time.perf_counter()
    Kb = pr.boundary_stiffness()                 # Nitsche terms (empty here: no rotation-fixed edge)
    K = (K + Kb).tocsr()
    times["boundary_stiffness_s"] = time.perf_counter() - t
    for key in ("constraints_first_s", "constraints_warm_s"):
        t = time.perf_counter()
        f = pr.load_vector()
        Cm, _ = pr.constraints()
        times[key] = time.perf_counter() - t
    st, w = pr.evaluator.values(A.face, np.asarray(A.bary))

    K.sort_indices()
    Cm = sp.csr_matrix(Cm)
    out_dir.mkdir(parents=True, exist_ok=True)
    for name, arr in (("K_data", K.data), ("K_indices", K.indices), ("K_indptr", K.indptr),
                      ("C_data", Cm.data), ("C_indices", Cm.indices), ("C_indptr", Cm.indptr),
                      ("f", f), ("probe_st", np.asarray(st)), ("probe_w", np.asarray(w))):
        np.save(out_dir / f"{name}.npy", arr)
    meta = {"n_z": nz, "n_theta": 2 * nz, "n_vertices": int(len(m.vertices)), "n_control": int(shell.n_control),
            "n_dofs": int(K.shape[0]), "n_constraints": int(Cm.shape[0]), "C_shape": list(Cm.shape),
            "K_nnz": int(K.nnz), "C_nnz": int(Cm.nnz), **times, "build_peak_rss_MB": _peak_mb()}
    (out_dir / "meta.json").write_text(json.dumps(meta, indent=1))
    return meta


def load_case(case_dir: Path, system: str):
    """(A, b, to_u, meta): the system matrix (full, CSR), right-hand side, and x -> u (3 n,)."""
    import scipy.sparse as sp

    meta = json.loads((case_dir / "meta.json").read_text())
    ld = lambda name: np.load(case_dir / f"{name}.npy")  # noqa: E731
    n = meta["n_dofs"]
    K = sp.csr_matrix((ld("K_data"), ld("K_indices"), ld("K_indptr")), shape=(n, n))
    C = sp.csr_matrix((ld("C_data"), ld("C_indices"), ld("C_indptr")), shape=tuple(meta["C_shape"]))
    f = ld("f")
    if system == "kkt":
        from graspdef.solve.sparse import kkt_matrix

        A, _ = kkt_matrix(K, C)
        b = np.concatenate([f, np.zeros(C.shape[0])])
        return A, b, (lambda x: x[:n]), meta, (K, C, f)
    fixed = np.zeros(n, bool)
    fixed[np.unique(C.indices)] = True
    free = np.flatnonzero(~fixed)
    A = K[free][:, free].tocsr()

    def to_u(x):
        u = np.zeros(n)
        u[free] = x
        return u
    return A, f[free], to_u, meta, None


# --------------------------------------------------------------------------------------------
# the solvers: each takes (A full CSR, b) and returns (x, {analysis_s, factor_s, solve_s, ...});
# the format conversion happens in prepare(), before the clock starts.
# --------------------------------------------------------------------------------------------

def _upper_csr(A):
    """Upper triangle of a symmetric CSR matrix with an explicit (possibly zero) diagonal."""
    import scipy.sparse as sp

    U = sp.triu(A, k=1, format="coo")
    n = A.shape[0]
    out = sp.coo_matrix((np.concatenate([U.data, A.diagonal()]),
                         (np.concatenate([U.row, np.arange(n)]), np.concatenate([U.col, np.arange(n)]))),
                        shape=A.shape).tocsr()
    out.sort_indices()
    return out


def project_pardiso_iparm() -> dict[int, int]:
    """The iparm values (1-based index -> value) of graspdef's KKT factorisations
    (``graspdef.solve.sparse._PARDISO_IPARM``), so that the benchmark follows the production
    settings when they change -- without iparm 35 (zero-based indices), which graspdef's own PARDISO
    call uses and pypardiso's one-based call, used here, must not.  (Until 2026-11-27 this read them by
    stubbing a module-level ``_factor_pardiso`` that had become a method: the function had stopped working.)"""
    from graspdef.solve import sparse as gs

    return {k: int(v) for k, v in gs._PARDISO_IPARM.items() if k != 35}


def _pardiso(mtype: int):
    def prepare(A, b, extra):
        return _upper_csr(A), project_pardiso_iparm()

    def run(data, b):
        import pypardiso

        U, project = data
        s = pypardiso.PyPardisoSolver(mtype=mtype)
        if mtype == -2:
            settings = project                               # exactly the production settings
        else:                                                # SPD: the production ordering only
            settings = {1: 1, 2: project.get(2, 2)}
        for i, v in settings.items():
            s.set_iparm(i, v)
        s.set_iparm(18, -1)             # report nnz(L) (reporting only)
        s._check_A(U)
        bb = np.asfortranarray(b.reshape(-1, 1))
        tm = {}
        for phase, key in ((11, "analysis_s"), (22, "factor_s"), (33, "solve_s")):
            s.set_phase(phase)
            t = time.perf_counter()
            x = s._call_pardiso(U, bb)
            tm[key] = time.perf_counter() - t
        tm.update(factor_nnz=int(s.get_iparm(18)), n_negative=int(s.get_iparm(23)),
                  perturbed_pivots=int(s.get_iparm(14)), iparm=" ".join(f"{i}:{v}" for i, v in settings.items()))
        s.free_memory(everything=True)
        return x.ravel(), tm
    return prepare, run


def _solve_kkt():
    def prepare(A, b, extra):
        return extra                     # (K, C, f): solve_kkt builds everything itself

    def run(KCf, b):
        from graspdef.solve.sparse import solve_kkt

        K, C, f = KCf
        d = np.abs(K.diagonal())
        scale = float(d[d > 0].mean())              # as in kkt_matrix: multipliers come back scaled
        t = time.perf_counter()
        r = solve_kkt(K, C, f, backend="pardiso")
        end_to_end = time.perf_counter() - t
        x = np.concatenate([r.u, r.multipliers / scale])
        return x, {"factor_s": r.seconds_factor, "solve_s": r.seconds_solve, "end_to_end_s": end_to_end,
                   "n_negative": r.n_negative}
    return prepare, run


def _superlu(spec: str):
    def prepare(A, b, extra):
        return A.tocsc()

    def run(Acsc, b):
        from scipy.sparse.linalg import splu

        t = time.perf_counter()
        lu = splu(Acsc, permc_spec=spec)
        t1 = time.perf_counter()
        x = lu.solve(b)
        t2 = time.perf_counter()
        return x, {"factor_s": t1 - t, "solve_s": t2 - t1, "factor_nnz": int(lu.L.nnz + lu.U.nnz)}
    return prepare, run


def _mumps(sym: int):
    def prepare(A, b, extra):
        import scipy.sparse as sp

        U = sp.triu(A, format="coo")
        return (U.row.astype(np.int32) + 1, U.col.astype(np.int32) + 1, U.data.copy(), A.shape[0])

    def run(coo, b):
        import mumps

        irn, jcn, a, n = coo
        x = b.copy()
        tm = {}
        with mumps.DMumpsContext(par=1, sym=sym) as ctx:
            ctx.set_shape(n)
            ctx.set_centralized_assembled(irn, jcn, a)
            ctx.set_rhs(x)
            ctx.set_silent()
            ctx.set_icntl(7, 7)          # automatic choice of the ordering (reported below)
            ctx.set_icntl(14, 50)        # 50 % extra workspace for delayed pivots
            for job, key in ((1, "analysis_s"), (2, "factor_s"), (3, "solve_s")):
                t = time.perf_counter()
                ctx.run(job=job)
                tm[key] = time.perf_counter() - t
            orderings = {0: "AMD", 2: "AMF", 3: "SCOTCH", 4: "PORD", 5: "METIS", 6: "QAMD"}
            tm.update(factor_nnz=int(ctx.get_infog(29)) if ctx.get_infog(29) > 0 else None,
                      n_negative=int(ctx.get_infog(12)) if sym == 2 else None,
                      ordering=orderings.get(ctx.get_infog(7), str(ctx.get_infog(7))))
        return x, tm
    return prepare, run


def _qdldl(regularise: bool = False):
    """QDLDL: LDL^T without pivoting (for quasi-definite matrices), AMD ordering, upper triangle in.

    With ``regularise`` the zero block of the KKT matrix becomes -delta I (delta = 1e-8 times the
    constraint scale, as OSQP does) and the solution is refined iteratively in the true system."""
    def prepare(A, b, extra):
        import scipy.sparse as sp

        U = _upper_csr(A)                      # explicit (zero) diagonal entries kept
        if regularise:
            m = extra[1].shape[0]
            d = np.abs(extra[0].diagonal())
            delta = 1e-8 * float(d[d > 0].mean())
            U = U - sp.diags(np.r_[np.zeros(A.shape[0] - m), np.full(m, delta)], format="csr")
        return U.tocsc(), A

    def run(data, b):
        import qdldl

        Uc, A = data
        t = time.perf_counter()
        F = qdldl.Solver(Uc, upper=True)       # AMD + symbolic + numeric
        t1 = time.perf_counter()
        x = F.solve(b)
        steps = 0
        if regularise:                         # iterative refinement in the unperturbed system
            for steps in range(1, 11):
                r = b - A @ x
                if np.linalg.norm(r) <= 1e-12 * np.linalg.norm(b):
                    break
                x = x + F.solve(r)
        t2 = time.perf_counter()
        return x, {"factor_s": t1 - t, "solve_s": t2 - t1, "refinement_steps": steps if regularise else None}
    return prepare, run


def _cholmod():
    def prepare(A, b, extra):
        return A.tocsc()

    def run(Acsc, b):
        from sksparse.cholmod import analyze

        t = time.perf_counter()
        F = analyze(Acsc)                # supernodal/simplicial chosen by CHOLMOD ("auto")
        t1 = time.perf_counter()
        F.cholesky_inplace(Acsc)
        t2 = time.perf_counter()
        x = F(b)
        t3 = time.perf_counter()
        return x, {"analysis_s": t1 - t, "factor_s": t2 - t1, "solve_s": t3 - t2}
    return prepare, run


def _cholespy():
    def prepare(A, b, extra):
        Acsc = A.tocsc()
        return (Acsc.shape[0], Acsc.indptr.astype(np.int32), Acsc.indices.astype(np.int32), Acsc.data)

    def run(csc, b):
        from cholespy import CholeskySolverD, MatrixType

        n, ip, ix, data = csc
        t = time.perf_counter()
        F = CholeskySolverD(n, ip, ix, data, MatrixType.CSC)   # analysis + factorisation
        t1 = time.perf_counter()
        x = np.zeros_like(b)
        F.solve(b, x)
        t2 = time.perf_counter()
        return x, {"factor_s": t1 - t, "solve_s": t2 - t1}
    return prepare, run


IMPLEMENTATIONS = {
    "pardiso": lambda: _pardiso(-2), "solve_kkt": _solve_kkt, "mumps": lambda: _mumps(2),
    "superlu-colamd": lambda: _superlu("COLAMD"), "superlu-mmd_at_plus_a": lambda: _superlu("MMD_AT_PLUS_A"),
    "qdldl": _qdldl, "qdldl-regularised": lambda: _qdldl(True), "pardiso-spd": lambda: _pardiso(2), "cholmod": _cholmod, "cholmod-refblas": _cholmod,
    "cholespy": _cholespy, "mumps-spd": lambda: _mumps(1),
    "superlu-mmd_at_plus_a-spd": lambda: _superlu("MMD_AT_PLUS_A"), "qdldl-spd": _qdldl,
}


def run_solver(name: str, system: str, case_dir: Path, solution_path: Path | None) -> dict:
    A, b, to_u, meta, extra = load_case(case_dir, system)
    prepare, run = IMPLEMENTATIONS[name]()
    data = prepare(A, b, extra)
    extra = None
    before = _peak_mb()
    load = os.getloadavg()[0]            # other work on the machine distorts the times: recorded
    t = time.perf_counter()
    x, info = run(data, b)
    wall = time.perf_counter() - t
    peak = _peak_mb()
    x = np.asarray(x, dtype=float).ravel()
    rec = {"analysis_s": None, "factor_s": None, "solve_s": None, **info}
    rec["total_s"] = sum(rec[k] or 0.0 for k in ("analysis_s", "factor_s", "solve_s"))
    rec["wall_s"] = wall                 # all of run(): also import, library/MPI start-up, set-up
    rec["loadavg_1min"] = load
    rec.update(rss_before_MB=before, peak_rss_MB=peak, blas=_loaded_blas(), nnz=int(A.nnz), n=int(A.shape[0]))
    if np.all(np.isfinite(x)):
        rec["residual"] = float(np.linalg.norm(A @ x - b) / np.linalg.norm(b))
        u = to_u(x).reshape(-1, 3)
        st, w = np.load(case_dir / "probe_st.npy"), np.load(case_dir / "probe_w.npy")
        rec["u_A"] = float(-(w @ u[st])[0])
        if solution_path is not None:
            np.save(solution_path, to_u(x))
    else:
        rec.update(residual=None, u_A=None, status="non-finite solution")
    return rec


# --------------------------------------------------------------------------------------------
# the driver
# --------------------------------------------------------------------------------------------

def _spawn(args: list[str], timeout: float, env_extra: dict | None = None) -> tuple[dict | None, str]:
    env = dict(os.environ, **(env_extra or {}))
    cmd = [sys.executable, str(Path(__file__).resolve())] + args
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env, cwd=ROOT)
    except subprocess.TimeoutExpired:
        return None, f"timeout after {timeout:.0f} s"
    for line in reversed(p.stdout.splitlines()):
        if line.startswith("RESULT "):
            return json.loads(line[7:]), ""
    err = (p.stderr.strip().splitlines() or ["no output"])[-1]
    return None, f"failed (exit {p.returncode}): {err[:200]}"


def _available(module: str, env_extra: dict) -> str:
    """'' if the module imports in a subprocess with this environment, else the reason."""
    if any(k == "LD_LIBRARY_PATH" for k in env_extra) and not all(os.path.isdir(d) for d in REF_BLAS_DIRS):
        return "reference BLAS not installed"
    env = dict(os.environ, **env_extra)
    p = subprocess.run([sys.executable, "-c", f"import {module}"], capture_output=True, text=True, env=env)
    return "" if p.returncode == 0 else "not installed: " + (p.stderr.strip().splitlines() or ["?"])[-1][:120]


def _median(values):
    vals = [v for v in values if v is not None]
    return float(statistics.median(vals)) if vals else None


def _fmt(v, spec=".3g"):
    return "–" if v is None else format(v, spec)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[70, 224], help="n_z values (n_theta = 2 n_z)")
    ap.add_argument("--repeats", type=int, default=3, help="runs per solver below 50k vertices")
    ap.add_argument("--repeats-large", type=int, default=1, help="runs per solver above 50k vertices")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per solver run")
    ap.add_argument("--solvers", nargs="+", default=None, help="subset of: " + " ".join(s[0] for s in SOLVERS))
    ap.add_argument("--skip", nargs="+", default=[], help="solvers to report as skipped")
    ap.add_argument("--reuse-build", action="store_true",
                    help="reuse matrices and assembly timings of an earlier run from out/bench_sparse_cache")
    ap.add_argument("--out", default="out/bench_sparse_solvers.json")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    ap.add_argument("--system", help=argparse.SUPPRESS)
    ap.add_argument("--case", help=argparse.SUPPRESS)
    ap.add_argument("--solution", help=argparse.SUPPRESS)
    ap.add_argument("--build", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()

    if args.build is not None:                       # subprocess: build one size
        print("RESULT " + json.dumps(build_case(args.build, Path(args.case))), flush=True)
        return
    if args.worker is not None:                      # subprocess: one solver run
        rec = run_solver(args.worker, args.system, Path(args.case), Path(args.solution) if args.solution else None)
        print("RESULT " + json.dumps(rec), flush=True)
        return

    solvers = [s for s in SOLVERS if args.solvers is None or s[0] in args.solvers]
    out_path = ROOT / args.out if not Path(args.out).is_absolute() else Path(args.out)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    env_info = {"python": platform.python_version(), "cpus": os.cpu_count(), "loadavg_start": os.getloadavg(),
                "machine": platform.machine(), "date": time.strftime("%Y-%m-%d %H:%M:%S")}
    skip_reason = {name: "--skip" if name in args.skip else _available(mod, extra)
                   for name, _, mod, extra in solvers}
    timed_out: dict[str, str] = {}           # solvers not tried again at larger sizes, and why
    previous: dict[str, tuple[int, float]] = {}   # solver -> (n_dofs, median total) at a smaller size
    records, builds = [], []
    md = [f"# Sparse solver benchmark ({env_info['date']}, {env_info['cpus']} CPUs, "
          f"load average at start {env_info['loadavg_start'][0]:.2f})", ""]

    def save():
        out_path.write_text(json.dumps({"environment": env_info, "builds": builds, "records": records}, indent=1))

    for nz in args.sizes:
        case_dir = CACHE / f"nz{nz}"
        if args.reuse_build and (case_dir / "meta.json").exists():
            meta = json.loads((case_dir / "meta.json").read_text())
        else:
            print(f"[n_z={nz}] building ...", file=sys.stderr, flush=True)
            meta, err = _spawn(["--build", str(nz), "--case", str(case_dir)], timeout=3600)
            if meta is None:
                raise SystemExit(f"building n_z={nz} failed: {err}")
        builds.append(meta)
        large = meta["n_vertices"] > LARGE_VERTICES
        repeats = args.repeats_large if large else args.repeats
        size_recs = []
        for name, system, _, extra in solvers:
            base = {"size": nz, "n_vertices": meta["n_vertices"], "n_dofs": meta["n_dofs"], "solver": name,
                    "system": system}
            reason = skip_reason[name] or timed_out.get(name, "")
            if not reason and name in previous:   # a direct factorisation of a surface mesh: ~ n^1.5
                n0, t0 = previous[name]
                guess = t0 * (meta["n_dofs"] / n0) ** 1.5
                if guess > args.timeout:
                    reason = f"predicted {guess:.0f} s (> timeout) from {t0:.1f} s at {n0:,} DOFs, time ~ n^1.5"
            if reason:
                rec = {**base, "status": "skipped: " + reason, "runs": 0}
                records.append(rec), size_recs.append(rec)
                print(f"[n_z={nz}] {name}: {rec['status']}", file=sys.stderr, flush=True)
                continue
            runs, status = [], "ok"
            for r in range(repeats):
                sol = case_dir / f"solution_{name}.npy" if r == 0 else None
                wargs = ["--worker", name, "--system", system, "--case", str(case_dir)]
                res, err = _spawn(wargs + (["--solution", str(sol)] if sol else []), args.timeout, extra)
                if res is None:
                    status = err
                    if err.startswith("timeout"):
                        timed_out[name] = f"timed out (> {args.timeout:.0f} s) at n_z={nz}"
                    break
                runs.append(res)
                print(f"[n_z={nz}] {name} run {r + 1}: total {res['total_s']:.2f} s, "
                      f"peak {res['peak_rss_MB']:.0f} MB, residual {res.get('residual')}", file=sys.stderr, flush=True)
            rec = {**base, "status": status, "runs": len(runs)}
            if runs:
                last = runs[-1]
                rec.update(nnz=last["nnz"], blas=last["blas"],
                           **{k: _median([x.get(k) for x in runs])
                              for k in ("analysis_s", "factor_s", "solve_s", "total_s", "wall_s", "end_to_end_s", "peak_rss_MB",
                                        "rss_before_MB", "loadavg_1min")},
                           min_total_s=min(x["total_s"] for x in runs),
                           residual=max((x["residual"] for x in runs if x.get("residual") is not None), default=None),
                           u_A=last.get("u_A"), all_total_s=[x["total_s"] for x in runs],
                           **{k: last[k] for k in ("factor_nnz", "n_negative", "perturbed_pivots", "ordering",
                                                    "iparm", "refinement_steps") if last.get(k) is not None})
                if status == "ok" and rec["residual"] is not None and rec["residual"] > 1e-8:
                    rec["status"] = f"inaccurate (residual {rec['residual']:.1e})"
            records.append(rec), size_recs.append(rec)
            if rec.get("total_s") is not None:
                previous[name] = (meta["n_dofs"], rec["total_s"])
            save()

        # agreement of the solutions with the reference solver of each system
        n_dofs = meta["n_dofs"]
        for rec in size_recs:
            ref = case_dir / f"solution_{REFERENCE[rec['system']]}.npy"
            mine = case_dir / f"solution_{rec['solver']}.npy"
            if rec.get("runs") and ref.exists() and mine.exists():
                a, b = np.load(mine)[:n_dofs], np.load(ref)[:n_dofs]
                rec["rel_diff_vs_ref"] = float(np.linalg.norm(a - b) / np.linalg.norm(b))
        save()

        md += [f"## n_z = {nz}: {meta['n_vertices']:,} vertices ({meta['n_control']:,} control points), "
               f"{meta['n_dofs']:,} DOFs, {meta['n_constraints']} constraints, nnz(K) = {meta['K_nnz']:,}; "
               f"median of {repeats} run(s) per solver", "",
               "| system | solver | nnz(A) | analysis s | factor s | solve s | total s | min total s | wall s "
               "| peak RSS MB | nnz(factor) | residual | u_A | rel. diff | load | notes |",
               "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
        for r in size_recs:
            notes = [] if r["status"] == "ok" else [r["status"]]
            notes += [f"{k}={r[k]}" for k in ("ordering", "iparm", "n_negative", "perturbed_pivots",
                                                   "refinement_steps")
                      if r.get(k) is not None]
            if r.get("end_to_end_s") is not None:
                notes.append(f"end-to-end {r['end_to_end_s']:.3g} s")
            md.append(f"| {r['system']} | {r['solver']} | {_fmt(r.get('nnz'), ',')} | {_fmt(r.get('analysis_s'))} "
                      f"| {_fmt(r.get('factor_s'))} | {_fmt(r.get('solve_s'))} | {_fmt(r.get('total_s'))} "
                      f"| {_fmt(r.get('min_total_s'))} | {_fmt(r.get('wall_s'))} | {_fmt(r.get('peak_rss_MB'), '.0f')} "
                      f"| {_fmt(r.get('factor_nnz'), '.3g')} | {_fmt(r.get('residual'), '.1e')} "
                      f"| {_fmt(r.get('u_A'), '.5g')} | {_fmt(r.get('rel_diff_vs_ref'), '.1e')} "
                      f"| {_fmt(r.get('loadavg_1min'), '.1f')} | {'; '.join(notes)} |")
        md.append("")

    md += ["## Assembly (fresh process per size; 'first' includes loading the numba cache)", "",
           "| n_z | vertices | DOFs | nnz(K) | Shell s | hessian first s | hessian warm s "
           "| loads+constraints first s | warm s | build peak RSS MB |", "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for b in builds:
        md.append(f"| {b['n_z']} | {b['n_vertices']:,} | {b['n_dofs']:,} | {b['K_nnz']:,} | {b['shell_s']:.2f} "
                  f"| {b['hessian_first_s']:.2f} | {b['hessian_warm_s']:.2f} | {b['constraints_first_s']:.2f} "
                  f"| {b['constraints_warm_s']:.2f} | {b['build_peak_rss_MB']:.0f} |")
    md += ["", "BLAS/LAPACK/MKL libraries mapped in each solver's process:", ""]
    md += [f"- {name}: {blas or 'none'}" for name, blas in
           dict((r["solver"], r["blas"]) for r in records if "blas" in r).items()]
    md += ["", f"total = analysis + factor + solve (median; min total = fastest run); load = 1-minute load "
           "average when the run started (2 CPUs; a solver run itself brings it towards 2, more means other work competed); wall = the whole timed call including imports and library/MPI "
           f"start-up. Reference u_A (radial displacement at A) = {U_A_REFERENCE:.4e}; the spd system is a "
           "different (clamped-ring) problem. rel. diff = ||u - u_ref|| / ||u_ref|| against "
           f"{REFERENCE['kkt']} (kkt) and {REFERENCE['spd']} (spd).", "", f"JSON: {out_path}"]
    print("\n".join(md))
    save()


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
