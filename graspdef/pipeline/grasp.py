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
   RigidModes (six rows on the surface's mean displacement and mean rotation, no vertex
   picked; their reactions are the residual); a fixed object (the duck-head poke) by point supports from object.toml;
5. linear or nonlinear solve; the indentation (approach of the contact points) is fed back:
   predicted finger gap = rigid-proxy gap - approach, mismatch against MuJoCo's gap reported;
6. the run folder, written by the one writer (graspdef.runs.write_run): result.json (with the
   derived quantities and their definitions), contacts.json, deformed.ply / .vtu, undeformed.ply,
   path.csv (nonlinear).

Each step is a stage with a typed input and output, testable alone:
:func:`prepare_object` -> :class:`GraspObject`; :func:`settle` -> :class:`Settled`;
:func:`shell_problem` -> :class:`ShellSetup`; :func:`solve_shell` -> :class:`Solved`;
:func:`grasp_record` -> :class:`GraspOutcome` (the run record and the arrays the folder holds);
:func:`write_grasp_run`.  :func:`run_grasp` chains them.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..contact.barrier import CONTACT_PATH
from ..contact.mapping import map_contacts
from ..errors import ProblemError, SolverError
from ..objects import build_shell, load_object, scene_xml
from ..objects.checks import check_thin_shell
from ..problem.loads import BodyForce
from ..problem.potentials import EnclosedGas
from ..problem.problem import Problem
from ..problem.supports import PointSupport, RigidModes
from ..problem.terms import RestQuadratic
from ..runs import derived as D
from ..runs.record import SI_UNITS, RunRecord
from ..runs.write import write_run
from ..shell.energy import ShellEnergy
from ..sim.grasp import GraspSettings, grasp
from ..solve.linear import solve_linear
from ..solve.nonlinear import PathOptions, PathStopped, solve_nonlinear
from ..solve.output import path_rows

log = logging.getLogger(__name__)


@dataclass
class GraspRun:
    out: Path | None
    result: dict          # the run record as its JSON document


@dataclass
class GraspObject:
    """Stage 1: the object's data and its shell."""

    xml: Path
    spec: object                   # graspdef.objects ObjectSpec
    shell: object                  # graspdef.shell.Shell
    shell_info: dict
    p0: float                      # enclosed air's initial gauge pressure [Pa] (0: none)


@dataclass
class Settled:
    """Stage 2: MuJoCo's settled grasp (contacts, object pose, per-finger forces)."""

    g: object                      # graspdef.sim.grasp.GraspResult
    targets: dict                  # finger -> target normal force [N]


@dataclass
class ShellSetup:
    """Stage 3: the shell problem of the settled contacts."""

    problem: Problem
    mapping: object                # graspdef.contact.mapping.ContactMapping
    fingertips: list               # geometric contact: the fingertip obstacles (else empty)
    free: bool                     # a free body (rigid modes removed) or one held by point supports
    probes: dict
    residual_F: np.ndarray
    residual_M: np.ndarray
    friction: dict = field(default_factory=dict)   # finger -> (mu, source) of the shell-side friction terms


@dataclass
class Solved:
    """Stage 4: the solution (complete, or where its path stopped)."""

    sol: object
    completed: bool
    stop_reason: str | None


@dataclass
class GraspOutcome:
    """Stage 5: the run record and the arrays the run folder holds (SI)."""

    record: RunRecord
    rest: np.ndarray               # (n, 3) limit surface at rest [m]
    deformed: np.ndarray           # (n, 3) deformed limit surface [m]
    faces: np.ndarray
    displacement: np.ndarray       # (n, 3) the field of derived.max_displacement [m]
    contacts: dict                 # contacts.json
    path: tuple | None             # (header, rows) of path.csv
    fields: dict                   # further per-vertex fields (SI; e.g. strain_energy_density [J/m^2])


