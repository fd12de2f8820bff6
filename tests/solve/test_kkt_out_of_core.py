"""PARDISO out of core (backend "pardiso-ooc", graspdef.solve.sparse): the factor goes to files in
a temporary folder and only OOC_CORE_MB of it stays in memory -- for problems whose in-core factor
does not fit (README "Speed": the 100k pinched cylinder; docs/speed.md, "Out of core").  Invariant: the solution is SuperLU's to
1e-10, the residual check passes, the inertia is that of the stable state; the files and the
process's environment are left as they were.

Each check runs in a fresh interpreter: a process holds one out-of-core solver, on MKL's sequential
layer, and no in-core PARDISO solver (graspdef.solve.sparse.require_one_ooc_handle and
require_sequential_mkl: a second out-of-core handle corrupted memory, and MKL's threads gave a
wrong out-of-core factor on a busy machine, together about 1 in 75 runs of this file until
2026-11-27; docs/speed.md, "Out of core").  Those interpreters end with os._exit once their answer is
printed, as ``graspdef solve`` does after an out-of-core solve (graspdef.cli.console).

The references are SuperLU's.  The right-hand sides are the plate's own load (a centre point
load)."""
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from graspdef.errors import ProblemError
from graspdef.solve.sparse import pardiso_available

ROOT = Path(__file__).resolve().parents[2]
needs_pardiso = pytest.mark.skipif(not pardiso_available(), reason="PARDISO (pypardiso + MKL) not installed")
#: ``graspdef solve --backend pardiso-ooc`` end to end: 9 of the 10 failures of this file in about
#: 1,050 runs of it in two loops side by side (2026-11-26 to 27; the tenth's test was not recorded)
#: came in these two tests -- a wrong factor caught by its check, a path refused at its first step, a
#: Python object overwritten, a wrong "completed" answer; then (2026-11-27, ninth session, MKL on its
#: sequential layer, one handle) 4 failures in 2,941 out-of-core processes, these tests' and standalone
#: ones: memory corruption in MKL's out-of-core mode, cause not found; not in `make test` until it is
#: (docs/speed.md, "Out of core"); `make test-ooc` runs them
OOC_CLI = pytest.mark.ooc_cli

PRELUDE = """
import json, os, sys
import numpy as np
from graspdef.problem.config import load_problem
from graspdef.solve.linear import rest_stiffness, solve_linear
from graspdef.solve.sparse import KKTSystem
from graspdef.testing import plate_problem
import graspdef.solve.sparse as sparse
OOC = ("MKL_PARDISO_OOC_PATH", "MKL_PARDISO_OOC_MAX_CORE_SIZE", "MKL_PARDISO_OOC_KEEP_FILE")
def plate(n):
    path = os.path.join(sys.argv[1], f"plate{n}.toml")
    open(path, "w").write(plate_problem(n=n))
    return load_problem(path).problem
def system(pr):
    K = rest_stiffness(pr)
    C, _, g = pr.constraints(with_targets=True)
    return K, C, g, pr.load_vector()
out = {}
"""


def _run(tmp_path, body: str) -> dict:
    """Run PRELUDE + body in a fresh interpreter (the repository on its path); body fills ``out``."""
    # the process ends with os._exit once its answer is printed: MKL's out-of-core mode has been seen to
    # crash a process at exit (1 of 60 with two such solvers) after correct results -- what is checked
    # here is the solutions, the folders and the environment (graspdef.cli.console does the same)
    code = PRELUDE + body + "\nprint(json.dumps(out), flush=True)\nos._exit(0)\n"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    r = subprocess.run([sys.executable, "-c", code, str(tmp_path)], capture_output=True, text=True, env=env,
                       cwd=tmp_path, timeout=300, check=False)
    assert r.returncode == 0, r.stderr[-3000:]
    return json.loads(r.stdout.strip().splitlines()[-1])


