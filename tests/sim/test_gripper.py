"""The gripper model: its force range is a parameter (a target beyond it refused, never clipped),
and the fingertips' pad size and material can be changed per run."""
from __future__ import annotations

import shutil

import numpy as np
import pytest

from graspdef.errors import GraspdefError
from graspdef.objects import SCENES
from graspdef.sim.grasp import check_targets, force_range
from graspdef.sim.gripper import PAD_MATERIALS, FingertipChange, GripperModel, gripper_xml
from graspdef.sim.scene import SimError, load_scene, mujoco


def _sphere_scene(tmp_path, force_max):
    """The test sphere's scene with a gripper of ``force_max`` [N] in a folder of its own."""
    (tmp_path / "parallel_gripper").mkdir()
    for tip in ("pin", "pad"):
        (tmp_path / "parallel_gripper" / f"parallel_gripper_{tip}.xml").write_text(
            gripper_xml(GripperModel(tip, force_max=force_max)))
    (tmp_path / "scene").mkdir()
    for f in ("scene.xml", "scene_pad.xml"):
        shutil.copy(SCENES / "test_sphere" / f, tmp_path / "scene" / f)
    return tmp_path / "scene"


@pytest.mark.parametrize("force_max", [70.0, 140.0])
def test_force_range_is_a_parameter(tmp_path, force_max):
    sc = load_scene(_sphere_scene(tmp_path, force_max) / "scene.xml", "sphere")
    assert force_range(sc) == {"left": (0.0, force_max), "right": (0.0, force_max)}
    check_targets(sc, {"left": force_max, "right": 0.5 * force_max})          # inside: accepted
    with pytest.raises(SimError, match=f"{1.01 * force_max:g} N is beyond what the gripper can exert "
                                       rf"\(0\.\.{force_max:g} N"):
        check_targets(sc, {"left": 1.01 * force_max, "right": 1.0})


def test_shipped_gripper_covers_real_grippers():
    """Real parallel grippers: 70 N continuous (Franka Hand) to 235 N (Robotiq 2F-85)."""
    for scene in ("tennis_ball", "soda_can", "duck"):
        sc = load_scene(SCENES / scene / "scene.xml", scene.split("_head")[0])
        lo, hi = force_range(sc)["left"]
        assert lo == 0 and hi >= 235.0


def test_pad_size_and_material_per_run():
    mj = mujoco()
    xml = SCENES / "tennis_ball" / "scene_pad.xml"
    base = load_scene(xml, "tennis_ball")
    sc = load_scene(xml, "tennis_ball", FingertipChange(0.030, "steel"))
    for side in ("left", "right"):
        g0 = mj.mj_name2id(base.model, mj.mjtObj.mjOBJ_GEOM, f"{side}_pad")
        g = mj.mj_name2id(sc.model, mj.mjtObj.mjOBJ_GEOM, f"{side}_pad")
        assert np.allclose(base.model.geom_size[g0], [0.002, 0.012, 0.012])
        assert np.allclose(sc.model.geom_size[g], [0.002, 0.015, 0.015])        # 30 mm face, thickness kept
        assert np.allclose(sc.model.geom_friction[g], PAD_MATERIALS["steel"].friction)
        assert np.allclose(sc.model.geom_solref[g], [-1e6, -2000.0])
        # the face stays at the finger origin: the pad's centre is 2 mm behind it as before
        assert np.allclose(sc.model.geom_pos[g], base.model.geom_pos[g0])
    with pytest.raises(SimError, match="a pad size is for pad fingertips; this scene has pins"):
        load_scene(SCENES / "tennis_ball" / "scene.xml", "tennis_ball", FingertipChange(0.03))
    with pytest.raises(GraspdefError, match="pad size must be 2 to 100 mm"):
        FingertipChange(0.5)
    with pytest.raises(GraspdefError, match="unknown fingertip material 'wood'; accepted: rubber, steel"):
        FingertipChange(None, "wood")


def test_shipped_gripper_files_are_the_model():
    """scenes/parallel_gripper/*.xml are gripper_xml's text (scripts/make_scenes.py writes them)."""
    for tip in ("pin", "pad"):
        text = (SCENES / "parallel_gripper" / f"parallel_gripper_{tip}.xml").read_text()
        assert text == gripper_xml(GripperModel(tip), "scripts/make_scenes.py")
