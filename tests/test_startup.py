"""Start-up stays cheap (issue 17): what a fresh process imports for ``import graspdef``, for the
command line's parser, for ``graspdef --help`` and for a linear plate solve.

Each case runs in a new interpreter and reads ``sys.modules`` at its end: an invariant of the code,
not a time (scripts/bench_startup.py measures the times).  The plate solve is also checked against
Navier's series for the simply supported plate, and against the same solve in a process that
imported the heavy packages first (lazy imports change no number)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from graspdef.cli import COMMANDS, build_parser, command_module, requested_command

ROOT = Path(__file__).resolve().parents[1]
PLATE = ROOT / "benchmarks" / "plate_ss_uniform.toml"
#: packages that only some subcommands need; none may load for ``import graspdef`` or ``--help``
HEAVY = ("trimesh", "open3d", "mujoco", "viser", "dask", "distributed", "matplotlib", "numba", "numpy", "scipy")
#: packages a linear solve of a problem file has no use for
NOT_FOR_A_SOLVE = ("trimesh", "open3d", "mujoco", "viser", "dask", "distributed", "matplotlib", "pymeshlab", "coacd",
                   "scipy.spatial",     # (locating a probe or a load needs no KD-tree: 0.12 s of start-up)
                   "numba")             # (its kernels run from the ahead-of-time module: 0.5 s of start-up)

#: the tail of every probe: which of the watched modules, and which subcommand modules, are loaded
REPORT = ("\nimport json, sys\n"
          "print(json.dumps({'loaded': sorted(m for m in WATCH if m in sys.modules),\n"
          "                  'cli': sorted(m for m in sys.modules if m.startswith('graspdef.cli.'))}))\n")


#: one thread for numba, OpenMP, MKL (PARDISO) and OpenBLAS: the threaded solve's sums may be ordered
#: differently from run to run (the plate's centre deflection by ~1e-13 of itself); a single-threaded
#: one is the same to the bit in every run, so two runs can be compared exactly
ONE_THREAD = {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}


def _loaded(body: str, watch: tuple[str, ...], env_extra: dict | None = None) -> dict:
    """Run ``body`` in a fresh interpreter (in the repository) and return what it left loaded."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("OMP_WAIT_POLICY", "PYPARDISO_MKL_RT", "NUMBA_THREADING_LAYER")} | (env_extra or {})
    code = f"WATCH = {watch!r}\n{body}{REPORT}"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=ROOT,
                       check=False)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_import_graspdef_loads_no_heavy_package():
    out = _loaded("import graspdef\n", HEAVY)
    assert out == {"loaded": [], "cli": []}


def test_every_room_is_a_lazy_attribute():
    """``graspdef.<room>`` works for every room of ARCHITECTURE.md (but cli and testing), and
    ``import graspdef`` imports none of them (the attribute imports it on first use)."""
    rooms = {p.stem for p in (ROOT / "graspdef").iterdir()
             if (p.suffix == ".py" or (p / "__init__.py").is_file()) and not p.name.startswith("__")}
    out = _loaded("import graspdef\nWATCH = tuple(f'graspdef.{r}' for r in graspdef._SUBPACKAGES)\n", HEAVY)
    assert out["loaded"] == []
    import graspdef
    assert rooms - {"cli", "testing", "errors"} == graspdef._SUBPACKAGES
    assert graspdef._SUBPACKAGES <= set(dir(graspdef))
    assert graspdef.units.length_scale("mm") == 1e-3


def test_building_the_whole_parser_loads_no_heavy_package():
    """``build_parser()`` imports every subcommand module, and they import their libraries only in ``run``."""
    out = _loaded("import graspdef.cli\ngraspdef.cli.build_parser()\n", HEAVY)
    assert out["loaded"] == []
    assert len(out["cli"]) >= len(COMMANDS)