@needs_pardiso
def test_out_of_core_solution_equals_the_in_core_one(tmp_path):
    """The simply supported plate under a centre load: SuperLU's displacements (to 1e-10 of the
    largest), the residual check passed, the inertia of a stable state (one negative pivot per
    constraint); the environment as before.  Then, in another process (one out-of-core solver per
    process), one system factorised twice on one pattern (a Newton iteration's refactorisation): its
    folder holds the L factor's file while open and is gone after closing."""
    out = _run(tmp_path, """
pr = plate(16)
before = {k: os.environ.get(k) for k in OOC}
a = solve_linear(pr, backend="superlu")
b = solve_linear(pr, backend="pardiso-ooc")
out["backend"] = b.kkt.backend
out["du"] = float(np.abs(b.u - a.u).max() / np.abs(a.u).max())
out["neg"] = [b.kkt.n_negative, len(b.kkt.multipliers)]
out["residual"] = b.kkt.residual
out["env_same"] = {k: os.environ.get(k) for k in OOC} == before
""")
    assert out["backend"] == "pardiso-ooc"
    assert out["du"] <= 1e-10
    assert out["neg"][0] == out["neg"][1]
    assert out["residual"] <= 1e-8
    assert out["env_same"]
    out = _run(tmp_path, """
K, C, g, f = system(plate(8))
with KKTSystem(C, "superlu") as ref:
    ref.factor(K)
    u_ref = ref.solve(f, g)[0]
kkt = KKTSystem(C, "pardiso-ooc")
out["runs"] = []
for scale in (1.0, 2.0):
    kkt.factor(K * scale)
    folder = kkt._ooc_dir
    u, _, rel = kkt.solve(f, g)
    out["runs"].append({"lnz": any("lnz" in n for n in os.listdir(folder)), "rel": rel,
                        "du": float(np.abs(u * scale - u_ref).max() / np.abs(u_ref).max())})
kkt.close()
out["folder_gone"] = not os.path.exists(folder)
""")
    for r in out["runs"]:
        assert r["lnz"] and r["rel"] <= 1e-8 and r["du"] <= 1e-10, r
    assert out["folder_gone"]


@needs_pardiso
def test_too_little_memory_for_out_of_core_is_raised_to_pardisos_need(tmp_path):
    """An in-memory part below what PARDISO's out-of-core factorisation needs for the matrix (4 MB
    for the 40 x 40 plate; it needs 12,465 KB by its analysis, iparm 61, and measured, 12 MB fail
    with error -9 and 13 MB factorise) is raised to that need plus 10 % (14 MB) after the analysis,
    before the factorisation: no -9 (which is now an error: its old remedy, a second handle with
    more memory, is refused) and no second analysis, the same solution as SuperLU's.  Before
    2026-11-27 the -9 was the signal (the system closed, the memory doubled to 16 MB, the matrix
    analysed again), and this check failed in 3 of 260 processes; then 0 of 120."""
    out = _run(tmp_path, """
sparse.OOC_CORE_MB = 4
K, C, g, f = system(plate(40))
with KKTSystem(C, "superlu") as ref:
    ref.factor(K)
    u_ref = ref.solve(f, g)[0]
with KKTSystem(C, "pardiso-ooc") as kkt:
    kkt.factor(K)
    out["core_mb"] = kkt.ooc_core_mb
    u, _, out["rel"] = kkt.solve(f, g)
    folder = kkt._ooc_dir
out["du"] = float(np.abs(u - u_ref).max() / np.abs(u_ref).max())
out["folder_gone"] = not os.path.exists(folder)
""")
    assert 13 <= out["core_mb"] <= 16, out
    assert out["rel"] <= 1e-8 and out["du"] <= 1e-10
    assert out["folder_gone"]


@needs_pardiso
def test_the_out_of_core_folder_is_given_without_a_trailing_separator(tmp_path):
    """MKL 2026.2 writes one byte past a heap buffer when MKL_PARDISO_OOC_PATH ends in a separator
    (valgrind's memcheck: an invalid write of size 1 in ``mkl_pds_lp64_pardiso_ooc_read_cfg_file``
    for "/tmp/x/", none for "/tmp/x"); that byte corrupts whatever the heap has next to it.  Every
    PARDISO call of an out-of-core system sees its folder without the separator, an existing
    folder, where MKL puts its files (mkl_pardiso_*.bin).  (The failures that remained after this
    fix had two other causes: test_one_out_of_core_solver_per_process and
    test_out_of_core_runs_on_mkls_sequential_layer_and_only_there.)"""
    out = _run(tmp_path, """
seen = []
real = sparse.environment
def spy(values):
    path = values.get("MKL_PARDISO_OOC_PATH")
    if path is not None:
        seen.append([path, os.path.isdir(path), sorted(os.listdir(path))])
    return real(values)
sparse.environment = spy
K, C, g, f = system(plate(8))
with KKTSystem(C, "pardiso-ooc") as kkt:
    kkt.factor(K)
    kkt.solve(f, g)
out["seen"] = seen
""")
    seen = out["seen"]
    assert len(seen) >= 3                                     # analysis, factorisation, solution
    assert all(not p.endswith(os.sep) and is_dir for p, is_dir, _ in seen), seen
    assert any(name.startswith("mkl_pardiso_") for _, _, files in seen for name in files), seen


