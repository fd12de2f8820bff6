"""Forward models: parameters theta -> the predicted displacement [m] of every row of a measured
table (graspdef.fit.table.MeasuredTable).  A model is any callable ``model(theta) -> (m,) array``;
it may count its solves in ``n_solves`` and describe itself in ``description`` (fit.json).

* :class:`ObjectModel` -- an object's grasp chain (graspdef.pipeline.grasp): MuJoCo settles the
  grasp once per force of the table (the rigid proxy does not depend on theta: the coupling is
  one-way), then per theta and force the shell is built with theta's E, thickness and air
  pressure, the settled contacts are mapped onto it and it is solved (linear, or a nonlinear load
  path per force); the row's displacement is read from the grasp record, by the same definitions
  as ``graspdef grasp`` (:data:`OBJECT_POINTS`).
* :class:`ShellModel` -- a shell problem of one's own (tests, studies): ``build(theta)`` returns a
  :class:`~graspdef.problem.problem.Problem` whose loads are those of 1 N per finger, so that the
  load factor is the force in newtons; linear: one solve, scaled by each force (exact); nonlinear:
  one load path to the largest force landing exactly on every other force of the table
  (``PathOptions.targets``); displacements from the unloaded equilibrium (load factor 0: with air,
  the inflated shell).  ``measures``: point name -> ``f(problem, u) -> float`` of the control
  displacements ``u`` (:func:`half_approach`, :func:`probe_along`, :func:`max_displacement`).
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from ..errors import ProblemError, SolverError
from .table import MeasuredTable

#: what a row's ``point`` names for an object, and where the grasp record holds it
OBJECT_POINTS = {
    "finger": "derived indentation_per_finger (two fingers: half the approach of their load points along the "
              "grasp axis) or indentation (one finger: its load point's displacement along its push)",
    "max": "derived max_displacement (largest limit-surface displacement, rigid motion removed)",
    "approach": "feedback approach_m (two fingers: approach of their load points along the grasp axis)",
    "left": "fingers.left.displacement_along_normal_m (the left load point along the contact normal)",
    "right": "fingers.right.displacement_along_normal_m (the right load point along the contact normal)",
}


def _check_points(table: MeasuredTable, accepted) -> None:
    for i, p in enumerate(table.point):
        if p not in accepted:
            raise ProblemError(f"{table.file or 'table'}: row {i + 1}: unknown point {p!r}; accepted: "
                               f"{', '.join(accepted)}")


class ObjectModel:
    """The grasp chain of an object (see the module docstring).  ``names``: the parameters theta
    holds (a subset of graspdef.fit.PARAMETERS); the others keep object.toml's values.  ``gas``:
    None = object.toml's air (nonlinear only), False = none, True = required; ``control_faces``:
    a control mesh of that many faces instead of object.toml's (graspdef.pipeline.grasp.prepare_object)."""

    def __init__(self, scene, table: MeasuredTable, names, analysis: str = "nonlinear", contact: str = "point",
                 steps: int | None = None, settings=None, progress: Callable[[str], None] | None = None,
                 model: str = "full", patch_size: float = 0.045, gas: bool | None = None,
                 control_faces: int | None = None):
        from ..objects.build import outer_surface
        from ..pipeline.grasp import check_force, prepare_object, settle
        from ..sim.grasp import GraspSettings

        say = progress or (lambda msg: None)
        if contact != "point":
            raise ProblemError("the fit's forward model uses point loads (--contact point): geometric contact paths "
                               "are not smooth enough in the parameters for finite differences")
        _check_points(table, OBJECT_POINTS)
        if model not in ("full", "patch"):
            raise ProblemError(f"model must be 'full' or 'patch', got {model!r}")
        if model == "patch":
            from ..pipeline.patch import check_size

            patch_size = check_size(patch_size)
            if "pressure" in names:
                raise ProblemError("the patch model has no air (the paper modelled none): pressure cannot be fitted")
        self.model, self.patch_size = model, patch_size
        self.names, self.table, self.analysis, self.contact = list(names), table, analysis, contact
        if "pressure" in self.names and analysis != "nonlinear":
            raise ProblemError("pressure (the enclosed air) needs --analysis nonlinear (p V = const is nonlinear)")
        from ..objects import load_object

        spec = load_object(scene)                     # checked before any heavy work
        if "pressure" in self.names and gas is False:
            raise ProblemError("gas off: the object's air is removed, so its pressure cannot be fitted")
        if "pressure" in self.names and spec.gas is None:
            raise ProblemError(f"{spec.file}: no [gas] table: the object has no enclosed air whose pressure could "
                               "be fitted")
        for f in sorted(set(table.force.tolist())):
            check_force(scene, f)                      # the gripper's range, before the shell is built
        say("building the shell from the object's data")
        self.obj = prepare_object(scene, analysis, gas=False if model == "patch" else gas, control_faces=control_faces)
        if model == "patch":
            from ..pipeline.patch import check_object_size

            check_object_size(self.obj.shell, patch_size)
        spec = self.obj.spec
        self.steps = steps or spec.steps
        self.outer, _ = outer_surface(spec)
        self.settled = {}
        for f in sorted(set(table.force.tolist())):
            say(f"closing the gripper in MuJoCo at {f:g} N")
            self.settled[f] = settle(self.obj, f, settings or GraspSettings())
        self.n_solves = 0
        self.description = {"kind": "object grasp chain (graspdef.pipeline.grasp)", "scene": str(self.obj.xml),
                            "object": spec.body, "analysis": analysis, "contact": contact, "model": model,
                            **({"patch_size_m": patch_size} if model == "patch" else {}),
                            "material_law": spec.material.law, "nu": spec.material.nu,
                            "object_values": self.start(), "points": {p: OBJECT_POINTS[p] for p in sorted(set(table.point))},
                            "coupling": "MuJoCo settles each force once (rigid proxy, independent of the parameters); "
                                        "the shell is rebuilt and solved per parameter set and force"}

    def start(self) -> dict:
        """object.toml's values of the parameters (SI): the default start of a fit."""
        spec = self.obj.spec
        out = {"E": spec.material.E, "thickness": spec.thickness}
        if spec.gas is not None:
            out["pressure"] = spec.gas.p0
        return {k: v for k, v in out.items() if k in self.names}

    def _object(self, theta: dict):
        from ..objects.data import GasSpec
        from ..pipeline.grasp import GraspObject
        from ..scans import mid_surface
        from ..shell.model import Shell

        spec, p0 = self.obj.spec, self.obj.p0
        if "E" in theta:
            spec = spec.replace(E=theta["E"])
        if "thickness" in theta:
            spec = spec.replace(thickness=float(theta["thickness"]))
        if "pressure" in theta:
            p0 = float(theta["pressure"])
            spec = spec.replace(gas=GasSpec(p0, "graspdef fit", spec.gas.p_atm))
        mid = mid_surface(self.outer, spec.thickness)
        shell = Shell(mid.vertices, mid.faces, spec.shell_material(self.analysis), spec.thickness)
        return GraspObject(self.obj.xml, spec, shell, self.obj.shell_info, p0)

    def record(self, theta: dict, force: float) -> dict:
        """The grasp record (result.json's document) at ``theta`` and ``force`` [N]; a load path
        that stops raises SolverError."""
        return self.outcome(theta, force).record.to_json()

    def surface(self, theta: dict, force: float, side: str = "mid", outcome=None):
        """The deformed limit surface at ``theta`` and ``force`` [N] (the object's frame, rigid motion
        of a free body removed; a TriMesh [m]): ``side`` "mid" (deformed.ply of the run) or "outer"
        (moved by half of theta's thickness along its outward normals: what a scanner sees).
        ``outcome``: that solve's GraspOutcome when the caller has it (no second solve)."""
        from ..geometry import TriMesh

        if side not in ("mid", "outer"):
            raise ProblemError(f"side must be 'mid' or 'outer', got {side!r}")
        o = outcome if outcome is not None else self.outcome(theta, force)
        mesh = TriMesh(o.deformed, o.faces)
        if side == "outer":
            from .scan import outer

            mesh = outer(mesh, 0.5 * float(theta.get("thickness", self.obj.spec.thickness)))
        return mesh

    def outcome(self, theta: dict, force: float):
        """graspdef.pipeline.grasp.GraspOutcome (record and surfaces) at ``theta`` and ``force``."""
        from ..pipeline.grasp import grasp_record, shell_problem, solve_shell

        obj = self._object(theta)
        st = self.settled[force]
        if self.model == "patch":
            from ..pipeline.patch import patch_record, patch_setups, solve_patch

            pps = patch_setups(obj, st, self.patch_size, self.analysis)
            solved = []
            for pp in pps:
                us, sol = solve_patch(pp, self.analysis, self.steps)
                solved.append((us[pp.force], sol))
            self.n_solves += 1
            return patch_record(obj, st, pps, solved, force, self.analysis, {})
        setup = shell_problem(obj, st, self.contact)
        solved = solve_shell(setup, self.analysis, self.steps)
        self.n_solves += 1
        if not solved.completed:
            raise SolverError(f"at {force:g} N the load path stopped: {solved.stop_reason}")
        return grasp_record(obj, st, setup, solved, force, self.contact, self.analysis, {})

    def __call__(self, theta: dict) -> np.ndarray:
        out = np.empty(len(self.table))
        for f in sorted(set(self.table.force.tolist())):
            r = self.record(theta, f)
            for i in np.flatnonzero(self.table.force == f):
                out[i] = object_point(r, self.table.point[i])
        return out


