"""Force-controlled closing of the parallel gripper, settling, and contact extraction.

The procedure (``grasp``):

1. reset with gravity switched off (the object floats where the scene put it; an optional
   equality ``<object>_hold``, a weld to the world, also holds it);
2. approach: each active finger is pushed with ``approach_force`` until it touches the object;
3. ramp: the actuator forces rise linearly to their targets;
4. ramp gravity back in over ``gravity_time`` (a free object is then held by the fingers
   only), release any hold, and settle until the fingers and the object are at rest;
5. extract every finger-object contact with ``mj_contactForce`` (world-frame point, normal,
   force on the object, normal and friction components) and sum per finger.

With force actuators on frictionless slide joints the static balance of each finger is
actuator force = contact force along the closing axis, so the measured normal force equals
the target once the finger is at rest (checked: SimError beyond ``force_rtol_error``).
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np

from ..contact.records import ContactSet, Pose
from .scene import SIDES, Scene, SimError, check_warnings, load_scene, mujoco

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class GraspSettings:
    """Times [s], forces [N] and tolerances of the closing procedure."""

    approach_force: float = 2.0
    approach_time: float = 3.0
    dwell_time: float = 0.1           # at the approach force after first contact (impact dies out)
    ramp_time: float = 0.2
    hold_time: float = 0.1
    gravity_time: float = 0.2
    settle_time: float = 0.3
    max_settle_time: float = 3.0
    velocity_tol: float = 2e-4        # m/s: finger and object speeds counted as "at rest"
    force_rtol_error: float = 0.05    # measured normal force vs target beyond this: SimError


@dataclass
class GraspResult:
    """The settled grasp: contacts (world frame), per-finger sums, the object's pose, the
    fingertip gap and the convergence record."""

    scene: str
    object: str
    targets: dict
    contacts: ContactSet
    pose: Pose
    tip_gap: float
    sim_time: float
    wall_time: float
    settled: bool
    max_speed: float
    object_mass: float
    gravity: np.ndarray
    info: dict = field(default_factory=dict)

    def per_finger(self) -> dict:
        return self.contacts.per_finger()

    def force_errors(self) -> dict:
        pf = self.per_finger()
        return {s: (pf[s]["normal_force"] - t) / t for s, t in self.targets.items() if t > 0 and s in pf}

    def record(self) -> dict:
        pf = self.per_finger()
        return {
            "scene": self.scene, "object": self.object, "targets_N": self.targets,
            "per_finger": {s: {"n_contacts": v["n_contacts"], "normal_force_N": v["normal_force"],
                               "friction_force_N": v["friction_force"], "force_N": v["force"].tolist(),
                               "point_m": v["point"].tolist(), "normal": v["normal"].tolist(),
                               "friction_coefficient": v.get("friction_coefficient")}
                           for s, v in pf.items()},
            "force_relative_error": self.force_errors(),
            "net_contact_force_N": self.contacts.net_force().tolist(),
            "object_weight_N": (self.object_mass * self.gravity).tolist(),
            "object_pose": self.pose.record(), "tip_gap_m": self.tip_gap,
            "sim_time_s": self.sim_time, "wall_time_s": self.wall_time, "settled": self.settled,
            "max_speed_m_per_s": self.max_speed, **self.info,
        }


def _contacts(sc: Scene, active: dict) -> ContactSet:
    mj = mujoco()
    m, d = sc.model, sc.data
    obj = set(int(g) for g in sc.object_geoms)
    pos, nrm, frc, trq, fn, ft, fing, geoms, mu = [], [], [], [], [], [], [], [], []
    f6 = np.zeros(6)
    for i in range(d.ncon):
        c = d.contact[i]
        g1, g2 = int(c.geom1), int(c.geom2)
        if g2 in obj:
            other, sign = g1, 1.0       # force of geom1 on geom2 = +frame^T f
        elif g1 in obj:
            other, sign = g2, -1.0
        else:
            continue
        side = sc.finger_body_of_geom(other)
        if side is None:
            continue
        mj.mj_contactForce(m, d, i, f6)
        if c.dist > 0 and f6[0] <= 0:      # found within the margin, not touching (gap)
            continue
        frame = np.asarray(c.frame).reshape(3, 3)
        pos.append(np.asarray(c.pos).copy())
        nrm.append(sign * frame[0])
        frc.append(sign * (frame.T @ f6[:3]))
        # condim 4/6: torsional (and rolling) friction torques in the contact frame
        trq.append(sign * (frame.T @ f6[3:6]) if c.dim >= 4 else np.zeros(3))
        fn.append(f6[0])
        ft.append(float(np.hypot(f6[1], f6[2])))
        fing.append(side)
        mu.append(float(c.friction[0]))          # the contact's sliding friction (MuJoCo's geom mix)
        geoms.append((m.geom(other).name, m.geom(g2 if sign > 0 else g1).name))
    if not fing:
        return ContactSet(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0), ())
    return ContactSet(np.array(pos), np.array(nrm), np.array(frc), np.array(fn), np.array(ft), tuple(fing),
                      tuple(geoms), np.array(trq), np.array(mu))


def _fingertip(sc: Scene, side: str, body: int, axis: np.ndarray) -> dict:
    """The fingertip geom of ``side`` at the current state (world frame): MuJoCo type name,
    size, position, rotation (columns = geom axes) and the finger's closing axis (unit)."""
    mj = mujoco()
    m, d = sc.model, sc.data
    for name in (f"{side}_pin", f"{side}_pad"):
        gid = mj.mj_name2id(m, mj.mjtObj.mjOBJ_GEOM, name)
        if gid >= 0:
            break
    else:
        raise SimError(f"{sc.path}: no fingertip geom '{side}_pin' or '{side}_pad'")
    return {"geom": name, "type": mj.mjtGeom(int(m.geom_type[gid])).name.removeprefix("mjGEOM_").lower(),
            "size": m.geom_size[gid].tolist(), "friction": m.geom_friction[gid].tolist(),
            "solref": m.geom_solref[gid].tolist(), "position": d.geom_xpos[gid].tolist(),
            "rotation": d.geom_xmat[gid].reshape(3, 3).tolist(), "axis": (axis / np.linalg.norm(axis)).tolist()}


