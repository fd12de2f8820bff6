"""Peak memory of a nonlinear solve against the control-vertex count: the measurements behind
graspdef.shell.memory's estimate (400 MB + 60 kB per control vertex, chosen above them).

    python scripts/memory_estimate.py            # levels 3..6 of an icosphere, one process each
    python scripts/memory_estimate.py 3 4 5      # chosen levels

Each size runs in a fresh process (peak resident set size, ru_maxrss): a compressible neo-Hookean
sphere (R 30 mm, t 2 mm, E 1 MPa, nu 0.45) pinched by two 0.5 N point loads, rigid modes removed,
one load step of the path solver.  Prints a table and writes out/memory_estimate.json (bytes).
Do not run it while other heavy jobs share the machine (the solve's threads)."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

CHILD = r"""
import resource, sys, time
from graspdef import runtime
runtime.configure()
from graspdef.geometry import icosphere
from graspdef.problem.loads import PointLoad
from graspdef.problem.problem import Problem
from graspdef.problem.supports import RigidModes
from graspdef.shell.hyperelastic import CompressibleNeoHookean
from graspdef.shell.model import Shell
from graspdef.solve.nonlinear import PathOptions, solve_nonlinear
m = icosphere(0.03, int(sys.argv[1]))
sh = Shell(m.vertices, m.faces, CompressibleNeoHookean.from_E_nu(1e6, 0.45), 0.002)
free = Problem(sh, [], [RigidModes()])
a, b = free.locate((0.03, 0, 0), "a", tol=1e-3), free.locate((-0.03, 0, 0), "b", tol=1e-3)
pr = Problem(sh, [PointLoad(a.face, a.bary, (-0.5, 0, 0)), PointLoad(b.face, b.bary, (0.5, 0, 0))], [RigidModes()])
t = time.perf_counter()
solve_nonlinear(pr, PathOptions(steps=1, max_steps=4))
print(len(m.vertices), resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024, time.perf_counter() - t)
"""


def main(levels) -> None:
    from graspdef.shell.memory import memory_estimate

    rows = []
    print(f"{'vertices':>9} {'peak MB':>9} {'estimate MB':>12} {'solve s':>8}")
    for lvl in levels:
        out = subprocess.run([sys.executable, "-c", CHILD, str(lvl)], capture_output=True, text=True, check=True)
        n, peak, secs = out.stdout.split()
        n, peak, secs = int(n), float(peak), float(secs)
        rows.append({"level": lvl, "control_vertices": n, "peak_bytes": peak, "estimate_bytes": memory_estimate(n),
                     "solve_s": secs})
        print(f"{n:9d} {peak / 2**20:9.0f} {memory_estimate(n) / 2**20:12.0f} {secs:8.1f}", flush=True)
    (ROOT / "out").mkdir(exist_ok=True)
    (ROOT / "out" / "memory_estimate.json").write_text(json.dumps({"units": {"memory": "bytes", "time": "s"},
                                                                   "rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [3, 4, 5, 6])