@needs_pardiso
def test_out_of_core_runs_on_mkls_sequential_layer_and_only_there(tmp_path):
    """An out-of-core solve puts MKL on its sequential threading layer (asked for GNU OpenMP
    afterwards, MKL answers with the layer in effect, 1, and one thread); in a process whose MKL
    already runs threaded (an in-core PARDISO solve first) an out-of-core system is refused with one
    line before any out-of-core call (graspdef.solve.sparse.require_sequential_mkl: threaded, the
    out-of-core factor came out wrong about once in 60 runs of this file on a busy machine)."""
    out = _run(tmp_path, """
K, C, g, f = system(plate(8))
with KKTSystem(C, "pardiso-ooc") as kkt:
    kkt.factor(K)
    out["rel"] = kkt.solve(f, g)[2]
    lib = kkt._solver.libmkl
    out["layer"] = int(lib.MKL_Set_Threading_Layer(3))
    out["threads"] = int(lib.MKL_Get_Max_Threads())
""")
    assert out["layer"] == 1 and out["threads"] == 1 and out["rel"] <= 1e-8
    out = _run(tmp_path, """
import tempfile
from graspdef.errors import SolverError
tempfile.tempdir = sys.argv[1]                  # an out-of-core folder would go here
K, C, g, f = system(plate(8))
with KKTSystem(C, "pardiso") as kkt:
    kkt.factor(K)
    out["rel"] = kkt.solve(f, g)[2]
try:
    with KKTSystem(C, "pardiso-ooc") as kkt:
        kkt.factor(K)
    out["error"] = None
except SolverError as exc:
    out["error"] = str(exc)
out["left"] = sorted(n for n in os.listdir(sys.argv[1]) if n.startswith("graspdef_pardiso_ooc_"))
""")
    assert out["rel"] <= 1e-8
    assert "sequential threading layer" in out["error"] and "process of its own" in out["error"], out
    assert "\n" not in out["error"] and out["left"] == []


@needs_pardiso
def test_one_out_of_core_solver_per_process(tmp_path):
    """A second out-of-core system in a process is refused with one line before it calls PARDISO
    (MKL 2026.2 corrupted memory in processes that made a second out-of-core handle:
    graspdef.solve.sparse.require_one_ooc_handle), after the first was closed as well as beside it;
    the first one's solution stands, and no folder is left behind."""
    out = _run(tmp_path, """
import tempfile
from graspdef.errors import SolverError
tempfile.tempdir = sys.argv[1]                  # the out-of-core folders go here
K, C, g, f = system(plate(8))
with KKTSystem(C, "superlu") as ref:
    ref.factor(K)
    u_ref = ref.solve(f, g)[0]
first = KKTSystem(C, "pardiso-ooc")
first.factor(K)
u = first.solve(f, g)[0]
out["du"] = float(np.abs(u - u_ref).max() / np.abs(u_ref).max())
out["errors"] = []
for close_first in (False, True):
    if close_first:
        first.close()
    try:
        with KKTSystem(C, "pardiso-ooc") as kkt:
            kkt.factor(K)
        out["errors"].append(None)
    except SolverError as exc:
        out["errors"].append(str(exc))
out["left"] = sorted(n for n in os.listdir(sys.argv[1]) if n.startswith("graspdef_pardiso_ooc_"))
""")
    assert out["du"] <= 1e-10
    for e in out["errors"]:
        assert e is not None and "one solver per process" in e and "process of its own" in e and "\n" not in e, out
    assert out["left"] == []