def _speed(sc: Scene) -> float:
    d, m = sc.data, sc.model
    v = [abs(d.qvel[sc.fingers[s][2]]) for s in SIDES]
    if sc.free:
        j = [j for j in range(m.njnt) if m.jnt_bodyid[j] == sc.object_body][0]
        a = int(m.jnt_dofadr[j])
        v.append(float(np.linalg.norm(d.qvel[a:a + 3])))
    return float(max(v))


def force_range(sc: Scene) -> dict:
    """Per finger, the squeezing force range [N] of the gripper model (its actuator's control
    range times its gear; unlimited: (-inf, inf))."""
    m = sc.model
    out = {}
    for s in SIDES:
        a = sc.fingers[s][3]
        lo, hi = (m.actuator_ctrlrange[a] if m.actuator_ctrllimited[a] else (-np.inf, np.inf))
        out[s] = (lo * m.actuator_gear[a, 0], hi * m.actuator_gear[a, 0])
    return out


def check_targets(sc: Scene, targets: dict) -> None:
    """Refuse a target force that is not a non-negative number or lies outside the gripper's
    force range (a clear error, never a silent clip)."""
    rng = force_range(sc)
    for s, f in targets.items():
        lo, hi = rng[s]
        if not np.isfinite(f) or f < 0:
            raise SimError(f"{s} finger: target force must be a non-negative number [N], got {f!r}")
        if f > hi or f < lo:
            raise SimError(f"{s} finger: target force {f:g} N is beyond what the gripper can exert "
                           f"({lo:g}..{hi:g} N, its actuator's range in the scene)")


