"""The grasp chain: MuJoCo scene -> settled contacts -> point loads on the shell -> linear or
nonlinear shell solve -> run folder (graspdef.pipeline.grasp)."""
from .grasp import GraspRun as GraspRun
from .grasp import ShellSpec as ShellSpec
from .grasp import grasp_cli as grasp_cli
from .grasp import load_shell_spec as load_shell_spec
from .grasp import run_grasp as run_grasp

__all__ = ["GraspRun", "ShellSpec", "grasp_cli", "load_shell_spec", "run_grasp"]
