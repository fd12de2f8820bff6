"""``graspdef grasp SCENE --force F [--contact point] [--analysis nonlinear] --out DIR``.

The chain (issue 5):

1. read the object's data (``object.toml`` beside the scene: body, scan, thickness, material law,
   gas, supports; graspdef.objects) and build the shell: control mesh of the scan
   (graspdef.scans.control_mesh), offset inward by t/2 (mid_surface);
2. MuJoCo: close the gripper until each finger presses with the target force, settle, extract
   the contacts and the object's pose (graspdef.sim.grasp);
3. contacts -> object frame -> point loads on the limit surface keeping total force and moment
   (graspdef.contact.map_contacts); the object's weight enters as a body force, so the loads
   balance to MuJoCo's settling accuracy; the residual net force and moment are reported;
4. a free object is held only by the fingers: its rigid-body modes are removed by
   RigidModes (a statically determinate 3-2-1 support in nonlinear solves, whose reactions
   are the residual); a fixed object (the duck-head poke) by point supports from object.toml;
5. linear or nonlinear solve; the indentation (approach of the contact points) is fed back:
   predicted finger gap = rigid-proxy gap - approach, mismatch against MuJoCo's gap reported;
6. the run folder, written atomically: result.json, contacts.json, deformed.ply,
   undeformed.ply (limit surface, metres), path.csv (nonlinear).
"""
from __future__ import annotations

import csv
import json
import logging
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..contact.mapping import map_contacts
from ..errors import ProblemError
from ..geometry.io import atomic_folder, save_ply
from ..geometry.provenance import write_provenance
from ..objects import build_shell, load_object, scene_xml
from ..problem.loads import BodyForce
from ..problem.potentials import EnclosedGas
from ..problem.problem import Problem
from ..problem.supports import PointSupport, RigidModes
from ..sim.grasp import GraspSettings, grasp
from ..solve.linear import solve_linear
from ..solve.nonlinear import PathOptions, PathStopped, solve_nonlinear

log = logging.getLogger(__name__)


@dataclass
class GraspRun:
    out: Path
    result: dict


def _rigid_fit_residual(x: np.ndarray, u: np.ndarray) -> np.ndarray:
    """u minus its least-squares infinitesimal rigid motion (translation + rotation about the
    centroid): the deformation part."""
    c = x.mean(axis=0)
    r = x - c
    A = np.zeros((3 * len(x), 6))
    A[:, :3] = np.tile(np.eye(3), (len(x), 1))
    for k in range(3):
        e = np.zeros(3)
        e[k] = 1
        A[:, 3 + k] = np.cross(e, r).ravel()
    coef = np.linalg.lstsq(A, u.ravel(), rcond=None)[0]
    return u - (A @ coef).reshape(-1, 3)


