"""Speed of a nonlinear path: a neo-Hookean rubber sphere (R = 32.5 mm, t = 2.5 mm, E = 1 MPa,
the paper's tennis-ball dimensions) squeezed by two opposite point forces up to 20 N in 20 load
steps (issue 3's speed case).  Prints and saves (JSON) the wall time of each run -- set-up,
path, per-step Newton iterations -- and their median.

    python scripts/bench_nonlinear_speed.py [--subdivisions 5] [--runs 3] [--gas-kpa 80] [--fixed-steps] [--krylov 10]
                                            [--predictor cubic]
                                            [--ref GIT_REF] [--out out/bench_nonlinear_speed.json]

``--ref``: also run the OLD code of that git ref (checked out into a temporary worktree), its runs
interleaved with the NEW code's (the working tree), and print both side by side (one untimed run of
each tree, at up to 2,562 control vertices, first warms its numba cache).

``--predictor cubic|quadratic|linear``: PathOptions.predictor (an OLD tree without that predictor runs
its default).  ``--krylov N`` (10 unless given): the path takes inexact Newton steps (PathOptions.krylov = N, off in
the solver's default; code before them ignores it).  ``--krylov 0``: the solver's default path.

subdivisions 5 gives 10,242 control vertices.  The ball holds air (80 kPa gauge by default, a
tennis ball's): without it the path turns at a limit point near 3 N (the pole inverts) and never
reaches 20 N.  Runs are separate processes (numba's compile
cache warm, no shared state)."""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from _trees import code_trees, tree_env       # scripts/_trees.py: the working tree and --ref's worktree

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import json, sys, time
t0 = time.perf_counter()
import numpy as np
from graspdef.geometry import sphere
from graspdef.problem.loads import PointLoad
from graspdef.problem.potentials import EnclosedGas
from graspdef.problem.problem import Problem
from graspdef.problem.supports import RigidModes
from graspdef.shell.hyperelastic import NeoHookean
from graspdef.shell.model import Shell
from graspdef.solve.nonlinear import PathOptions, solve_nonlinear
sub, steps, force, gas, fixed = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), sys.argv[5] == "1"
krylov = int(sys.argv[6]) if len(sys.argv) > 6 else 0
predictor = sys.argv[7] if len(sys.argv) > 7 else None
t_imp = time.perf_counter()
R, t = 0.0325, 0.0025
m = sphere(R, sub)
shell = Shell(m.vertices, m.faces, NeoHookean(1e6 / 3), t)
loads = [EnclosedGas(gas * 1e3)] if gas > 0 else []
pr = Problem(shell, loads, [RigidModes()])
top, bot = pr.locate((0, 0, R)), pr.locate((0, 0, -R))
pr.loads += [PointLoad(top.face, top.bary, (0, 0, -force)), PointLoad(bot.face, bot.bary, (0, 0, force))]
pr.probes["top"] = top
t_setup = time.perf_counter()
def show(i):
    print(f"  point {i['step']}: load factor {i['load_factor']:.4f}, {i['iterations']} Newton iterations, "
          f"{i['seconds']:.1f} s", file=sys.stderr, flush=True)
# fixed: the steps never grow (desired_iterations = 1), so the path takes exactly `steps` steps
opts = PathOptions(steps=steps, max_steps=10 * steps, **({"desired_iterations": 1} if fixed else {}),
                   # inexact Newton steps where the code has them (older code: ignored)
                   **({"krylov": krylov} if "krylov" in PathOptions.__dataclass_fields__ else {}))
if predictor is not None:
    import dataclasses
    from graspdef.solve import nonlinear as _nl
    if predictor in getattr(_nl, "PREDICTORS", ()):        # older code without it: its default
        opts = dataclasses.replace(opts, predictor=predictor)
sol = solve_nonlinear(pr, opts, progress=show)
t_end = time.perf_counter()
print(json.dumps({"n_control": int(shell.mesh.n_real), "import_s": t_imp - t0, "setup_s": t_setup - t_imp,
                  "path_s": t_end - t_setup, "total_s": t_end - t0, "steps": len(sol.path) - 1,
                  "newton_iterations": sol.iterations(), "factorisations": sol.n_factorisations,
                  # counters the code before inexact Newton steps did not keep: None there
                  "hessians": getattr(sol, "n_hessians", None),
                  "back_substitutions": getattr(sol, "n_back_substitutions", None),
                  # calls (a block of right-hand sides is one call); code before blocks: each was one
                  "back_calls": getattr(sol, "n_back_calls", getattr(sol, "n_back_substitutions", None)),
                  "inexact_steps": getattr(sol, "n_inexact", None), "gmres_iterations": getattr(sol, "n_krylov", None),
                  # local corrections (PathOptions.local_rings; code before them: None)
                  "local_steps": getattr(sol, "n_local", None),
                  "factor_s": sol.timings["factor"], "solve_s": sol.timings["solve"],
                  "top_displacement_mm": float(-sol.probe("top")[2] * 1e3),
                  "stable": [p.stable for p in sol.path]}))
