"""The paper's own model (Tian & Jia 2010, Sec. IX-A; ``graspdef grasp --model patch``).

Each finger contact gets its own subdivision displacement field over a square patch of the surface
around the contact (45 mm x 45 mm in the paper), the rest of the object fixed: the patch's whole
border is clamped (displacement and rotation about the border), the finger's normal force is a
point load at the contact, Poisson's ratio 0.5, no air inside.

Per finger (:func:`build_patch`):

1. the object's control mesh (the control points whose limit surface is the object's mid-surface)
   is Loop-refined ``levels`` times -- a closed mesh's refinement has the same limit surface, so
   the patch is cut from the same surface, only with more control points (default: the fewest
   levels that make the mean edge at most ``size / PATCH_CELLS``);
2. the patch is cut there (graspdef.geometry.cut: the faces inside a square of side ``size`` in
   the tangent plane at the contact, the piece holding the contact; a disc, else one line);
3. a Shell on it (not interpolated: its control points are the refined object's), with the
   object's thickness and the material at nu = 0.5 (linear: LinearElastic(E, 0.5); nonlinear: the
   object's law at nu = 0.5, i.e. incompressible neo-Hookean or Mooney-Rivlin);
4. supports: EdgeSupport "clamped" on every boundary edge (graspdef.problem.supports: the
   displacement at two Gauss points per edge by Lagrange multipliers, the rotation about the edge by
   Nitsche's method); load: the finger's normal force [N] at the contact's nearest limit-surface
   point, along the inward normal of the patch's box (-n).

Measured per finger (:func:`patch_measures`): the largest |u| over the patch's limit-surface
vertices (``max_displacement_m``: what Table I's "measured max. displacement" is; the clamped
patch carries no rigid motion), the load point's displacement along the push
(``displacement_along_push_m``), and the border's largest |u| and rotation about the border
(``border``: zero up to the support's discretisation).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import ProblemError, SolverError
from ..geometry.cut import Patch, cut_patch
from ..problem.loads import PointLoad
from ..problem.problem import Problem, locate
from ..problem.supports import EdgeSupport
from ..shell.materials import LinearElastic
from ..shell.model import Shell

#: the paper's patch side [m] (Sec. IX-A: "a 45 mm x 45 mm patch")
PATCH_SIZE = 0.045
#: Poisson's ratio of the paper's model
PATCH_NU = 0.5
#: default refinement: the mean control edge is at most size / PATCH_CELLS
PATCH_CELLS = 32
#: the models of ``graspdef grasp --model``
MODELS = ("full", "patch")
#: the contact point may lie this far [m] from the patch's limit surface (MuJoCo's rigid proxy is
#: the outer surface, the shell its mid-surface t/2 inside; plus the soft contact's penetration)
CONTACT_TOL = 5e-3


def _border(x):
    return np.ones(len(x), bool)


def patch_material(material_spec, analysis: str):
    """The shell material of the patch model: the object's law (graspdef.objects MaterialSpec) at
    nu = 0.5 -- linear: LinearElastic(E, 0.5); nonlinear: the law's incompressible form."""
    if analysis == "linear":
        return LinearElastic(material_spec.E, PATCH_NU)
    return dataclasses.replace(material_spec, nu=PATCH_NU).shell_material("nonlinear")


def refined_control_mesh(shell: Shell, levels: int) -> tuple[np.ndarray, np.ndarray]:
    """The real control points and faces of ``shell`` after ``levels`` Loop refinements (the same
    limit surface for a closed mesh)."""
    from ..subdivision.rules import refine

    x = np.asarray(shell.mesh.vertices[: shell.mesh.n_real], float)
    f = np.asarray(shell.mesh.faces[: shell.mesh.n_real_faces], np.int64)
    for _ in range(int(levels)):
        S, f = refine(f, len(x))
        x = S @ x
    return x, f


def mean_edge(vertices: np.ndarray, faces: np.ndarray) -> float:
    p = np.asarray(vertices)[np.asarray(faces)]
    return float(np.linalg.norm(p[:, [1, 2, 0]] - p, axis=-1).mean())


