"""Contact between the gripper and the shell: contact records (world frame) and their mapping onto
the shell as point loads that keep the total force and moment exactly (graspdef.contact.mapping).
Never imports mujoco (graspdef.sim produces the records)."""
from .mapping import LoadMapping as LoadMapping
from .mapping import map_contacts as map_contacts
from .records import ContactSet as ContactSet
from .records import Pose as Pose

__all__ = ["ContactSet", "LoadMapping", "Pose", "map_contacts"]
