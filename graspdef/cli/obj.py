"""``graspdef object show SCENE``: what a grasp of this object will use, as the data states it;
``graspdef object add NAME --mesh FILE ...``: a mesh of one's own -> an object folder to grasp."""
from __future__ import annotations

import argparse

DESCRIPTION = ("object add: repair and remesh a mesh file into a Loop control mesh, make its collision geometry, "
               "mass and inertia, place it between the gripper's fingers and write a self-contained folder that "
               "'graspdef grasp FOLDER' runs.  object show: print, with units and sources, what 'graspdef grasp' "
               "will use: the shell's law for each analysis, the enclosed air, the fingers.")

LAWS = {"neo-hookean": "neo_hookean", "mooney-rivlin": "mooney_rivlin", "svk": "svk", "linear": "linear"}
ADD_EXAMPLE = ("example: graspdef object add mustard --mesh mustard_mm.ply --units mm --thickness 0.8mm --E 300MPa "
               "--nu 0.45 --law neo-hookean --mass 60g --out mustard")


def add_arguments(p: argparse.ArgumentParser) -> None:
    sub = p.add_subparsers(dest="action", required=True)
    show = sub.add_parser("show", help="print the object's data")
    show.add_argument("scene", help="scene.xml, its folder, or a name under scenes/ (e.g. tennis_ball)")
    add = sub.add_parser("add", help="make an object folder from a mesh file", epilog=ADD_EXAMPLE,
                         description=("Repair the mesh, remesh it into a Loop control mesh (isotropic remeshing), make "
                                      "collision geometry (convex hull or CoACD parts), mass and inertia, place it "
                                      "between the fingers at a grasp and write a folder that 'graspdef grasp' runs "
                                      "from any working directory.  Quantities take units: 2.5mm, 2MPa, 80kPa, 60g."))
    add.add_argument("name", help="the object's name (letters, digits, _): its MuJoCo body name")
    add.add_argument("--mesh", required=True, help="mesh file: PLY, OBJ, STL, GLB, OFF (a closed surface; raw scans "
                     "are repaired where that cannot change the shape)")
    add.add_argument("--units", default="auto", help="the mesh's length unit: mm, m, cm, in, or auto (a PLY's "
                     "'comment units' line, else the object's size)")
    add.add_argument("--out", help="the folder to write (default: ./NAME); never overwritten")
    add.add_argument("--thickness", required=True, help="wall thickness, e.g. 2.5mm")
    add.add_argument("--law", required=True, choices=list(LAWS), help="material law")
    add.add_argument("--E", required=True, help="small-strain Young's modulus, e.g. 2MPa")
    add.add_argument("--nu", required=True, type=float, help="Poisson's ratio, 0 to 0.5 (0.5: incompressible)")
    add.add_argument("--c2-over-c1", dest="c2_over_c1", type=float, help="Mooney-Rivlin C2/C1 (mooney-rivlin only)")
    add.add_argument("--material-source", default="", help="where E and nu come from (stored in object.toml)")
    add.add_argument("--gas", help="enclosed air's gauge pressure of the unloaded object, e.g. 80kPa (default: none)")
    add.add_argument("--gas-source", default="", help="where the pressure comes from (stored in object.toml)")
    mass = add.add_mutually_exclusive_group()
    mass.add_argument("--density", help="the wall's density, e.g. 950kg/m^3 (mass = density x thickness x area)")
    mass.add_argument("--mass", help="the whole object's mass, e.g. 60g (spread over its surface)")
    add.add_argument("--friction", type=float, default=0.8, help="Coulomb friction of the object's surface (0.8)")
    add.add_argument("--faces", type=int, default=2000, help="control mesh size in faces (2000)")
    add.add_argument("--grasp-axis", help='the closing direction in the mesh frame, e.g. "[1, 0, 0]" (with '
                     "--grasp-point; default: the best antipodal pair)")
    add.add_argument("--grasp-point", help='a point inside the object on the grasp line, e.g. "[0, 0, 80] mm"')
    add.add_argument("--max-force", default="235N", help="the gripper's force range per finger, e.g. 140N (235N: "
                     "the upper end of real parallel grippers)")
    add.add_argument("--steps", type=int, default=4, help="initial load steps of the nonlinear path (4)")