def prepare_object(scene, analysis: str = "nonlinear", gas: bool | None = None, control_faces: int | None = None,
                   E: float | None = None) -> GraspObject:
    """Stage 1: read the object's data beside ``scene`` and build its shell.

    ``gas``: None = as object.toml says (nonlinear only); False/True forces the enclosed air off/on
    (on: object.toml's [gas] p0; an error if it gives none).  ``E`` [Pa]: overrides the Young's
    modulus of object.toml's material law."""
    if analysis not in ("linear", "nonlinear"):
        raise ProblemError(f"analysis must be 'linear' or 'nonlinear', got {analysis!r}")
    xml = scene_xml(scene)
    spec = load_object(xml)
    if control_faces:
        if spec.control_mesh is not None:
            raise ProblemError(f"{spec.file}: the object gives its own control mesh ({spec.control_mesh.name}); "
                               "a different size is made with graspdef object add --faces")
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
    if analysis == "linear" and p0 > 0:
        raise ProblemError("an enclosed gas needs the nonlinear analysis (p V = const is nonlinear)")
    shell, shell_info = build_shell(spec, analysis)
    check_thin_shell(spec.thickness, shell.rest_positions[: shell.mesh.n_real], spec.file)
    return GraspObject(xml, spec, shell, shell_info, p0)


def check_force(scene, force: float, fingertips=None) -> None:
    """Refuse, before any heavy work, a per-finger force outside the scene's gripper range."""
    from ..sim.grasp import check_targets
    from ..sim.scene import load_scene

    xml = scene_xml(scene)
    spec = load_object(xml)
    check_targets(load_scene(xml, spec.body, fingertips), {s: (force if s in spec.fingers else 0.0) for s in ("left", "right")})


#: net force of the mapped loads on a free object, relative to the finger force, above which the run
#: carries a warning (MuJoCo settles the tennis ball to ~1e-5 N)
EQUILIBRIUM_RTOL = 0.01


def settle(obj: GraspObject, force: float, settings: GraspSettings = GraspSettings(), fingertips=None,
           friction: float | None = None) -> Settled:
    """Stage 2: close the gripper to ``force`` [N] per finger in MuJoCo and settle (``fingertips``:
    a per-run graspdef.sim.gripper.FingertipChange: pad size, material; ``friction``: the sliding
    friction coefficient of fingertips and object, None: the scene's)."""
    if not np.isfinite(force) or force <= 0:
        raise ProblemError(f"force must be a positive number of newtons, got {force!r}")
    targets = {s: (force if s in obj.spec.fingers else 0.0) for s in ("left", "right")}
    return Settled(grasp(obj.xml, targets, obj.spec.body, settings, fingertips, friction), targets)


def shell_problem(obj: GraspObject, st: Settled, contact: str = "point", friction: float | None = None) -> ShellSetup:
    """Stage 3: the contacts as loads on the shell (point loads, or rigid fingertips), the weight,
    the enclosed air, the supports and the probes.

    Geometric contact with a friction coefficient mu > 0 adds each fingertip's Coulomb friction
    on the shell (graspdef.contact.friction.FingerFriction); mu is ``friction`` (the run's, also
    given to MuJoCo) or, None, each finger's MuJoCo contacts' (the scene's geom friction, mixed
    as MuJoCo does: the larger of the fingertip's and the object's)."""
    if contact not in ("point", "geometric"):
        raise ProblemError(f"contact must be 'point' (the paper's point loads) or 'geometric' (rigid fingertips), "
                           f"got {contact!r}")
    shell, spec, g = obj.shell, obj.spec, st.g
    cs = g.contacts.transformed(g.pose)
    mapping = map_contacts(shell, cs)
    loads = list(mapping.loads)
    fingertips = []
    mus = {}
    if contact == "geometric":      # fingertips as rigid obstacles; MuJoCo's other force parts stay dead loads
        from ..contact.friction import FingerFriction, check_mu
        from .geometric import finger_contacts

        loads, fingertips = finger_contacts(mapping, g, st.targets, spec.thickness)
        pf = g.per_finger()
        for fc in fingertips:
            mu = friction if friction is not None else pf.get(fc.name, {}).get("friction_coefficient")
            source = "--friction" if friction is not None else "scene (MuJoCo's contacts of this finger)"
            if mu is None:
                raise ProblemError(f"geometric contact: no friction coefficient for the {fc.name} finger's contacts")
            mus[fc.name] = (check_mu(mu, f"{fc.name} finger: friction coefficient"), source)
        loads = loads + fingertips + [FingerFriction(fc, mus[fc.name][0]) for fc in fingertips if mus[fc.name][0] > 0]
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
    if obj.p0 > 0:
        loads.append(EnclosedGas(obj.p0) if spec.gas.p_atm is None else EnclosedGas(obj.p0, spec.gas.p_atm))
    probes = {}
    for s in sorted(set(mapping.finger)):
        idx = [i for i, f in enumerate(mapping.finger) if f == s]
        k = idx[int(np.argmax([np.linalg.norm(mapping.forces[i]) for i in idx]))]
        probes[s] = mapping.surface_points[k]
    problem = Problem(shell, loads, supports, probes)
    # net force and moment of the assembled dead loads (contacts + weight): what the rigid-mode
    # support has to carry; zero up to MuJoCo's settling and the mass discretisation
    fvec = problem.dead_load_vector().reshape(-1, 3)
    return ShellSetup(problem, mapping, fingertips, free, probes, fvec.sum(axis=0),
                      np.cross(shell.rest_positions, fvec).sum(axis=0), mus)


