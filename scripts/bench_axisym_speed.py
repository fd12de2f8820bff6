"""Speed of the thesis's hemisphere load paths (start -> limit point -> unloading to half the limit load, or until
the path can no longer be continued), median of several runs.

    .venv/bin/python scripts/bench_axisym_speed.py [--repeat 3] [--json out/axisym_speed.json]
"""
import argparse
import json
import platform
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from graspdef.axisym.bench import hemisphere_path  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", default="out/axisym_speed.json")
    args = ap.parse_args()
    rows = []
    for case in ("edge_couple", "ring", "uniform"):
        times, p, m = [], None, None
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            m, p = hemisphere_path(case)
            times.append(time.perf_counter() - t0)
        d = m.build()
        iters = sum(q.iterations for q in p.points)
        row = dict(case=case, median_seconds=round(statistics.median(times), 3), runs=[round(t, 3) for t in times],
                   steps=len(p.points) - 1, newton_iterations=iters, pieces=int(d.batch["L"].size),
                   rk_steps_per_piece=d.nsteps, dofs=int(d.free.size),
                   limit=p.limits[0]["lam"] if p.limits else None, ended_by=p.stopped_by[:120] or "unloading")
        rows.append(row)
        print(f"{case:12s} median {row['median_seconds']:6.2f} s  ({row['steps']} steps, {iters} Newton iterations,"
              f" {row['pieces']} pieces x {d.nsteps} RK4 steps, {row['dofs']} free dofs), limit {row['limit']:.5g}")
    out = Path(args.json)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(dict(machine=platform.platform(), python=platform.python_version(), paths=rows),
                              indent=1))
    print(f"wrote {out}")


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
