"""The grasp chain: MuJoCo scene -> settled contacts -> point loads on the shell -> linear or
nonlinear shell solve -> run folder (graspdef.pipeline.grasp).

Importing this package is cheap; the chain itself loads on first use (PEP 562)."""
from __future__ import annotations

__all__ = ["GraspRun", "run_grasp"]


def __getattr__(name: str):
    if name in __all__:
        from . import grasp

        return getattr(grasp, name)
    raise AttributeError(f"module 'graspdef.pipeline' has no attribute {name!r}")
