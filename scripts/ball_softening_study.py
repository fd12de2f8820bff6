"""Why the model's tennis ball re-stiffens where Table I keeps softening (issue 16, item 4's evidence).

Table I (Tian & Jia 2010; scenes/tennis_ball/table1_tian_jia_2010.csv) gives the ball's maximum
displacement d at four forces per finger F.  Its secant stiffness falls 4.15 -> 1.68 -> 1.26 ->
0.97 N/mm; the all-rows fit of the full ball with its air (scripts/gallery/paper_cross_validation.py)
gives 4.29 -> 1.64 -> 1.18 -> 1.51: the last interval re-stiffens.  This script measures:

1. the measured curve's shape: F / sqrt(d) per row and the local exponents
   dlog F / dlog d between rows.  A point-loaded spherical shell past mirror buckling follows
   Pogorelov's law F ~ E t^(5/2) d^(1/2) / R (A. V. Pogorelov, Bendings of Surfaces and
   Stability of Shells, AMS 1988; L. Pauchard & S. Rica, Phil. Mag. B 78 (1998) 225;
   A. Vaziri & L. Mahadevan, PNAS 105 (2008) 7913): exponent 1/2.
2. the fitted model with air (E, p: the cross-validation's all-rows fit, or --E-MPa/--p-kPa) on a
   dense force grid at two control meshes (1,280 and 5,120 faces): its local exponents, its
   enclosed air's gauge pressure and volume at each force, and the air's share of the finger
   force, F_air = p_gauge (-dV/dd) / 2 (the work the two fingers do on the air per unit of d, per
   finger; a finite difference over the grid).
3. the ball without air (the paper modelled none), E alone: a hyperelastic shell under dead loads
   without air has u(F / E) only (its energy is proportional to E), so one load sweep at E0 gives
   the response at every E: d(F; E) = d0(F E0 / E); E is fitted to the four rows by least squares
   on that curve (log-log interpolation of the sweep).  Not exact here: MuJoCo's settled loads
   (contact points, friction) are not exactly proportional to the force -- 2 N at 1 MPa and 4 N at
   2 MPa differ by 8e-4 in the indentation (15.865 vs 15.878 mm, 1,280 faces).

4. the wall thickness set free (a felt cover thickens the wall that bends; the scan's 2.5 mm is the
   rubber's): graspdef.fit on all four rows, (E, t) without air and (E, t, p) with air, from the
   values above; their residuals and secant stiffnesses (``--thickness-fits``).

    PYTHONPATH=. python scripts/ball_softening_study.py [--faces 1280,5120] [--E-MPa 11.12 --p-kPa 7.35]
                                                        [--xval out/gallery/paper_cross_validation/paper_cross_validation.json]
                                                        [--thickness-fits] [--out out/ball_softening]

Writes ball_softening.json (SI units) and prints its tables.
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
TABLE = ROOT / "scenes" / "tennis_ball" / "table1_tian_jia_2010.csv"
AIR_FORCES = (10.63, 14.0, 16.5, 18.0, 19.0, 20.37, 20.9, 21.48, 22.0, 23.0)
NOAIR_FORCES = (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 14.0, 16.0, 18.0, 21.0, 24.0)
NOAIR_E0 = 7.5e6


def exponents(F, d) -> list[float]:
    """Local exponents dlog F / dlog d between consecutive points."""
    F, d = np.asarray(F, float), np.asarray(d, float)
    return (np.diff(np.log(F)) / np.diff(np.log(d))).tolist()


def measured_shape(F, d) -> dict:
    c = F / np.sqrt(d * 1e3)
    return {"F_over_sqrt_d_N_per_sqrt_mm": c.tolist(), "spread_rel": float((c.max() - c.min()) / c.mean()),
            "local_exponents": exponents(F, d),
            "secant_N_per_mm": (np.concatenate([[F[0] / d[0]], np.diff(F) / np.diff(d)]) / 1e3).tolist()}


def _model(faces: int, forces, gas: bool, names):
    from graspdef.fit.models import ObjectModel
    from graspdef.fit.table import MeasuredTable

    t = MeasuredTable(np.array(forces, float), np.full(len(forces), 1e-3), ("max",) * len(forces))
    return ObjectModel("tennis_ball", t, names, analysis="nonlinear", gas=None if gas else False, control_faces=faces)


def solve_point(om, theta: dict, force: float) -> dict:
    """One force: max displacement [m], indentation per finger [m] and, with air, its gauge pressure
    [Pa] and volume [m^3] at the end of the load path (the last row of the run's path.csv)."""
    from graspdef.fit.models import object_point

    o = om.outcome(theta, force)
    rec = o.record.to_json()
    header, rows = o.path
    last = dict(zip(header, rows[-1]))
    gas = {k: (float(last[c]) if c in last else None) for k, c in (("gauge_pressure_Pa", "gas0_gauge_pressure_Pa"),
                                                                    ("volume_m3", "gas0_volume_m3"))}
    return {"force_N": force, "max_m": object_point(rec, "max"), "finger_m": object_point(rec, "finger"), **gas}


def sweep(om, theta, forces, say) -> list[dict]:
    from graspdef.errors import GraspdefError

    out = []
    for f in forces:
        t0 = time.perf_counter()
        try:
            r = solve_point(om, theta, f)
        except GraspdefError as exc:
            say(f"  {f:6.2f} N: {exc}")
            out.append({"force_N": f, "failure": str(exc)})
            continue
        r["seconds"] = time.perf_counter() - t0
        say(f"  {f:6.2f} N: max {r['max_m'] * 1e3:7.3f} mm, per finger {r['finger_m'] * 1e3:7.3f} mm"
            + (f", air {r['gauge_pressure_Pa'] / 1e3:6.2f} kPa, {r['volume_m3'] * 1e6:7.2f} cm3"
               if r["gauge_pressure_Pa"] is not None else "") + f" ({r['seconds']:.0f} s)")
        out.append(r)
    return out


def air_share(points, F_rows) -> dict:
    """The air's part of the finger force along the path, F_air = p_gauge (-dV/dd) / 2 per finger
    (d: the indentation per finger; dV/dd by np.gradient over the grid), at every grid point; and
    at the table's forces the secant stiffness of the whole ball and of its wall alone,
    (dF - dF_air) / dd (max displacement, like the table)."""
    ok = [p for p in points if "max_m" in p]
    F = np.array([p["force_N"] for p in ok])
    d = np.array([p["finger_m"] for p in ok])
    dmax = np.array([p["max_m"] for p in ok])
    V = np.array([p["volume_m3"] for p in ok])
    pg = np.array([p["gauge_pressure_Pa"] for p in ok])
    Fair = pg * (-np.gradient(V, d)) / 2
    out = {"force_N": F.tolist(), "air_force_N": Fair.tolist(), "air_share": (Fair / F).tolist()}
    idx = [int(np.flatnonzero(np.isclose(F, f))[0]) for f in F_rows if np.any(np.isclose(F, f))]
    if len(idx) == len(F_rows):
        Fr, dr, Far = F[idx], dmax[idx], Fair[idx]
        out["rows"] = {"air_force_N": Far.tolist(),
                       "secant_N_per_mm": (np.concatenate([[Fr[0] / dr[0]], np.diff(Fr) / np.diff(dr)]) / 1e3).tolist(),
                       "wall_secant_N_per_mm": (np.concatenate([[(Fr[0] - Far[0]) / dr[0]],
                                                                np.diff(Fr - Far) / np.diff(dr)]) / 1e3).tolist()}
    return out


def show_air(air: dict) -> None:
    print("  air's share of the finger force " + " / ".join(
        f"{f:.2f} N: {sh * 100:.0f} %" for f, sh in zip(air["force_N"], air["air_share"])), flush=True)
    if "rows" in air:
        r = air["rows"]
        print("  at the table's forces: secant stiffness " + " / ".join(f"{k:.2f}" for k in r["secant_N_per_mm"])
              + " N/mm; of the wall alone (the air's part removed) "
              + " / ".join(f"{k:.2f}" for k in r["wall_secant_N_per_mm"]) + " N/mm", flush=True)


def fit_scaled(F_sweep, d_sweep, E0, F, d) -> tuple[float, np.ndarray]:
    """E minimising sum (d(F_i; E) - d_i)^2 with d(F; E) = d0(F E0 / E) (log-log interpolation of the
    sweep at E0); returns E and the predictions."""
    from scipy.optimize import minimize_scalar

    lF, ld = np.log(F_sweep), np.log(d_sweep)

    def pred(E):
        x = np.log(F * E0 / E)
        return np.exp(np.interp(x, lF, ld, left=np.nan, right=np.nan))

    lo = E0 * F.max() / F_sweep.max() * 1.0001          # stay inside the sweep
    hi = E0 * F.min() / F_sweep.min() * 0.9999
    res = minimize_scalar(lambda lE: float(np.nansum((pred(math.exp(lE)) - d) ** 2)
                                           + 1e3 * np.isnan(pred(math.exp(lE))).sum()),
                          bounds=(math.log(lo), math.log(hi)), method="bounded", options={"xatol": 1e-8})
    E = math.exp(res.x)
    return E, pred(E)


def thickness_fits(F, d) -> dict:
    """Part 4: all four rows fitted with the thickness free, without air (E, t) and with it (E, t, p)."""
    from graspdef.errors import GraspdefError
    from graspdef.fit import ObjectModel, fit, read_table

    table = read_table(TABLE)
    out = {}
    for key, gas, start in (("no air: E, t", False, {"E": 14e6, "thickness": 2.5e-3}),
                            ("air: E, t, p", None, {"E": 11e6, "thickness": 2.5e-3, "pressure": 7.4e3})):
        print(f"fitting {key} to the four rows", flush=True)
        try:
            om = ObjectModel("tennis_ball", table, list(start), "nonlinear", gas=gas)
            r = fit(om, table, start, max_nfev=40)
        except GraspdefError as exc:
            out[key] = {"failure": str(exc)}
            continue
        out[key] = {"parameters": dict(zip(r.names, r.values.tolist())), "std": dict(zip(r.names, r.std.tolist())),
                    "converged": r.converged, "rows_m": r.predicted.tolist(), "rms_m": r.rms,
                    "secant_N_per_mm": measured_shape(F, r.predicted)["secant_N_per_mm"],
                    "warnings": list(r.warnings), "solves": om.n_solves, "seconds": r.seconds}
    return out


def show_fit(key: str, v: dict, F) -> None:
    if "failure" in v:
        print(f"{key}: failed: {v['failure']}", flush=True)
        return
    par = ", ".join(f"{k} = {x / 1e6:.3g} MPa" if k == "E" else f"{k} = {x * 1e3:.3g} mm" if k == "thickness"
                    else f"{k} = {x / 1e3:.3g} kPa" for k, x in v["parameters"].items())
    print(f"{key}: {par}{'' if v['converged'] else ' (NOT converged)'}; rows " + " / ".join(
        f"{y * 1e3:.2f}" for y in v["rows_m"]) + f" mm, RMS {v['rms_m'] * 1e3:.3f} mm; secants "
        + " / ".join(f"{k:.2f}" for k in v["secant_N_per_mm"]) + " N/mm", flush=True)
    for w in v["warnings"]:
        print(f"  warning: {w}", flush=True)


def derive_air(ent: dict, F) -> dict:
    """An air sweep's derived figures from its points (see air_share)."""
    ok = [q for q in ent["points"] if "max_m" in q]
    rows = [next((q["max_m"] for q in ok if np.isclose(q["force_N"], f)), None) for f in F]
    ent.update(local_exponents=exponents([q["force_N"] for q in ok], [q["max_m"] for q in ok]), rows_m=rows,
               air=air_share(ok, F))
    ent.pop("air_share", None)
    if None not in rows:
        ent["rows_local_exponents"] = exponents(F, rows)
        ent["rows_secant_N_per_mm"] = measured_shape(F, np.array(rows))["secant_N_per_mm"]
    print("  local exponents " + " / ".join(f"{e:.3f}" for e in ent["local_exponents"]), flush=True)
    show_air(ent["air"])
    return ent


def derive_noair(ent: dict, E0: float, F, d) -> dict:
    """A no-air sweep's fitted E and its predictions of the table (see fit_scaled)."""
    ok = [q for q in ent["points"] if "max_m" in q]
    Fs, ds = np.array([q["force_N"] for q in ok]), np.array([q["max_m"] for q in ok])
    E, pred = fit_scaled(Fs, ds, E0, F, d)
    ent.update(local_exponents=exponents(Fs, ds), E_fitted_Pa=E, rows_m=pred.tolist(),
               rows_error_rel=(pred / d - 1).tolist(), rows_local_exponents=exponents(F, pred),
               rows_secant_N_per_mm=measured_shape(F, pred)["secant_N_per_mm"])
    print("  local exponents " + " / ".join(f"{e:.3f}" for e in ent["local_exponents"]), flush=True)
    print(f"  E fitted to the four rows: {E / 1e6:.4g} MPa; rows " + " / ".join(
        f"{y * 1e3:.2f} ({(y / dd - 1) * 100:+.0f} %)" for y, dd in zip(pred, d)) + "; secants "
        + " / ".join(f"{k:.2f}" for k in ent["rows_secant_N_per_mm"]) + " N/mm", flush=True)
    return ent


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--faces", default="1280,5120", help="control-mesh faces, comma-separated")
    ap.add_argument("--xval", default=str(ROOT / "out" / "gallery" / "paper_cross_validation" /
                                          "paper_cross_validation.json"),
                    help="the cross-validation's JSON: E and p of its all-rows fit of the ball with air")
    ap.add_argument("--E-MPa", type=float, default=None)
    ap.add_argument("--p-kPa", type=float, default=None)
    ap.add_argument("--skip", default="", help="parts to skip: air, noair")
    ap.add_argument("--thickness-fits", action="store_true", help="part 4: fits with the wall thickness free")
    ap.add_argument("--from-json", default=None, help="re-derive the figures of a finished run's JSON (no solves)")
    ap.add_argument("--out", default=str(ROOT / "out" / "ball_softening"))
    a = ap.parse_args()
    for opt, f in (("--from-json", a.from_json), ("--xval", a.xval)):
        if f and not Path(f).is_file() and (opt == "--from-json" or (a.E_MPa is None and "air" not in a.skip)):
            raise SystemExit(f"{opt}: no such file: {f}")

    from graspdef import runtime

    runtime.configure()
    from graspdef.fit.table import read_table

    table = read_table(TABLE)
    F, d = table.force.astype(float), table.displacement.astype(float)
    rec = {"what": "tennis ball, Table I: the shape of the force-displacement curve, measured and modelled",
           "units": {"force": "N", "displacement": "m", "pressure": "Pa (gauge)", "volume": "m^3", "E": "Pa"},
           "measured": {"force_N": F.tolist(), "max_displacement_m": d.tolist(), **measured_shape(F, d)}}
    m = rec["measured"]
    print("measured: F/sqrt(d[mm]) = " + " / ".join(f"{c:.3f}" for c in m["F_over_sqrt_d_N_per_sqrt_mm"])
          + f" N/sqrt(mm) (spread {m['spread_rel'] * 100:.1f} %); local exponents "
          + " / ".join(f"{e:.3f}" for e in m["local_exponents"]) + "; secants "
          + " / ".join(f"{k:.2f}" for k in m["secant_N_per_mm"]) + " N/mm", flush=True)
    faces = [int(x) for x in a.faces.split(",")]
    skip = set(filter(None, a.skip.split(",")))
    old = json.loads(Path(a.from_json).read_text()) if a.from_json else None

    if "air" not in skip:
        if old is not None:
            rec["air"] = old["air"]
        elif a.E_MPa is not None and a.p_kPa is not None:
            rec["air"] = {"E_Pa": a.E_MPa * 1e6, "p0_Pa": a.p_kPa * 1e3, "source": "command line", "meshes": {}}
        else:
            xv = json.loads(Path(a.xval).read_text())
            case = next(c for c in xv["cases"] if c["case"].startswith("tennis"))
            s = case["models"]["full-nonlinear"]["schemes"][0]
            if not s["scheme"].startswith("all"):
                raise SystemExit(f"{a.xval}: the first scheme is not the all-rows fit")
            rec["air"] = {"E_Pa": s["parameters"]["E"], "p0_Pa": s["parameters"]["pressure"],
                          "source": f"{a.xval}: all-rows fit", "meshes": {}}
        E, p = rec["air"]["E_Pa"], rec["air"]["p0_Pa"]
        for nf in (list(rec["air"]["meshes"]) if old is not None else faces):
            print(f"with air, E = {E / 1e6:.4g} MPa, p0 = {p / 1e3:.4g} kPa, {nf} control faces:", flush=True)
            if old is None:
                om = _model(int(nf), AIR_FORCES, True, ["E", "pressure"])
                rec["air"]["meshes"][str(nf)] = {
                    "control_vertices": int(om.obj.shell_info.get("control_vertices", 0)),
                    "points": sweep(om, {"E": E, "pressure": p}, AIR_FORCES, lambda s: print(s, flush=True))}
            derive_air(rec["air"]["meshes"][str(nf)], F)

    if "noair" not in skip and (old is None or "no_air" in old):
        rec["no_air"] = old["no_air"] if old is not None else {"E0_Pa": NOAIR_E0, "meshes": {}}
        E0 = rec["no_air"]["E0_Pa"]
        for nf in (list(rec["no_air"]["meshes"]) if old is not None else faces):
            print(f"without air, E0 = {E0 / 1e6:g} MPa, {nf} control faces:", flush=True)
            if old is None:
                om = _model(int(nf), NOAIR_FORCES, False, ["E"])
                rec["no_air"]["meshes"][str(nf)] = {
                    "control_vertices": int(om.obj.shell_info.get("control_vertices", 0)),
                    "points": sweep(om, {"E": E0}, NOAIR_FORCES, lambda s: print(s, flush=True))}
            derive_noair(rec["no_air"]["meshes"][str(nf)], E0, F, d)

    if a.thickness_fits:
        rec["thickness_fits"] = old.get("thickness_fits") if old is not None and "thickness_fits" in old else \
            thickness_fits(F, d)
        for k, v in rec["thickness_fits"].items():
            show_fit(k, v, F)

    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "ball_softening.json").write_text(json.dumps(rec, indent=1))
    print(f"wrote {out / 'ball_softening.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
