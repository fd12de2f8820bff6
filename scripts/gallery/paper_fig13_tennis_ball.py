"""Tian & Jia (2010) Fig. 13: the deformed regions of the tennis ball grasped at 21.48 N per
finger (Table I's fourth row), superposed on the undeformed ball.

Paper: the two contact points move 10.27 mm (measured); the deformed regions (bordered by red
curves in the paper) are local around the contacts; the nonlinear result is "within 7 %" of the
scan.  graspdef (full mode): neo-Hookean shell, E = 1 MPa, t = 2.5 mm, 80 kPa air, point loads
from the settled MuJoCo grasp, displacements from the unloaded (inflated) ball: 19.57 mm per
finger -- 1.9x the measurement (not reproduced; see paper_table1_grasps.py and docs/grasp.md).
Away from the contacts the ball moves little, as in the paper: printed as the far-field |u| (the
largest displacement, rigid motion removed, farther than one radius from both contacts; 2.0 mm).
The picture colours |u|.

Fast mode: the same nonlinear run on a coarse control mesh (320 faces, 162 vertices; full: 1,280
faces, 642 vertices): 17.71 mm.  Its assertions: an invariant of the antipodal grasp (the two
contact points move equally, rigid motion removed), the mesh trend (the point load's dimple
deepens with refinement: coarse below the full-mode 19.57 mm, within 20 %) and that the dimples
dominate (far-field |u| below the indentation).

    python scripts/gallery/paper_fig13_tennis_ball.py [--out DIR] [--fast] [--contact point]
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import numpy as np  # noqa: E402

import _common as C  # noqa: E402
from paper_table1_grasps import grasp_record  # noqa: E402

NAME = "paper_fig13_tennis_ball"
FORCE_N, MEASURED_MM = 21.48, 10.27


def main(argv: list[str] | None = None) -> dict:
    a = C.parse(NAME, __doc__, argv, lambda ap: ap.add_argument("--contact", default="point"))
    clock = C.Timer()
    run_dir = a.out / "run"
    g = grasp_record("tennis_ball", FORCE_N, "nonlinear", a.contact, run_dir, control_faces=320 if a.fast else None)
    s = C.run_surfaces(run_dir)
    mag = s["u_mag"]
    res = C.run_surfaces(run_dir)["record"]
    x = s["undeformed"]
    dist = {k: np.linalg.norm(x - np.asarray(v["load_point_m"]), axis=1) for k, v in res["fingers"].items()}
    at_contact = {k: 1e3 * float(mag[np.argmin(d)]) for k, d in dist.items()}   # rigid motion removed
    far = np.min(list(dist.values()), axis=0) > g["contact_separation_mm"] * 1e-3 / 2
    key = {"force_per_finger_N": FORCE_N, "analysis": "nonlinear", "control_vertices": g["control_vertices"],
           "gas_kPa": g["gas_kPa"],
           "indentation_per_finger_mm": g["indentation_mm"], "measured_mm": MEASURED_MM,
           "ratio_to_measured": g["indentation_mm"] / MEASURED_MM,
           "contact_displacement_mm": at_contact,
           "max_displacement_mm": g["max_displacement_mm"],
           "far_field_max_displacement_mm": 1e3 * float(mag[far].max()), "far_field_definition":
           "max |u| (rigid motion removed) over vertices farther than one ball radius from both contacts",
           "completed": g["completed"]}
    print(C.table([key], ["analysis", "control_vertices", "force_per_finger_N", "indentation_per_finger_mm", "measured_mm",
                          "ratio_to_measured", "far_field_max_displacement_mm"]))

    label = f"neo-Hookean + 80 kPa air, {g['control_vertices']} control vertices"
    fig = C.surfaces_figure(run_dir, ((10.0, 0.0), (10.0, -90.0)),
                            (f"seen along the grasp axis ({label})", "side view (fingers left and right)"),
                            f"Fig. 13: tennis ball at {FORCE_N} N per finger: graspdef {g['indentation_mm']:.2f} mm "
                            f"per finger, measured {MEASURED_MM} mm; far field {key['far_field_max_displacement_mm']:.1f} mm")
    rec = {"figure": "Tian & Jia 2010, Fig. 13", "fast": a.fast, "key": key, "run": g, "run_dir": run_dir,
           "seconds": clock()}
    return C.finish(a.out, NAME, rec, fig)


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
