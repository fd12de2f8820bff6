"""``graspdef rank OBJECT --force F``: sample antipodal candidates on an object's surface, screen
them with the linear shell (one factorisation, a back-substitution each) and write the ranked
table.  The object is a scene folder with its object.toml (``graspdef object add`` makes one)."""
from __future__ import annotations

import csv
import json
import time
from pathlib import Path

import numpy as np

from ..errors import ProblemError
from ..objects import build_shell, load_object, scene_xml
from ..objects.build import outer_surface
from ..objects.placement import CLEARANCE, antipodal_candidates
from ..runs.folder import atomic_folder, check_output_folder
from ..sim.gripper import OPEN, TRAVEL
from .screen import LinearScreen, rank

#: ranking.csv columns and their units
COLUMNS = ["rank", "candidate", "first_x_m", "first_y_m", "first_z_m", "second_x_m", "second_y_m", "second_z_m",
           "width_m", "antipodal_angle_deg", "indentation_per_finger_m", "work_J", "grasp_stiffness_N_per_m",
           "max_displacement_m", "friction_margin_deg", "weight_torque_ratio"]


def _scene_facts(xml, body: str) -> tuple[float, np.ndarray, float]:
    """(mass [kg], centre of mass [m, object frame], Coulomb friction of the fingertip contact:
    MuJoCo combines two geoms' by their maximum) of the scene's object."""
    from ..sim.scene import load_scene

    sc = load_scene(xml, body)
    m = sc.model
    mu_obj = float(m.geom_friction[sc.object_geoms, 0].max())
    tips = [g for g in range(m.ngeom) if sc.finger_body_of_geom(g) is not None and m.geom_contype[g]]
    mu_tip = float(m.geom_friction[tips, 0].max()) if tips else mu_obj
    return float(m.body_mass[sc.object_body]), np.array(m.body_ipos[sc.object_body]), max(mu_obj, mu_tip)


def rank_object(scene, force: float, candidates: int = 2000, out=None, top: int = 10, progress=None) -> dict:
    """Rank up to ``candidates`` antipodal grasps of ``scene``'s object at ``force`` [N] per finger;
    write ``out`` (ranking.csv, ranking.json) when given; return the record (SI)."""
    say = progress or (lambda stage, info=None: None)
    if not (np.isfinite(force) and force > 0):
        raise ProblemError(f"force must be a positive number of newtons, got {force!r}")
    if not 1 <= int(candidates) <= 100_000:
        raise ProblemError(f"--candidates must be 1 to 100,000, got {candidates}")
    if out is not None:
        check_output_folder(out)
    t0 = time.perf_counter()
    xml = scene_xml(scene)
    spec = load_object(xml)
    mass, com, friction = _scene_facts(xml, spec.body)
    say("candidates")
    outer, _ = outer_surface(spec)
    cands = antipodal_candidates(outer, com, friction, max_width=2 * (OPEN - CLEARANCE),
                                 min_width=2 * (OPEN - TRAVEL) + 2 * CLEARANCE, n=int(candidates), seed=0)
    cands = cands[: int(candidates)]
    if not cands:
        raise ProblemError(f"{spec.file}: no antipodal grasp candidates within the gripper's opening and the "
                           f"friction cone (friction {friction:g})")
    t_cand = time.perf_counter()
    say("factor")
    shell, _ = build_shell(spec, "linear")
    screen = LinearScreen(shell)
    t_factor = time.perf_counter()
    rows = []
    try:
        for i, g in enumerate(cands):
            rows.append(screen.evaluate(i, g, force, friction, mass, com))
            say("candidate", {"done": i + 1, "of": len(cands)})
    finally:
        screen.close()
    t_screen = time.perf_counter()
    ranked = rank(rows)
    table = [{"rank": k + 1, **r.row()} for k, r in enumerate(ranked)]
    per_min = 60.0 * len(rows) / (t_screen - t_factor)
    record = {
        "schema": "graspdef.ranking", "version": 1,
        "units": {"length": "m", "force": "N", "energy": "J", "stiffness": "N/m", "angle": "deg"},
        "object": spec.body, "scene": str(xml), "force_N": float(force), "friction": friction, "mass_kg": mass,
        "centre_of_mass_m": com.tolist(), "material": {"model": "linear_elastic", "E_Pa": spec.material.E,
                                                       "nu": spec.material.nu},
        "thickness_m": spec.thickness, "control_vertices": int(shell.mesh.n_real), "n_candidates": len(rows),
        "ranking": "held candidates (friction margin > 0 and weight torque ratio < 1) first, then least work",
        "timings_s": {"candidates": t_cand - t0, "factor": t_factor - t_cand, "screen": t_screen - t_factor,
                      "total": t_screen - t0},
        "candidates_per_minute": per_min, "top": table[: int(top)],
    }
    if out is not None:
        with atomic_folder(out) as tmp:
            with open(tmp / "ranking.csv", "w", newline="") as fh:
                w = csv.DictWriter(fh, COLUMNS)
                w.writeheader()
                for row in table:
                    w.writerow({k: (f"{v:.9g}" if isinstance(v, float) else v) for k, v in row.items()})
            (tmp / "ranking.json").write_text(json.dumps(record, indent=1) + "\n")
        record["out"] = str(Path(out))
    return record
