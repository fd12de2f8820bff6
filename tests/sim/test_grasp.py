"""The force-controlled grasp (graspdef.sim.grasp) on a rigid sphere, and bad input.

Physics: a finger on a frictionless slide joint driven by a force actuator is in static
balance when the contact force along the joint axis equals the actuator force; for a sphere
held at its equator by two pins the contact normal is the closing axis, so the normal force
equals the target.  The sphere is held by the fingers only, so the contact forces carry its
weight: sum F = -m g (Newton's first law); two point contacts on a sphere in static balance
without torque are antipodal (the line through both contacts passes through the centre)."""
import numpy as np
import pytest

import mujoco  # noqa: F401  (the sim extra is part of make test)

from pathlib import Path

from graspdef.sim import SimError, grasp

SCENES = Path(__file__).resolve().parents[2] / "scenes"


@pytest.mark.parametrize("scene", ["scene.xml", "scene_pad.xml"])
@pytest.mark.parametrize("force", [10.63, 21.48])
def test_sphere_squeezed_to_target(scene, force):
    r = grasp(SCENES / "test_sphere" / scene, force, "sphere")
    assert r.settled
    pf = r.per_finger()
    assert set(pf) == {"left", "right"}
    for s in ("left", "right"):
        assert pf[s]["normal_force"] == pytest.approx(force, rel=0.01)
        assert r.info["axial_force_N"][s] == pytest.approx(force, rel=1e-6)
    weight = r.object_mass * r.gravity
    assert np.allclose(r.contacts.net_force() + weight, 0.0, atol=1e-3 * force)
    n_l, n_r = pf["left"]["normal"], pf["right"]["normal"]
    assert n_l @ n_r == pytest.approx(-1.0, abs=1e-4)
    # the contact line passes through the centre
    c = r.pose.position
    d = pf["right"]["point"] - pf["left"]["point"]
    off = np.cross(c - pf["left"]["point"], d / np.linalg.norm(d))
    assert np.linalg.norm(off) < 1e-4


def test_force_beyond_actuator_range():
    """The shipped gripper covers real parallel grippers (0..235 N per finger); beyond: refused."""
    with pytest.raises(SimError, match=r"300 N is beyond what the gripper can exert \(0\.\.235 N"):
        grasp(SCENES / "test_sphere" / "scene.xml", 300.0, "sphere")


def test_missing_object_and_gripper(tmp_path):
    with pytest.raises(SimError, match="no object body named 'duck'"):
        grasp(SCENES / "test_sphere" / "scene.xml", 5.0, "duck")
    xml = tmp_path / "nogripper.xml"
    xml.write_text('<mujoco><worldbody><body name="sphere"><freejoint/>'
                   '<geom type="sphere" size="0.03"/></body></worldbody></mujoco>')
    with pytest.raises(SimError, match="no parallel gripper"):
        grasp(xml, 5.0, "sphere")


def test_no_contact_after_closing(tmp_path):
    """A sphere too small for the fingers' travel: they close to their limit without touching."""
    src = (SCENES / "test_sphere" / "scene.xml").read_text()
    small = src.replace('size="0.0325"', 'size="0.003"').replace("../parallel_gripper/",
                                                                 str(SCENES / "parallel_gripper") + "/")
    (tmp_path / "scene.xml").write_text(small)
    with pytest.raises(SimError, match="no contact after closing"):
        grasp(tmp_path / "scene.xml", 5.0, "sphere")