def run_grasp(scene, force: float, contact: str = "point", analysis: str = "nonlinear", out=None,
              gas: bool | None = None, settings: GraspSettings = GraspSettings(), control_faces: int | None = None,
              steps: int | None = None, E: float | None = None) -> GraspRun:
    """Run the whole chain for ``scene`` at ``force`` [N] per finger; write the run folder ``out``
    (when given) and return its result record.

    ``gas``: None = as object.toml says (nonlinear only); False/True forces the enclosed air off/on
    (on: object.toml's [gas] p0; an error if it gives none).  ``E`` [Pa]: overrides the Young's
    modulus of object.toml's material law."""
    t0 = time.perf_counter()
    if contact not in ("point", "geometric"):
        raise ProblemError(f"contact must be 'point' (the paper's point loads) or 'geometric' (rigid fingertips), "
                           f"got {contact!r}")
    if analysis not in ("linear", "nonlinear"):
        raise ProblemError(f"analysis must be 'linear' or 'nonlinear', got {analysis!r}")
    if not np.isfinite(force) or force <= 0:
        raise ProblemError(f"force must be a positive number of newtons, got {force!r}")
    xml = scene_xml(scene)
    spec = load_object(xml)
    if control_faces:
        spec = spec.replace(control_faces=int(control_faces))
    if E is not None:
        if not (np.isfinite(E) and E > 0):
            raise ProblemError(f"E must be a positive number of pascals, got {E!r}")
        spec = spec.replace(E=float(E))
    if gas and spec.gas is None:
        raise ProblemError(f"{spec.file}: gas on, but the object has no enclosed air: give [gas] p0 (gauge "
                           "pressure) with its source")
    if gas is None:     # the object's air; a linear shell cannot hold it (p V = const), so none there
        p0 = spec.gas.p0 if spec.gas is not None and analysis == "nonlinear" else 0.0
    else:
        p0 = spec.gas.p0 if gas else 0.0
    t_setup = time.perf_counter()
    shell, shell_info = build_shell(spec, analysis)
    t_shell = time.perf_counter()
    targets = {s: (force if s in spec.fingers else 0.0) for s in ("left", "right")}
    g = grasp(xml, targets, spec.body, settings)
    t_sim = time.perf_counter()
    cs = g.contacts.transformed(g.pose)
    mapping = map_contacts(shell, cs)
    loads = list(mapping.loads)
    fingertips = []
    if contact == "geometric":      # fingertips as rigid obstacles; MuJoCo's other force parts stay dead loads
        from .geometric import finger_contacts

        loads, fingertips = finger_contacts(mapping, g, targets, spec.thickness)
        loads = loads + fingertips
    g_obj = g.pose.vector_to_object(g.gravity)
    free = bool(g.info.get("free_object", True))
    if free:
        # the weight as a body force over the limit surface, with the density that gives MuJoCo's
        # mass exactly (the quadrature's own volume t * A, not the control mesh's)
        volume = float(BodyForce(1.0, (0.0, 0.0, 1.0)).vector(shell, shell.evaluator)[:, 2].sum())
        loads.append(BodyForce(g.object_mass / volume, tuple(g_obj)))
        supports = [RigidModes()]
    else:
        supports = []
        pr0 = Problem(shell, [], [RigidModes()])
        for i, p in enumerate(spec.fixed_points):
            sp = pr0.locate(p, f"fixed point {i}", tol=5e-3)
            supports.append(PointSupport(sp.face, sp.bary, name=f"fixed_{i}"))
        if not supports:
            raise ProblemError(f"{spec.file}: a fixed object needs [supports] fixed_points")
    if p0 > 0:
        loads.append(EnclosedGas(p0) if spec.gas.p_atm is None else EnclosedGas(p0, spec.gas.p_atm))
    probes = {}
    for s in sorted(set(mapping.finger)):
        idx = [i for i, f in enumerate(mapping.finger) if f == s]
        k = idx[int(np.argmax([np.linalg.norm(mapping.forces[i]) for i in idx]))]
        probes[s] = mapping.surface_points[k]
    problem = Problem(shell, loads, supports, probes)
    # net force and moment of the assembled dead loads (contacts + weight): what the rigid-mode
    # support has to carry; zero up to MuJoCo's settling and the mass discretisation
    fvec = problem.dead_load_vector().reshape(-1, 3)
    residual_F = fvec.sum(axis=0)
    residual_M = np.cross(shell.rest_positions, fvec).sum(axis=0)
    completed, stop_reason = True, None
    # contact paths take a few more Newton iterations per step (the barrier stiffens as the patch
    # grows): let the step grow unless a step took more than 8; and they pass close to
    # bifurcations (a ball between two pins may roll), where the branch a load-controlled path
    # follows depends on its steps: refresh a stale tangent at contraction worse than 1/2 and
    # factorise every converged point (the settings the contact tables were made with; the
    # solver's defaults for smooth paths, reuse_ratio 0.9 and inertia_rtol 1e-4, stop the pinned
    # ball at 12.9 of 20.37 N)
    path_opts = {"desired_iterations": 8, "reuse_ratio": 0.5, "inertia_rtol": 0.0} if fingertips else {}
    opt = PathOptions(steps=steps or spec.steps, max_steps=40 * (steps or spec.steps), min_step=1e-3, **path_opts)
    if analysis == "linear" and p0 > 0:
        raise ProblemError("an enclosed gas needs the nonlinear analysis (p V = const is nonlinear)")
    if analysis == "linear" and not fingertips:
        sol = solve_linear(problem)
    else:
        from .geometric import solve_contact

        try:
            sol = solve_contact(problem, opt, linear=analysis == "linear") if fingertips else solve_nonlinear(problem, opt)
        except PathStopped as exc:
            sol, completed, stop_reason = exc.solution, False, str(exc)
    t_solve = time.perf_counter()
    # displacements and indentation (rigid-motion free)
    Lm = sol.limit_map()
    x_lim = Lm @ shell.mesh.vertices
    # displacements from the unloaded equilibrium (load factor 0: the shell inflated by its air,
    # which is the state the scan and MuJoCo's rigid proxy show), not from the stress-free shape
    ref = sol.path[0] if hasattr(sol, "path") else None
    u_lim = sol.vertex_displacements() - (Lm @ ref.u if ref is not None else 0.0)
    u_def = _rigid_fit_residual(x_lim, u_lim) if free else u_lim
    fingers = {}
    pf = g.per_finger()
    def probe(s):
        return sol.probe(s) - (np.asarray(ref.probes[s]) if ref is not None else 0.0)

    for s, sp in probes.items():
        u = probe(s)
        n = pf[s]["normal"]
        fingers[s] = {"target_N": targets[s], "normal_force_N": pf[s]["normal_force"],
                      "axial_force_N": g.info["axial_force_N"][s],
                      "friction_force_N": pf[s]["friction_force"], "n_contacts": pf[s]["n_contacts"],
                      "load_point_m": mapping.points[[i for i, f in enumerate(mapping.finger) if f == s][0]].tolist(),
                      "displacement_m": u.tolist(), "displacement_along_normal_m": float(u @ g.pose.vector_to_object(n))}
    feedback = {}
    if len(probes) == 2:
        e = g.pose.vector_to_object(pf["right"]["point"] - pf["left"]["point"])
        sep = float(np.linalg.norm(e))
        e /= sep
        approach = float((probe("left") - probe("right")) @ e)
        feedback = {"rigid_contact_separation_m": sep, "approach_m": approach,
                    "indentation_per_finger_m": approach / 2,
                    "mujoco_tip_gap_m": g.tip_gap, "predicted_tip_gap_m": g.tip_gap - approach,
                    "mismatch_m": approach,
                    "note": "one-way coupling: MuJoCo's rigid proxy keeps the fingers at the undeformed gap "
                            "(less its soft-contact penetration); the shell says they close by 'approach'"}
    else:
        s = next(iter(probes))
        ind = fingers[s]["displacement_along_normal_m"]      # along the push: positive = indented
        feedback = {"indentation_m": ind, "mujoco_tip_gap_m": g.tip_gap, "mismatch_m": ind}
    geo = None
    if fingertips:
        from .geometric import contact_reports

        lam = getattr(sol, "load_factor", 1.0)
        geo = contact_reports(shell, fingertips, sol.u, lam, None if ref is None else ref.u)
        for s, r in geo.items():
            fingers[s].update({"advance_m": r["advance_m"], "contact_area_m2": r["contact_area_m2"],
                               "contact_force_N": r.get("contact_force_N"),
                               "contact_force_along_axis_N": r.get("contact_force_along_axis_N"),
                               "peak_pressure_Pa": r.get("peak_pressure_Pa")})
        adv = [r["advance_m"] - r["touch_advance_m"] for r in geo.values()]
        key = "indentation_per_finger_m" if len(adv) == 2 else "indentation_m"
        feedback.update({"probe_approach_m": feedback.get("approach_m"), "approach_m": float(sum(adv)),
                         key: float(sum(adv)) / len(adv), "predicted_tip_gap_m": g.tip_gap - float(sum(adv)),
                         "mismatch_m": float(sum(adv)),
                         "note": "geometric contact: the approach is the fingers' travel from where they touch the "
                                 "unloaded shell (advance of each force-controlled fingertip)"})
        # net force of everything acting on the shell (dead loads + contact forces): what the
        # 3-2-1 support carries
        residual_F = residual_F + sum(np.asarray(r.get("contact_force_N", np.zeros(3))) for r in geo.values())
    rec = {
        "scene": str(xml), "object": spec.body, "force_N": force, "contact": contact, "analysis": analysis,
        "material": {"model": spec.material.model(analysis), "E_Pa": spec.material.E, "nu": spec.material.nu,
                     "thickness_m": spec.thickness},
        "gas_p0_Pa": p0, "shell": shell_info,
        "max_displacement_m": float(np.linalg.norm(u_def, axis=1).max()),
        "max_displacement_raw_m": float(np.linalg.norm(u_lim, axis=1).max()),
        "fingers": fingers, "feedback": feedback,
        "displacement_reference": "unloaded equilibrium (load factor 0; with air: the inflated shell)",
        "contact_area_m2": float(sum(r["contact_area_m2"] for r in geo.values())) if geo else 0.0,
        "load_mapping": mapping.record(),
        "residual": {"net_force_N": np.asarray(residual_F).tolist(),
                     "net_moment_Nm": None if geo else np.asarray(residual_M).tolist()},
        "mujoco": g.record(),
        "convergence": {"completed": completed, "stop_reason": stop_reason},
        "timings_s": {"shell_setup": t_shell - t_setup, "mujoco": t_sim - t_shell, "solve": t_solve - t_sim,
                      "total": time.perf_counter() - t0},
        "units": "SI (m, N, Pa)",
    }
    if geo:
        rec["geometric_contact"] = {
            "model": "rigid force-controlled fingertips, IPC log barrier on mid-surface samples against the "
                     "fingertip inflated by t/2", "fingers": geo,
            "contact_area_definition": "sampled surface area with gap < dhat (contact pressure > 0)",
            "friction": "MuJoCo's contact forces less their finger-axis parts, as dead loads at the contacts"}
    if hasattr(sol, "path"):
        rec["convergence"].update({"load_factor": sol.load_factor, "n_points": len(sol.path),
                                   "newton_iterations": sol.iterations(), "n_factorisations": sol.n_factorisations,
                                   "critical_points": [dict(cp, probes={k: np.asarray(v).tolist() for k, v in cp["probes"].items()})
                                                       for cp in sol.critical_points]})
    else:
        rec["convergence"].update({"relative_residual": sol.kkt.residual})
    if analysis == "linear" and fingertips:
        rec["convergence"]["note"] = "linear shell (rest stiffness K0) with contact: a load path of the nonlinear solver"
    if out is not None:
        out = Path(out)
        config = {"scene": str(scene), "force_N": force, "contact": contact, "analysis": analysis, "gas": gas,
                  "control_faces": control_faces, "steps": steps, "E_Pa": E, "settings": dict(settings.__dict__),
                  "object_toml": spec.file.read_text()}
        _write(out, rec, g, sol, x_lim, u_def, config)
    return GraspRun(Path(out) if out is not None else None, rec)


