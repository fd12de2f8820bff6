"""An object's shell: the control mesh of its scan (or the object's own control mesh), offset
inward by half the thickness, with the material of its data for the analysis asked for."""
from __future__ import annotations

from ..errors import MeshError
from ..geometry import TriMesh, validate_mesh
from ..scans import mid_surface, scan_entry
from ..scans.cache import cached_control_mesh
from ..scans.manifest import ply_units, read_surface
from ..shell.memory import check_memory
from ..shell.model import Shell
from .data import ObjectSpec


def outer_surface(spec: ObjectSpec) -> tuple[TriMesh, dict]:
    """The outer surface's control mesh [m] of ``spec`` and how it was made: the object's own
    ``control_mesh`` file (read as it is, its unit from the PLY header), or the control mesh of
    the scan (graspdef.scans.control_mesh, ``spec.control_faces``, ``spec.remesh``, ``spec.relax``;
    read from the disk cache of graspdef.scans.cache when a run made it before)."""
    if spec.control_mesh is not None:
        units = ply_units(spec.control_mesh)
        if units is None:
            raise MeshError(f"{spec.control_mesh}: no 'comment units <unit>' line in the PLY header "
                            "(graspdef object add writes one)")
        v, f = read_surface(spec.control_mesh, units)
        validate_mesh(v, f, str(spec.control_mesh))
        return TriMesh(v, f), {"control_mesh": spec.control_mesh.name, "remesh": "given"}
    entry = scan_entry(spec.scan)
    outer, rep = cached_control_mesh(entry.file(), entry.units, spec.control_faces, spec.remesh, relax=spec.relax)
    return outer, {"scan": spec.scan, "remesh": getattr(rep, "method", spec.remesh)}


def build_shell(spec: ObjectSpec, analysis: str) -> tuple[Shell, dict]:
    """(Shell, info) of ``spec`` for ``analysis`` ("linear" or "nonlinear"): the outer surface's
    control mesh (:func:`outer_surface`) offset inward by t/2 (mid_surface), and
    ``spec.shell_material(analysis)``.  ``info``: where the mesh came from, its size and the
    remeshing method used."""
    material = spec.shell_material(analysis)
    outer, info = outer_surface(spec)
    check_memory(outer.n_vertices, f"{spec.file}: the control mesh")
    mid = mid_surface(outer, spec.thickness)
    return Shell(mid.vertices, mid.faces, material, spec.thickness), {
        **info, "control_faces": int(len(mid.faces)), "control_vertices": int(len(mid.vertices))}
