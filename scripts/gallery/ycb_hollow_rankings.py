"""Where to grasp three hollow YCB objects: ``graspdef rank`` on the mustard bottle, the bleach
cleanser bottle and the tomato soup can (scans from ../shared/scans, CC BY 4.0), each made an
object folder by ``graspdef object add`` and ranked at 20 N per finger.

No ranking is published for these objects; the walls and materials are assumptions, stated with
their sources below, and the YCB masses are of the full containers (the shells here are empty):

* mustard bottle (LDPE squeeze bottle): E 300 MPa, nu 0.45, wall 0.8 mm, 60 g -- the README
  tutorial's assumptions (no LDPE data in ../shared/MATERIALS.md; LDPE's modulus is typically
  0.1-0.4 GPa);
* bleach cleanser bottle (HDPE): E 1.0 GPa, nu 0.42, wall 0.7 mm, 70 g -- HDPE grades' flexural
  modulus 1.0-1.4 GPa (a vendor summary; Amjadi & Fatemi, Polymers 12:1857, 2020, measure HDPE's
  tensile behaviour), the wall assumed;
* tomato soup can (tinplate steel): E 200 GPa, nu 0.3, wall 0.2 mm, 50 g -- steel's modulus, a
  food can's wall assumed.

Each object's ranking folder (ranking.csv/json, compliance.ply, shapes.npz) and report are
written under ``--out``; ``<name>.png`` shows the three compliance maps with the best ten grasps
and the Pareto fronts (work against the deformed friction margin).
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT, Timer, finish, parse, surface, table  # noqa: E402

NAME = "ycb_hollow_rankings"
SCANS = ROOT.parent / "shared" / "scans"
FORCE = 20.0

#: (key, YCB folder, law, E [Pa], nu, wall [m], mass [kg], source)
OBJECTS = [
    ("mustard", "ycb_006_mustard_bottle", "neo_hookean", 300e6, 0.45, 0.0008, 0.060,
     "README tutorial's assumption for an LDPE squeeze bottle (LDPE 0.1-0.4 GPa typical)"),
    ("bleach", "ycb_021_bleach_cleanser", "neo_hookean", 1.0e9, 0.42, 0.0007, 0.070,
     "HDPE: flexural modulus 1.0-1.4 GPa (vendor summary); wall assumed"),
    ("soup_can", "ycb_005_tomato_soup_can", "svk", 200e9, 0.3, 0.0002, 0.050,
     "tinplate steel E 200 GPa; a food can's wall assumed"),
]


def main(argv=None) -> dict:
    a = parse(NAME, __doc__, argv, lambda ap: ap.add_argument(
        "--only", default=None, help="one object key (mustard, bleach, soup_can)"))
    from graspdef import runtime

    runtime.configure()
    import matplotlib.pyplot as plt
    import numpy as np
    import trimesh

    from graspdef.objects.add import add_object
    from graspdef.objects.data import MaterialSpec
    from graspdef.ranking import rank_object
    from graspdef.report import build_report
    from graspdef.runs.ranking import read_ranking

    faces, n = (2000, 300) if a.fast else (2000, 2000)
    todo = [o for o in OBJECTS if a.only in (None, o[0])]
    rows, key = [], {}
    fig, axes = plt.subplots(2, len(todo), figsize=(4.2 * len(todo), 7.5), squeeze=False)
    for col, (k, folder, law, E, nu, t, mass, source) in enumerate(todo):
        clock = Timer()
        stl = a.out / f"{k}_mm.stl"
        m = trimesh.load(SCANS / folder / "nontextured.ply")
        m.apply_scale(1000.0)
        m.export(stl)
        obj = a.out / k
        if obj.exists():
            import shutil

            shutil.rmtree(obj)
        add_object(k, stl, obj, units="mm", thickness=t, material=MaterialSpec(law, E, nu, None, source),
                   mass=mass, faces=faces)
        rec = rank_object(obj, FORCE, n, a.out / f"{k}_rank")
        build_report([a.out / f"{k}_rank"], a.out / f"{k}_rank" / "report.html")
        r = read_ranking(a.out / f"{k}_rank")
        best = r.row(0)
        row = {"object": k, "ycb": folder, "law": law, "E_Pa": E, "nu": nu, "wall_mm": t * 1e3, "mass_g": mass * 1e3,
               "control_vertices": rec["control_vertices"], "candidates": rec["n_candidates"], "held": rec["n_held"],
               "candidates_per_minute": rec["candidates_per_minute"],
               "best_width_mm": best["width_m"] * 1e3, "best_indentation_mm": best["indentation_per_finger_m"] * 1e3,
               "best_work_mJ": best["work_J"] * 1e3, "best_rigid_rank": best["rigid_rank"],
               "rigid_vs_deformable_spearman": rec["rank_correlation"]["rigid_vs_deformable_spearman"],
               "median_indentation_mm": float(np.median(r.table["indentation_per_finger_m"])) * 1e3,
               "seconds": clock(), "source": source}
        rows.append(row)
        key[k] = {"best_indentation_mm": row["best_indentation_mm"], "held": row["held"],
                  "spearman": row["rigid_vs_deformable_spearman"]}
        p, q = r.contacts()
        segs = np.stack([p[:10], q[:10]], 1)
        surface(axes[0, col], r.vertices, r.faces, r.compliance, title=f"{k}: compliance (log), best 10",
                log=True, label="compliance [m/N]", views=("iso",), segments=segs)
        ax = axes[1, col]
        w, mg, h, pf = (r.table["work_J"] * 1e3, r.table["deformed_friction_margin_deg"],
                        r.table["held"].astype(bool), r.table["pareto"].astype(bool))
        ax.scatter(w[~h], mg[~h], s=6, c="0.7", label="not held")
        ax.scatter(w[h], mg[h], s=6, c="tab:blue", label="held")
        o = np.argsort(w[pf])
        ax.plot(w[pf][o], mg[pf][o], "o-", c="tab:red", ms=4, label="Pareto front")
        ax.set_xscale("log")
        ax.set_xlabel("work to reach 20 N [mJ]")
        ax.set_ylabel("deformed friction margin [deg]")
        ax.set_title(f"{k}: {row['held']} of {row['candidates']} hold", fontsize=9)
        ax.legend(fontsize=7)
        print(f"{k}: {row['candidates']} candidates, {row['held']} hold, best {row['best_width_mm']:.1f} mm wide, "
              f"indentation {row['best_indentation_mm']:.3f} mm, rigid rank {row['best_rigid_rank']}, "
              f"Spearman rigid vs deformable {row['rigid_vs_deformable_spearman']:.2f} ({row['seconds']:.0f} s)",
              flush=True)
    fig.tight_layout()
    print(table(rows, ["object", "wall_mm", "E_Pa", "candidates", "held", "best_indentation_mm", "best_rigid_rank",
                       "rigid_vs_deformable_spearman", "seconds"]))
    return finish(a.out, NAME, {"fast": bool(a.fast), "force_N": FORCE, "rows": rows, "key": key,
                                "published": "none: no ranking is published; materials assumed (see sources)"},
                  fig, rows)


if __name__ == "__main__":
    main()
