"""``graspdef rank OBJECT --force F [--candidates N] --out DIR``: where to grasp an object."""
from __future__ import annotations

import argparse

from ._common import progress

DESCRIPTION = ("Sample antipodal grasp candidates on the object's surface (within the gripper's opening and the "
               "friction cone, reachable from outside), screen each with the linear shell (one factorisation, "
               "back-substitutions in blocks) and rank them: those that hold (deformed friction margin, the "
               "weight's torque and slip, the strain limit) first, by least work spent deforming the object. "
               "Writes a ranking folder (ranking.csv/json, compliance.ply, shapes.npz) for graspdef view and "
               "graspdef report.")


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("scene", help="an object folder (graspdef object add), a scene.xml, or a name under scenes/")
    how_hard = ap        # --force or --force-range: checked by rank_object (one line, exit 2)
    how_hard.add_argument("--force", help="squeezing force per finger, e.g. 20 or 20N")
    how_hard.add_argument("--force-range", nargs=2, metavar=("A", "B"), help="a range of forces per finger, e.g. "
                          "2N 40N: each candidate at the least force in it that holds the object against its "
                          "weight (slip and twist), ranked by the work at that force")
    ap.add_argument("--candidates", type=int, default=2000, help="how many candidates to screen (2000)")
    ap.add_argument("--strain-limit", default=None, help="the wall's allowed principal strain, e.g. 2%% or 0.02 "
                    "(default: none; the peak strain is reported)")
    ap.add_argument("--pad-size", default="24mm", help="edge of the flat pad, for the contact-area estimate (24mm)")
    ap.add_argument("--recheck", type=int, default=0, help="re-run the best K candidates fully nonlinear with "
                    "the pad gripper (MuJoCo, friction) and report the rank correlation (0: none)")
    where = ap.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=None, help="screen on an embedded Dask LocalCluster of N "
                       "worker processes (each factorises once; worth it for tens of thousands of candidates)")
    where.add_argument("--scheduler", default=None, help="screen on a running Dask cluster (tcp://HOST:PORT)")
    ap.add_argument("--chunks", type=int, default=None, help="Dask tasks (default: two per worker)")
    ap.add_argument("--no-map", dest="with_map", action="store_false", help="skip the compliance map")
    ap.add_argument("--top", type=int, default=10, help="how many to print (10)")
    ap.add_argument("--out", required=True, help="folder to write (a ranking folder is replaced)")


def _fraction(text: str | None) -> float | None:
    from ..errors import ProblemError

    if text is None:
        return None
    t = str(text).strip()
    try:
        return float(t[:-1]) / 100.0 if t.endswith("%") else float(t)
    except ValueError:
        raise ProblemError(f"--strain-limit: {text!r} is not a strain (e.g. 2% or 0.02)") from None


def run(a: argparse.Namespace) -> int:
    import sys

    from ..ranking import rank_object
    from ..units import quantity

    force = None if a.force is None else quantity(a.force, "force", implied="N", what="--force")
    force_range = None if a.force_range is None else tuple(
        quantity(x, "force", implied="N", what="--force-range") for x in a.force_range)
    pad = quantity(a.pad_size, "length", what="--pad-size")

    def say(stage, info=None):
        if stage in ("candidate", "map", "recheck") and info is not None:
            if not getattr(a, "quiet", False):
                what = {"candidate": "screened", "map": "compliance map", "recheck": "nonlinear recheck"}[stage]
                print(f"\r[graspdef]   {what} {info['done']} / {info['of']}", end="" if info["done"] < info["of"]
                      else "\n", file=sys.stderr, flush=True)
        elif info is None:
            progress(a, {"candidates": "sampling antipodal candidates", "factor": "factorising the shell's stiffness",
                         "map": "the compliance map", "recheck": "nonlinear recheck of the best candidates"
                         }.get(stage, stage))

    kw = dict(force_range=force_range, top=a.top, strain_limit=_fraction(a.strain_limit), pad_size=pad, with_map=a.with_map,
              recheck=a.recheck, progress=say)
    if a.workers is not None or a.scheduler is not None:
        from ..sweep.rank import rank_on_dask

        r = rank_on_dask(a.scene, force, a.candidates, a.out, scheduler=a.scheduler, workers=a.workers or 2,
                         chunks=a.chunks, **kw)
    else:
        if a.chunks is not None:
            from ..errors import ProblemError

            raise ProblemError("--chunks needs --workers or --scheduler (the Dask screen)")
        r = rank_object(a.scene, force, a.candidates, a.out, **kw)
    at = (f"{r['force_N']:g} N" if not r.get("force_range_N") else
          f"{r['force_range_N'][0]:g}-{r['force_range_N'][1]:g} N (each at its least holding force)")
    print(f"{r['object']}: {r['n_candidates']} candidates at {at} per finger, friction {r['friction']:g}; "
          f"screened {r['candidates_per_minute']:.0f} per minute ({r['control_vertices']} control vertices); "
          f"{r['n_held']} hold; rigid vs deformable rank correlation "
          f"{r['rank_correlation']['rigid_vs_deformable_spearman']:.2f}")
    print(f"{'rank':>4} {'width mm':>8} {'force N':>7} {'indent mm':>9} {'work mJ':>8} {'k N/mm':>7} {'strain %':>8} "
          f"{'margin deg':>10} {'rigid':>5} {'held':>4}")
    for row in r["top"]:
        print(f"{row['rank']:4d} {row['width_m'] * 1e3:8.1f} {row['force_N']:7.2f} {row['indentation_per_finger_m'] * 1e3:9.3f} "
              f"{row['work_J'] * 1e3:8.3f} {row['grasp_stiffness_N_per_m'] * 1e-3:7.2f} {row['peak_strain'] * 100:8.2f} "
              f"{row['deformed_friction_margin_deg']:10.1f} {row['rigid_rank']:5d} {'yes' if row['held'] else 'no':>4}")
    if r.get("recheck"):
        print(f"nonlinear recheck of the best {len(r['recheck'])}: Spearman {r['recheck_spearman']:.2f} "
              "(linear vs nonlinear closing)")
    print(f"ranking: {r['out']} (graspdef view {r['out']}; graspdef report {r['out']})")
    return 0
