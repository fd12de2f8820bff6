"""``graspdef object show SCENE``: what a grasp of this object will use, as the data states it."""
from __future__ import annotations

import argparse

HELP = "show an object's data (mesh, thickness, material law with E and nu, gas, fingers) as a grasp uses it"
DESCRIPTION = ("Read the object.toml beside a scene and print, with units and sources, what 'graspdef grasp' "
               "will use: the shell's law for each analysis, the enclosed air, the fingers.")


def add_arguments(p: argparse.ArgumentParser) -> None:
    sub = p.add_subparsers(dest="action", required=True)
    show = sub.add_parser("show", help="print the object's data")
    show.add_argument("scene", help="scene.xml, its folder, or a name under scenes/ (e.g. tennis_ball)")


def describe(spec) -> list[str]:
    """The lines of ``object show`` for an ObjectSpec (SI inside, shown in mm, MPa, kPa)."""
    m = spec.material
    lines = [f"object {spec.body}: {spec.file}",
             f"  scan: {spec.scan}; control mesh {spec.control_faces} faces ({spec.remesh}, relax {spec.relax})",
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
    from ..objects import load_object, scene_xml

    print("\n".join(describe(load_object(scene_xml(args.scene)))))
    return 0
