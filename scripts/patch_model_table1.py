"""Tian & Jia 2010, Table I, with the paper's own model (graspdef.pipeline.patch): fit E to the four
tennis-ball rows, linear and nonlinear, and E from row 1 alone with its predictions of rows 2-4.

    PYTHONPATH=. python scripts/patch_model_table1.py [--levels 2] [--size 45mm] [--out out/patch_model_table1]

The forward model (a plain callable for graspdef.fit.fit): MuJoCo settles the grasp once at each
force of the table (the rigid proxy does not depend on E); per E, the left finger's patch is cut
around the contact of the grasp at the largest force (the contact moves by the distance printed as
"contact spread" between the four settles) and loaded by 1 N; linear: one solve, scaled by each
force (exact); nonlinear: one load path to the largest force landing on the others.  A row's
prediction is the patch's max displacement (Table I's "measured max. displacement").  Nothing is
tuned: E is the only unknown, the start is 5 MPa, the patch size, thickness (2.5 mm), nu = 0.5 and the
mesh are fixed beforehand.  Writes <out>.json and <out>.md.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


class LeftPatch:
    """The paper's patch model of the tennis ball (Table I) as a forward model of E: MuJoCo settles
    the pin grasp once at each of ``forces`` [N] (the rigid proxy does not depend on E); the left
    finger's patch (side ``size`` [m], ``levels`` Loop refinements, default graspdef.pipeline.patch's)
    is cut around the contact of the grasp at the largest force; ``displacements(E, analysis, fs)``
    returns the patch's max displacement [m] at each force of ``fs`` (linear: one solve scaled,
    exact; nonlinear: one load path landing on every force) and the patch problem."""

    def __init__(self, forces, size: float = 0.045, levels: int | None = None):
        from graspdef.pipeline.grasp import prepare_object, settle
        from graspdef.pipeline.patch import default_levels, refined_control_mesh

        self.forces, self.size = [float(f) for f in forces], float(size)
        obj = prepare_object("tennis_ball", "linear", gas=False)
        pts = {}
        for f in self.forces:
            st = settle(obj, f)
            pf = st.g.contacts.transformed(st.g.pose).per_finger()
            pts[f] = (pf["left"]["point"], pf["left"]["normal_force"])
        top = max(self.forces)
        self.spread = float(max(np.linalg.norm(pts[f][0] - pts[top][0]) for f in self.forces))
        self.normal_forces = [float(pts[f][1]) for f in self.forces]
        self.centre = pts[top][0]
        self.levels = default_levels(obj.shell, self.size) if levels is None else int(levels)
        self.xc, self.fc = refined_control_mesh(obj.shell, self.levels)
        self.spec = obj.spec

    def description(self, analysis: str) -> dict:
        return {"kind": "patch model (graspdef.pipeline.patch), left finger", "analysis": analysis,
                "patch_size_m": self.size, "refine_levels": self.levels}

    def displacements(self, E: float, analysis: str, fs):
        from graspdef.pipeline.patch import build_patch, patch_material, patch_measures, solve_patch

        mat = patch_material(self.spec.material.with_E(E), analysis)
        pp = build_patch(self.xc, self.fc, mat, self.spec.thickness, self.centre, 1.0, self.size, "left", self.levels)
        us, _ = solve_patch(pp, analysis, steps=4, forces=fs)
        return np.array([patch_measures(pp, us[f], border=False)["max_displacement_m"] for f in fs]), pp


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--levels", type=int, default=None,
                    help="Loop refinements of the ball's control mesh before the cut (default: graspdef grasp "
                         "--model patch's, graspdef.pipeline.patch.default_levels)")
    ap.add_argument("--size", default="45mm", help="patch side")
    ap.add_argument("--analyses", default="linear,nonlinear")
    ap.add_argument("--E0-MPa", dest="E0", type=float, default=5.0, help="start of the fit [MPa]")
    ap.add_argument("--out", default=str(ROOT / "out" / "patch_model_table1"))
    a = ap.parse_args()

    from graspdef.errors import GraspdefError
    from graspdef.fit.estimate import fit
    from graspdef.fit.table import MeasuredTable, read_table
    from graspdef.units import quantity

    size = quantity(a.size, "length", what="--size")
    table = read_table(ROOT / "scenes" / "tennis_ball" / "table1_tian_jia_2010.csv")
    forces = table.force.tolist()
    t0 = time.perf_counter()
    lp = LeftPatch(forces, size, a.levels)
    a.levels = lp.levels
    print(f"MuJoCo: 4 settles in {time.perf_counter() - t0:.1f} s; left contact spread {lp.spread * 1e3:.2f} mm; "
          f"settled normal forces {[round(v, 3) for v in lp.normal_forces]} N")
    spec = lp.spec
    out: dict = {"table": {"force_N": forces, "measured_max_displacement_m": table.displacement.tolist(),
                           "paper_average_shape_error_m": {"nonlinear": [0.31e-3, 0.62e-3, 0.81e-3, 0.65e-3],
                                                           "linear": [0.30e-3, 0.85e-3, 2.0e-3, 2.37e-3]}},
                 "patch_size_m": size, "refine_levels": a.levels, "thickness_m": spec.thickness, "nu": 0.5,
                 "contact_spread_m": float(lp.spread), "models": {}}

    class PatchModel:
        def __init__(self, analysis, rows):
            self.analysis, self.rows = analysis, rows
            self.n_solves = 0
            self.description = lp.description(analysis)
            self.seconds = []

        def displacements(self, theta, fs):
            t = time.perf_counter()
            y, pp = lp.displacements(theta["E"], self.analysis, fs)
            self.n_solves += 1
            self.seconds.append(time.perf_counter() - t)
            return y, pp

        def __call__(self, theta):
            return self.displacements(theta, [forces[i] for i in self.rows])[0]

    for analysis in a.analyses.split(","):
        rec: dict = {}
        for label, rows in (("all_rows", [0, 1, 2, 3]), ("row_1", [0])):
            sub = MeasuredTable(table.force[rows], table.displacement[rows], tuple(table.point[i] for i in rows),
                                file=table.file, units=table.units)
            model = PatchModel(analysis, rows)
            print(f"{analysis}, {label}: fitting E ...", flush=True)
            res = fit(model, sub, {"E": a.E0 * 1e6}, max_nfev=20,
                      progress=lambda info: print(f"   E = {info['theta']['E'] / 1e6:.4f} MPa: rms "
                                                  f"{info['rms_m'] * 1e3:.3f} mm", flush=True))
            E = res.value("E")
            entry = {"fit": res.to_json(), "E_Pa": E, "E_std_Pa": float(res.std[0]),
                     "seconds_per_evaluation": float(np.median(model.seconds)) if model.seconds else None}
            # predictions of every row at the fitted E (rows 2-4 are predictions for the row-1 fit)
            try:
                y, pp = model.displacements({"E": E}, forces)
                entry["predicted_m"] = y.tolist()
                entry["error_m"] = (y - table.displacement).tolist()
                entry["patch"] = {"control_vertices": int(len(pp.patch.vertices)), "control_faces": int(len(pp.patch.faces))}
            except GraspdefError as exc:
                entry["predicted_m"] = None
                entry["failure"] = str(exc)
            print(f"{analysis}, {label}: E = {E / 1e6:.4f} +- {res.std[0] / 1e6:.4f} MPa, converged {res.converged}; "
                  f"predicted {np.round(np.asarray(entry.get('predicted_m') or [np.nan] * 4) * 1e3, 3).tolist()} mm",
                  flush=True)
            rec[label] = entry
        y = rec["all_rows"].get("predicted_m")
        if y is not None:
            k_meas = np.diff(table.force) / np.diff(table.displacement) / 1e3
            k_pred = np.diff(table.force) / np.diff(y) / 1e3
            rec["secant_stiffness_N_per_mm"] = {"measured": k_meas.tolist(), "predicted": k_pred.tolist(),
                                                "first_row": [float(table.force[0] / table.displacement[0] / 1e3),
                                                              float(table.force[0] / y[0] / 1e3)]}
        out["models"][analysis] = rec
    out["seconds"] = time.perf_counter() - t0
    dest = Path(a.out)
    dest.parent.mkdir(parents=True, exist_ok=True)
    dest.with_suffix(".json").write_text(json.dumps(out, indent=2, default=float) + "\n")
    dest.with_suffix(".md").write_text(markdown(out) + "\n")
    print(markdown(out))
    return 0


def markdown(out: dict) -> str:
    t = out["table"]
    lines = [f"Patch model (side {out['patch_size_m'] * 1e3:g} mm, border clamped, nu = 0.5, t = "
             f"{out['thickness_m'] * 1e3:g} mm, no air, {out['refine_levels']} refinement(s)); max. displacement [mm]",
             ""]
    heads = ["force [N]", "measured"]
    cols = []
    for an, rec in out["models"].items():
        for label in ("all_rows", "row_1"):
            e = rec[label]
            name = f"{an}, E fitted to {'rows 1-4' if label == 'all_rows' else 'row 1'} ({e['E_Pa'] / 1e6:.3g}"
            name += f" ± {e['E_std_Pa'] / 1e6:.2g} MPa)" if label == "all_rows" and np.isfinite(e["E_std_Pa"] or np.nan) else " MPa)"
            heads.append(name)
            cols.append(e.get("predicted_m"))
    lines.append("| " + " | ".join(heads) + " |")
    lines.append("|" + "---|" * len(heads))
    for i, (f, d) in enumerate(zip(t["force_N"], t["measured_max_displacement_m"])):
        cells = [f"{f:g}", f"{d * 1e3:.2f}"]
        for c in cols:
            cells.append("path stopped" if c is None else f"{c[i] * 1e3:.2f} ({(c[i] - d) * 1e3:+.2f})")
        lines.append("| " + " | ".join(cells) + " |")
    for an, rec in out["models"].items():
        k = rec.get("secant_stiffness_N_per_mm")
        if k:
            lines.append(f"\n{an}: secant stiffness between rows [N/mm]: measured "
                         f"{', '.join(f'{v:.2f}' for v in k['measured'])}; predicted "
                         f"{', '.join(f'{v:.2f}' for v in k['predicted'])} (F/d at row 1: measured "
                         f"{k['first_row'][0]:.2f}, predicted {k['first_row'][1]:.2f})")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main())
