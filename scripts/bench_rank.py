"""Speed of ``graspdef rank``'s linear screen: candidates per minute at ~2,500 control vertices.

    python scripts/bench_rank.py [--repeats 3] [--candidates 2000] [--faces 5000]

Makes the object folder itself (the YCB mustard bottle of the README's tutorial, from
../shared/scans, exported as an STL in mm, ``graspdef object add --faces 5000``: 2,364 control
vertices), then ranks ``--candidates`` at 20 N ``--repeats`` times (no map, no recheck) and prints
the median of the screen's candidates per minute (the back-substitutions and every figure; the
one-off factorisation and set-up are reported apart).  Writes out/bench_rank.json.  Run it on a
quiet machine: the screen uses both cores."""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
SCANS = ROOT.parent / "shared" / "scans"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--candidates", type=int, default=2000)
    ap.add_argument("--faces", type=int, default=5000)
    a = ap.parse_args()
    from graspdef import runtime

    runtime.configure()
    import trimesh

    from graspdef.objects.add import add_object
    from graspdef.objects.data import MaterialSpec
    from graspdef.ranking import rank_object

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        m = trimesh.load(SCANS / "ycb_006_mustard_bottle" / "nontextured.ply")
        m.apply_scale(1000)
        m.export(tmp / "mustard_mm.stl")
        add_object("mustard", tmp / "mustard_mm.stl", tmp / "mustard", units="mm", thickness=0.0008,
                   material=MaterialSpec("neo_hookean", 300e6, 0.45, None, "README tutorial's assumption"),
                   mass=0.06, faces=a.faces)
        runs = []
        for k in range(a.repeats):
            r = rank_object(tmp / "mustard", 20.0, a.candidates, tmp / f"r{k}", with_map=False)
            runs.append({"candidates_per_minute": r["candidates_per_minute"], "timings_s": r["timings_s"],
                         "n_candidates": r["n_candidates"]})
            print(f"run {k + 1}: {r['n_candidates']} candidates, screen {r['timings_s']['screen']:.2f} s "
                  f"({r['candidates_per_minute']:.0f} per minute), factorisation and set-up "
                  f"{r['timings_s']['factor_and_setup']:.1f} s, control vertices {r['control_vertices']}", flush=True)
    med = statistics.median(x["candidates_per_minute"] for x in runs)
    out = {"object": "YCB 006 mustard bottle (README tutorial), --faces %d" % a.faces,
           "control_vertices": r["control_vertices"], "samples": r["samples"], "force_N": 20.0, "runs": runs,
           "median_candidates_per_minute": med,
           "median_factor_and_setup_s": statistics.median(x["timings_s"]["factor_and_setup"] for x in runs)}
    print(f"median: {med:.0f} candidates per minute at {r['control_vertices']} control vertices")
    (ROOT / "out").mkdir(exist_ok=True)
    (ROOT / "out" / "bench_rank.json").write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