def object_point(record: dict, point: str) -> float:
    """The displacement [m] a table row's ``point`` names, read from a grasp record."""
    d = record["derived"]
    if point == "finger":
        return float(d.get("indentation_per_finger", d.get("indentation"))["value"])
    if point == "max":
        return float(d["max_displacement"]["value"])
    if point == "approach":
        if "approach_m" not in record["feedback"]:
            raise ProblemError("point 'approach' needs two fingers (this grasp has one)")
        return float(record["feedback"]["approach_m"])
    if point not in record["fingers"]:
        raise ProblemError(f"point {point!r}: this grasp has no such finger (fingers: {', '.join(record['fingers'])})")
    return float(record["fingers"][point]["displacement_along_normal_m"])


# ------------------------------------------------------------------------------------------------
def _probe(problem, name: str, u: np.ndarray) -> np.ndarray:
    sp_ = problem.probes[name]
    st, w = problem.evaluator.values(sp_.face, np.asarray(sp_.bary))
    return w @ u[st]


def _probe_rest(problem, name: str) -> np.ndarray:
    return _probe(problem, name, problem.shell.rest_positions)


def half_approach(a: str, b: str) -> Callable:
    """Measure: half the approach of probes ``a`` and ``b`` along the line between them at rest
    (the indentation per finger of a pinch)."""
    def measure(problem, u):
        e = _probe_rest(problem, b) - _probe_rest(problem, a)
        e /= np.linalg.norm(e)
        return 0.5 * float((_probe(problem, a, u) - _probe(problem, b, u)) @ e)
    return measure