def default_levels(shell: Shell, size: float, cells: int = PATCH_CELLS) -> int:
    """The fewest Loop refinements after which the mean control edge is at most ``size / cells``."""
    h = mean_edge(shell.mesh.vertices, shell.mesh.faces[: shell.mesh.n_real_faces])
    return max(0, int(np.ceil(np.log2(h * cells / size)))) if h * cells > size else 0


def check_size(size, name: str = "--patch-size") -> float:
    try:
        s = float(size)
    except (TypeError, ValueError):
        raise ProblemError(f"{name}: the patch size must be a positive length, got {size!r}") from None
    if not (np.isfinite(s) and s > 0):
        raise ProblemError(f"{name}: the patch size must be a positive length, got {size!r}")
    return s


def check_object_size(shell: Shell, size) -> float:
    """``size`` [m] as a float; a patch wider than the object (its largest extent along x, y or z)
    is refused: nothing of the object would be left to hold the border."""
    size = check_size(size)
    extent = float(np.ptp(shell.rest_positions[: shell.mesh.n_real], axis=0).max())
    if size > extent:
        raise ProblemError(f"--patch-size {size * 1e3:.3g} mm is larger than the object ({extent * 1e3:.3g} mm "
                           "across)")
    return size


@dataclass
class PatchProblem:
    """One finger's patch: its problem (a point load of ``force`` [N] along ``-normal``), the cut,
    and where the load acts."""

    finger: str
    problem: Problem
    patch: Patch
    levels: int
    size: float
    point: np.ndarray          # the load point on the limit surface [m] (object frame)
    normal: np.ndarray         # outward unit normal of the patch's box
    force: float               # [N]
    contact_distance: float    # contact point -> limit surface [m]


def build_patch(control_vertices: np.ndarray, control_faces: np.ndarray, material, thickness: float, centre,
                force: float, size: float = PATCH_SIZE, finger: str = "finger", levels: int = 0,
                normal=None, axis=None, tol: float = CONTACT_TOL) -> PatchProblem:
    """The patch problem of one contact (module docstring) on a control mesh that is already refined
    (``levels`` is only recorded).  ``centre`` [m]: the contact; ``force`` [N] > 0 along the
    inward normal; ``normal``: the outward normal (default: the mesh's around the centre)."""
    size = check_size(size)
    if not (np.isfinite(force) and force > 0):
        raise ProblemError(f"{finger}: the finger force must be a positive number of newtons, got {force!r}")
    patch = cut_patch(control_vertices, control_faces, centre, size, normal=normal, axis=axis,
                      name=f"{finger} finger's patch")
    shell = Shell(patch.vertices, patch.faces, material, thickness, interpolate=False)
    sp_, dist = locate(shell, None, centre, f"{finger} finger's contact", tol=tol)
    n = patch.axes[2]
    load = PointLoad(sp_.face, sp_.bary, tuple((-force * n).tolist()))
    problem = Problem(shell, [load], [EdgeSupport("clamped", _border, name="patch border")], {finger: sp_})
    st, w = shell.evaluator.values(sp_.face, np.asarray(sp_.bary))
    point = w @ shell.rest_positions[st]
    return PatchProblem(finger, problem, patch, int(levels), size, point, n, float(force), float(dist))


def solve_patch(pp: PatchProblem, analysis: str, steps: int = 4, forces=None, progress=None):
    """Solve one patch: linear (one solve; at ``forces`` [N]: scaled, exact) or nonlinear (a load path
    to the largest of ``forces``, landing on each, default: the patch's force).  Returns
    ``{force: control displacements (n_control, 3) [m]}`` and the solution object of the
    patch's force (or of the path)."""
    from ..solve.linear import solve_linear
    from ..solve.nonlinear import PathOptions, PathStopped, solve_nonlinear

    forces = sorted({float(pp.force)} if forces is None else {float(f) for f in forces})
    if analysis == "linear":
        sol = solve_linear(pp.problem)
        return {f: (f / pp.force) * sol.u for f in forces}, sol
    if analysis != "nonlinear":
        raise ProblemError(f"analysis must be 'linear' or 'nonlinear', got {analysis!r}")
    scale = forces[-1] / pp.force
    opt = PathOptions(max_load=scale, targets=tuple(f / pp.force for f in forces[:-1]), steps=steps,
                      max_steps=40 * steps, min_step=1e-3)
    try:
        sol = solve_nonlinear(pp.problem, opt, progress=progress)
    except PathStopped as exc:
        raise SolverError(f"{pp.finger} finger's patch: the load path stopped: {exc}") from None
    return {f: sol.at(f / pp.force).u for f in forces}, sol


