"""Generate the MuJoCo grasp scenes in scenes/ from the real scans (issue 5).

    python scripts/make_scenes.py            # rewrites scenes/*/*.xml, assets/*.obj (object.toml is written by hand)

Maintenance script, not imported by graspdef or its tests; its outputs are committed.  Needs
trimesh (always) and coacd (the duck's convex decomposition; `pip install coacd==1.0.14`).

Conventions (mujoco_menagerie, ../shared/STYLE.md section 8): the robot file
scenes/parallel_gripper/parallel_gripper_<tip>.xml holds only the gripper; each scene folder
holds scene.xml (includes the robot), assets/ (collision meshes, metres, in the scan's own
frame), object.toml (the object's data for graspdef.objects: scan, thickness, material law, gas,
written by hand with a source for each value) and README.md.  SI units throughout.

Object frame = scan frame: the collision meshes keep the scan's coordinates (metres), and the
object body is placed so that the chosen grasp point of the scan lies at the world origin, where
the fingers meet.  The body's mass and inertia are computed here from a density: a thin shell
(areal density rho * t over the scan surface) or a solid (rho over the enclosed volume).
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import trimesh

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from graspdef.geometry.mass import shell_inertia as _shell, solid_inertia as _solid  # noqa: E402
from graspdef.scans import load_scan  # noqa: E402
from graspdef.sim.gripper import TIPS, GripperModel, gripper_xml  # noqa: E402
from graspdef.sim.mjcf import mesh_assets, object_body, object_defaults, quat_z, rotmat, scene_xml  # noqa: E402

SCENES = ROOT / "scenes"
OBJ_DEFAULTS = object_defaults(0.8)


def shell_inertia(mesh: trimesh.Trimesh, areal_density: float):
    return _shell(mesh.vertices, mesh.faces, areal_density)


def solid_inertia(mesh: trimesh.Trimesh, density: float):
    return _solid(mesh.vertices, mesh.faces, density)


def write_hulls(folder: Path, parts: list[trimesh.Trimesh], stem: str) -> list[str]:
    (folder / "assets").mkdir(parents=True, exist_ok=True)
    names = []
    for i, p in enumerate(parts):
        name = f"{stem}_collision_{i}" if len(parts) > 1 else f"{stem}_collision"
        p.export(folder / "assets" / f"{name}.obj", file_type="obj", digits=9)
        names.append(name)
    return names


def mesh_scene(folder: str, name: str, scan_id: str, parts: list[trimesh.Trimesh], grasp_point, mass_info,
               tips=("pin",), yaw_deg: float = 0.0, free: bool = True, comment: str = "") -> dict:
    d = SCENES / folder
    names = write_hulls(d, parts, name)
    assets, geoms = mesh_assets(names, 0.8)
    q = quat_z(yaw_deg)
    pos = -rotmat(q) @ np.asarray(grasp_point, float)
    mass, com, inertia = mass_info
    body = object_body(name, pos, q, mass, com, inertia, geoms, free)
    for tip in tips:
        fname = "scene.xml" if tip == tips[0] else f"scene_{tip}.xml"
        (d / fname).write_text(scene_xml(name, tip, body, assets, comment=comment))
    return {"mass": mass, "pos": pos, "quat": q}


def soda_can_scene() -> dict:
    """The soda can of Tian & Jia 2010 (Table I, last row): an EMPTY aluminium beverage can, as a thin shell.

    Geometry: the YCB 005 (tomato soup can) scan, the only can-sized scan in ../shared/scans
    (67.9 x 101.9 mm; a 355 ml soda can is about 66 x 122 mm).  Mass: the shell's own, rho * t
    over the scan surface (the lids included), with rho = 2,720 kg/m^3 (AA3004, specific gravity
    2.72) and t = 0.1 mm (the can body's wall), thin-shell inertia of that mass; about 8.1 g.  A
    real empty 355 ml can weighs 13-15 g (taller, and its ends are 0.3-0.4 mm thick); the shell
    here is the scan at the uniform body-wall thickness that scenes/soda_can/object.toml simulates.
    Sources: scenes/soda_can/README.md.  Regenerate this scene alone with
    `python -c "import scripts.make_scenes as m; m.soda_can_scene()"` (from the repository root).
    """
    scan = load_scan("ycb_005_tomato_soup_can")
    tm = trimesh.Trimesh(scan.vertices, scan.faces, process=True)
    hull = tm.convex_hull
    t, rho = 0.1e-3, 2720.0                                       # AA3004 body wall 0.1 mm, 2,720 kg/m^3
    info = shell_inertia(tm, rho * t)
    centre = tm.bounds.mean(axis=0)
    out = mesh_scene("soda_can", "soda_can", "ycb_005_tomato_soup_can", [hull], centre, info,
                     comment=f"Empty aluminium soda can (YCB 005 soup-can scan, convex hull) as a thin shell: "
                             f"{rho:.0f} kg/m^3 x {t * 1e3:.1f} mm over the scan surface "
                             f"({tm.area * 1e4:.1f} cm^2) = {info[0] * 1e3:.2f} g.")
    print(f"soda can: empty aluminium shell, area {tm.area * 1e4:.1f} cm^2, mass {info[0] * 1e3:.2f} g")
    return out


def main() -> None:
    for tip in TIPS:
        (SCENES / "parallel_gripper").mkdir(parents=True, exist_ok=True)
        (SCENES / "parallel_gripper" / f"parallel_gripper_{tip}.xml").write_text(
            gripper_xml(GripperModel(tip), "scripts/make_scenes.py"))

    # --- test sphere: rigid, R = 32.5 mm, 58 g (a tennis ball's size and mass) --------------------
    R, m = 0.0325, 0.058
    I = 2 / 3 * m * R ** 2                                        # thin spherical shell
    body = object_body("sphere", (0, 0, 0), (1, 0, 0, 0), m, (0, 0, 0), np.diag([I, I, I]),
                       f'      <geom name="sphere_collision" class="object_collision" type="sphere" size="{R}"/>')
    d = SCENES / "test_sphere"
    d.mkdir(parents=True, exist_ok=True)
    for tip in ("pin", "pad"):
        fname = "scene.xml" if tip == "pin" else "scene_pad.xml"
        (d / fname).write_text(scene_xml("sphere", tip, body, OBJ_DEFAULTS, comment=(
            "Test scene: a rigid sphere (R 32.5 mm, 58 g, thin-shell inertia) squeezed by the parallel gripper.")))

    # --- tennis ball (YCB 056): convex hull of the scan; shell mass from density --------------------
    scan = load_scan("ycb_056_tennis_ball")
    tm = trimesh.Trimesh(scan.vertices, scan.faces, process=True)
    hull = tm.convex_hull
    # effective wall density: ITF ball mass 56.0-59.4 g -> 57.7 g over the scan area at t = 2.5 mm
    t = 2.5e-3
    rho = 0.0577 / (tm.area * t)
    info = shell_inertia(tm, rho * t)
    centre = tm.bounds.mean(axis=0)
    mesh_scene("tennis_ball", "tennis_ball", "ycb_056_tennis_ball", [hull], centre, info, tips=("pin", "pad"),
               comment=f"Tennis ball (YCB 056 scan, convex hull) squeezed by the parallel gripper; wall density "
                       f"{rho:.0f} kg/m^3 x 2.5 mm over the scan surface = {info[0] * 1e3:.1f} g.")
    print(f"tennis ball: rho_eff = {rho:.1f} kg/m^3, mass {info[0] * 1e3:.2f} g, hull {len(hull.vertices)} vertices")

    soda_can_scene()

    # --- rubber duck (LINEMOD obj 9, mm -> m): CoACD convex decomposition; rubber shell mass -------
    import coacd
    scan = load_scan("linemod_lmo_obj09_duck")
    tm = trimesh.Trimesh(scan.vertices, scan.faces, process=True)
    coacd.set_log_level("error")
    parts = coacd.run_coacd(coacd.Mesh(tm.vertices, tm.faces), threshold=0.03, max_convex_hull=16, seed=0)
    hulls = [trimesh.Trimesh(v, f, process=True).convex_hull for v, f in parts]
    t, rho = 1.0e-3, 1100.0                                       # vinyl/rubber wall 1 mm (paper: "?.0 mm")
    info = shell_inertia(tm, rho * t)
    # antipodal grasp across the body (duck y axis -> gripper x axis) at the widest section
    v = tm.vertices
    grasp = np.array([-0.0017, 0.0, -0.0283])   # the body's widest section (scan vertices)
    mesh_scene("duck", "duck", "linemod_lmo_obj09_duck", hulls, grasp, info, yaw_deg=90.0,
               comment=f"Rubber duck (LINEMOD obj 9 scan, mm -> m, CoACD {len(hulls)} convex parts), grasped across "
                       f"its body; rubber shell 1 mm x 1100 kg/m^3 = {info[0] * 1e3:.1f} g.")
    # duck-head poke: the duck fixed to the world (its base held, as in the paper), the right
    # finger pokes the side of the head; the left finger stays open (zero force)
    head = np.array([0.0082, 0.0, 0.0147])      # the head's widest section (scan vertices)
    mesh_scene("duck_head_poke", "duck", "linemod_lmo_obj09_duck", hulls, head, info, yaw_deg=90.0, free=False,
               comment="Rubber duck fixed at its base (no free joint), its head poked sideways by the right finger.")
    print(f"duck: {len(hulls)} convex parts, mass {info[0] * 1e3:.1f} g, y range at grasp "
          f"{v[:, 1].min():.4f}..{v[:, 1].max():.4f}")


if __name__ == "__main__":
    main()