def describe(spec) -> list[str]:
    """The lines of ``object show`` for an ObjectSpec (SI inside, shown in mm, MPa, kPa)."""
    m = spec.material
    lines = [f"object {spec.body}: {spec.file}",
             (f"  scan: {spec.scan}; control mesh {spec.control_faces} faces ({spec.remesh}, relax {spec.relax})"
              if spec.control_mesh is None else f"  control mesh: {spec.control_mesh}"
              + (f" (made from {spec.surface})" if spec.surface is not None else "")),
             f"  thickness: {spec.thickness * 1e3:.4g} mm",
             f"  material: law {m.law}, E = {m.E / 1e6:.4g} MPa, nu = {m.nu:g}"
             + (f", C2/C1 = {m.c2_over_c1:g}" if m.c2_over_c1 is not None else "")
             + (f" (source: {m.source})" if m.source else " (no source given)")]
    for analysis in ("linear", "nonlinear"):
        try:
            lines.append(f"  {analysis} analysis uses: {m.model(analysis)}")
        except Exception as exc:  # noqa: BLE001 - a law without that form: say why
            lines.append(f"  {analysis} analysis: not available ({exc})")
    if spec.gas is None:
        lines.append("  enclosed air: none")
    else:
        patm = "standard atmosphere" if spec.gas.p_atm is None else f"{spec.gas.p_atm / 1e3:.4g} kPa ambient"
        lines.append(f"  enclosed air: p0 = {spec.gas.p0 / 1e3:.4g} kPa gauge, {patm} (source: {spec.gas.source}); "
                     "nonlinear analyses only")
    lines.append(f"  fingers: {', '.join(spec.fingers)}; path steps {spec.steps}")
    if spec.fixed_points:
        lines.append(f"  fixed points [mm]: {[[round(c * 1e3, 3) for c in p] for p in spec.fixed_points]}")
    return lines


def run(args: argparse.Namespace) -> int:
    if args.action == "add":
        return _add(args)
    from ..objects import load_object, scene_xml

    print("\n".join(describe(load_object(scene_xml(args.scene)))))
    return 0


def _add(a: argparse.Namespace) -> int:
    from pathlib import Path

    from ..errors import ProblemError
    from ..objects.add import add_object
    from ..objects.data import GasSpec, MaterialSpec
    from ..units import quantity, quantity_vector
    from ._common import progress

    law = LAWS[a.law]
    if (law == "mooney_rivlin") != (a.c2_over_c1 is not None):
        raise ProblemError("--c2-over-c1 is given for --law mooney-rivlin, and only for it")
    if not 0.0 <= a.nu <= 0.5:
        raise ProblemError(f"--nu must be 0 to 0.5, got {a.nu:g}")
    material = MaterialSpec(law, quantity(a.E, "pressure", what="--E"), a.nu, a.c2_over_c1,
                            a.material_source or "stated by the user (graspdef object add)")
    gas = None
    if a.gas is not None:
        gas = GasSpec(quantity(a.gas, "pressure", what="--gas"),
                      a.gas_source or "stated by the user (graspdef object add --gas)")
        if not gas.p0 > 0:
            raise ProblemError(f"--gas must be a positive gauge pressure, got {a.gas!r}")
    if (a.grasp_axis is None) != (a.grasp_point is None):
        raise ProblemError("give --grasp-axis and --grasp-point together, or neither (the best antipodal pair)")
    axis = point = None
    if a.grasp_axis is not None:
        axis = _numbers(a.grasp_axis, "--grasp-axis")
        point = quantity_vector(a.grasp_point, "length", what="--grasp-point")
    done = add_object(
        a.name, a.mesh, a.out or Path(a.name), thickness=quantity(a.thickness, "length", what="--thickness"),
        material=material, gas=gas, units=a.units,
        density=None if a.density is None else quantity(a.density, "density", what="--density"),
        mass=None if a.mass is None else quantity(a.mass, "mass", what="--mass"), friction=a.friction,
        faces=a.faces, grasp_axis=axis, grasp_point=point,
        force_max=quantity(a.max_force, "force", what="--max-force"), steps=a.steps,
        say=lambda line: progress(a, line))
    print("\n".join(done.summary()))
    print(f"object folder: {done.folder}")
    progress(a, f"grasp it: graspdef grasp {done.folder} --force 40 --out runs/{a.name}_40N")
    return 0


def _numbers(text: str, what: str) -> tuple[float, float, float]:
    import math

    from ..errors import ProblemError

    parts = text.strip().strip("[]").replace(",", " ").split()
    try:
        vals = tuple(float(p) for p in parts)
    except ValueError:
        raise ProblemError(f"{what} {text!r}: three numbers, e.g. \"[1, 0, 0]\"") from None
    if len(vals) != 3 or not all(math.isfinite(v) for v in vals):
        raise ProblemError(f"{what} {text!r}: three finite numbers, e.g. \"[1, 0, 0]\"")
    return vals
