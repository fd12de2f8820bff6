"""The duck's two measured grasps and its unknown wall thickness (issue 16 item 4's evidence): for
each wall thickness t the linear shell's compliance at the finger is computed once per grasp (linear:
the indentation scales as 1/E exactly), and the modulus that reproduces each measurement follows,
E_i(t) = c_i(t) / d_i.  One material must have E_antipodal(t) = E_poke(t); the ratio
E_poke / E_antipodal against t shows whether some wall thickness lets one E reproduce both, which
is what the cross-validation (scripts/gallery/paper_cross_validation.py) cannot do at the assumed
t = 1 mm (30 vs 93 MPa).

Measurements (Tian & Jia 2010, Figs. 14-15): antipodal grasp at 19.22 N per finger, max
displacements 8.56 and 6.73 mm at the two fingers (compared with half the fingers' approach against
their mean, 7.645 mm); head poke at 18.33 N, 7.52 mm (the finger's indentation).

    PYTHONPATH=. python scripts/duck_thickness_study.py [--t-mm 0.5,1,2,3] [--out out/duck_thickness]
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CASES = (("duck", 19.22, (8.56 + 6.73) / 2 * 1e-3), ("duck_head_poke", 18.33, 7.52e-3))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--t-mm", default="0.5,1,2,3", help="wall thicknesses [mm]")
    ap.add_argument("--out", default=str(ROOT / "out" / "duck_thickness"))
    a = ap.parse_args()

    from graspdef import runtime
    from graspdef.errors import GraspdefError

    runtime.configure()
    from graspdef.fit.models import ObjectModel, object_point
    from graspdef.fit.table import MeasuredTable

    ts = [float(x) * 1e-3 for x in a.t_mm.split(",")]
    models = {}
    for scene, f, d in CASES:
        models[scene] = ObjectModel(scene, MeasuredTable(np.array([f]), np.array([d]), ("finger",)), ["E", "thickness"],
                                    analysis="linear")
    rows = []
    for t in ts:
        row = {"thickness_m": t}
        try:
            for scene, f, d in CASES:
                t0 = time.perf_counter()
                y = object_point(models[scene].record({"E": 1e6, "thickness": t}, f), "finger")   # at E = 1 MPa
                row[scene] = {"indentation_at_1MPa_m": y, "E_reproducing_Pa": y * 1e6 / d,
                              "seconds": time.perf_counter() - t0}
        except GraspdefError as exc:
            row["failure"] = str(exc)
            rows.append(row)
            print(f"t = {t * 1e3:g} mm: {exc}", flush=True)
            continue
        row["ratio_E_poke_over_E_antipodal"] = row["duck_head_poke"]["E_reproducing_Pa"] / row["duck"]["E_reproducing_Pa"]
        rows.append(row)
        print(f"t = {t * 1e3:g} mm: E for the antipodal grasp {row['duck']['E_reproducing_Pa'] / 1e6:.3g} MPa, "
              f"for the head poke {row['duck_head_poke']['E_reproducing_Pa'] / 1e6:.3g} MPa, ratio "
              f"{row['ratio_E_poke_over_E_antipodal']:.3f}", flush=True)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "duck_thickness.json").write_text(json.dumps({"units": {"thickness": "m", "E": "Pa", "indentation": "m"},
                                                         "analysis": "linear, point loads", "rows": rows}, indent=2) + "\n")
    print(f"wrote {out / 'duck_thickness.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
