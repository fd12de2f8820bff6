"""Speed and memory of the linear solver on the pinched cylinder (full model, rigid diaphragms).

For each size the whole solve runs in a fresh subprocess (so peak memory is that solve's own)
several times; medians are reported:

* set-up: control mesh, ghost layer, Loop basis at the quadrature points, rest geometry;
* assembly: the Hessian at rest K (3x3-block sparse), the load vector and the support
  constraints C;
* solve: KKT factorisation and solve (PARDISO symmetric indefinite by default), as timed by
  ``solve_linear``;
* peak resident memory of the process (VmHWM; out of core plus its PARDISO worker's).

Targets (issue 2): 10,000 control vertices, assembly + solve <= 2 s; 100,000 control vertices
<= 60 s and <= 8 GB.  Writes ``bench_speed.json`` to ``--out``.

    python scripts/bench_speed.py [--sizes 70 224] [--repeats 5 3] [--ref GIT_REF --rounds 3] [--backend pardiso-ooc]
                                  [--collocation 2 1] [--out out/bench_speed]

``--ref GIT_REF``: also measure the OLD code of that git ref (a temporary worktree, scripts/_trees.py),
OLD and NEW processes alternating ``--rounds`` times per size; the table then has a row per tree and
the medians are over all of that tree's timed runs.

``--collocation 2 1``: the supports' collocation points per edge (``Problem.n_collocation``, a problem
file's ``[solver] collocation``; default 2), one row per value, the processes of the values alternating
like the trees'.  The cylinder's diaphragms are closed rings, where two points per edge give nearly
dependent rows, of which graspdef drops those within 1 % of the others' span
(``problem.supports.well_conditioned_rows``; until 2026-11-27 it replaced them by dense orthonormal
rows, which doubled the 100k factorisation), and one point per edge gives sparse, well-conditioned rows.
"""
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
n_z = int(sys.argv[1]); repeats = int(sys.argv[2])
sys.path.insert(0, sys.argv[3])
backend = sys.argv[4] if len(sys.argv) > 4 else "auto"
ncol = int(sys.argv[5]) if len(sys.argv) > 5 else 2
from convergence import pinched_cylinder_problem
from graspdef.solve.linear import solve_linear
runs = []
# the first run warms caches (numba, imports) and is dropped; out of core one timed run per process
# (its worker process, graspdef.solve.pardiso_ooc, counts in the peak below)
ooc = backend == "pardiso-ooc"
for rep in (range(repeats + 1) if not ooc else range(1, 2)):
    t0 = time.perf_counter()
    pr = pinched_cylinder_problem(n_z)
    pr.n_collocation = ncol
    t1 = time.perf_counter()
    sol = solve_linear(pr, backend=backend)
    t = sol.timings
    if rep:
        runs.append({"setup": t1 - t0, "assembly": t["assembly"] + t["loads_constraints"],
                     "solve": t["factor"] + t["solve"], "factor": t["factor"],
                     "u_A": float(-sol.probe("A")[0]), "n_dofs": int(pr.shell.n_dofs),
                     "m": int(len(sol.kkt.multipliers)), "n_control": int(pr.shell.mesh.n_real),
                     "backend": sol.kkt.backend})
peak = 0
for line in open("/proc/self/status"):
    if line.startswith("VmHWM"):
        peak = int(line.split()[1]) / 1024
# out of core the factor lives in a worker process, ended by now: its peak is added (an upper bound
# of the two processes' peak together, as each may have peaked at another time)
if ooc:
    import resource
    peak += resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