def solve_shell(setup: ShellSetup, analysis: str, steps: int, progress=None) -> Solved:
    """Stage 4: linear or nonlinear solve; a path that stops is returned as far as it got.
    ``progress``: called with each converged path point's info (load factor, Newton iterations,
    seconds; graspdef.solve.nonlinear)."""
    fingertips = setup.fingertips
    opt = PathOptions(steps=steps, max_steps=40 * steps, min_step=1e-3, **(CONTACT_PATH if fingertips else {}))
    if analysis == "linear" and not fingertips:
        return Solved(solve_linear(setup.problem), True, None)
    from .geometric import solve_contact

    try:
        sol = solve_contact(setup.problem, opt, linear=analysis == "linear", progress=progress) if fingertips \
            else solve_nonlinear(setup.problem, opt, progress=progress)
    except PathStopped as exc:
        if not exc.solution.path:       # not even the unloaded state: nothing to record
            raise SolverError(f"the shell solve found no equilibrium to record: {exc}") from None
        return Solved(exc.solution, False, str(exc))
    return Solved(sol, True, None)


def grasp_record(obj: GraspObject, st: Settled, setup: ShellSetup, solved: Solved, force: float, contact: str,
                 analysis: str, timings: dict) -> GraspOutcome:
    """Stage 5: displacements (from the unloaded equilibrium, rigid motion removed for a free
    body), indentation, contact reports, the derived quantities and the run record."""
    shell, spec, g, sol = obj.shell, obj.spec, st.g, solved.sol
    mapping, probes, free, fingertips = setup.mapping, setup.probes, setup.free, setup.fingertips
    Lm = sol.limit_map()
    x_lim = Lm @ shell.mesh.vertices
    # displacements from the unloaded equilibrium (load factor 0: the shell inflated by its air,
    # which is the state the scan and MuJoCo's rigid proxy show), not from the stress-free shape
    ref = sol.path[0] if hasattr(sol, "path") else None
    u_lim = sol.vertex_displacements() - (Lm @ ref.u if ref is not None else 0.0)
    u_def = D.rigid_fit_residual(x_lim, u_lim) if free else u_lim
    fingers = {}
    pf = g.per_finger()

    def probe(s):
        return sol.probe(s) - (np.asarray(ref.probes[s]) if ref is not None else 0.0)

    for s, sp in probes.items():
        u = probe(s)
        n = pf[s]["normal"]
        fingers[s] = {"target_N": st.targets[s], "normal_force_N": pf[s]["normal_force"],
                      "axial_force_N": g.info["axial_force_N"][s],
                      "friction_force_N": pf[s]["friction_force"], "n_contacts": pf[s]["n_contacts"],
                      "load_point_m": mapping.points[[i for i, f in enumerate(mapping.finger) if f == s][0]].tolist(),
                      "displacement_m": u.tolist(), "displacement_along_normal_m": float(u @ g.pose.vector_to_object(n))}
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
    residual_F = setup.residual_F
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
        # rigid-mode rows carry
        residual_F = residual_F + sum(np.asarray(r.get("contact_force_N", np.zeros(3))) for r in geo.values())
        last = sol.path[-1].extra if hasattr(sol, "path") else {}
        for s, (mu, source) in setup.friction.items():
            pre = f"friction_{s}_0_"
            fr = {k[len(pre):]: v for k, v in last.items() if k.startswith(pre)}
            fingers[s]["friction"] = {"mu": mu, "mu_source": source, **fr}
            if fr:
                f_vec = np.array([fr["friction_force_x_N"], fr["friction_force_y_N"], fr["friction_force_z_N"]])
                residual_F = residual_F + f_vec
    reference = "unloaded equilibrium (load factor 0; with air: the inflated shell)" if ref is not None \
        else "rest shape"
    derived = {"max_displacement": D.max_displacement(x_lim, u_def, "m", rigid_motion_removed=free,
                                                      reference=reference)}
    if "indentation_per_finger_m" in feedback:
        derived["indentation_per_finger"] = D.entry(
            feedback["indentation_per_finger_m"], "m", "indentation per finger",
            "half the approach of the two fingers' load points along the grasp axis" if not geo else
            "mean travel of the force-controlled fingertips from first touch")
    else:
        derived["indentation"] = D.entry(feedback["indentation_m"], "m", "indentation",
                                         "displacement of the load point along the finger's push")
    if geo:
        derived["contact_area"] = D.entry(float(sum(r["contact_area_m2"] for r in geo.values())), "m2",
                                          "contact area", "sampled surface area with gap < dhat (pressure > 0), "
                                                          "all fingers")
    if any("tangential_force_N" in f.get("friction", {}) for f in fingers.values()):
        derived["friction_force"] = D.entry(
            {s: f["friction"]["tangential_force_N"] for s, f in fingers.items() if "tangential_force_N" in f.get("friction", {})},
            "N", "friction force per finger",
            "shell-side Coulomb friction (geometric contact): |sum of the friction forces of the finger's samples on the "
            "shell| normal to its closing axis, at the last load step")
    derived["finger_force"] = D.entry({s: f["normal_force_N"] for s, f in fingers.items()}, "N",
                                      "normal force per finger", "MuJoCo's settled normal contact force of each finger")
    derived["net_force_residual"] = D.entry(np.linalg.norm(residual_F), "N", "net force residual",
                                            "|sum of all forces on the shell|: what the rigid-mode support carries")
    x_final = shell.rest_positions + sol.u
    if analysis == "linear":           # the linear shell's energy (1/2) u.K0 u, also on a contact path
        strain = sol.strain_energy if not fingertips else RestQuadratic(shell).evaluate(x_final, 0.0, 0).value
        density = None
    else:
        energy = ShellEnergy(shell)
        strain, density = energy.energy(x_final), energy.vertex_energy_density(x_final)
    derived["strain_energy"] = D.entry(float(strain), "J", "strain energy",
                                       "elastic energy of the shell at the final state, from its stress-free shape")
    conv = {"completed": solved.completed, "stop_reason": solved.stop_reason}
    if hasattr(sol, "path"):
        conv.update(sol.convergence())
    else:
        conv.update({"relative_residual": sol.kkt.residual})
    if analysis == "linear" and fingertips:
        conv["note"] = "linear shell (rest stiffness K0) with contact: a load path of the nonlinear solver"
    data = {
        "scene": str(obj.xml), "object": spec.body, "force_N": force, "contact": contact, "model": "full",
        "material": {"model": spec.material.model(analysis), "E_Pa": spec.material.E, "nu": spec.material.nu,
                     "thickness_m": spec.thickness},
        "thickness_m": spec.thickness, "gas_p0_Pa": obj.p0, "shell": obj.shell_info,
        "fingers": fingers, "feedback": feedback, "displacement_reference": reference,
        "load_mapping": mapping.record(),
        "residual": {"net_force_N": np.asarray(residual_F).tolist(),
                     "net_moment_Nm": None if geo else np.asarray(setup.residual_M).tolist()},
        "mujoco": g.record(), "convergence": conv, "timings_s": timings,
    }
    if geo:
        data["geometric_contact"] = {
            "model": "rigid force-controlled fingertips, IPC log barrier on mid-surface samples against the "
                     "fingertip inflated by t/2", "fingers": geo,
            "contact_area_definition": "sampled surface area with gap < dhat (contact pressure > 0)",
            "friction": "MuJoCo's contact forces less their finger-axis parts, as dead loads at the contacts"
                        + ("; plus the fingertips' Coulomb friction on the shell (graspdef.contact.friction: IPC's "
                           "lagged smoothed friction, one lagging pass per load step)" if setup.friction else "")}
    pf_mu = {s: v.get("friction_coefficient") for s, v in g.per_finger().items()}
    data["friction"] = {
        "mu": {s: m for s, (m, _) in setup.friction.items()} if geo else pf_mu, "mujoco_mu": pf_mu,
        "shell_side": any(m > 0 for m, _ in setup.friction.values()),
        "definitions": {
            "mu": "Coulomb sliding friction coefficient of finger and object, one value for both sides (MuJoCo's "
                  "contacts and, with geometric contact, the shell-side friction term); point loads carry MuJoCo's "
                  "friction forces and have no shell-side friction",
            "mujoco_mu": "the sliding friction coefficient of each finger's MuJoCo contacts (MuJoCo mixes a geom "
                         "pair's values by taking the larger; the largest over the finger's contacts)",
            "fingers.*.friction": "geometric contact, per finger at the last load step: n_stick / n_slip = samples "
                                  "with a lagged normal force whose slip since the previous converged step is below / "
                                  "at least eps_v_m; tangential_force_N = |friction force on the shell| normal to the "
                                  "closing axis; friction_force_[xyz]_N its components (object frame); "
                                  "lagged_normal_force_N = the normal force the friction is lagged from; max_slip_m = "
                                  "the largest slip of the step"}}
    data["warnings"] = D.plausibility_warnings(analysis, derived["max_displacement"]["value"], spec.thickness,
                                               float(np.ptp(x_lim, axis=0).max()))
    if free and not fingertips and np.linalg.norm(setup.residual_F) > EQUILIBRIUM_RTOL * force:
        data["warnings"].append(
            f"the loads on the free object are not in equilibrium: net force {np.linalg.norm(setup.residual_F):.3g} N "
            f"(> {EQUILIBRIUM_RTOL:.0%} of the finger force), net moment {np.linalg.norm(setup.residual_M):.3g} N m; "
            "the rigid-mode support carries it (MuJoCo did not settle: the object slips or rolls)")
    rec = RunRecord("grasp", spec.body, analysis, dict(SI_UNITS), derived, {}, data)
    verts, faces = sol.deformed_surface()
    contacts = {"frame": "world", "units": {"length": "m", "force": "N"}, "object_pose": g.pose.record(),
                "contacts": g.contacts.records(), "per_finger": data["mujoco"]["per_finger"]}
    path = path_rows(sol) if hasattr(sol, "path") else None
    fields = {} if density is None else {"strain_energy_density": density}
    return GraspOutcome(rec, x_lim, verts, faces, u_def, contacts, path, fields)