def limit_displacements(pp: PatchProblem, u: np.ndarray) -> np.ndarray:
    """Limit-surface displacements (n_vertices, 3) [m] of the patch's real control vertices."""
    from ..subdivision.rules import limit_matrix

    mesh = pp.problem.shell.mesh
    return limit_matrix(mesh.faces, mesh.n_control, np.arange(mesh.n_real)) @ u


def border_values(pp: PatchProblem, u: np.ndarray, n_points: int = 4) -> dict:
    """On the border's limit curve, at ``n_points`` points per boundary edge: the largest |u| [m]
    and the largest rotation about the border [rad] (the change of the surface normal's component
    along the in-surface direction normal to the edge, linearised: (a3' - a3) . nu)."""
    from ..shell.kinematics import normal as unit_normal

    shell = pp.problem.shell
    ev = shell.evaluator
    mesh = shell.mesh
    ab = mesh.boundary_edges
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    taus = (np.arange(n_points) + 0.5) / n_points
    x0 = shell.rest_positions
    x1 = x0 + u
    umax, rmax = 0.0, 0.0
    for e in range(len(ab)):
        face = int(mesh.boundary_faces[e])
        i = int(np.flatnonzero(mesh.faces[face] == ab[e, 0])[0])
        pts = (1 - taus)[:, None] * corners[i] + taus[:, None] * corners[(i + 1) % 3]
        st, N, dN, ddN = ev.basis(face, pts)
        umax = max(umax, float(np.linalg.norm(N @ u[st], axis=1).max()))
        y0 = np.concatenate([np.einsum("qsk,sd->qkd", dN, x0[st]), np.einsum("qsk,sd->qkd", ddN, x0[st])], axis=1)
        y1 = np.concatenate([np.einsum("qsk,sd->qkd", dN, x1[st]), np.einsum("qsk,sd->qkd", ddN, x1[st])], axis=1)
        n0, _ = unit_normal(y0)
        n1, _ = unit_normal(y1)
        t = x0[ab[e, 1]] - x0[ab[e, 0]]
        conormal = np.cross(n0, t)
        conormal /= np.linalg.norm(conormal, axis=1, keepdims=True)
        rmax = max(rmax, float(np.abs(np.einsum("qd,qd->q", n1 - n0, conormal)).max()))
    return {"max_displacement_m": umax, "max_rotation_rad": rmax, "points_per_edge": n_points}


def patch_measures(pp: PatchProblem, u: np.ndarray, border: bool = True) -> dict:
    """What the run record holds per finger (module docstring), SI."""
    ul = limit_displacements(pp, u)
    mag = np.linalg.norm(ul, axis=1)
    k = int(np.argmax(mag))
    sp_ = pp.problem.probes[pp.finger]
    st, w = pp.problem.evaluator.values(sp_.face, np.asarray(sp_.bary))
    up = w @ u[st]
    mesh = pp.problem.shell.mesh
    out = {"max_displacement_m": float(mag[k]),
           "max_displacement_at_m": (mesh.vertices[:mesh.n_real][k]).tolist(),
           "load_point_displacement_m": up.tolist(),
           "displacement_along_push_m": float(-up @ pp.normal)}
    if border:
        out["border"] = border_values(pp, u)
    return out


def patch_info(pp: PatchProblem) -> dict:
    """The patch's geometry for the record."""
    shell = pp.problem.shell
    return {"size_m": pp.size, "shape": "square in the tangent plane at the contact (geometry.cut)",
            "refine_levels": pp.levels, "control_vertices": int(len(pp.patch.vertices)),
            "control_faces": int(len(pp.patch.faces)), "area_m2": shell.area(),
            "mean_edge_m": mean_edge(pp.patch.vertices, pp.patch.faces), "axes": pp.patch.axes.tolist(),
            "load_point_m": pp.point.tolist(), "outward_normal": pp.normal.tolist(), "force_N": pp.force,
            "contact_to_surface_m": pp.contact_distance}