def test_help_imports_no_subcommand_module():
    body = ("import contextlib, io\nfrom graspdef.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            "    try:\n        main(['--help'])\n    except SystemExit as e:\n        assert e.code == 0, e.code\n")
    out = _loaded(body, HEAVY)
    assert out == {"loaded": [], "cli": []}


def test_help_lists_every_subcommand_with_its_line():
    r = subprocess.run([sys.executable, "-m", "graspdef.cli", "--help"], capture_output=True, text=True, cwd=ROOT,
                       check=False)
    assert r.returncode == 0, r.stderr
    text = " ".join(r.stdout.split())                      # argparse wraps the lines
    for name, (_, line) in COMMANDS.items():
        assert f"{name} {' '.join(line.split())}" in text, name


def test_every_subcommand_module_has_the_protocol():
    for name in COMMANDS:
        mod = command_module(name)
        assert isinstance(mod.DESCRIPTION, str) and mod.DESCRIPTION, name
        assert callable(mod.add_arguments) and callable(mod.run), name


@pytest.mark.parametrize("argv", [
    ["solve", "benchmarks/plate_ss_uniform.toml", "--out", "out/plate"],
    ["-q", "solve", "p.toml", "--out", "o", "--backend", "superlu"],
    ["bench", "linear", "--json", "b.json"],
    ["grasp", "tennis_ball", "--force", "21.48", "--out", "g"],
    ["object", "show", "tennis_ball"],
    ["sweep", "sweeps/smoke.toml", "--out", "s", "--workers", "2"],
    ["rank", "mustard", "--force", "20", "--out", "r"],
    ["view", "out/plate", "--port", "8081"],
    ["report", "out/plate"],
    ["score", "a.ply", "ycb_056_tennis_ball", "--out", "sc"],
    ["fit", "tennis_ball", "--data", "t.csv", "--params", "E,pressure", "--analysis", "linear", "--out", "f"],
])
def test_the_one_subcommand_parser_parses_as_the_whole_one(argv):
    """The parser ``main`` builds (the requested subcommand's arguments alone) gives the same
    namespace as the parser with every subcommand."""
    assert requested_command(argv) == next(a for a in argv if not a.startswith("-"))
    whole = vars(build_parser().parse_args(argv))
    one = vars(build_parser([requested_command(argv)]).parse_args(argv))
    assert one == whole


def test_requested_command():
    assert requested_command([]) is None
    assert requested_command(["--help"]) is None
    assert requested_command(["-q", "-h"]) is None
    assert requested_command(["nosuch", "x"]) is None
    assert requested_command(["-q", "object", "add", "solve"]) == "object"


def _solve_plate(out: Path, preload: str = "") -> tuple[dict, dict]:
    """Solve the plate into ``out`` in a fresh single-threaded process (after ``preload``): what it
    left loaded, and its result.json."""
    body = (f"{preload}\nfrom graspdef.cli import main\n"
            f"assert main(['-q', 'solve', {str(PLATE)!r}, '--out', {str(out)!r}]) == 0\n")
    loaded = _loaded(body, NOT_FOR_A_SOLVE, ONE_THREAD)
    return loaded, json.loads((out / "result.json").read_text())


@pytest.fixture(scope="module")
def lazy_plate(tmp_path_factory):
    out = tmp_path_factory.mktemp("startup") / "plate"
    return out, *_solve_plate(out)


def test_plate_solve_loads_only_what_it_uses(lazy_plate):
    """``graspdef solve`` of the Tian & Jia plate imports its own subcommand alone and none of the
    packages of mesh files, scenes, viewers, clusters or plots; its centre deflection is Navier's
    (Timoshenko & Woinowsky-Krieger: w = 0.00406235 q L^4 / D, in the problem file's [reference])."""
    _, loaded, rec = lazy_plate
    assert loaded == {"loaded": [], "cli": ["graspdef.cli._common", "graspdef.cli.solve"]}
    ref = tomllib.loads(PLATE.read_text())["reference"]
    w = rec["probes"]["centre"]["displacement"][2]
    assert abs(w - ref["value"]) <= ref["tolerance"] * ref["value"], (w, ref["value"])


def test_lazy_imports_change_no_number(lazy_plate, tmp_path):
    """The same solve in a process that imported the heavy packages first (as the code did before
    they became lazy): the same probe, largest displacement and deformed surface, to the last bit
    (both single-threaded, see ONE_THREAD)."""
    out, _, lazy = lazy_plate
    loaded, eager = _solve_plate(tmp_path / "eager", preload="import trimesh, scipy.spatial, scipy.stats")
    assert "trimesh" in loaded["loaded"]
    assert lazy["n_control"] == eager["n_control"] == 1681
    assert lazy["probes"] == eager["probes"]
    assert lazy["derived"]["max_displacement"] == eager["derived"]["max_displacement"]
    assert (out / "deformed.ply").read_bytes() == (tmp_path / "eager" / "deformed.ply").read_bytes()


def test_both_kernel_builds_give_the_same_plate_to_the_bit(lazy_plate, tmp_path):
    """The plate in a process whose kernels ran ahead of time (no numba, no GNU OpenMP; lazy_plate)
    and in one forced onto numba's parallel JIT build first (GNU OpenMP loaded before MKL): the same
    result to the bit (both single-threaded).  The kernels agree to the bit (tests/test_compiled.py);
    PARDISO did not until runtime.configure fixed MKL's threading layer (MKL_THREADING_LAYER=GNU):
    with MKL choosing by itself, the free-edge pull-out's solution differed in its last bits."""
    out, _, lazy = lazy_plate
    loaded, jit = _solve_plate(tmp_path / "jit", preload="import graspdef.compiled as c\nc.SERIAL_MAX = -1")
    assert lazy["derived"]["max_displacement"] == jit["derived"]["max_displacement"]
    assert lazy["probes"] == jit["probes"]
    assert (out / "deformed.ply").read_bytes() == (tmp_path / "jit" / "deformed.ply").read_bytes()


def _fresh_json(code: str, unset: str, extra: dict | None = None):
    """Run ``code`` in a fresh interpreter with the environment variable ``unset`` removed (and
    ``extra`` added); returns the JSON of its last printed line."""
    env = {k: v for k, v in os.environ.items() if k != unset} | (extra or {})
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=ROOT, check=False)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_configure_fixes_openblas_threads_unless_the_user_did():
    """graspdef.runtime.configure sets OPENBLAS_NUM_THREADS=1 when it is unset, keeps a user's
    value, and says whether it came before numpy's first import (only then does OpenBLAS read it)."""
    code = ("import json, os\nfrom graspdef import runtime\n{pre}r = runtime.configure()\n"
            "print(json.dumps([os.environ['OPENBLAS_NUM_THREADS'], r['OPENBLAS_NUM_THREADS'], r['blas_threads_fixed']]))")

    def run(pre="", extra=None):
        return _fresh_json(code.format(pre=pre), "OPENBLAS_NUM_THREADS", extra)

    assert run() == ["1", "1", True]
    assert run(extra={"OPENBLAS_NUM_THREADS": "2"}) == ["2", "2", True]
    assert run(pre="import numpy\n") == ["1", "1", False]