def probe_along(name: str, direction) -> Callable:
    """Measure: the displacement of probe ``name`` along ``direction``."""
    n = np.asarray(direction, float) / np.linalg.norm(direction)
    return lambda problem, u: float(_probe(problem, name, u) @ n)


def max_displacement(problem, u) -> float:
    """Measure: the largest limit-surface displacement of the real control vertices."""
    from ..subdivision.rules import limit_matrix

    mesh = problem.shell.mesh
    L = limit_matrix(mesh.faces, mesh.n_control, np.arange(mesh.n_real))
    return float(np.linalg.norm(L @ u, axis=1).max())


class ShellModel:
    """A shell problem's forward model (see the module docstring)."""

    def __init__(self, build: Callable[[dict], object], table: MeasuredTable, measures: dict,
                 analysis: str = "linear", steps: int = 4, tol: float = 1e-10):
        if analysis not in ("linear", "nonlinear"):
            raise ProblemError(f"analysis must be 'linear' or 'nonlinear', got {analysis!r}")
        _check_points(table, measures)
        self.build, self.table, self.measures, self.analysis = build, table, dict(measures), analysis
        self.steps, self.tol = steps, tol
        self.n_solves = 0
        self.description = {"kind": "shell problem", "analysis": analysis, "points": sorted(self.measures)}

    def displacements(self, theta: dict) -> dict:
        """force [N] -> control displacements (n_control, 3) [m] from the unloaded equilibrium,
        for every force of the table; and the problem."""
        problem = self.build(theta)
        forces = sorted(set(self.table.force.tolist()))
        self.n_solves += 1
        if self.analysis == "linear":
            from ..solve.linear import solve_linear

            u1 = solve_linear(problem).u
            return problem, {f: f * u1 for f in forces}
        from ..solve.nonlinear import PathOptions, solve_nonlinear

        opt = PathOptions(max_load=forces[-1], targets=tuple(forces[:-1]), steps=self.steps, tol=self.tol)
        sol = solve_nonlinear(problem, opt)          # PathStopped (a SolverError) if it stops
        u0 = sol.path[0].u
        return problem, {f: sol.at(f).u - u0 for f in forces}

    def __call__(self, theta: dict) -> np.ndarray:
        problem, us = self.displacements(theta)
        return np.array([self.measures[p](problem, us[f]) for f, p in zip(self.table.force.tolist(), self.table.point)])
