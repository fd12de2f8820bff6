"""How much of each duck finger's travel is a dent, and how much the part swinging as a rigid body
(issue 16, item 4's evidence for the duck's cross-prediction).

The paper (Tian & Jia 2010, Sec. IX-B) reports the antipodal grasp (19.22 N per finger; 8.56 and
6.73 mm at the two fingers) and the head poked by one finger (18.33 N; 7.52 mm), and scores its
shapes after a *local* alignment of scan and model.  graspdef compares the finger's travel (half the
fingers' approach; the poking finger's indentation).  Fitted on one grasp, the nonlinear shell
predicts the other within -13 % / +21 % (scripts/gallery/paper_cross_validation.py).  Here each
grasp is solved at the nonlinear fits' E and the displacement near each finger is split into

* the rigid motion of a ring of the surface around the contact (the samples between r_in and
  r_out from the load point, aligned undeformed -> deformed by least squares, Kabsch), and
* the local dent: the displacement left at the load point once that ring's rigid motion is
  removed (what a local alignment of two scans would show),

for several rings.  Reads the run folders' undeformed.ply / deformed.ply (metres, the same limit-
surface samples), result.json (load points, object frame) and contacts.json (the fingers' forces,
world frame, with the object's pose).

    PYTHONPATH=. python scripts/duck_poke_study.py [--E-MPa-antipodal 89.59] [--E-MPa-poke 103.77]
                                                   [--out out/duck_poke]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RINGS_MM = ((10, 20), (15, 25), (15, 30), (20, 35))
CASES = (("duck", 19.22, "antipodal grasp"), ("duck_head_poke", 18.33, "head poke"))


def kabsch(A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation R and translation c with B ~ A R^T + c (least squares over the rows)."""
    ca, cb = A.mean(0), B.mean(0)
    U, _, Vt = np.linalg.svd((A - ca).T @ (B - cb))
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T))])
    R = Vt.T @ D @ U.T
    return R, cb - ca @ R.T


def split(X: np.ndarray, Y: np.ndarray, p: np.ndarray, push: np.ndarray, r_in: float, r_out: float) -> dict:
    """The displacement at the sample nearest the load point ``p`` along the finger's push direction
    ``push`` (unit: the direction of the finger's force on the object): total, and after removing the
    rigid motion of the ring r_in < |x - p| < r_out."""
    dist = np.linalg.norm(X - p, axis=1)
    ring = (dist > r_in) & (dist < r_out)
    if ring.sum() < 6:
        raise SystemExit(f"ring {r_in * 1e3:g}-{r_out * 1e3:g} mm holds {ring.sum()} samples: too few")
    R, c = kabsch(X[ring], Y[ring])
    k = int(dist.argmin())
    aligned = X[k] @ R.T + c
    # the rotation angle from sin and cos (atan2): arccos of the trace loses half the digits near 0
    # (a rotation of 1e-16 came out 1.2e-6 degrees, and the test's bound flipped with the rounding)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    angle = float(np.degrees(np.arctan2(0.5 * np.linalg.norm(w), 0.5 * (np.trace(R) - 1))))
    misfit = np.linalg.norm(Y[ring] - (X[ring] @ R.T + c), axis=1)
    return {"ring_mm": [r_in * 1e3, r_out * 1e3], "ring_samples": int(ring.sum()), "ring_rotation_deg": angle,
            "ring_misfit_rms_m": float(np.sqrt(np.mean(misfit ** 2))),
            "total_along_push_m": float((Y[k] - X[k]) @ push), "dent_along_push_m": float((Y[k] - aligned) @ push),
            "sample_to_load_point_m": float(dist[k])}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--E-MPa-antipodal", type=float, default=89.59, help="E of the nonlinear fit on the antipodal "
                                                                          "grasp (cross-validation)")
    ap.add_argument("--E-MPa-poke", type=float, default=103.77, help="E of the nonlinear fit on the poke")
    ap.add_argument("--out", default=str(ROOT / "out" / "duck_poke"))
    a = ap.parse_args()
    import trimesh

    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    rec = {"what": "duck: each finger's travel split into a ring's rigid motion and the local dent",
           "units": {"length": "m", "force": "N", "E": "Pa", "angle": "deg"}, "runs": []}
    for E_label, E in (("antipodal fit", a.E_MPa_antipodal), ("poke fit", a.E_MPa_poke)):
        for scene, force, what in CASES:
            run = out / f"{scene}_E{E:g}"
            cmd = [sys.executable, "-m", "graspdef.cli", "grasp", scene, "--force", str(force), "--analysis",
                   "nonlinear", "--E-MPa", str(E), "--out", str(run)]
            p = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
            if p.returncode != 0:
                print(f"{what} at E = {E:g} MPa: failed: {p.stderr.strip().splitlines()[-1]}", flush=True)
                rec["runs"].append({"scene": scene, "E_Pa": E * 1e6, "failure": p.stderr.strip().splitlines()[-1]})
                continue
            r = json.loads((run / "result.json").read_text())
            X = np.asarray(trimesh.load(run / "undeformed.ply", process=False).vertices)
            Y = np.asarray(trimesh.load(run / "deformed.ply", process=False).vertices)
            ent = {"scene": scene, "what": what, "E_Pa": E * 1e6, "E_from": E_label, "force_N": force,
                   "max_displacement_m": r["derived"]["max_displacement"]["value"], "fingers": {}}
            pts = {n: np.array(f["load_point_m"]) for n, f in r["fingers"].items()}
            con = json.loads((run / "contacts.json").read_text())     # world frame: rotate into the object's
            Rw = np.array(con["object_pose"]["rotation"])
            for name, f in r["fingers"].items():
                u = np.array(f["displacement_m"])
                push = Rw.T @ np.array(con["per_finger"][name]["force_N"])   # the finger's force on the object
                push = push / np.linalg.norm(push)
                ent["fingers"][name] = {"load_point_displacement_along_push_m": float(u @ push),
                                        "rings": [split(X, Y, pts[name], push, ri * 1e-3, ro * 1e-3)
                                                  for ri, ro in RINGS_MM]}
                rs = ent["fingers"][name]["rings"]
                print(f"{what}, E = {E:g} MPa ({E_label}), {name} finger: travel {u @ push * 1e3:.2f} mm; "
                      + "; ".join(f"ring {x['ring_mm'][0]:.0f}-{x['ring_mm'][1]:.0f} mm turns "
                                  f"{x['ring_rotation_deg']:.1f} deg, dent {x['dent_along_push_m'] * 1e3:.2f} mm"
                                  for x in rs), flush=True)
            rec["runs"].append(ent)
    (out / "duck_poke.json").write_text(json.dumps(rec, indent=1))
    print(f"wrote {out / 'duck_poke.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
