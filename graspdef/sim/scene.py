"""Loading a MuJoCo scene and looking up the gripper and the object by name."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import GraspdefError

#: finger names of the parallel gripper (scenes/parallel_gripper): <side>_finger body,
#: <side>_finger_joint, <side>_finger_actuator
SIDES = ("left", "right")


class SimError(GraspdefError):
    """A scene or a simulated grasp is unusable (missing names, unreachable force, no contact,
    MuJoCo warnings)."""


def mujoco():
    """The mujoco module (imported on first use; a clear error when it is missing)."""
    try:
        import mujoco as mj
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise SimError(f"the MuJoCo bridge needs the 'mujoco' package (pip install 'graspdef[sim]'): {exc}") from exc
    return mj


def check_warnings(model, data, what: str) -> None:
    """Raise SimError if MuJoCo raised any warning (too many contacts, bad inertia, instability ...)."""
    mj = mujoco()
    bad = [f"{mj.mjtWarning(i).name} (x{int(w.number)})" for i, w in enumerate(data.warning) if w.number > 0]
    if bad:
        raise SimError(f"{what}: MuJoCo warnings: {', '.join(bad)}")


@dataclass
class Scene:
    """A compiled MuJoCo scene with the gripper's and the object's ids.

    ``object`` is the name of the object body; ``fingers`` maps "left"/"right" to
    (body id, joint qpos address, joint dof address, actuator id)."""

    path: Path
    model: object
    data: object
    object: str
    object_body: int
    object_geoms: np.ndarray
    fingers: dict
    free: bool
    hold: int | None

    def finger_body_of_geom(self, g: int) -> str | None:
        b = int(self.model.geom_bodyid[g])
        for side, (fb, *_rest) in self.fingers.items():
            if b == fb:
                return side
        return None

    def body_pose(self):
        from ..contact.records import Pose

        d = self.data
        return Pose(d.xpos[self.object_body].copy(), d.xmat[self.object_body].reshape(3, 3).copy())

    def tip_gap(self) -> float:
        """Distance between the fingertip faces along the closing axis [m] (rigid fingertips:
        the object's width between the contacts, less MuJoCo's soft-contact penetration)."""
        mj = mujoco()
        m, d = self.model, self.data
        x = {}
        for side in SIDES:
            gid = mj.mj_name2id(m, mj.mjtObj.mjOBJ_GEOM, f"{side}_pin")
            if gid < 0:
                gid = mj.mj_name2id(m, mj.mjtObj.mjOBJ_GEOM, f"{side}_pad")
            if gid < 0:
                raise SimError(f"{self.path}: no fingertip geom '{side}_pin' or '{side}_pad'")
            # the fingertip surface is at the finger body's origin (scenes/parallel_gripper)
            x[side] = d.xpos[int(m.geom_bodyid[gid])].copy()
        return float(np.linalg.norm(x["right"] - x["left"]))


def load_scene(path, object: str, fingertips=None, friction: float | None = None) -> Scene:
    """Compile ``path`` (an MJCF scene) and look up the gripper and the body ``object``.
    ``fingertips``: a :class:`graspdef.sim.gripper.FingertipChange` (pad size, material) applied
    to the scene's fingertip geoms for this run (None: the scene as written).  ``friction``: the
    sliding friction coefficient mu of this run, set on both sides of the grasp -- the fingertip
    geoms and the object's collision geoms -- so that MuJoCo's mix of the pair (the larger of
    the two) is mu (None: the scene's values; torsional and rolling friction stay the scene's).

    Raises SimError if the file does not compile, or the parallel gripper (left/right finger
    bodies, joints, actuators) or the object body is missing."""
    mj = mujoco()
    path = Path(path)
    if not path.is_file():
        raise SimError(f"scene file not found: {path}")
    try:
        if fingertips is None or fingertips.empty:
            model = mj.MjModel.from_xml_path(str(path))
        else:
            spec = mj.MjSpec.from_file(str(path))
            fingertips.apply(spec, path)
            model = spec.compile()
    except ValueError as exc:
        raise SimError(f"{path}: MuJoCo cannot compile the scene: {str(exc).strip().splitlines()[0]}") from exc
    data = mj.MjData(model)
    ob = mj.mj_name2id(model, mj.mjtObj.mjOBJ_BODY, object)
    if ob < 0:
        names = [model.body(i).name for i in range(1, model.nbody)]
        raise SimError(f"{path}: no object body named '{object}' (bodies: {', '.join(names)})")
    fingers = {}
    for side in SIDES:
        b = mj.mj_name2id(model, mj.mjtObj.mjOBJ_BODY, f"{side}_finger")
        j = mj.mj_name2id(model, mj.mjtObj.mjOBJ_JOINT, f"{side}_finger_joint")
        a = mj.mj_name2id(model, mj.mjtObj.mjOBJ_ACTUATOR, f"{side}_finger_actuator")
        if min(b, j, a) < 0:
            raise SimError(f"{path}: no parallel gripper: needs body '{side}_finger', joint '{side}_finger_joint' "
                           f"and actuator '{side}_finger_actuator'")
        fingers[side] = (b, int(model.jnt_qposadr[j]), int(model.jnt_dofadr[j]), a)
    geoms = np.flatnonzero(model.geom_bodyid == ob)
    geoms = geoms[(model.geom_contype[geoms] != 0) | (model.geom_conaffinity[geoms] != 0)]
    if geoms.size == 0:
        raise SimError(f"{path}: object '{object}' has no collision geoms")
    jnt = [j for j in range(model.njnt) if model.jnt_bodyid[j] == ob]
    free = any(model.jnt_type[j] == mj.mjtJoint.mjJNT_FREE for j in jnt)
    if friction is not None:
        from ..contact.friction import check_mu

        mu = check_mu(friction, "friction coefficient (--friction)")
        tips = [mj.mj_name2id(model, mj.mjtObj.mjOBJ_GEOM, f"{s}_{k}") for s in SIDES for k in ("pin", "pad")]
        model.geom_friction[[g for g in tips if g >= 0] + [int(g) for g in geoms], 0] = mu
    hold = mj.mj_name2id(model, mj.mjtObj.mjOBJ_EQUALITY, f"{object}_hold")
    return Scene(path, model, data, object, ob, geoms, fingers, free, hold if hold >= 0 else None)
