"""``graspdef rank OBJECT --force F``: sample antipodal candidates on an object's surface, screen
them with the linear shell (one factorisation, back-substitutions in blocks), rank them and write
the ranking folder (graspdef.runs.ranking).  The object is a folder with its object.toml
(``graspdef object add`` makes one), a scene.xml, or a name under scenes/.

Ranking criterion: candidates that hold (deformed friction margin > 0, the weight's torque and
slip ratios < 1, the strain limit kept when one is given) first, by least work spent deforming
the object; then the others, by least work.  The rigid baseline ranks by the rest friction margin
(largest first), then the weight's torque ratio -- what a planner that ignores deformation sees.
"""
from __future__ import annotations

import math
import time

import numpy as np

from ..errors import ProblemError
from ..objects import build_shell, load_object, scene_xml
from ..objects.build import outer_surface
from ..objects.placement import CLEARANCE, antipodal_candidates
from ..pipeline.grasp import check_force
from ..runs.folder import check_output_folder
from ..runs.ranking import write_ranking
from ..sim.gripper import OPEN, TRAVEL, GripperModel
from .screen import LinearScreen, PairFigures

#: torsional friction of a fingertip contact [m] (MuJoCo condim 4: torque = this x normal force;
#: the scenes' 0.005)
TORSIONAL_FRICTION = 0.005
G = 9.81
#: candidates whose linear displacement is stored for the viewer (shapes.npz)
SHAPES = 50


def scene_facts(xml, body: str) -> tuple[float, np.ndarray, float]:
    """(mass [kg], centre of mass [m, object frame], Coulomb friction of the fingertip contact:
    MuJoCo combines two geoms' by their maximum) of the scene's object."""
    from ..sim.scene import load_scene

    sc = load_scene(xml, body)
    m = sc.model
    mu_obj = float(m.geom_friction[sc.object_geoms, 0].max())
    tips = [g for g in range(m.ngeom) if sc.finger_body_of_geom(g) is not None and m.geom_contype[g]]
    mu_tip = float(m.geom_friction[tips, 0].max()) if tips else mu_obj
    return float(m.body_mass[sc.object_body]), np.array(m.body_ipos[sc.object_body]), max(mu_obj, mu_tip)


def pareto_front(work: np.ndarray, margin: np.ndarray) -> np.ndarray:
    """Mask of the candidates no other beats in both (less work, larger margin)."""
    order = np.lexsort((-margin, work))
    front = np.zeros(len(work), bool)
    best = -np.inf
    for i in order:
        if margin[i] > best:
            front[i] = True
            best = margin[i]
    return front


def compliance_map(screen: LinearScreen, max_width: float | None = None, progress=None) -> dict:
    """Per control vertex: compliance [m/N] of the pinch along its inward normal (unit forces at
    the vertex's limit point and at the far side's sample where the normal line leaves the
    surface), its stiffness [N/m] and width [m]; NaN where the line finds no far side or the
    width exceeds ``max_width``."""
    import trimesh

    n = screen.n_control
    # the far side along the normal line, on the outer face of the control vertices' limit points
    # (a coarse triangulation of the same surface; the hit is then snapped to the nearest sample)
    faces = screen.shell.mesh.faces[: screen.shell.mesh.n_real_faces]
    tm = trimesh.Trimesh(screen.outer[:n], faces, process=False)
    start = screen.outer[:n] - 1e-6 * screen.normal[:n]
    locs, ray, _ = tm.ray.intersects_location(start, -screen.normal[:n], multiple_hits=True)
    dist = np.einsum("ij,ij->i", locs - start[ray], -screen.normal[:n][ray])
    ok = dist > 1e-4 * float(np.ptp(screen.outer, axis=0).max())
    locs, ray, dist = locs[ok], ray[ok], dist[ok]
    far = np.full(n, -1)
    width = np.full(n, np.nan)
    if len(ray):
        order = np.lexsort((dist, ray))
        first = order[np.r_[True, ray[order][1:] != ray[order][:-1]]]
        j, _ = screen.locate(locs[first])
        far[ray[first]] = j
        width[ray[first]] = dist[first]
    has = (far >= 0) & (far != np.arange(n))
    if max_width is not None:
        has &= width <= max_width
    comp = np.full(n, np.nan)
    idx = np.flatnonzero(has)
    if len(idx):
        fig = screen.evaluate(idx, far[idx], 1.0, progress)
        comp[idx] = fig.closing_m
    with np.errstate(divide="ignore", invalid="ignore"):
        stiff = 1.0 / comp
    return {"compliance_m_per_N": comp, "stiffness_N_per_m": stiff, "pinch_width_m": np.where(has, width, np.nan)}


