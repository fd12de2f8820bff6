"""``graspdef object add``: a mesh file of one's own -> a self-contained object folder that
``graspdef grasp FOLDER --force F`` runs from any working directory.

The chain (each step refuses bad input with one line, before anything is written):

1. read the mesh (PLY/OBJ/STL/GLB/OFF, a raw scan included) in its units (``mm``, ``m``, or
   ``auto``: a PLY's ``comment units`` line, else the size: an object 5 mm to 2 m across in
   metres, 5 mm to 2 m in millimetres);
2. repair it into a closed, outward-oriented surface (:mod:`graspdef.scans.repair`);
3. remesh it into a Loop control mesh of about the requested number of faces (isotropic remeshing,
   :func:`graspdef.scans.control_mesh`), measured: smallest angle, valence histogram, two-sided
   Hausdorff distance to the input;
4. check the thin-shell range, the mid-surface offset and the memory a solve of that size needs;
5. mass and inertia of the shell (a wall density, or the total mass spread over the surface);
6. collision geometry: the convex hull, or a CoACD convex decomposition of a non-convex object;
7. the grasp: the line given (axis + point), or the best antipodal pair; the pose that puts it on
   the gripper's closing axis;
8. write the folder atomically: object.toml, control_mesh.ply, surface.ply, scene.xml (pin
   fingertips), scene_pad.xml (pads), gripper/ (the robot files, so the includes resolve inside
   the folder), assets/ (collision meshes), object_add.json (every measurement, SI) and README.md;
   then compile the scene in MuJoCo.
"""
from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from ..errors import ProblemError
from ..geometry import TriMesh
from ..geometry.io import save_ply
from ..geometry.mass import shell_inertia
from ..geometry.mesh import unique_edges, vertex_valence
from ..runs.folder import atomic_folder
from ..scans import control_mesh, mid_surface, ply_units, read_surface
from ..scans.repair import repair_surface
from ..sim.gripper import DEFAULT_FORCE_MAX, TIPS, GripperModel, gripper_xml
from ..sim.mjcf import mesh_assets, object_body, quat_of, scene_xml
from ..units import LENGTH_UNITS
from ..shell.memory import check_memory
from .checks import check_thin_shell
from .collision import collision_parts
from .data import GasSpec, MaterialSpec
from .placement import Grasp, best_antipodal, grasp_along, pose_for

#: input formats trimesh reads that ``object add`` accepts
MESH_SUFFIXES = (".ply", ".obj", ".stl", ".glb", ".gltf", ".off")
#: object size range [m] that ``--units auto`` reads as metres (else millimetres)
AUTO_METRES = (0.005, 2.0)
GENERATOR = "graspdef object add"


@dataclass(frozen=True)
class AddedObject:
    """What ``object add`` made: the folder, the control-mesh measurements, the grasp, the mass."""

    folder: Path
    record: dict

    def summary(self) -> list[str]:
        r = self.record
        cm, g = r["control_mesh"], r["grasp"]
        hist = ", ".join(f"{k}: {v}" for k, v in cm["valence_histogram"].items())
        return [
            f"{r['name']}: {Path(r['input']['file']).name} ({r['input']['units']}: {r['input']['units_reason']}), "
            f"{r['input']['size_mm'][0]:.1f} x {r['input']['size_mm'][1]:.1f} x {r['input']['size_mm'][2]:.1f} mm",
            *(f"  repaired: {x}" for x in r["repairs"]),
            f"  control mesh: {cm['n_vertices']} vertices, {cm['n_faces']} faces (isotropic remeshing); smallest "
            f"angle {cm['min_angle_deg']:.1f} deg; valences {hist}; Hausdorff distance to the input "
            f"{cm['hausdorff_m'] * 1e3:.2f} mm (rms {cm['input_to_mesh_rms_m'] * 1e3:.2f} mm)",
            *_topology(cm),
            f"  shell: thickness {r['thickness_m'] * 1e3:.4g} mm, mass {r['mass_kg'] * 1e3:.4g} g; collision: "
            f"{r['collision']}",
            f"  grasp: {g['how']}, {g['width_m'] * 1e3:.1f} mm wide, antipodal within {g['antipodal_angle_deg']:.1f} "
            f"deg; gripper force range 0..{r['gripper_force_max_N']:g} N per finger",
            f"  memory estimate of a nonlinear solve: {r['memory_estimate_bytes'] / 2**30:.2f} GiB",
        ]