"""


def _run(a, tree: Path) -> dict:
    t0 = time.perf_counter()
    env = tree_env(tree)          # the tree's own runtime.configure() (scripts/_trees.py)
    res = subprocess.run([sys.executable, "-c", CHILD, str(a.subdivisions), str(a.steps), str(a.force), str(a.gas_kpa),
                          "1" if a.fixed_steps else "0", str(a.krylov)] + ([a.predictor] if a.predictor else []),
                         cwd=tree, env=env,
                         stdout=subprocess.PIPE, stderr=None if a.verbose else subprocess.DEVNULL, text=True)
    if res.returncode:
        raise SystemExit(f"a run in {tree} failed")
    r = json.loads(res.stdout.strip().splitlines()[-1])
    r["wall_s"] = time.perf_counter() - t0
    return r


def _show(label: str, k: int, r: dict) -> None:
    print(f"{label} run {k + 1}: {r['n_control']} control vertices, path {r['path_s']:.1f} s (set-up {r['setup_s']:.1f} s, "
          f"factor {r['factor_s']:.1f} s, {r['factorisations']} factorisations), {r['steps']} steps, "
          f"Newton iterations {r['newton_iterations']}, "
          + (f"{r['hessians']} Hessians, {r['back_substitutions']} back-substitutions in {r.get('back_calls')} calls, {r['inexact_steps']} inexact "
             f"Newton steps ({r['gmres_iterations']} GMRES iterations), " if r.get("hessians") is not None else "")
          + (f"{r['local_steps']} local corrections, " if r.get("local_steps") is not None else "")
          + f"pole displacement {r['top_displacement_mm']:.2f} mm", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--subdivisions", type=int, default=5)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--force", type=float, default=20.0, help="each point force [N]")
    ap.add_argument("--gas-kpa", type=float, default=80.0, help="initial gauge pressure of enclosed air [kPa]")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--ref", default=None, help="git ref of OLD code to run beside the working tree's")
    ap.add_argument("--out", default="out/bench_nonlinear_speed.json")
    ap.add_argument("--fixed-steps", action="store_true",
                    help="exactly --steps equal load steps (by default the step grows after easy steps)")
    ap.add_argument("--verbose", action="store_true", help="show each run's progress")
    ap.add_argument("--krylov", type=int, default=10,
                    help="PathOptions.krylov: GMRES iterations of an inexact Newton step before a fresh factorisation "
                         "(0: none, the solver's default; code without the option ignores it)")
    ap.add_argument("--predictor", default=None, choices=["quadratic", "linear", "cubic"],
                    help="PathOptions.predictor (default: the solver's; code without the option uses its default)")
    a = ap.parse_args()
    with code_trees(ROOT, a.ref, "bench_nonlinear_") as trees:
        runs: dict[str, list] = {k: [] for k in trees}
        # warm numba's on-disk cache of each tree (not timed), on a mesh whose kernels take the same
        # build as the timed one's: from 5,120 faces (subdivisions 4) on the parallel JIT build
        # (graspdef.compiled.SERIAL_MAX).  Warmed at subdivisions 2 (the serial ahead-of-time build),
        # a fresh OLD worktree compiled its parallel kernels in its first timed run: 32-35 s against
        # 15-17 s for the next ones (2026-11-28)
        for tree in trees.values():
            _run(argparse.Namespace(**{**vars(a), "subdivisions": min(a.subdivisions, 4), "steps": 2}), tree)
        for k in range(a.runs):
            for label, tree in trees.items():
                r = _run(a, tree)
                runs[label].append(r)
                _show(label, k, r)
    keys = ("path_s", "setup_s", "total_s", "factor_s", "factorisations", "steps")
    med = {label: {key: statistics.median(r[key] for r in rs) for key in keys} for label, rs in runs.items()}
    for label, m in med.items():
        print(f"{label}: median over {a.runs} runs: path {m['path_s']:.1f} s, set-up {m['setup_s']:.1f} s, "
              f"total (incl. imports) {m['total_s']:.1f} s, {m['steps']:.0f} steps, {m['factorisations']:.0f} factorisations, "
              f"pole displacement {runs[label][0]['top_displacement_mm']:.3f} mm")
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps({"case": vars(a), "runs": runs, "median": med}, indent=2) + "\n")
    print(f"wrote {a.out}")


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
