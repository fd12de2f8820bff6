"""Writing a solved problem to a run folder: ``result.json`` and the deformed limit surface.

Files are first written to a temporary folder next to the target and moved into place only when
everything succeeded, so an error leaves no partial output.
"""
from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path

import numpy as np

from ..geometry.io import save_ply
from ..problem.config import ProblemSpec
from .linear import LinearSolution


def result_record(spec: ProblemSpec, sol: LinearSolution) -> dict:
    """The result as a JSON-ready dict, lengths in the problem file's unit."""
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
        "units": {"length": spec.length_unit, "force": spec.force_unit,
                  "energy": "consistent" if spec.length_unit == "consistent" else f"{spec.force_unit}*{spec.length_unit}"},
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


def write_run(out: str | Path, spec: ProblemSpec, sol: LinearSolution, config_text: str) -> Path:
    """Write result.json, deformed.ply and the problem file into ``out`` atomically."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    try:
        rec = result_record(spec, sol)
        (tmp / "result.json").write_text(json.dumps(rec, indent=2) + "\n")
        verts, faces = sol.deformed_surface()
        disp = np.linalg.norm(sol.vertex_displacements(), axis=1)
        save_ply(tmp / "deformed.ply", verts, faces, units=spec.length_unit,
                 vertex_scalars={"displacement": disp / spec.length_scale})
        (tmp / "problem.toml").write_text(config_text)
        if out.exists():
            shutil.rmtree(out)
        tmp.rename(out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return out