def _topology(cm: dict) -> list[str]:
    """The summary's line on handles, if the surface has any (a closed surface of genus g has g)."""
    g = cm.get("genus", 0)
    if not g:
        return []
    small = cm["shortest_edge_m"] < 0.1 * cm["median_edge_m"]
    return [f"  topology: genus {g} (Euler characteristic {cm['euler']}): {g} handle{'s' if g > 1 else ''} kept "
            f"from the input; shortest control-mesh edge {cm['shortest_edge_m'] * 1e3:.2g} mm (median "
            f"{cm['median_edge_m'] * 1e3:.2g} mm)" + ("; handles this small are usually scan noise, and they bound the "
                                                         "wall thickness the mid-surface allows" if small else "")]


def _units(path: Path, units: str, vertices: np.ndarray) -> tuple[str, str]:
    if units != "auto":
        if units not in LENGTH_UNITS:
            raise ProblemError(f"--units {units!r}: accepted: auto, {', '.join(LENGTH_UNITS)}")
        return units, "as given"
    stated = ply_units(path)
    if stated is not None:
        return stated, "the PLY header's 'comment units' line"
    size = float(np.ptp(vertices, axis=0).max())
    lo, hi = AUTO_METRES
    if lo <= size <= hi:
        return "m", f"{size:.4g} units across: metres"
    if lo * 1e3 <= size <= hi * 1e3:
        return "mm", f"{size:.4g} units across: millimetres"
    raise ProblemError(f"{path}: the mesh is {size:.4g} units across, neither an object of 5 mm to 2 m in metres "
                       "nor in millimetres: give --units")


def read_input(path, units: str = "auto") -> tuple[np.ndarray, np.ndarray, str, str]:
    """(vertices [m], faces, unit, why that unit) of a user's mesh file."""
    path = Path(path)
    if not path.is_file():
        raise ProblemError(f"--mesh {path}: file not found")
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise ProblemError(f"--mesh {path}: unknown mesh format {path.suffix!r}; accepted: "
                           f"{', '.join(MESH_SUFFIXES)}")
    v, f = read_surface(path, "m")
    unit, why = _units(path, units, v)
    return v * LENGTH_UNITS[unit], f, unit, why


def _hausdorff(a: TriMesh, b: TriMesh) -> tuple[float, float]:
    """(two-sided Hausdorff distance [m] between the surfaces, sampled at 20,000 points each, and
    the rms distance from ``a``'s samples to ``b``)."""
    ta = trimesh.Trimesh(a.vertices, a.faces, process=False)
    tb = trimesh.Trimesh(b.vertices, b.faces, process=False)
    pa = np.vstack([a.vertices, trimesh.sample.sample_surface(ta, 20000, seed=0)[0]])
    pb = np.vstack([b.vertices, trimesh.sample.sample_surface(tb, 20000, seed=0)[0]])
    da = np.asarray(trimesh.proximity.closest_point(tb, pa)[1])
    db = np.asarray(trimesh.proximity.closest_point(ta, pb)[1])
    return float(max(da.max(), db.max())), float(np.sqrt(np.mean(da ** 2)))


def _check_name(name: str) -> None:
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]{0,63}", name or ""):
        raise ProblemError(f"object name {name!r}: use letters, digits and _ (a MuJoCo body name), starting with a "
                           "letter")


def _toml_str(s: str) -> str:
    return json.dumps(str(s))


def object_toml(name: str, record: dict, material: MaterialSpec, gas: GasSpec | None, steps: int) -> str:
    """The object.toml text of an added object (every value with its unit; SI numbers in comments)."""
    m = material
    mat = [f"law = {_toml_str(m.law)}", f'E = "{m.E / 1e6:.9g} MPa"', f"nu = {m.nu:g}"]
    if m.c2_over_c1 is not None:
        mat.append(f"C2_over_C1 = {m.c2_over_c1:g}")
    mat.append(f"source = {_toml_str(m.source or 'given to graspdef object add')}")
    gas_txt = ""
    if gas is not None:
        gas_txt = (f'\n[gas]\np0 = "{gas.p0 / 1e3:.9g} kPa"                     # gauge, the unloaded object\n'
                   f"source = {_toml_str(gas.source)}\n")
    return f"""# {name}: an object added by `{GENERATOR}` from {record['input']['file']}
# ({record['input']['units']}); its data for graspdef.objects.  SI inside; every value states its unit.
[object]
body = {_toml_str(name)}
control_mesh = "control_mesh.ply"    # outer surface, the Loop control mesh (PLY 'comment units m')
surface = "surface.ply"              # the input surface, repaired (m): what the control mesh approximates

[shell]
thickness = "{record['thickness_m'] * 1e3:.9g} mm"
source = {_toml_str(record['thickness_source'])}

[material]
{chr(10).join(mat)}
{gas_txt}
[solver]
steps = {steps}                            # initial load steps of the nonlinear path (adaptive)
"""


