"""``--contact geometric`` end to end: the tennis ball (coarse 320-face control mesh) squeezed by
the pad gripper (scenes/tennis_ball/scene_pad.xml), the fingertips as rigid force-controlled
obstacles (graspdef.contact.barrier)."""
import json

import numpy as np
import pytest

import mujoco  # noqa: F401  (the sim extra is part of make test)

from graspdef.pipeline import run_grasp

PADS = "scenes/tennis_ball/scene_pad.xml"


def _support_force(r):
    """What the rigid-mode support carries beyond the object's weight [N] (see :func:`_check`)."""
    res = np.asarray(r["residual"]["net_force_N"])
    if r["friction"]["shell_side"]:
        R = np.asarray(r["mujoco"]["object_pose"]["rotation"])
        res = res - np.asarray(r["mujoco"]["object_weight_N"]) @ R
    return float(np.linalg.norm(res))


def _check(r, force, support=True):
    for s in ("left", "right"):
        f = r["fingers"][s]
        assert f["contact_force_along_axis_N"] == pytest.approx(force, rel=1e-8)     # force control
        assert f["contact_area_m2"] > 0
        g = r["geometric_contact"]["fingers"][s]
        assert g["min_gap_m"] > 0 and g["min_gap_fine_m"] > 0                     # no penetration
    # MuJoCo's friction and the weight stay dead loads: with the contact forces they balance to
    # the lateral force of the frictionless contact (small for this symmetric grasp).  With the
    # shell-side friction (the scene's mu by default), the fingertips' friction takes up MuJoCo's
    # friction loads where they act and the weight goes to the rigid-mode support: the residual
    # is then the weight (graspdef.contact.friction, docs/grasp.md "Friction")
    if support:
        assert _support_force(r) < 0.05 * force
    assert r["convergence"]["completed"]


def test_tennis_ball_pads_geometric_nonlinear(tmp_path):
    """Neo-Hookean ball with its 80 kPa air, 3 N per pad: the fingers' force along their axes is
    the target, nothing penetrates, the run folder is complete; the contact patch is much larger
    than a pin's (the pad flattens the ball)."""
    out = tmp_path / "run"
    r = run_grasp(PADS, 3.0, "geometric", "nonlinear", out, control_faces=320).result
    _check(r, 3.0)
    ind = r["feedback"]["indentation_per_finger_m"]
    assert 0 < ind < 5e-3
    assert r["derived"]["contact_area"]["value"] / 2 > 2e-5                      # > 20 mm^2 per pad
    rec = json.loads((out / "result.json").read_text())
    assert rec["contact"] == "geometric" and rec["derived"]["contact_area"]["value"] > 0
    for f in ("result.json", "contacts.json", "deformed.ply", "undeformed.ply", "path.csv"):
        assert (out / f).is_file()
    # friction: the scene's mu (rubber pads 1.2 against the ball's geoms: MuJoCo takes the larger) on
    # both sides, recorded per finger with stick/slip counts and the friction force
    mu = r["friction"]["mu"]
    assert r["friction"]["shell_side"] and mu == r["friction"]["mujoco_mu"] and all(m > 0 for m in mu.values())
    for s in ("left", "right"):
        fr = r["fingers"][s]["friction"]
        assert fr["mu"] == mu[s] and fr["n_stick"] + fr["n_slip"] > 0 and fr["tangential_force_N"] >= 0
    assert "friction_force" in r["derived"]
    assert any(c.startswith("friction_left_0_n_stick") for c in (out / "path.csv").read_text().splitlines()[0].split(","))


def test_tennis_ball_frictionless_slips_out():
    """--friction 0 sets mu = 0 on the fingertip and object geoms: nothing holds the 58 g ball
    against gravity in MuJoCo's settle step, which says so in one line (the shell is never
    solved; the shell side's mu = 0 limit is tests/contact/test_friction.py's)."""
    from graspdef.sim.scene import SimError

    with pytest.raises(SimError, match="slipped out"):
        run_grasp(PADS, 3.0, "geometric", "nonlinear", None, control_faces=320, friction=0.0)


@pytest.fixture(scope="module")
def linear_pads():
    """The linear shell with pad contact at 1 and 3 N per finger (320 faces)."""
    return [run_grasp(PADS, f, "geometric", "linear", None, control_faces=320).result for f in (1.0, 3.0)]


@pytest.mark.slow
def test_tennis_ball_contact_area_grows_with_load(linear_pads):
    """Linear shell with pad contact at 1 and 3 N: the contact area grows with the load, the
    indentation too (and less than proportionally: the patch stiffens as it grows).  What the
    rigid-mode support carries is the next test's."""
    rs = linear_pads
    for r, f in zip(rs, (1.0, 3.0)):
        _check(r, f, support=False)
    assert rs[0]["derived"]["contact_area"]["value"] < rs[1]["derived"]["contact_area"]["value"]
    i0, i1 = (r["feedback"]["indentation_per_finger_m"] for r in rs)
    assert 0 < i0 < i1


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="a known model limitation (docs/grasp.md, Friction, Limitations): the "
                   "smoothed, lagged shell-side friction does not take up all of MuJoCo's friction dead loads, and "
                   "the rigid-mode support carries the rest: 0.101 N beyond the weight at 1 N, 0.106 N at 3 N")
def test_linear_pads_support_carries_only_the_weight(linear_pads):
    """The model's intent with shell-side friction (docs/grasp.md): the fingertips' friction takes
    up MuJoCo's friction loads where they act, so the rigid-mode support carries the object's
    weight and nothing else (here to 5 % of the finger force, as the nonlinear 3 N grasp above
    does: 0.0099 N).  The linear pads miss it (measured 0.101 N at 1 N, 0.106 N at 3 N; the
    nonlinear shell at 1 N 0.039 N): expected to fail, strictly, so a change that fixes it shows."""
    for r, f in zip(linear_pads, (1.0, 3.0)):
        assert _support_force(r) < 0.05 * f
