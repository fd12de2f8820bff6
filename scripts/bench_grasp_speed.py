"""Speed of the tennis-ball grasp end to end (issue 5 target: <= 30 s): MuJoCo settle + mapping +
nonlinear neo-Hookean shell with enclosed air at 21.48 N per finger, each run in a fresh process
(numba's cache warm).  Prints each run and the median; saves JSON.

    python scripts/bench_grasp_speed.py [--runs 3] [--contact point|geometric] [--scene tennis_ball]
                                        [--ref GIT_REF] [--out out/bench_grasp_speed.json]

``--contact geometric``: the fingertips as rigid obstacles (graspdef.contact.barrier); ``--scene
scenes/tennis_ball/scene_pad.xml`` for the pads.  ``--ref GIT_REF``: also run the OLD code of that
git ref (a temporary worktree), OLD and NEW alternating run by run on the same machine; each
tree's numba cache is warmed by one untimed run.
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
t0 = time.perf_counter()
from graspdef.pipeline import run_grasp
r = run_grasp(sys.argv[3], 21.48, sys.argv[2], "nonlinear", sys.argv[1]).result
r["timings_s"]["with_imports"] = time.perf_counter() - t0
print(json.dumps({"timings": r["timings_s"], "indentation_mm": r["feedback"]["indentation_per_finger_m"] * 1e3,
                  "completed": r["convergence"]["completed"], "contact_area_m2": r["derived"].get("contact_area", {}).get("value"),
                  "iterations": r["convergence"].get("newton_iterations"),
                  "factorisations": r["convergence"].get("n_factorisations")}))
"""


def _run(k: int, tree: Path, a) -> dict:
    """One fresh process of the grasp in ``tree`` (its graspdef on PYTHONPATH)."""
    t0 = time.perf_counter()
    env = tree_env(tree)          # the tree's own runtime.configure() (scripts/_trees.py)
    env.setdefault("GRASPDEF_SHARED_SCANS", str(ROOT.parent / "shared" / "scans"))   # the OLD tree's ../shared is not there
    res = subprocess.run([sys.executable, "-c", CHILD, f"out/bench_grasp_run{k}", a.contact, a.scene], capture_output=True,
                         text=True, cwd=tree, env=env)
    if res.returncode:
        print(res.stderr[-3000:], file=sys.stderr)
        raise SystemExit(f"run {k} in {tree} failed")
    r = json.loads(res.stdout.strip().splitlines()[-1])
    r["wall_s"] = time.perf_counter() - t0
    return r


def _show(label: str, k: int, r: dict) -> None:
    print(f"{label} run {k}: wall {r['wall_s']:.1f} s; " + ", ".join(f"{n} {v:.1f} s" for n, v in r["timings"].items()) +
          f"; indentation {r['indentation_mm']:.4f} mm; {r['factorisations']} factorisations" +
          ("" if r["completed"] else " -- PATH STOPPED before the full force (not a valid timing)"), flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--out", default="out/bench_grasp_speed.json")
    ap.add_argument("--contact", default="point", choices=["point", "geometric"])
    ap.add_argument("--scene", default="tennis_ball")
    ap.add_argument("--ref", default=None, help="git ref of OLD code to run beside the working tree's")
    a = ap.parse_args()
    with code_trees(ROOT, a.ref, "bench_grasp_") as trees:
        runs: dict[str, list] = {k: [] for k in trees}
        for label, tree in trees.items():            # warm each tree's numba on-disk cache (not timed)
            _show(label + " (warm-up)", 0, _run(0, tree, a))
        for k in range(1, a.runs + 1):
            for label, tree in trees.items():
                r = _run(k, tree, a)
                runs[label].append(r)
                _show(label, k, r)
    med = {}
    for label, rs in runs.items():
        if not all(r["completed"] for r in rs):
            raise SystemExit(f"{label}: some runs stopped before the full force: their times are not comparable")
        med[label] = statistics.median(r["wall_s"] for r in rs)
        print(f"{label}: median wall time over {a.runs} runs: {med[label]:.1f} s (indentation "
              f"{rs[0]['indentation_mm']:.4f} mm, {rs[0]['factorisations']} factorisations)")
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps({"contact": a.contact, "scene": a.scene, "ref": a.ref, "runs": runs,
                                       "median_wall_s": med}, indent=2) + "\n")


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
