"""Every scene compiles and steps without MuJoCo warnings (mujoco_menagerie's scene test)."""
from pathlib import Path

import numpy as np
import pytest

import mujoco

SCENES = sorted((Path(__file__).resolve().parents[2] / "scenes").glob("*/scene*.xml"))


def test_there_are_scenes():
    names = {p.parent.name for p in SCENES}
    assert {"test_sphere", "tennis_ball", "soda_can", "duck", "duck_head_poke"} <= names


@pytest.mark.parametrize("path", SCENES, ids=[f"{p.parent.name}/{p.name}" for p in SCENES])
def test_scene_compiles_and_steps_without_warnings(path):
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    data.ctrl[:] = 5.0                              # squeeze while falling: contacts happen
    mujoco.mj_step(model, data, nstep=1000)
    assert all(w.number == 0 for w in data.warning), [mujoco.mjtWarning(i).name for i, w in enumerate(data.warning) if w.number]
    assert np.all(np.isfinite(data.qpos))
    assert (path.parent / "README.md").is_file()


def test_object_frame_is_the_scan_frame():
    """The collision mesh keeps the scan's coordinates: its vertices, mapped by the body pose, sit
    where the scene put the scan (object frame = scan frame; what the load mapping relies on)."""
    import trimesh

    from graspdef.scans import load_scan

    path = Path(__file__).resolve().parents[2] / "scenes" / "tennis_ball" / "scene.xml"
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    b = model.body("tennis_ball").id
    R, p = data.xmat[b].reshape(3, 3), data.xpos[b]
    scan = load_scan("ycb_056_tennis_ball").vertices
    hull = trimesh.Trimesh(scan).convex_hull
    g = model.geom("tennis_ball_collision").id
    # geom frame holds the (re-centred) mesh: its world position is the hull's centre in the world
    centre_world = data.geom_xpos[g]
    vert = model.mesh_vert[model.mesh_vertadr[model.geom_dataid[g]]:][:model.mesh_vertnum[model.geom_dataid[g]]]
    world = vert @ data.geom_xmat[g].reshape(3, 3).T + centre_world
    obj = (world - p) @ R
    lo, hi = obj.min(axis=0), obj.max(axis=0)
    assert np.allclose(lo, hull.bounds[0], atol=1e-6) and np.allclose(hi, hull.bounds[1], atol=1e-6)
