"""Where to grasp an object: antipodal candidates screened by the linear shell
(:mod:`graspdef.ranking.screen`) and ranked (:func:`rank_object`)."""
from .run import rank_object

__all__ = ["rank_object"]
