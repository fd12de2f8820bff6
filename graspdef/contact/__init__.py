"""Contact between the gripper and the shell: contact records (world frame) and their mapping onto
the shell as point loads that keep the total force and moment exactly (graspdef.contact.mapping),
or the fingertips as rigid, force-controlled, penetration-free obstacles (graspdef.contact.barrier)
with Coulomb friction on the shell (graspdef.contact.friction).
Never imports mujoco (graspdef.sim produces the records)."""
from .obstacles import Capsule as Capsule
from .barrier import FingerContact as FingerContact
from .friction import FingerFriction as FingerFriction
from .obstacles import RoundedBox as RoundedBox
from .mapping import LoadMapping as LoadMapping
from .mapping import map_contacts as map_contacts
from .records import ContactSet as ContactSet
from .records import Pose as Pose

__all__ = ["Capsule", "FingerContact", "FingerFriction", "RoundedBox", "ContactSet", "LoadMapping", "Pose", "map_contacts"]