def screen_chunk(scene, force, first: np.ndarray, second: np.ndarray, pad_size: float) -> PairFigures:
    """The linear figures of the pairs (``first[j]``, ``second[j]``) [m, contacts on the outer
    surface] of ``scene``'s object at ``force`` [N, one or one per pair] -- a whole screen in one call (its own
    factorisation): the unit of work a Dask worker runs (graspdef.sweep.rank)."""
    spec = load_object(scene_xml(scene))
    shell, _ = build_shell(spec, "linear")
    screen = LinearScreen(shell, shell.material.E, shell.material.nu, pad_radius=0.5 * pad_size)
    try:
        return screen.evaluate(screen.locate(first)[0], screen.locate(second)[0], force)
    finally:
        screen.close()


def holding_force(mass: float, friction: float, off: np.ndarray) -> np.ndarray:
    """The least squeezing force per finger [N] at which the weight neither slips the grasp
    (m g <= 2 friction F) nor twists it about the grasp line (m g off <= 2 TORSIONAL_FRICTION F),
    per candidate of line distance ``off`` [m] from the centre of mass (gravity across the line)."""
    return np.maximum(mass * G / (2.0 * friction), mass * G * np.asarray(off) / (2.0 * TORSIONAL_FRICTION))


def rank_object(scene, force: float | None = None, candidates: int = 2000, out=None, *, top: int = 10,
                force_range: tuple[float, float] | None = None,
                strain_limit: float | None = None, pad_size: float = GripperModel.pad_size,
                with_map: bool = True, recheck: int = 0, progress=None, screen_with=None,
                extra: dict | None = None) -> dict:
    """Rank up to ``candidates`` antipodal grasps of ``scene``'s object at ``force`` [N] per finger,
    or, with ``force_range`` (A, B) [N], each at the least force in [A, B] that holds it against its
    weight (:func:`holding_force`; B when none does) -- how hard to grasp, and where; write the
    ranking folder ``out`` when given; return the record (SI).

    ``strain_limit``: the wall's allowed principal strain (e.g. 0.02); ``pad_size`` [m]: the flat
    pad's edge for the contact-area estimate; ``recheck``: re-run the best k fully nonlinear
    (graspdef.ranking.recheck); ``progress(stage, info)``; ``screen_with(first, second)``: screens
    the candidates elsewhere (graspdef.sweep.rank: on Dask) at their forces (``screen_with(first,
    second, forces)``) and returns their PairFigures; ``extra``:
    entries added to the record (how it was screened)."""
    say = progress or (lambda stage, info=None: None)
    if (force is None) == (force_range is None):
        raise ProblemError("give --force F or --force-range A B, one of them")
    if force_range is not None:
        lo, hi = (float(x) for x in force_range)
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
            raise ProblemError(f"--force-range must be two forces 0 < A < B in newtons, got {force_range!r}")
        force = hi
    if not (isinstance(force, (int, float)) and math.isfinite(force) and force > 0):
        raise ProblemError(f"--force must be a positive number of newtons, got {force!r}")
    if not 1 <= int(candidates) <= 100_000:
        raise ProblemError(f"--candidates must be 1 to 100,000, got {candidates}")
    if strain_limit is not None and not (math.isfinite(strain_limit) and 0 < strain_limit < 1):
        raise ProblemError(f"--strain-limit must be a strain between 0 and 1 (e.g. 0.02 or 2%), got {strain_limit!r}")
    if not 0 <= int(recheck) <= 50:
        raise ProblemError(f"--recheck must be 0 to 50 candidates, got {recheck}")
    GripperModel(tip="pad", pad_size=pad_size)                          # checks the pad size
    if out is not None:
        check_output_folder(out, "ranking.json")
    t0 = time.perf_counter()
    xml = scene_xml(scene)
    spec = load_object(xml)
    check_force(xml, float(force))                   # the gripper's force range
    if spec.gas is not None:
        raise ProblemError(f"{spec.file}: the object encloses a gas ([gas]); the linear screen has no pressurised "
                           "rest state (its prestress and the gas's volume stiffness), so it would rank a different "
                           "object: rank it without the gas, or grasp candidates one by one (graspdef grasp)")
    if recheck and spec.material.law == "linear":
        raise ProblemError(f"{spec.file}: --recheck grasps nonlinearly, and [material] law = 'linear' has no "
                           "finite-strain form: give the object law = 'svk' or a hyperelastic law")
    mass, com, friction = scene_facts(xml, spec.body)
    say("candidates")
    outer, _ = outer_surface(spec)
    max_width, min_width = 2 * (OPEN - CLEARANCE), 2 * (OPEN - TRAVEL) + 2 * CLEARANCE
    cands = antipodal_candidates(outer, com, friction, max_width=max_width, min_width=min_width,
                                 n=int(candidates), seed=0, limit=int(candidates),
                                 max_reach=OPEN - CLEARANCE)
    if not cands:
        raise ProblemError(f"{spec.file}: no antipodal grasp candidates {min_width * 1e3:.0f} to {max_width * 1e3:.0f} mm "
                           f"wide (the gripper's opening) within the friction cone (friction {friction:g})")
    t_cand = time.perf_counter()
    say("factor")
    shell, _ = build_shell(spec, "linear")
    E, nu = shell.material.E, shell.material.nu
    screen = LinearScreen(shell, E, nu, pad_radius=0.5 * pad_size)
    try:
        t_factor = time.perf_counter()
        first = np.array([g.first for g in cands])
        second = np.array([g.second for g in cands])
        i1, d1 = screen.locate(first)
        i2, d2 = screen.locate(second)
        if force_range is None:
            forces = np.full(len(cands), float(force))
        else:
            axis = np.array([g.axis for g in cands])
            off = np.linalg.norm(np.cross(com - first, axis), axis=1)
            forces = np.clip(holding_force(mass, friction, off), lo, hi)
        if screen_with is None:
            fig = screen.evaluate(i1, i2, forces, lambda done, of: say("candidate", {"done": done, "of": len(cands)}))
        else:
            fig = screen_with(first, second, forces)
        t_screen = time.perf_counter()
        rows = _rows(cands, fig, forces, friction, mass, com, strain_limit)
        order = [r["candidate"] for r in rows]
        best = np.array(order[: min(SHAPES, len(order))])
        U, _, _ = screen.solve(i1[best], i2[best], forces[best])
        shapes = screen.surface_displacements(U)
        maps = {"compliance_m_per_N": np.full(screen.n_control, np.nan), "stiffness_N_per_m":
                np.full(screen.n_control, np.nan), "pinch_width_m": np.full(screen.n_control, np.nan)}
        if with_map:
            say("map")
            maps = compliance_map(screen, max_width=None,
                                  progress=lambda done, of: say("map", {"done": done, "of": of}))
        t_map = time.perf_counter()
        rest = screen.L @ shell.rest_positions
        faces = shell.mesh.faces[: shell.mesh.n_real_faces]
        locate_err = float(max(d1.max(), d2.max()))
        n_samples, level = screen.samples.n, screen.samples.level
    finally:
        screen.close()
    from scipy.stats import spearmanr  # here, not at import: ~0.5 s that Dask's screen_chunk workers never need

    rho = spearmanr([r["rank"] for r in rows], [r["rigid_rank"] for r in rows]).statistic if len(rows) > 2 else math.nan
    record = {
        "units": {"length": "m", "force": "N", "energy": "J", "stiffness": "N/m", "angle": "deg", "stress": "Pa",
                  "area": "m^2"},
        "object": spec.body, "scene": str(xml), "force_N": float(force),
        "force_range_N": None if force_range is None else [lo, hi],
        "force_rule": ("one force for every candidate" if force_range is None else
                       "each candidate at the least force in the range that holds it against its weight "
                       "(slip: m g / (2 friction); twist: m g off / (2 torsional friction)); the range's top "
                       "when none does"),
        "friction": friction, "mass_kg": mass,
        "centre_of_mass_m": com.tolist(), "gravity_m_per_s2": G, "torsional_friction_m": TORSIONAL_FRICTION,
        "material": {"model": "linear_elastic (the object's small-strain moduli)", "E_Pa": E, "nu": nu,
                     "law": spec.material.law, "source": spec.material.source},
        "thickness_m": spec.thickness, "control_vertices": int(shell.mesh.n_real),
        "samples": {"level": level, "n": int(n_samples),
                    "largest_contact_to_sample_m": locate_err},
        "pad_size_m": pad_size, "strain_limit": strain_limit,
        "n_candidates": len(rows), "candidates_requested": int(candidates),
        "gripper_opening_m": [min_width, max_width],
        "ranking": ("held candidates (deformed friction margin > 0, weight torque and slip ratios < 1, strain "
                    "limit kept) first, by least work spent deforming the object; then the others, by least work"),
        "rigid_ranking": "rest friction margin (largest first), then the weight's torque ratio (smallest first)",
        "rank_correlation": {"rigid_vs_deformable_spearman": float(rho)},
        "n_held": int(sum(r["held"] for r in rows)), "n_pareto": int(sum(r["pareto"] for r in rows)),
        "n_beyond_linear_range": int(sum(r["indentation_per_finger_m"] > spec.thickness for r in rows)),
        "linear_range": ("the screen is linear: a candidate whose indentation per finger exceeds the wall's thickness "
                         "is outside its range (its figures, the deformed normals most, are indicative only; "
                         "--recheck runs the best nonlinearly)"),
        "timings_s": {"candidates": t_cand - t0, "factor_and_setup": t_factor - t_cand, "screen": t_screen - t_factor,
                      "map": t_map - t_screen, "total": t_map - t0},
        "candidates_per_minute": 60.0 * len(rows) / max(t_screen - t_factor, 1e-9),
        "top": rows[: int(top)],
    }
    record.update(extra or {})
    if recheck:
        from .recheck import recheck_top

        say("recheck")
        record.update(recheck_top(scene, spec, rows[: int(recheck)], progress=say))
    if out is not None:
        write_ranking(out, record, rows, rest, faces, maps, best, shapes)
        record["out"] = str(out)
    return record


