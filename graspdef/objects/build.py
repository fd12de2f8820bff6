"""An object's shell: the control mesh of its scan, offset inward by half the thickness, with
the material of its data for the analysis asked for."""
from __future__ import annotations

from ..scans import control_mesh, load_scan, mid_surface
from ..shell.model import Shell
from .data import ObjectSpec


def build_shell(spec: ObjectSpec, analysis: str) -> tuple[Shell, dict]:
    """(Shell, info) of ``spec`` for ``analysis`` ("linear" or "nonlinear"): the control mesh of
    the scan (graspdef.scans.control_mesh, ``spec.control_faces``, ``spec.remesh``,
    ``spec.relax``) offset inward by t/2 (mid_surface), and ``spec.shell_material(analysis)``.
    ``info``: scan id, control mesh size and the remeshing method used."""
    material = spec.shell_material(analysis)
    scan = load_scan(spec.scan)
    outer, rep = control_mesh(scan, spec.control_faces, spec.remesh, relax=spec.relax)
    mid = mid_surface(outer, spec.thickness)
    return Shell(mid.vertices, mid.faces, material, spec.thickness), {
        "scan": spec.scan, "control_faces": int(len(mid.faces)), "control_vertices": int(len(mid.vertices)),
        "remesh": getattr(rep, "method", spec.remesh)}
