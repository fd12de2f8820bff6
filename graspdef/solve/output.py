"""A solved problem as a run record (:class:`graspdef.runs.RunRecord`, SI) and its run folder.

The record is SI (metres, newtons, joules); a problem in consistent units keeps them and says
so.  The folder is written by the one writer, :func:`graspdef.runs.write_run`.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..problem.config import ProblemSpec
from ..runs import derived as D
from ..runs.record import CONSISTENT_UNITS, SI_UNITS, RunRecord
from ..runs.write import write_run as _write_run
from ..shell.energy import ShellEnergy
from .linear import LinearSolution
from .nonlinear import NonlinearSolution


def _units(spec: ProblemSpec) -> dict:
    return dict(CONSISTENT_UNITS if spec.length_unit == "consistent" else SI_UNITS)


def path_rows(sol: NonlinearSolution, length_unit: str = "m", energy_unit: str = "J") -> tuple[list[str], list[list]]:
    """The load path as a table (header, rows), SI: one row per converged point."""
    names = list(sol.problem.probes)
    extra = sorted({k for p in sol.path for k in p.extra})
    header = ["point", "kind", "load_factor", f"energy[{energy_unit}]", "newton_iterations", "stable",
              "negative_eigenvalues"]
    header += [f"{n}_u{c}[{length_unit}]" for n in names for c in "xyz"]
    header += extra
    rows = []
    for i, p in enumerate(sol.path):
        row = [i, p.kind, p.load_factor, p.energy, p.iterations,
               "" if p.stable is None else int(p.stable), "" if p.instability is None else p.instability]
        row += [float(v) for n in names for v in p.probes[n]]
        row += [p.extra.get(k, "") for k in extra]
        rows.append(row)
    return header, rows


def _probes(sol) -> dict:
    mesh = sol.problem.shell.mesh
    out = {}
    for name, pt in sol.problem.probes.items():
        st, w = sol.problem.evaluator.values(pt.face, np.asarray(pt.bary))
        out[name] = {"position": (w @ mesh.vertices[st]).tolist(), "displacement": (w @ sol.u[st]).tolist(),
                     "face": pt.face, "bary": list(pt.bary)}
    return out


def _mesh_counts(sol) -> dict:
    mesh = sol.problem.shell.mesh
    return {"n_control": int(mesh.n_real), "n_ghost": int(mesh.n_control - mesh.n_real),
            "n_faces": int(mesh.n_real_faces), "n_dofs": int(3 * mesh.n_control)}


def result_record(spec: ProblemSpec, sol: LinearSolution | NonlinearSolution) -> RunRecord:
    """The run record of a solved problem (SI, or the problem's consistent units)."""
    units = _units(spec)
    L, E = units["length"], units["energy"]
    rest = sol.limit_map() @ sol.problem.shell.mesh.vertices
    derived = {"max_displacement": D.max_displacement(rest, sol.vertex_displacements(), L, rigid_motion_removed=False,
                                                      reference="rest shape")}
    t = np.asarray(sol.problem.shell.thickness, dtype=float)
    warnings = D.plausibility_warnings("nonlinear" if isinstance(sol, NonlinearSolution) else "linear",
                                       derived["max_displacement"]["value"], float(t.max()),
                                       float(np.ptp(rest, axis=0).max()), L)
    data: dict = {"problem": spec.name, "thickness_m" if L == "m" else "thickness": float(t.max()),
                  "warnings": warnings,
                  "probes": _probes(sol), **_mesh_counts(sol),
                  "timings_s": {k: float(v) for k, v in sol.timings.items()}}
    if isinstance(sol, NonlinearSolution):
        conv = sol.convergence()
        crit = conv.pop("critical_points")
        derived["total_potential_energy"] = D.entry(sol.path[-1].energy, E, "total potential energy",
                                                    "shell energy minus the work of the loads at the last point")
        data.update({"method": sol.options.method, "stable": sol.path[-1].stable, "critical_points": crit,
                     "convergence": {"completed": sol.completed, "stop_reason": sol.stop_reason, **conv},
                     "options": {k: (list(v) if isinstance(v, tuple) else v) for k, v in sol.options.__dict__.items()}})
        return RunRecord("solve", spec.name, "nonlinear", units, derived, {}, data)
    force, moment = sol.net_load()
    derived["strain_energy"] = D.entry(sol.strain_energy, E, "strain energy", "(1/2) f.u at equilibrium")
    derived["net_load_force"] = D.entry(force, units["force"], "net applied force", "sum of the applied loads")
    data.update({"net_load": {"force": force.tolist(), "moment_about_origin": moment.tolist()},
                 "n_constraints": int(len(sol.kkt.multipliers)),
                 "solver": {"backend": sol.kkt.backend, "precision": sol.kkt.precision,
                            "relative_residual": sol.kkt.residual,
                            "negative_pivots": sol.kkt.n_negative}})
    return RunRecord("solve", spec.name, "linear", units, derived, {}, data)


def write_run(out: str | Path, spec: ProblemSpec, sol: LinearSolution | NonlinearSolution, config_text: str) -> Path:
    """Write the run folder of a solved problem (graspdef.runs.write_run): result.json, the
    surfaces, the problem file, and for a load path path.csv and path_u.npz."""
    rec = result_record(spec, sol)
    L = sol.limit_map()
    verts, faces = sol.deformed_surface()
    path = path_u = None
    fields = {}
    if isinstance(sol, NonlinearSolution):
        path = path_rows(sol, rec.units["length"], rec.units["energy"])
        path_u = (np.stack([p.u for p in sol.path]), sol.load_factors(), L)
        shell = sol.problem.shell
        fields["strain_energy_density"] = ShellEnergy(shell).vertex_energy_density(shell.rest_positions + sol.u)
    return _write_run(out, rec, rest=L @ sol.problem.shell.mesh.vertices, deformed=verts, faces=faces,
                      displacement=sol.vertex_displacements(), path=path, path_u=path_u,
                      text_files={"problem.toml": config_text}, vertex_fields=fields,
                      provenance={"problem_file": "problem.toml", "name": spec.name, "backend": spec.backend,
                                  "text": config_text})
