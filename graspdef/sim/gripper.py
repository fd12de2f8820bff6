"""The parallel gripper model: its parameters (force range, fingertip shape, pad size and material)
and its MJCF text, and per-run fingertip changes of a compiled scene.

The robot file ``parallel_gripper_<tip>.xml`` holds only the gripper (mujoco_menagerie's
convention); a scene includes it.  SI units: m, kg, N, s.  The fingers slide along the world x
axis and meet at the origin of the gripper frame; each finger is driven by a force actuator, so
the control IS the squeezing force [N] (what Tian & Jia's BarrettHand strain gauges read).

The force range is a parameter of the model (``GripperModel.force_max``), not a constant of the
code: real parallel grippers exert 70 N (Franka Hand, continuous) to 235 N (Robotiq 2F-85,
maximum) per grasp; :data:`DEFAULT_FORCE_MAX` is the upper end.  A target outside the range is
refused by :func:`graspdef.sim.grasp.check_targets`, never clipped.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..errors import ProblemError

#: fingertip face distance from the grasp centre with the fingers open [m]
OPEN = 0.066
#: finger joint travel [m]: the tips close from OPEN to OPEN - TRAVEL = 6 mm from the centre
TRAVEL = 0.06
#: per-finger force range's upper end of the default model [N] (Robotiq 2F-85 datasheet:
#: grip force 20-235 N; Franka Hand: 70 N continuous, 140 N maximum)
DEFAULT_FORCE_MAX = 235.0
TIPS = ("pin", "pad")


@dataclass(frozen=True)
class PadMaterial:
    """A fingertip material as MuJoCo's contact sees it: Coulomb friction (sliding, torsional [m],
    rolling [m]) and the contact's stiffness [N/m] and damping [N s/m] of the soft constraint
    (MuJoCo's direct solref; about critical, 2 sqrt(stiffness))."""

    name: str
    friction: tuple[float, float, float]
    stiffness: float
    damping: float
    note: str


#: fingertip materials (assumed values: typical Coulomb coefficients, not measurements)
PAD_MATERIALS = {
    "rubber": PadMaterial("rubber", (1.2, 0.005, 0.0001), 1e5, 630.0,
                          "rubber-like pad: friction 1.2, stiffness 1e5 (0.2 mm of penetration at 20 N)"),
    "steel": PadMaterial("steel", (0.8, 0.005, 0.0001), 1e6, 2000.0,
                         "rigid steel: friction 0.8, stiffness 1e6 (0.02 mm of penetration at 20 N)"),
}


@dataclass(frozen=True)
class GripperModel:
    """A two-finger parallel gripper.

    Attributes
    ----------
    tip : {"pin", "pad"}
        Capsule pin (radius 2 mm, point contact) or box pad.
    force_max : float
        Upper end of each finger's force range [N].
    pad_size : float
        Edge of the square pad face [m] (pads only).
    material : str
        Fingertip material, a key of :data:`PAD_MATERIALS` (pin default: steel; pad: rubber).
    """

    tip: str = "pin"
    force_max: float = DEFAULT_FORCE_MAX
    pad_size: float = 0.024
    material: str | None = None

    def __post_init__(self) -> None:
        if self.tip not in TIPS:
            raise ProblemError(f"unknown fingertip {self.tip!r}; accepted: {', '.join(TIPS)}")
        if not (math.isfinite(self.force_max) and self.force_max > 0):
            raise ProblemError(f"gripper force range: the maximum must be a positive number of newtons, "
                               f"got {self.force_max!r}")
        if not (math.isfinite(self.pad_size) and 0.002 <= self.pad_size <= 0.1):
            raise ProblemError(f"pad size must be 2 to 100 mm, got {self.pad_size * 1e3:g} mm")
        if self.material is not None and self.material not in PAD_MATERIALS:
            raise ProblemError(f"unknown fingertip material {self.material!r}; accepted: {', '.join(PAD_MATERIALS)}")

    @property
    def pad_material(self) -> PadMaterial:
        return PAD_MATERIALS[self.material or ("rubber" if self.tip == "pad" else "steel")]

    def with_tip(self, tip: str) -> "GripperModel":
        return replace(self, tip=tip)


def _tip_default(g: GripperModel) -> str:
    m = g.pad_material
    fr = " ".join(f"{v:g}" for v in m.friction)
    if g.tip == "pin":
        return f"""      <default class="fingertip">
        <!-- pin: capsule radius 2 mm (point contact);
             {m.note};
             condim 4: torsional friction stops the object pivoting about the grasp axis; solref
             given directly (negative values) as stiffness and critical damping -->
        <geom type="capsule" size="0.002" condim="4" friction="{fr}"
              solref="-{m.stiffness:g} -{m.damping:g}" solimp="0.99 0.999 0.0005" rgba="0.75 0.75 0.78 1"/>
      </default>"""
    h = g.pad_size / 2
    return f"""      <default class="fingertip">
        <!-- pad {g.pad_size * 1e3:g} x {g.pad_size * 1e3:g} x 4 mm, {m.note} -->
        <geom type="box" size="0.002 {h:g} {h:g}" condim="4" friction="{fr}"
              solref="-{m.stiffness:g} -{m.damping:g}" solimp="0.95 0.99 0.001" rgba="0.12 0.12 0.12 1"/>
      </default>"""


def _tip_geom(side: str, tip: str) -> str:
    s = -1 if side == "left" else 1          # the finger body's x axis points away from the centre
    if tip == "pin":
        # capsule from 8 mm to 2 mm behind the finger origin: its tip surface is at the origin
        return f'<geom name="{side}_pin" class="fingertip" fromto="{s * 0.008:g} 0 0 {s * 0.002:g} 0 0"/>'
    return f'<geom name="{side}_pad" class="fingertip" pos="{s * 0.002:g} 0 0"/>'


def gripper_xml(g: GripperModel = GripperModel(), generator: str = "graspdef.sim.gripper") -> str:
    """The MJCF text of the robot file ``parallel_gripper_<tip>.xml`` for model ``g``."""
    fingers = []
    for side, s in (("left", -1), ("right", 1)):
        fingers.append(f"""      <body name="{side}_finger" pos="{s * OPEN:g} 0 0">
        <!-- closing direction: towards the centre -->
        <joint name="{side}_finger_joint" class="finger" axis="{-s} 0 0"/>
        <inertial pos="{s * 0.006:g} 0 0.04" mass="0.1" diaginertia="1e-4 1e-4 1e-5"/>
        <geom name="{side}_finger_link" class="visual" type="box" size="0.003 0.008 0.045"
              pos="{s * 0.011:g} 0 0.045"/>
        <geom name="{side}_finger_link_collision" class="collision" type="box" size="0.003 0.008 0.045"
              pos="{s * 0.011:g} 0 0.045"/>
        {_tip_geom(side, g.tip)}
      </body>""")
    return f"""<!-- Two-finger parallel gripper with {g.tip} fingertips (robot only; generated by
     {generator}).  SI units: m, kg, N, s.  The fingers slide along the world x axis
     and meet at the origin of the gripper frame; each finger is driven by a force actuator, so
     the control IS the squeezing force [N] (what Tian & Jia's BarrettHand strain gauges read). -->
<mujoco model="parallel_gripper_{g.tip}">
  <default>
    <default class="parallel_gripper">
      <default class="finger">
        <!-- slide joint: damping 20 N s/m closes at 5 cm/s under 1 N; travel 0..{TRAVEL * 1e3:g} mm -->
        <joint type="slide" damping="20" armature="0.01" limited="true" range="0 {TRAVEL:g}"/>
        <!-- ctrl = squeezing force [N] per finger; range 0..{g.force_max:g} N, a parameter of the
             gripper model (real parallel grippers: 70 N continuous to 235 N maximum) -->
        <motor ctrllimited="true" ctrlrange="0 {g.force_max:g}" gear="1"/>
      </default>
      <default class="visual">
        <geom group="2" contype="0" conaffinity="0" rgba="0.35 0.35 0.4 1"/>
      </default>
      <default class="collision">
        <!-- the finger links never touch the object in these scenes; kept for completeness -->
        <geom group="3" contype="0" conaffinity="0"/>
      </default>
{_tip_default(g)}
    </default>
  </default>

  <worldbody>
    <body name="gripper" childclass="parallel_gripper" pos="0 0 0">
      <geom name="gripper_palm" class="visual" type="box" size="0.09 0.012 0.006" pos="0 0 0.096"/>
{chr(10).join(fingers)}
    </body>
  </worldbody>

  <actuator>
    <motor name="left_finger_actuator" class="finger" joint="left_finger_joint"/>
    <motor name="right_finger_actuator" class="finger" joint="right_finger_joint"/>
  </actuator>
</mujoco>
"""


@dataclass(frozen=True)
class FingertipChange:
    """Per-run changes of a scene's fingertips: pad edge [m] (pads only) and material."""

    pad_size: float | None = None
    material: str | None = None

    def __post_init__(self) -> None:
        if self.pad_size is not None and not (math.isfinite(self.pad_size) and 0.002 <= self.pad_size <= 0.1):
            raise ProblemError(f"pad size must be 2 to 100 mm, got {self.pad_size * 1e3:g} mm")
        if self.material is not None and self.material not in PAD_MATERIALS:
            raise ProblemError(f"unknown fingertip material {self.material!r}; accepted: {', '.join(PAD_MATERIALS)}")

    @property
    def empty(self) -> bool:
        return self.pad_size is None and self.material is None

    def apply(self, spec, path) -> None:
        """Edit the fingertip geoms of an ``mujoco.MjSpec`` in place (``path``: for messages)."""
        from .scene import SIDES, SimError

        for side in SIDES:
            pin, pad = spec.geom(f"{side}_pin"), spec.geom(f"{side}_pad")
            geom = pad if pad is not None else pin
            if geom is None:
                raise SimError(f"{path}: no fingertip geom '{side}_pin' or '{side}_pad'")
            if self.pad_size is not None:
                if pad is None:
                    raise SimError(f"{path}: a pad size is for pad fingertips; this scene has pins "
                                   "(use --fingertips pad)")
                geom.size = [geom.size[0], self.pad_size / 2, self.pad_size / 2]
            if self.material is not None:
                m = PAD_MATERIALS[self.material]
                geom.friction = list(m.friction)
                geom.solref = [-m.stiffness, -m.damping]