@needs_pardiso
def test_out_of_core_keeps_its_one_analysis(tmp_path):
    """One analysis per out-of-core system: a matrix whose pattern lies inside the analysed one (a
    Newton tangent with an entry fewer) is factorised on it and solved to SuperLU's answer; one
    with an entry outside it is refused with one line naming both counts; PARDISO's fallback
    settings (a fresh handle each) are not tried out of core."""
    out = _run(tmp_path, """
from graspdef.errors import SolverError
import scipy.sparse as sp
K, C, g, f = system(plate(8))
K = K.tocsr()
K.sort_indices()
# an off-diagonal pair dropped (symmetric): a pattern inside K's
i = 0
j = int(K.indices[K.indptr[0]:K.indptr[1]][-1])
fewer = K.tolil()
fewer[i, j] = 0.0
fewer[j, i] = 0.0
fewer = fewer.tocsr()
fewer.eliminate_zeros()
with KKTSystem(C, "superlu") as ref:
    ref.factor(fewer)
    u_ref = ref.solve(f, g)[0]
with KKTSystem(C, "pardiso-ooc") as kkt:
    kkt.factor(K)
    analysed = kkt._map
    kkt.factor(fewer)
    out["same_analysis"] = kkt._map is analysed
    u, _, out["rel"] = kkt.solve(f, g)
    out["du"] = float(np.abs(u - u_ref).max() / np.abs(u_ref).max())
    out["retry"] = kkt.retry_robust()
    n = K.shape[0]
    corner = sp.coo_matrix(([1e-3, 1e-3], ([0, n - 1], [n - 1, 0])), shape=K.shape)
    more = sparse.union_sum(K, corner)          # K's pattern (its explicit zeros kept) and two entries
    try:
        kkt.factor(more)
        out["error"] = None
    except SolverError as exc:
        out["error"] = str(exc)
    out["nnz"] = [int(K.nnz), int(more.nnz)]
""")
    assert out["same_analysis"] and out["rel"] <= 1e-8 and out["du"] <= 1e-10, out
    assert out["retry"] is False
    assert out["error"] is not None and "sparsity pattern changed" in out["error"], out
    assert out["nnz"][1] == out["nnz"][0] + 2
    assert f"{out['nnz'][0]:,}" in out["error"] and f"{out['nnz'][1]:,}" in out["error"]


def test_ooc_path_drops_the_trailing_separator():
    from graspdef.errors import SolverError
    from graspdef.solve.sparse import ooc_path

    assert ooc_path("/tmp/graspdef_pardiso_ooc_x/") == "/tmp/graspdef_pardiso_ooc_x"
    assert ooc_path("/tmp/graspdef_pardiso_ooc_x") == "/tmp/graspdef_pardiso_ooc_x"
    with pytest.raises(SolverError, match="root"):
        ooc_path("/")


def _solve_cli(tmp_path, path, backend: str) -> dict:
    """``graspdef solve PATH --backend BACKEND`` in a process of its own (the console script); its
    result.json, after requiring exit status 0."""
    r = subprocess.run([sys.executable, "-c", "from graspdef.cli import console; console()",
                        "-q", "solve", str(path), "--backend", backend,
                        "--out", str(tmp_path / backend)], capture_output=True, text=True, cwd=tmp_path,
                       env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=300, check=False)
    assert r.returncode == 0, (r.returncode, r.stderr[-3000:])
    return json.loads((tmp_path / backend / "result.json").read_text())


@OOC_CLI
@needs_pardiso
def test_graspdef_solve_out_of_core(tmp_path):
    """``graspdef solve --backend pardiso-ooc`` (a process of its own): the run folder records the
    backend and the same centre deflection as the in-core solve (to 1e-10 of it)."""
    from graspdef.testing import plate_problem

    path = tmp_path / "plate.toml"
    path.write_text(plate_problem(n=12))
    w = {}
    for backend in ("pardiso", "pardiso-ooc"):
        rec = _solve_cli(tmp_path, path, backend)
        assert rec["solver"]["backend"] == backend
        w[backend] = rec["probes"]["centre"]["displacement"][2]
    assert w["pardiso-ooc"] == pytest.approx(w["pardiso"], rel=1e-10, abs=0)


@OOC_CLI
@needs_pardiso
def test_graspdef_solve_out_of_core_follows_a_nonlinear_path(tmp_path):
    """A nonlinear path out of core (the cantilever rolled up by an end moment, to 0.1 of it in two
    steps): the run completes with the in-core path's tip displacement (to 1e-9 of it).  Its
    tangents used to fill the flat plate's exact zeros after the first step (31,203 -> 55,359
    non-zeros), and a second analysis crashed the process on the same handle (segmentation fault)
    and, on a fresh handle, corrupted memory in 2 of 281 processes; now the tangent keeps one
    pattern from the start (test_a_flat_shells_tangent_keeps_its_pattern) and one handle serves."""
    text = (ROOT / "benchmarks" / "nonlinear" / "cantilever_moment.toml").read_text()
    path = tmp_path / "cantilever.toml"
    path.write_text(text.replace("steps = 20", "steps = 2\nmax_load = 0.1"))
    w = {}
    for backend in ("pardiso", "pardiso-ooc"):
        rec = _solve_cli(tmp_path, path, backend)
        assert rec["convergence"]["completed"]
        w[backend] = rec["probes"]["tip"]["displacement"][0]
    assert w["pardiso-ooc"] == pytest.approx(w["pardiso"], rel=1e-9, abs=0)


