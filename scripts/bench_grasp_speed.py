"""Speed of the tennis-ball grasp end to end (issue 5 target: <= 30 s): MuJoCo settle + mapping +
nonlinear neo-Hookean shell with enclosed air at 21.48 N per finger, each run in a fresh process
(numba's cache warm).  Prints each run and the median; saves JSON.

    python scripts/bench_grasp_speed.py [--runs 3] [--contact point|geometric] [--scene tennis_ball]
                                        [--out out/bench_grasp_speed.json]

``--contact geometric``: the fingertips as rigid obstacles (graspdef.contact.barrier); ``--scene
scenes/tennis_ball/scene_pad.xml`` for the pads.
"""
from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--out", default="out/bench_grasp_speed.json")
    ap.add_argument("--contact", default="point", choices=["point", "geometric"])
    ap.add_argument("--scene", default="tennis_ball")
    a = ap.parse_args()
    runs = []
    for k in range(a.runs + 1):                      # run 0 warms numba's on-disk cache
        t0 = time.perf_counter()
        res = subprocess.run([sys.executable, "-c", CHILD, f"out/bench_grasp_run{k}", a.contact, a.scene], capture_output=True, text=True)
        if res.returncode:
            print(res.stderr[-3000:], file=sys.stderr)
            raise SystemExit(f"run {k} failed")
        r = json.loads(res.stdout.strip().splitlines()[-1])
        r["wall_s"] = time.perf_counter() - t0
        print(f"run {k}{' (warm-up)' if k == 0 else ''}: wall {r['wall_s']:.1f} s; " +
              ", ".join(f"{n} {v:.1f} s" for n, v in r["timings"].items()) +
              f"; indentation {r['indentation_mm']:.2f} mm" +
              ("" if r["completed"] else " -- PATH STOPPED before the full force (not a valid timing)"), flush=True)
        if k:
            runs.append(r)
    if not all(r["completed"] for r in runs):
        raise SystemExit("some runs stopped before the full force: their times are not comparable")
    med = statistics.median(r["wall_s"] for r in runs)
    print(f"median wall time over {a.runs} runs: {med:.1f} s (target 30 s)")
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps({"contact": a.contact, "scene": a.scene, "runs": runs, "median_wall_s": med},
                                      indent=2) + "\n")


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