# ------------------------------------------------------------------------------------------------
# the grasp chain with the patch model (graspdef.pipeline.grasp.run_grasp(model="patch"))

def patch_setups(obj, st, size: float = PATCH_SIZE, analysis: str = "nonlinear", levels: int | None = None,
                 forces: dict | None = None) -> list:
    """One :class:`PatchProblem` per finger of MuJoCo's settled grasp ``st`` (graspdef.pipeline.grasp
    Settled) on ``obj``'s shell (GraspObject): the patch around the finger's force-weighted mean contact
    point (object frame), loaded by its settled normal force (or ``forces[finger]`` [N])."""
    size = check_object_size(obj.shell, size)
    shell, spec, g = obj.shell, obj.spec, st.g
    lv = default_levels(shell, size) if levels is None else int(levels)
    if lv < 0:
        raise ProblemError(f"patch refinement levels must be >= 0, got {levels!r}")
    xc, fc = refined_control_mesh(shell, lv)
    material = patch_material(spec.material, analysis)
    pf = g.contacts.transformed(g.pose).per_finger()
    out = []
    for s in sorted(pf):
        if st.targets.get(s, 0.0) <= 0 or pf[s]["n_contacts"] == 0:
            continue
        F = float(pf[s]["normal_force"] if forces is None else forces[s])
        out.append(build_patch(xc, fc, material, spec.thickness, pf[s]["point"], F, size, s, lv))
    if not out:
        raise ProblemError("patch model: MuJoCo's settled grasp has no finger in contact with the object")
    return out


