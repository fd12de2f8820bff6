"""Registration of scans to predicted surfaces (open3d ICP, imported lazily) and scores against
them, with the undeformed shape as the baseline."""

from graspdef.registration.icp import (
    Registration,
    RegistrationError,
    apply,
    check_units,
    register,
    rotation_angle,
)
from graspdef.registration.score import SurfaceScore, score, score_cli, score_surface

__all__ = ["Registration", "RegistrationError", "SurfaceScore", "apply", "check_units",
           "register", "rotation_angle", "score", "score_cli", "score_surface"]