def _rows(cands, fig, force: np.ndarray, friction, mass, com, strain_limit) -> list[dict]:
    """The table's rows in rank order (every column of graspdef.runs.ranking.COLUMNS)."""
    cone = math.degrees(math.atan(friction))
    n = len(cands)
    first = np.array([g.first for g in cands])
    second = np.array([g.second for g in cands])
    axis = np.array([g.axis for g in cands])
    angle = np.array([g.angle_deg for g in cands])
    margin = cone - fig.rest_angle_deg
    off = np.linalg.norm(np.cross(np.asarray(com) - first, axis), axis=1)
    torque = mass * G * off / (2.0 * TORSIONAL_FRICTION * force)
    slip = mass * G / (2.0 * friction * force)
    dmargin = cone - fig.deformed_angle_deg
    ratio = fig.peak_strain / strain_limit if strain_limit else np.full(n, np.nan)
    # at most 1 (not below): with a force range a candidate sits exactly at its least holding force
    eps = 1e-9
    held = (dmargin > 0) & (torque <= 1.0 + eps) & (slip <= 1.0 + eps) & (~(ratio > 1.0))
    rank_order = np.lexsort((np.arange(n), fig.work_J, ~held))
    rigid_order = np.lexsort((np.arange(n), torque, -margin))
    rank = np.empty(n, np.int64)
    rank[rank_order] = np.arange(1, n + 1)
    rigid = np.empty(n, np.int64)
    rigid[rigid_order] = np.arange(1, n + 1)
    pareto = pareto_front(fig.work_J, dmargin)
    rows = []
    for i in rank_order:
        rows.append({
            "rank": int(rank[i]), "candidate": int(i),
            "first_x_m": first[i, 0], "first_y_m": first[i, 1], "first_z_m": first[i, 2],
            "second_x_m": second[i, 0], "second_y_m": second[i, 1], "second_z_m": second[i, 2],
            "width_m": float(np.linalg.norm(second[i] - first[i])), "antipodal_angle_deg": float(angle[i]),
            "friction_margin_deg": float(margin[i]), "rigid_rank": int(rigid[i]), "force_N": float(force[i]),
            "closing_m": float(fig.closing_m[i]), "indentation_per_finger_m": 0.5 * float(fig.closing_m[i]),
            "work_J": float(fig.work_J[i]), "strain_energy_J": float(fig.strain_energy_J[i]),
            "grasp_stiffness_N_per_m": float(fig.stiffness_N_per_m[i]),
            "max_displacement_m": float(fig.max_displacement_m[i]), "peak_strain": float(fig.peak_strain[i]),
            "peak_von_mises_Pa": float(fig.peak_von_mises_Pa[i]), "strain_limit_ratio": float(ratio[i]),
            "contact_area_m2": float(fig.contact_area_m2[i]),
            "deformed_friction_margin_deg": float(dmargin[i]), "weight_torque_ratio": float(torque[i]),
            "weight_slip_ratio": float(slip[i]), "held": int(held[i]), "pareto": int(pareto[i]),
        })
    return rows
