"""An object's data (``scenes/<scene>/object.toml``: scan, thickness, material law with E and nu,
enclosed gas with its source, fingers, supports), read and checked (:mod:`graspdef.objects.data`),
and its shell (:func:`build_shell`)."""
from .build import build_shell
from .data import LAWS, OBJECT_FILE, SCENES, GasSpec, MaterialSpec, ObjectSpec, load_object, read_object, scene_xml

__all__ = ["LAWS", "OBJECT_FILE", "SCENES", "GasSpec", "MaterialSpec", "ObjectSpec", "build_shell", "load_object",
           "read_object", "scene_xml"]