def readme(record: dict, summary: list[str]) -> str:
    return f"""# {record['name']}

Made by `{GENERATOR}` (SI units in every file; the PLY files state theirs in a `comment units`
header line). Grasp it with

    graspdef grasp {record['folder_name']} --force 40 --out runs/{record['name']}_40N
    graspdef grasp {record['folder_name']} --force 40 --fingertips pad --out runs/{record['name']}_40N_pad

| file | what |
|---|---|
| object.toml | the shell's data: control mesh, thickness, material law with E and nu, gas |
| control_mesh.ply | outer surface, Loop control mesh [m] |
| surface.ply | the input surface after repair [m] |
| scene.xml, scene_pad.xml | MuJoCo scenes: the gripper with pin / pad fingertips and the object, placed for the grasp |
| gripper/ | the gripper's robot files (force range 0..{record['gripper_force_max_N']:g} N per finger) |
| assets/ | collision meshes (convex parts) [m] |
| object_add.json | every measurement below, SI |

```
{chr(10).join(summary)}
```
"""


def add_object(name: str, mesh, out, *, thickness: float, material: MaterialSpec, gas: GasSpec | None = None,
               units: str = "auto", density: float | None = None, mass: float | None = None,
               friction: float = 0.8, faces: int = 2000, grasp_axis=None, grasp_point=None,
               force_max: float = DEFAULT_FORCE_MAX, steps: int = 4, thickness_source: str = "",
               say=None) -> AddedObject:
    """Make the object folder ``out`` for the mesh file ``mesh`` (see the module docstring).

    ``thickness`` [m]; ``density`` [kg/m^3] of the wall or ``mass`` [kg] of the whole object (one of
    them); ``friction``: Coulomb coefficient of the object's surface; ``faces``: control mesh size;
    ``grasp_axis`` and ``grasp_point`` [m, the mesh's frame after unit conversion]: the grasp line
    (both, or neither: the best antipodal pair); ``force_max`` [N]: the gripper's force range;
    ``say``: called with a line per step (progress)."""
    say = say or (lambda line: None)
    _check_name(name)
    out = Path(out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise ProblemError(f"--out {out} exists and is not empty: give a new folder (an object folder is never "
                           "overwritten)")
    if not (np.isfinite(thickness) and thickness > 0):
        raise ProblemError(f"--thickness must be a positive length, got {thickness!r}")
    if (density is None) == (mass is None):
        raise ProblemError("give the wall's --density (e.g. 950kg/m^3) or the object's --mass (e.g. 60g), one of them")
    for what, val in (("--density", density), ("--mass", mass)):
        if val is not None and not (np.isfinite(val) and val > 0):
            raise ProblemError(f"{what} must be positive, got {val!r}")
    if not (np.isfinite(friction) and 0 < friction <= 5):
        raise ProblemError(f"--friction must be a Coulomb coefficient in (0, 5], got {friction!r}")
    if not 100 <= int(faces) <= 200_000:
        raise ProblemError(f"--faces must be 100 to 200,000, got {faces}")
    if (grasp_axis is None) != (grasp_point is None):
        raise ProblemError("give --grasp-axis and --grasp-point together, or neither (the best antipodal pair)")
    gripper = GripperModel(force_max=float(force_max))

    say("reading the mesh")
    v, f, unit, why = read_input(mesh, units)
    size = np.ptp(v, axis=0)
    repaired = repair_surface(v, f, str(mesh))
    say("remeshing into a Loop control mesh")
    outer, rep = control_mesh(repaired.mesh, int(faces), "isotropic")
    check_thin_shell(thickness, outer.vertices, "--thickness")
    mid_surface(outer, thickness)                                 # the offset must not fold the surface
    need = check_memory(outer.n_vertices, f"a control mesh of {outer.n_faces} faces")
    lengths = np.linalg.norm(np.diff(outer.vertices[unique_edges(outer.faces)], axis=1)[:, 0], axis=1)
    haus, rms = _hausdorff(repaired.mesh, outer)
    val = vertex_valence(outer.faces, outer.n_vertices)
    area = float(trimesh.Trimesh(outer.vertices, outer.faces, process=False).area)
    areal = density * thickness if density is not None else mass / area
    m, com, inertia = shell_inertia(outer.vertices, outer.faces, areal)
    say("collision geometry")
    parts, how = collision_parts(outer)
    say("choosing the grasp")
    if grasp_axis is None:
        grasp: Grasp = best_antipodal(outer, com, friction, max_width=2 * 0.063, min_width=0.018)
    else:
        grasp = grasp_along(outer, grasp_point, grasp_axis)
    pos, R = pose_for(outer, grasp)
    record = {
        "schema": "graspdef.object_add", "version": 1, "units": {"length": "m", "mass": "kg", "force": "N"},
        "name": name, "folder_name": out.name,
        "input": {"file": str(Path(mesh).resolve()), "units": unit, "units_reason": why,
                  "size_mm": (size * 1e3).tolist(), "n_vertices": int(len(v)), "n_faces": int(len(f))},
        "repairs": repaired.repairs,
        "control_mesh": {"method": rep.method, "n_vertices": rep.n_vertices, "n_faces": rep.n_faces,
                         "euler": rep.euler, "min_angle_deg": rep.min_angle_deg,
                         "valence_histogram": {int(k): int(c) for k, c in enumerate(np.bincount(val)) if c},
                         "hausdorff_m": haus, "input_to_mesh_rms_m": rms, "volume_m3": rep.volume,
                         "genus": (2 - rep.euler) // 2, "shortest_edge_m": float(lengths.min()),
                         "median_edge_m": float(np.median(lengths))},
        "thickness_m": float(thickness), "thickness_source": thickness_source or "given to graspdef object add",
        "mass_kg": m, "mass_from": "density" if density is not None else "mass", "centre_of_mass_m": com.tolist(),
        "inertia_kg_m2": inertia.tolist(), "friction": float(friction), "collision": how,
        "grasp": grasp.record(), "pose": {"position_m": pos.tolist(), "rotation": R.tolist()},
        "gripper_force_max_N": gripper.force_max, "memory_estimate_bytes": need,
    }
    result = AddedObject(out, record)
    say("writing the folder")
    q = quat_of(R)
    with atomic_folder(out) as tmp:
        save_ply(tmp / "control_mesh.ply", outer.vertices, outer.faces, units="m")
        save_ply(tmp / "surface.ply", repaired.mesh.vertices, repaired.mesh.faces, units="m")
        (tmp / "assets").mkdir()
        names = []
        for i, p in enumerate(parts):
            n = f"{name}_collision_{i}" if len(parts) > 1 else f"{name}_collision"
            p.export(tmp / "assets" / f"{n}.obj", file_type="obj", digits=9)
            names.append(n)
        (tmp / "gripper").mkdir()
        assets, geoms = mesh_assets(names, friction)
        body = object_body(name, pos, q, m, com, inertia, geoms)
        for tip in TIPS:
            (tmp / "gripper" / f"parallel_gripper_{tip}.xml").write_text(gripper_xml(gripper.with_tip(tip), GENERATOR))
            (tmp / ("scene.xml" if tip == "pin" else f"scene_{tip}.xml")).write_text(scene_xml(
                name, tip, body, assets, gripper="gripper", generator=GENERATOR,
                comment=f"{name} ({Path(mesh).name}) between the parallel gripper's {tip} fingertips, placed for "
                        f"the grasp: {grasp.how}"))
        (tmp / "object.toml").write_text(object_toml(name, record, material, gas, steps))
        (tmp / "object_add.json").write_text(json.dumps(record, indent=1) + "\n")
        (tmp / "README.md").write_text(readme(record, result.summary()))
        _compile(tmp, name)
    return result


def _compile(folder: Path, name: str) -> None:
    """Compile both scenes in MuJoCo and read the object back (a folder that fails is not kept)."""
    from ..sim.scene import load_scene
    from .data import read_object

    for s in ("scene.xml", "scene_pad.xml"):
        load_scene(folder / s, name)
    read_object(folder / "object.toml", folder / "scene.xml")