print(json.dumps({"runs": runs, "peak_MB": peak}))
"""


def _child(n_z: int, repeats: int, tree: Path, backend: str = "auto", ncol: int = 2) -> dict:
    """One fresh process of ``tree``'s code: ``repeats`` timed solves after a warm-up (out of core:
    ``repeats`` processes of one timed solve each, merged)."""
    env = tree_env(tree)          # the tree's own runtime.configure() (scripts/_trees.py)
    results = []
    for _ in range(repeats if backend == "pardiso-ooc" else 1):
        out = subprocess.run([sys.executable, "-c", CHILD, str(n_z), str(repeats), str(tree / "scripts"), backend, str(ncol)],
                             capture_output=True, text=True, check=True, cwd=tree, env=env)
        results.append(json.loads(out.stdout.strip().splitlines()[-1]))
    return {"runs": [r for d in results for r in d["runs"]], "peak_MB": max(d["peak_MB"] for d in results)}


def summarise(n_z: int, data: list[dict], t0: float) -> dict:
    """Medians over the timed runs of one or more processes of one tree."""
    runs = [r for d in data for r in d["runs"]]
    med = {k: statistics.median(r[k] for r in runs) for k in ("setup", "assembly", "solve", "factor")}
    first = runs[0]
    return {"n_z": n_z, "n_control": first["n_control"], "n_dofs": first["n_dofs"],
            "n_constraints": first["m"], "backend": first["backend"], "repeats": len(runs),
            "median": med, "assembly_plus_solve": statistics.median(r["assembly"] + r["solve"] for r in runs),
            "total": med["setup"] + med["assembly"] + med["solve"], "peak_MB": max(d["peak_MB"] for d in data),
            "u_A": first["u_A"], "rel_error": (first["u_A"] - 1.8248e-5) / 1.8248e-5,
            "wall_s": time.perf_counter() - t0}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", type=int, nargs="+", default=[70, 224], help="n_z values (n_theta = 2 n_z)")
    ap.add_argument("--repeats", type=int, nargs="+", default=[5, 3], help="timed runs per size")
    ap.add_argument("--ref", help="git ref of the OLD code to measure beside the working tree")
    ap.add_argument("--rounds", type=int, default=3, help="with --ref: OLD/NEW processes alternating per size")
    ap.add_argument("--backend", default="auto", help="sparse solver: auto, pardiso, pardiso-ooc (out of core), superlu")
    ap.add_argument("--collocation", type=int, nargs="+", default=[2],
                    help="collocation points per supported edge (one row per value; default 2)")
    ap.add_argument("--out", default="out/bench_speed")
    a = ap.parse_args()
    if min(a.collocation) < 1:
        ap.error(f"--collocation: points per edge must be positive integers, got {a.collocation}")
    reps = a.repeats + [a.repeats[-1]] * (len(a.sizes) - len(a.repeats))
    rows = []
    with code_trees(ROOT, a.ref, prefix="bench_speed_") as trees:
        for n_z, r in zip(a.sizes, reps):
            rounds = a.rounds if a.ref or len(a.collocation) > 1 else 1
            print(f"pinched cylinder n_z={n_z}: {rounds} x {r} timed runs per tree ({', '.join(trees)}) ...",
                  file=sys.stderr, flush=True)
            cases = [(name, ncol) for name in trees for ncol in a.collocation]
            data, t0 = {c: [] for c in cases}, time.perf_counter()
            for _ in range(rounds):
                for name, ncol in cases:                  # OLD first, then NEW, alternating
                    data[name, ncol].append(_child(n_z, r, trees[name], a.backend, ncol))
            for name, ncol in cases:
                label = name if a.collocation == [2] else f"{name}, collocation {ncol}"
                rows.append({"tree": label, "collocation": ncol, **summarise(n_z, data[name, ncol], t0)})
    print("| code | control vertices | dofs | constraints | set-up [s] | assembly [s] | solve [s] (factor) | assembly + solve [s] | peak memory [MB] | u_A error |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for x in rows:
        m = x["median"]
        print(f"| {x['tree']} | {x['n_control']} | {x['n_dofs']} | {x['n_constraints']} | {m['setup']:.2f} | {m['assembly']:.2f} | "
              f"{m['solve']:.2f} ({m['factor']:.2f}) | {x['assembly_plus_solve']:.2f} | {x['peak_MB']:.0f} | "
              f"{100 * x['rel_error']:+.3f} % |")
    print(f"medians of {', '.join(str(x['repeats']) for x in rows)} timed runs (" + ("one process each, out of core" if a.backend == "pardiso-ooc" else "each process after one warm-up run") + "), "
          f"backend {rows[0]['backend']}" + (f"; OLD = {a.ref}" if a.ref else ""))
    o = Path(a.out)
    o.mkdir(parents=True, exist_ok=True)
    (o / "bench_speed.json").write_text(json.dumps({"ref": a.ref, "rows": rows}, indent=2) + "\n")


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