def _write(out: Path, rec: dict, g, sol, x_lim, u_def, config: dict | None = None) -> None:
    with atomic_folder(out) as tmp:
        write_provenance(tmp, config)
        rec = dict(rec, files={"deformed": "deformed.ply", "undeformed": "undeformed.ply", "contacts": "contacts.json"})
        (tmp / "result.json").write_text(json.dumps(rec, indent=2, default=float) + "\n")
        (tmp / "contacts.json").write_text(json.dumps({
            "frame": "world", "object_pose": g.pose.record(), "contacts": g.contacts.records(),
            "per_finger": rec["mujoco"]["per_finger"]}, indent=2) + "\n")
        verts, faces = sol.deformed_surface()
        save_ply(tmp / "deformed.ply", verts, faces, units="m",
                 vertex_scalars={"displacement": np.linalg.norm(u_def, axis=1)})
        save_ply(tmp / "undeformed.ply", x_lim, faces, units="m")
        if hasattr(sol, "path"):
            with open(tmp / "path.csv", "w", newline="") as fh:
                w = csv.writer(fh)
                names = list(sol.problem.probes)
                w.writerow(["point", "load_factor", "newton_iterations"] + [f"{n}_u{c}[m]" for n in names for c in "xyz"])
                for i, p in enumerate(sol.path):
                    w.writerow([i, p.load_factor, p.iterations] + [float(v) for n in names for v in p.probes[n]])