def grasp(scene, force: float | dict, object: str, settings: GraspSettings = GraspSettings(),
          fingertips=None, friction: float | None = None) -> GraspResult:
    """Close the gripper of ``scene`` (a path or a :class:`Scene`) on body ``object`` until each
    finger presses with its target force [N], settle and extract the contacts.

    ``force``: one number (both fingers) or {"left": F_l, "right": F_r} (0 = finger stays open;
    e.g. a one-finger poke).  ``fingertips``: a per-run
    :class:`graspdef.sim.gripper.FingertipChange` (pad size, material).  ``friction``: the sliding
    friction coefficient of fingertips and object for this run (graspdef.sim.scene.load_scene;
    None: the scene's).

    Raises SimError: missing gripper/object, a target outside the actuators' range, no contact
    after closing, MuJoCo warnings, or a settled force off its target by more than
    ``settings.force_rtol_error``."""
    mj = mujoco()
    t_wall = time.perf_counter()
    sc = scene if isinstance(scene, Scene) else load_scene(scene, object, fingertips, friction)
    m, d = sc.model, sc.data
    targets = {s: float(force) for s in SIDES} if np.isscalar(force) else {s: float(force.get(s, 0.0)) for s in SIDES}
    check_targets(sc, targets)
    active = [s for s in SIDES if targets[s] > 0]
    if not active:
        raise SimError("no finger has a positive target force")
    mj.mj_resetData(m, d)
    gravity = np.asarray(m.opt.gravity).copy()
    m.opt.gravity[:] = 0.0
    if sc.hold is not None:
        d.eq_active[sc.hold] = 1
    dt = m.opt.timestep
    chunk = max(1, int(round(0.005 / dt)))          # 5 ms between checks

    def touching() -> set:
        return set(_contacts(sc, active).finger)

    def set_ctrl(scale: dict) -> None:
        for s in SIDES:
            d.ctrl[sc.fingers[s][3]] = scale[s] / m.actuator_gear[sc.fingers[s][3], 0]

    # 2. approach
    set_ctrl({s: min(settings.approach_force, targets[s]) for s in SIDES})
    while not set(active) <= touching():
        if d.time > settings.approach_time:
            missing = sorted(set(active) - touching())
            raise SimError(f"{sc.path}: no contact after closing: the {' and '.join(missing)} finger(s) did not touch "
                           f"'{object}' within {settings.approach_time:g} s (object out of reach or too small)")
        mj.mj_step(m, d, nstep=chunk)
    t_contact = float(d.time)
    mj.mj_step(m, d, nstep=max(1, int(round(settings.dwell_time / dt))))
    # 3. ramp
    n_ramp = max(1, int(round(settings.ramp_time / (chunk * dt))))
    for k in range(1, n_ramp + 1):
        lam = k / n_ramp
        set_ctrl({s: (1 - lam) * min(settings.approach_force, targets[s]) + lam * targets[s] for s in SIDES})
        mj.mj_step(m, d, nstep=chunk)
    mj.mj_step(m, d, nstep=max(1, int(round(settings.hold_time / dt))))
    # 4. gravity in, release and settle
    n_g = max(1, int(round(settings.gravity_time / (chunk * dt))))
    for k in range(1, n_g + 1):
        m.opt.gravity[:] = gravity * k / n_g
        mj.mj_step(m, d, nstep=chunk)
    if sc.hold is not None:
        d.eq_active[sc.hold] = 0
    t_release = float(d.time)
    still, settled, speed = 0.0, False, np.inf
    while d.time - t_release < settings.max_settle_time:
        mj.mj_step(m, d, nstep=chunk)
        speed = _speed(sc)
        still = still + chunk * dt if speed < settings.velocity_tol else 0.0
        if d.time - t_release >= settings.settle_time and still >= 0.05:
            settled = True
            break
    check_warnings(m, d, str(sc.path))
    mj.mj_forward(m, d)
    cs = _contacts(sc, active)
    missing = set(active) - set(cs.finger)
    if missing:
        raise SimError(f"{sc.path}: no contact after settling for the {' and '.join(sorted(missing))} finger(s): "
                       f"'{object}' slipped out of the grasp")
    pf = cs.per_finger()
    axial = {}
    tips = {}
    for s in active:
        # the closing axis of the finger in the world (its slide joint's axis)
        b, _qa, da, _a = sc.fingers[s]
        j = [jj for jj in range(m.njnt) if m.jnt_bodyid[jj] == b][0]
        axis = d.xmat[b].reshape(3, 3) @ m.jnt_axis[j]
        axial[s] = float(pf[s]["force"] @ axis)
        tips[s] = _fingertip(sc, s, b, axis)
        err = (axial[s] - targets[s]) / targets[s]
        if abs(err) > settings.force_rtol_error:
            raise SimError(f"{sc.path}: {s} finger presses {axial[s]:.4g} N along its axis, target {targets[s]:.4g} N "
                           f"({100 * err:+.1f} %): the actuator cannot reach the target (joint limit?)")
    mass = float(m.body_subtreemass[sc.object_body])
    res = GraspResult(str(sc.path), object, targets, cs, sc.body_pose(), sc.tip_gap(), float(d.time),
                      time.perf_counter() - t_wall, settled, float(speed), mass, gravity,
                      {"axial_force_N": axial, "t_contact_s": t_contact, "t_release_s": t_release, "timestep_s": float(dt),
                       "free_object": sc.free, "fingertips": tips})
    if not settled:
        log.warning("%s: not settled after %.2f s (max speed %.2e m/s)", sc.path, settings.max_settle_time, speed)
    return res