def test_a_flat_shells_tangent_keeps_its_pattern():
    """The cantilever's tangent (shell + end moment + clamp) at rest, where the flat shell's Hessian
    has exact zeros, has the pattern it has bent: the equilibrium sums its terms on the union of
    their patterns with explicit zeros kept (graspdef.solve.sparse.union_sum; scipy's sum dropped
    them, 31,203 against 55,359 non-zeros), and the values are the sum's."""
    import numpy as np

    from graspdef.problem.config import load_problem
    from graspdef.solve.equilibrium import Equilibrium

    eq = Equilibrium(load_problem(ROOT / "benchmarks" / "nonlinear" / "cantilever_moment.toml").problem, backend="superlu")
    u = 1e-4 * np.random.default_rng(0).standard_normal(eq.X.size)
    H0, H1 = eq.evaluate(np.zeros_like(u), 0.05).hessian, eq.evaluate(u, 0.05).hessian
    assert H0.nnz == H1.nnz and np.array_equal(H0.indptr, H1.indptr) and np.array_equal(H0.indices, H1.indices)
    assert (H0.data == 0).sum() > 0.3 * H0.nnz                       # the rest state's exact zeros, kept
    parts = eq.evaluate(np.zeros_like(u), 0.05, keep_terms=True).terms
    total = sum(p.hessian.toarray() for p in parts if p.hessian is not None)
    assert np.array_equal(H0.toarray(), total)
    eq.close()


def test_the_backend_is_a_problem_file_setting(tmp_path):
    """[solver] backend = "pardiso-ooc" is accepted; a misspelt one is refused by name."""
    from graspdef.problem.config import load_problem
    from graspdef.testing import plate_problem

    path = tmp_path / "p.toml"
    path.write_text(plate_problem(n=4) + '[solver]\nbackend = "pardiso-ooc"\n')
    assert load_problem(path).backend == "pardiso-ooc"
    path.write_text(plate_problem(n=4) + '[solver]\nbackend = "pardiso_ooc"\n')
    with pytest.raises(ProblemError, match="pardiso-ooc"):
        load_problem(path)


def test_the_memory_check_allows_for_the_factor_on_disk():
    """A mesh refused in core is told about pardiso-ooc when out of core would fit, and accepted
    out of core (graspdef.shell.memory: 60 kB per vertex in core, 30 kB out of core, + 0.4 GB)."""
    from graspdef.shell.memory import check_memory

    have = 2.0 * 2**30                                      # 2 GiB free; 50,000 vertices: 3.4 / 1.9 GB
    with pytest.raises(ProblemError, match="pardiso-ooc") as exc:
        check_memory(50_000, "a mesh", available=have)
    assert "fewer faces" in str(exc.value)
    assert check_memory(50_000, "a mesh", available=have, out_of_core=True) == pytest.approx(0.4e9 + 50_000 * 30e3)
    with pytest.raises(ProblemError, match="out of core") as exc:                  # too large either way
        check_memory(200_000, "a mesh", available=have, out_of_core=True)
    assert "pardiso-ooc" not in str(exc.value)


def test_a_killed_solves_factor_folder_is_removed_by_the_next_one(tmp_path):
    """A process killed during an out-of-core solve leaves its factor files (its KKTSystem never
    closes): the next out-of-core folder removes the folders of processes that no longer run once
    they are an hour old, and keeps recent ones, those of running processes and any other folder."""
    from graspdef.solve.sparse import OOC_PREFIX, OOC_STALE_S, ooc_folder

    p = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True,
                       check=True)
    dead = tmp_path / f"{OOC_PREFIX}{int(p.stdout)}_abc"                  # that process has ended
    (dead / "sub").mkdir(parents=True)
    (dead / "mkl_pardiso_lnz.bin").write_bytes(b"\0" * 1000)
    recent = tmp_path / f"{OOC_PREFIX}{int(p.stdout)}_ghi"               # the same, touched just now
    recent.mkdir()
    alive = tmp_path / f"{OOC_PREFIX}{os.getpid()}_def"
    alive.mkdir()
    other = tmp_path / f"{OOC_PREFIX}notapid"
    other.mkdir()
    old = time.time() - OOC_STALE_S - 60
    for f in (dead, dead / "mkl_pardiso_lnz.bin", alive, other):
        os.utime(f, (old, old))
    new = ooc_folder(str(tmp_path))
    assert not dead.exists() and recent.exists() and alive.exists() and other.exists()
    assert os.path.basename(new).startswith(f"{OOC_PREFIX}{os.getpid()}_") and os.path.isdir(new)
