"""Writing a solved problem to a run folder: ``result.json`` and the deformed limit surface.

Files are first written to a temporary folder next to the target and moved into place only when
everything succeeded, so an error leaves no partial output.
"""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from ..geometry.io import atomic_folder, save_ply
from ..geometry.provenance import write_provenance
from ..problem.config import ProblemSpec
from .linear import LinearSolution
from .nonlinear import NonlinearSolution
from .pathfile import write_solution_path


def _energy_unit(spec: ProblemSpec) -> str:
    return "consistent" if spec.length_unit == "consistent" else f"{spec.force_unit}*{spec.length_unit}"


def path_rows(spec: ProblemSpec, sol: NonlinearSolution) -> tuple[list[str], list[list]]:
    """The load path as a table: header and rows, lengths and energies in the file's units."""
    ls, fs = spec.length_scale, spec.force_scale
    names = list(sol.problem.probes)
    extra = sorted({k for p in sol.path for k in p.extra})
    header = ["point", "kind", "load_factor", f"energy[{_energy_unit(spec)}]", "newton_iterations", "stable",
              "negative_eigenvalues"]
    header += [f"{n}_u{c}[{spec.length_unit}]" for n in names for c in "xyz"]
    header += extra
    rows = []
    for i, p in enumerate(sol.path):
        row = [i, p.kind, p.load_factor, p.energy / (fs * ls), p.iterations,
               "" if p.stable is None else int(p.stable), "" if p.instability is None else p.instability]
        row += [float(v) / ls for n in names for v in p.probes[n]]
        row += [p.extra.get(k, "") for k in extra]
        rows.append(row)
    return header, rows


def nonlinear_record(spec: ProblemSpec, sol: NonlinearSolution) -> dict:
    """Summary of a nonlinear path as a JSON-ready dict (the path itself goes to path.csv)."""
    ls = spec.length_scale
    mesh = sol.problem.shell.mesh
    probes = {}
    for name, pt in sol.problem.probes.items():
        st, w = sol.problem.evaluator.values(pt.face, np.asarray(pt.bary))
        probes[name] = {"position": (w @ mesh.vertices[st] / ls).tolist(),
                        "displacement": (w @ sol.u[st] / ls).tolist(), "face": pt.face, "bary": list(pt.bary)}
    crit = []
    for cp in sol.critical_points:
        c = dict(cp)
        c["probes"] = {k: (np.asarray(v) / ls).tolist() for k, v in cp["probes"].items()}
        crit.append(c)
    return {
        "name": spec.name,
        "units": {"length": spec.length_unit, "force": spec.force_unit, "energy": _energy_unit(spec)},
        "analysis": "nonlinear",
        "method": sol.options.method,
        "completed": sol.completed,
        "stop_reason": sol.stop_reason,
        "load_factor": sol.load_factor,
        "probes": probes,
        "max_displacement": sol.max_displacement() / ls,
        "energy": sol.path[-1].energy / (spec.force_scale * ls),
        "stable": sol.path[-1].stable,
        "critical_points": crit,
        "n_points": len(sol.path),
        "newton_iterations": sol.iterations(),
        "n_factorisations": sol.n_factorisations,
        "n_control": int(mesh.n_real),
        "n_ghost": int(mesh.n_control - mesh.n_real),
        "n_faces": int(mesh.n_real_faces),
        "n_dofs": int(3 * mesh.n_control),
        "options": {k: (list(v) if isinstance(v, tuple) else v) for k, v in sol.options.__dict__.items()},
        "timings": {k: float(v) for k, v in sol.timings.items()},
        "files": {"path": "path.csv", "deformed": "deformed.ply"},
    }


def result_record(spec: ProblemSpec, sol: LinearSolution | NonlinearSolution) -> dict:
    """The result as a JSON-ready dict, lengths in the problem file's unit."""
    if isinstance(sol, NonlinearSolution):
        return nonlinear_record(spec, sol)
    ls, fs = spec.length_scale, spec.force_scale
    mesh = sol.problem.shell.mesh
    probes = {}
    for name, pt in sol.problem.probes.items():
        st, w = sol.problem.evaluator.values(pt.face, np.asarray(pt.bary))
        probes[name] = {
            "position": (w @ mesh.vertices[st] / ls).tolist(),
            "displacement": (w @ sol.u[st] / ls).tolist(),
            "face": pt.face, "bary": list(pt.bary),
        }
    force, moment = sol.net_load()
    return {
        "name": spec.name,
        "units": {"length": spec.length_unit, "force": spec.force_unit, "energy": _energy_unit(spec)},
        "analysis": "linear",
        "probes": probes,
        "max_displacement": sol.max_displacement() / ls,
        "strain_energy": sol.strain_energy / (fs * ls),
        "net_load": {"force": (force / fs).tolist(), "moment": (moment / (fs * ls)).tolist()},
        "n_control": int(mesh.n_real),
        "n_ghost": int(mesh.n_control - mesh.n_real),
        "n_faces": int(mesh.n_real_faces),
        "n_dofs": int(3 * mesh.n_control),
        "n_constraints": int(len(sol.kkt.multipliers)),
        "solver": {"backend": sol.kkt.backend, "relative_residual": sol.kkt.residual,
                   "negative_pivots": sol.kkt.n_negative},
        "timings": {k: float(v) for k, v in sol.timings.items()},
    }


def write_run(out: str | Path, spec: ProblemSpec, sol: LinearSolution | NonlinearSolution, config_text: str) -> Path:
    """Write result.json, deformed.ply, undeformed.ply (the limit surface at rest: the baseline
    of scan scores), the problem file (and, for a nonlinear path, path.csv and path_u.npz -- the
    control-point displacements of every point, for the viewer) into ``out`` atomically."""
    with atomic_folder(out) as tmp:
        rec = result_record(spec, sol)
        (tmp / "result.json").write_text(json.dumps(rec, indent=2) + "\n")
        verts, faces = sol.deformed_surface()
        disp = np.linalg.norm(sol.vertex_displacements(), axis=1)
        save_ply(tmp / "deformed.ply", verts, faces, units=spec.length_unit,
                 vertex_scalars={"displacement": disp / spec.length_scale})
        L = sol.limit_map()
        save_ply(tmp / "undeformed.ply", L @ sol.problem.shell.mesh.vertices, faces, units=spec.length_unit)
        (tmp / "problem.toml").write_text(config_text)
        write_provenance(tmp, {"problem_file": "problem.toml", "name": spec.name, "backend": spec.backend,
                               "text": config_text})
        if isinstance(sol, NonlinearSolution):
            header, rows = path_rows(spec, sol)
            with open(tmp / "path.csv", "w", newline="") as fh:
                w = csv.writer(fh)
                w.writerow(header)
                w.writerows(rows)
            write_solution_path(tmp, sol)
    return Path(out)