def write_grasp_run(out, outcome: GraspOutcome, config: dict) -> Path:
    """Stage 6: the run folder (graspdef.runs.write_run)."""
    return write_run(out, outcome.record, rest=outcome.rest, deformed=outcome.deformed, faces=outcome.faces,
                     displacement=outcome.displacement, path=outcome.path, vertex_fields=outcome.fields,
                     json_files={"contacts.json": outcome.contacts}, provenance=config)


def run_grasp(scene, force: float, contact: str = "point", analysis: str = "nonlinear", out=None,
              gas: bool | None = None, settings: GraspSettings = GraspSettings(), control_faces: int | None = None,
              steps: int | None = None, E: float | None = None, progress=None, fingertips=None,
              friction: float | None = None, model: str = "full", patch_size: float = 0.045) -> GraspRun:
    """Run the whole chain for ``scene`` at ``force`` [N] per finger; write the run folder ``out``
    (when given) and return its record (see the stages above for the arguments; ``progress``:
    called with a stage name and, during the path, each converged point's info; ``fingertips``: a
    graspdef.sim.gripper.FingertipChange for this run; ``friction``: the sliding friction coefficient mu of
    fingertips and object, MuJoCo's and the shell-side term's, None: the scene's; ``model``: "full" (the whole
    object's shell) or "patch" (the paper's model, graspdef.pipeline.patch: a clamped square patch of side
    ``patch_size`` [m] per finger contact, nu = 0.5, point load, no air))."""
    say = progress or (lambda stage, info=None: None)
    t0 = time.perf_counter()
    if contact not in ("point", "geometric"):
        raise ProblemError(f"contact must be 'point' (the paper's point loads) or 'geometric' (rigid fingertips), "
                           f"got {contact!r}")
    if not np.isfinite(force) or force <= 0:
        raise ProblemError(f"force must be a positive number of newtons, got {force!r}")
    if model not in ("full", "patch"):
        raise ProblemError(f"model must be 'full' (the whole object) or 'patch' (the paper's clamped patch per "
                           f"contact), got {model!r}")
    if model == "patch":
        from .patch import check_size

        patch_size = check_size(patch_size)
        if contact != "point":
            raise ProblemError("the patch model loads each patch by a point load: --contact point only")
        if gas:
            raise ProblemError("the patch model has no air inside (the paper modelled none): --gas on is refused")
        gas = False
    if friction is not None:
        from ..contact.friction import check_mu

        friction = check_mu(friction, "friction coefficient (--friction)")
    check_force(scene, force, fingertips)     # the gripper's range, before the shell is built
    say("shell")
    obj = prepare_object(scene, analysis, gas, control_faces, E)
    if model == "patch":
        from .patch import check_object_size

        check_object_size(obj.shell, patch_size)      # before MuJoCo
    t_shell = time.perf_counter()
    say("mujoco")
    st = settle(obj, force, settings, fingertips, friction)
    t_sim = time.perf_counter()
    if model == "patch":
        from .patch import patch_record, patch_setups, solve_patch

        pps = patch_setups(obj, st, patch_size, analysis)
        say("solve")
        solved = [solve_patch(pp, analysis, steps or obj.spec.steps, progress=lambda info: say("point", info))
                  for pp in pps]
        solved = [(us[pp.force], sol) for pp, (us, sol) in zip(pps, solved)]
        t_solve = time.perf_counter()
        timings = {"shell_setup": t_shell - t0, "mujoco": t_sim - t_shell, "solve": t_solve - t_sim}
        outcome = patch_record(obj, st, pps, solved, force, analysis, timings)
    else:
        setup = shell_problem(obj, st, contact, friction)
        say("solve")
        solved = solve_shell(setup, analysis, steps or obj.spec.steps, progress=lambda info: say("point", info))
        t_solve = time.perf_counter()
        timings = {"shell_setup": t_shell - t0, "mujoco": t_sim - t_shell, "solve": t_solve - t_sim}
        outcome = grasp_record(obj, st, setup, solved, force, contact, analysis, timings)
    timings["total"] = time.perf_counter() - t0
    if out is not None:
        config = {"scene": str(scene), "force_N": force, "contact": contact, "analysis": analysis, "gas": gas,
                  "control_faces": control_faces, "steps": steps, "E_Pa": E, "friction": friction,
                  "model": model, "patch_size_m": patch_size if model == "patch" else None, "settings": dict(settings.__dict__),
                  "fingertips": None if fingertips is None else dict(fingertips.__dict__),
                  "object_toml": obj.spec.file.read_text()}
        out = write_grasp_run(out, outcome, config)
    return GraspRun(Path(out) if out is not None else None, outcome.record.to_json())
