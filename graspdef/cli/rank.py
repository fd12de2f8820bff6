"""``graspdef rank OBJECT --force F [--candidates N] --out DIR``: where to grasp an object."""
from __future__ import annotations

import argparse

from ._common import progress

HELP = "rank antipodal grasp candidates of an object by the work its shell takes (linear screen)"
DESCRIPTION = ("Sample antipodal grasp candidates on the object's surface (within the gripper's opening and the "
               "friction cone), screen each with the linear shell (one factorisation, one back-substitution per "
               "candidate) and rank them: held ones first, by least work spent deforming the object.")


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("scene", help="an object folder (graspdef object add), a scene.xml, or a name under scenes/")
    ap.add_argument("--force", type=float, required=True, help="squeezing force per finger [N]")
    ap.add_argument("--candidates", type=int, default=2000, help="how many candidates to screen (2000)")
    ap.add_argument("--top", type=int, default=10, help="how many to print (10)")
    ap.add_argument("--out", required=True, help="folder to write: ranking.csv, ranking.json (replaced if it exists)")


def run(a: argparse.Namespace) -> int:
    import sys

    from ..ranking import rank_object

    def say(stage, info=None):
        if stage == "candidate":
            if not getattr(a, "quiet", False) and (info["done"] % 100 == 0 or info["done"] == info["of"]):
                print(f"\r[graspdef]   screened {info['done']} / {info['of']}", end="" if info["done"] < info["of"]
                      else "\n", file=sys.stderr, flush=True)
        else:
            progress(a, {"candidates": "sampling antipodal candidates", "factor": "factorising the shell's "
                         "stiffness"}.get(stage, stage))

    r = rank_object(a.scene, a.force, a.candidates, a.out, a.top, progress=say)
    print(f"{r['object']}: {r['n_candidates']} candidates at {r['force_N']:g} N per finger, friction {r['friction']:g}; "
          f"screened {r['candidates_per_minute']:.0f} per minute ({r['control_vertices']} control vertices)")
    print(f"{'rank':>4} {'width mm':>8} {'angle deg':>9} {'indent mm':>9} {'work mJ':>8} {'k N/mm':>7} {'torque':>6}")
    for row in r["top"]:
        print(f"{row['rank']:4d} {row['width_m'] * 1e3:8.1f} {row['antipodal_angle_deg']:9.1f} "
              f"{row['indentation_per_finger_m'] * 1e3:9.3f} {row['work_J'] * 1e3:8.3f} "
              f"{row['grasp_stiffness_N_per_m'] * 1e-3:7.2f} {row['weight_torque_ratio']:6.2f}")
    print(f"ranking: {r['out']}/ranking.csv")
    return 0
