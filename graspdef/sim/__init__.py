"""MuJoCo bridge: load a grasp scene, close the force-controlled gripper, let it settle and
extract the contacts (graspdef.contact.ContactSet).  mujoco is imported lazily, only here."""
from .grasp import GraspResult as GraspResult
from .grasp import GraspSettings as GraspSettings
from .grasp import grasp as grasp
from .scene import Scene as Scene
from .scene import SimError as SimError
from .scene import load_scene as load_scene

__all__ = ["GraspResult", "GraspSettings", "Scene", "SimError", "grasp", "load_scene"]