def test_configure_keeps_mujoco_from_loading_opengl_unless_the_user_chose():
    """graspdef never renders with MuJoCo: runtime.configure sets MUJOCO_GL=disable when it is
    unset, so that ``import mujoco`` loads no OpenGL backend (GLFW, PyOpenGL; checked in
    sys.modules of a fresh interpreter, where without it GLFW is loaded), and keeps a user's own
    choice (EGL loads PyOpenGL's EGL)."""
    code = ("import json, os, sys\nfrom graspdef import runtime\n{pre}import mujoco\n"
            "print(json.dumps([os.environ.get('MUJOCO_GL'), "
            "sorted({{m.split('.')[0] for m in sys.modules if m.split('.')[0] in ('glfw', 'OpenGL')}})]))")

    def run(pre="runtime.configure()\n", extra=None):
        return _fresh_json(code.format(pre=pre), "MUJOCO_GL", extra)

    assert run() == ["disable", []]
    assert run(pre="") == [None, ["glfw"]]                 # what configure saves: GLFW's import
    assert run(extra={"MUJOCO_GL": "egl"}) == ["egl", ["OpenGL"]]


def test_a_pardiso_solver_without_configure_does_not_search_for_mkl():
    """A library user who never calls ``runtime.configure``: creating PARDISO solvers must not
    make pypardiso search sys.prefix for MKL's runtime (a recursive glob, ~1 s per solver and
    2-4 s on a loaded machine) -- ``graspdef.solve.sparse`` names the library once.  Counted in a
    fresh interpreter with PYPARDISO_MKL_RT unset: pypardiso's recursive globs for ``mkl_rt``."""
    code = ("import glob, json, os\n"
            "calls = []\n_glob = glob.glob\n"
            "def counting(pattern, *a, **k):\n"
            "    if 'mkl_rt' in pattern: calls.append(pattern)\n"
            "    return _glob(pattern, *a, **k)\n"
            "glob.glob = counting\n"
            "from graspdef.solve import sparse\n"
            "ok = sparse.pardiso_available()\n"
            "solvers = [sparse._new_pardiso(2) for _ in range(3)] if ok else []\n"
            "print(json.dumps([ok, [c for c in calls if '**' in c], os.environ.get('PYPARDISO_MKL_RT')]))")
    env = {k: v for k, v in os.environ.items() if k != "PYPARDISO_MKL_RT"}
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=ROOT, check=False)
    assert r.returncode == 0, r.stderr
    ok, recursive, named = json.loads(r.stdout.strip().splitlines()[-1])
    if not ok:
        pytest.skip("pypardiso not installed")
    assert recursive == [], recursive
    assert named and Path(named).is_file(), named


def test_a_grasp_with_a_cached_control_mesh_imports_no_trimesh(tmp_path):
    """The tennis-ball grasp (point loads, linear) twice in fresh processes sharing a control-mesh
    cache (graspdef.scans.cache): the first remeshes the scan (trimesh), the second reads the cached
    mesh and never imports trimesh (~0.5 s of start-up); both give the same indentation to the bit
    (the mid-surface's normals are trimesh's, computed without it)."""
    body = ("import sys, json\nfrom graspdef.pipeline import run_grasp\n"
            f"r = run_grasp('tennis_ball', 10.0, 'point', 'linear', sys.argv[1] if len(sys.argv) > 1 else {str(tmp_path / 'x')!r}).result\n"
            "print(json.dumps({'d': r['feedback']['indentation_per_finger_m']}))\n")
    env = {"GRASPDEF_CACHE_DIR": str(tmp_path / "cache"), **ONE_THREAD}
    outs = []
    for k in range(2):
        code = f"WATCH = ('trimesh',)\n{body}{REPORT}"
        r = subprocess.run([sys.executable, "-c", code, str(tmp_path / f"run{k}")], capture_output=True, text=True,
                           env=os.environ | env, cwd=ROOT, check=False)
        assert r.returncode == 0, r.stderr[-3000:]
        lines = r.stdout.strip().splitlines()
        outs.append((json.loads(lines[-2])["d"], json.loads(lines[-1])["loaded"]))
    assert outs[0][1] == ["trimesh"] and outs[1][1] == []
    assert outs[0][0] == outs[1][0] > 0