def patch_record(obj, st, pps: list, solved: list, force: float, analysis: str, timings: dict):
    """The run record and arrays (graspdef.pipeline.grasp.GraspOutcome) of the patch model:
    ``solved`` holds per patch (u at its force, the solution object)."""
    from ..runs import derived as D
    from ..runs.record import SI_UNITS, RunRecord
    from ..shell.energy import ShellEnergy
    from .grasp import GraspOutcome

    spec, g = obj.spec, st.g
    pf = g.per_finger()
    fingers, patches = {}, {}
    rest, deformed, faces, disp = [], [], [], []
    strain, offset = 0.0, 0
    conv = {"completed": True, "stop_reason": None, "patches": {}}
    for pp, (u, sol) in zip(pps, solved):
        s = pp.finger
        m = patch_measures(pp, u)
        patches[s] = {**patch_info(pp), **m}
        fingers[s] = {"target_N": st.targets[s], "normal_force_N": pf[s]["normal_force"],
                      "axial_force_N": g.info["axial_force_N"][s], "friction_force_N": pf[s]["friction_force"],
                      "n_contacts": pf[s]["n_contacts"], "load_point_m": pp.point.tolist(),
                      "displacement_m": m["load_point_displacement_m"],
                      "displacement_along_normal_m": m["displacement_along_push_m"],
                      "max_displacement_m": m["max_displacement_m"]}
        Lm = sol.limit_map()
        x0 = Lm @ pp.problem.shell.rest_positions
        ul = Lm @ u
        rest.append(x0)
        deformed.append(x0 + ul)
        disp.append(ul)
        mesh = pp.problem.shell.mesh
        faces.append(mesh.faces[: mesh.n_real_faces] + offset)
        offset += len(x0)
        if analysis == "linear":
            strain += float(sol.strain_energy)
            conv["patches"][s] = {"relative_residual": sol.kkt.residual}
        else:
            strain += float(ShellEnergy(pp.problem.shell).energy(pp.problem.shell.rest_positions + u))
            conv["patches"][s] = sol.convergence()
    rest, deformed, disp, faces = (np.concatenate(a) for a in (rest, deformed, disp, faces))
    reference = "rest shape (the patch model has no air)"
    derived = {"max_displacement": D.max_displacement(rest, disp, "m", rigid_motion_removed=False, reference=reference)}
    derived["max_displacement"]["definition"] = (
        "largest |u| over the limit-surface vertices of the mid-surface of every finger's patch (patch model: "
        "the rest of the object is fixed, the patch border clamped, so no rigid motion); u from the rest shape")
    derived["max_displacement_per_finger"] = D.entry(
        {s: p["max_displacement_m"] for s, p in patches.items()}, "m", "max. displacement per finger",
        "patch model: largest |u| over the limit-surface vertices of the finger's patch (Table I's measured max. "
        "displacement)")
    push = [f["displacement_along_normal_m"] for f in fingers.values()]
    if len(push) == 2:
        derived["indentation_per_finger"] = D.entry(
            float(np.mean(push)), "m", "indentation per finger",
            "patch model: mean displacement of the fingers' load points along their push (inward normal)")
        feedback = {"approach_m": float(sum(push)), "indentation_per_finger_m": float(np.mean(push)),
                    "mujoco_tip_gap_m": g.tip_gap, "predicted_tip_gap_m": g.tip_gap - float(sum(push)),
                    "mismatch_m": float(sum(push)),
                    "note": "patch model: approach = sum of the load points' displacements along their pushes"}
    else:
        derived["indentation"] = D.entry(float(push[0]), "m", "indentation",
                                         "patch model: displacement of the load point along the finger's push")
        feedback = {"indentation_m": float(push[0]), "mujoco_tip_gap_m": g.tip_gap, "mismatch_m": float(push[0])}
    derived["finger_force"] = D.entry({s: f["normal_force_N"] for s, f in fingers.items()}, "N",
                                      "normal force per finger", "MuJoCo's settled normal contact force of each finger")
    derived["strain_energy"] = D.entry(strain, "J", "strain energy",
                                       "elastic energy of the patches at the final state, from their stress-free shape")
    size = pps[0].size
    data = {
        "scene": str(obj.xml), "object": spec.body, "force_N": force, "contact": "point", "model": "patch",
        "patch_size_m": size,
        "patch_model": {
            "definition": "Tian & Jia 2010, Sec. IX-A: one subdivision displacement field per finger contact over a "
                          "square patch of side patch_size_m in the tangent plane at the contact (no deeper than "
                          "patch_size_m / 2 below it), the rest of the object fixed: the patch border clamped "
                          "(displacement at two Gauss points per edge, rotation about the border by Nitsche's method), "
                          "the finger's settled normal force as a point load along the inward normal, nu = 0.5, no air",
            "patches_definitions": {
                "max_displacement_m": "largest |u| over the patch's limit-surface vertices",
                "displacement_along_push_m": "the load point's displacement along the inward normal",
                "border.max_displacement_m": "largest |u| on the border's limit curve (4 points per edge)",
                "border.max_rotation_rad": "largest rotation about the border on it: (n' - n) . conormal",
                "refine_levels": "Loop refinements of the object's control mesh before the cut (same limit surface)"}},
        "patches": patches,
        "material": {"model": dataclasses.replace(spec.material, nu=PATCH_NU).model(analysis),
                     "E_Pa": spec.material.E, "nu": PATCH_NU, "thickness_m": spec.thickness,
                     "object_nu": spec.material.nu},
        "thickness_m": spec.thickness, "gas_p0_Pa": 0.0, "shell": obj.shell_info,
        "fingers": fingers, "feedback": feedback, "displacement_reference": reference,
        "mujoco": g.record(), "convergence": conv, "timings_s": timings,
    }
    extent = float(np.ptp(obj.shell.rest_positions[: obj.shell.mesh.n_real], axis=0).max())
    data["warnings"] = D.plausibility_warnings(analysis, derived["max_displacement"]["value"], spec.thickness, extent)
    rec = RunRecord("grasp", spec.body, analysis, dict(SI_UNITS), derived, {}, data)
    contacts = {"frame": "world", "units": {"length": "m", "force": "N"}, "object_pose": g.pose.record(),
                "contacts": g.contacts.records(), "per_finger": data["mujoco"]["per_finger"]}
    return GraspOutcome(rec, rest, deformed, faces, disp, contacts, None, {})
