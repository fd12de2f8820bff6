"""The nonlinear re-evaluation of the best candidates of a linear screen: each one grasped by the
whole chain (graspdef.pipeline: MuJoCo's pad gripper with friction settles the grasp; its contact
forces -- normal and friction, spread over the pads' contact points -- are mapped onto the shell
as loads, the paper's model; the object's own nonlinear law), with the object placed for that
candidate's grasp line (graspdef.objects.placement.pose_for).  (Geometric contact, the pads as
rigid obstacles, refuses a start where MuJoCo's soft pad sits inside the shell's outer surface,
which the settled pads of a stiff object often do.)

Each candidate runs in a copy of the object's folder whose pad scene has the object's pose
replaced (the gripper file is included by its absolute path).  A candidate the gripper cannot
make (the open fingers would cut the object) or whose grasp fails (MuJoCo drops it, the path
stops) is reported with its reason and left out of the rank correlation.
"""
from __future__ import annotations

import math
import re
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from ..errors import GraspdefError
from ..objects import scene_xml
from ..objects.build import outer_surface
from ..objects.placement import Grasp, pose_for
from ..pipeline.grasp import run_grasp
from ..sim.mjcf import fmt, quat_of


def posed_scene(scene, body: str, grasp: Grasp, outer, folder: Path) -> Path:
    """Copy the object's folder into ``folder`` with its pad scene posed for ``grasp``; return the
    new scene's path."""
    src = scene_xml(scene, "pad")
    pos, R = pose_for(outer, grasp, "recheck")
    shutil.copytree(src.parent, folder, ignore=shutil.ignore_patterns("runs", "*.csv", "ranking*"))
    xml = (folder / src.name).read_text()

    def absolute(m):
        f = m.group(1)
        return f'<include file="{(src.parent / f).resolve()}"/>'

    xml = re.sub(r'<include file="([^"]+)"/>', absolute, xml)
    pat = re.compile(r'(<body name="' + re.escape(body) + r'")[^>]*>')
    if not pat.search(xml):
        raise GraspdefError(f"{src}: no <body name=\"{body}\"> to place for the recheck")
    xml = pat.sub(lambda m: f'{m.group(1)} pos="{fmt(pos)}" quat="{fmt(quat_of(R))}">', xml, count=1)
    out = folder / src.name
    out.write_text(xml)
    return out


def recheck_top(scene, spec, rows: list[dict], progress=None) -> dict:
    """Grasp each candidate of ``rows`` (the ranking's best, in rank order) nonlinearly at its
    force (column force_N); return
    ``{"recheck": [...], "recheck_spearman": rho}`` -- rho between the linear and the nonlinear
    approach of the fingers over the candidates that ran."""
    say = progress or (lambda stage, info=None: None)
    outer, _ = outer_surface(spec)
    out = []
    with tempfile.TemporaryDirectory(prefix="graspdef-recheck-") as tmp:
        for k, r in enumerate(rows):
            say("recheck", {"done": k, "of": len(rows)})
            first = np.array([r["first_x_m"], r["first_y_m"], r["first_z_m"]])
            second = np.array([r["second_x_m"], r["second_y_m"], r["second_z_m"]])
            d = (second - first) / np.linalg.norm(second - first)
            g = Grasp(first, second, d, r["antipodal_angle_deg"], f"candidate {r['candidate']}")
            entry = {"rank": r["rank"], "candidate": r["candidate"], "linear_closing_m": r["closing_m"],
                     "linear_work_J": r["work_J"]}
            t0 = time.perf_counter()
            try:
                xml = posed_scene(scene, spec.body, g, outer, Path(tmp) / f"candidate_{r['candidate']}")
                run = run_grasp(xml, r["force_N"], contact="point", analysis="nonlinear")
                fb = run.result.get("feedback", {})
                approach = fb.get("approach_m")
                entry.update({"status": "ok", "nonlinear_closing_m": approach,
                              "nonlinear_max_displacement_m": _derived(run.result, "max_displacement"),
                              "seconds": time.perf_counter() - t0})
            except GraspdefError as exc:
                entry.update({"status": f"failed: {exc}", "nonlinear_closing_m": None,
                              "seconds": time.perf_counter() - t0})
            out.append(entry)
        say("recheck", {"done": len(rows), "of": len(rows)})
    ok = [e for e in out if e["nonlinear_closing_m"] is not None]
    from scipy.stats import spearmanr  # here, not at import (scipy.stats takes ~0.5 s)

    rho = (float(spearmanr([e["linear_closing_m"] for e in ok], [e["nonlinear_closing_m"] for e in ok]).statistic)
           if len(ok) >= 3 else math.nan)
    return {"recheck": out, "recheck_spearman": rho,
            "recheck_method": "graspdef grasp with the pad gripper (MuJoCo, friction), its contact forces as loads, "
                              "nonlinear, the object's law; "
                              "Spearman rank correlation of the linear and nonlinear closing over the candidates "
                              "that ran (NaN below 3)"}


def _derived(record: dict, key: str):
    d = record.get("derived", {}).get(key)
    return d.get("value") if isinstance(d, dict) else d
