"""graspdef: robot-grasp deformation simulator.

Kirchhoff-Love thin shells on Loop-subdivision limit surfaces (Cirak, Ortiz & Schroeder 2000), as
used by Tian & Jia (2010) for shells grasped by a robot hand.  SI units inside.

Importing graspdef is cheap and changes nothing in the process: the names below load on first
use (PEP 562), and process set-up for speed is explicit (:func:`graspdef.runtime.configure`).

>>> import graspdef as gd
>>> mesh = gd.geometry.icosphere(radius=0.0325, subdivisions=3)
>>> shell = gd.Shell(mesh.vertices, mesh.faces, gd.LinearElastic(E=1e6, nu=0.45), thickness=2.5e-3)
>>> problem = gd.Problem(shell, loads=[gd.Pressure(1e3)], supports=[gd.RigidModes()])
>>> sol = gd.solve_linear(problem)
>>> round(sol.max_displacement() * 1e6, 1)   # um; membrane theory p R^2 (1-nu)/(2 E t): 116.2 (R/t = 13)
116.6
"""
from __future__ import annotations

import importlib

from .errors import GraspdefError as GraspdefError
from .errors import MeshError as MeshError
from .errors import ProblemError as ProblemError
from .errors import SolverError as SolverError
from .errors import SupportError as SupportError

__version__ = "0.1.0"

#: public name -> the module that defines it (imported on first use)
_LAZY = {
    "load_problem": "graspdef.problem.config",
    "BodyForce": "graspdef.problem.loads",
    "PointLoad": "graspdef.problem.loads",
    "Pressure": "graspdef.problem.loads",
    "Problem": "graspdef.problem.problem",
    "SurfacePoint": "graspdef.problem.problem",
    "EdgeSupport": "graspdef.problem.supports",
    "PointSupport": "graspdef.problem.supports",
    "RigidModes": "graspdef.problem.supports",
    "ShellEnergy": "graspdef.shell.energy",
    "LinearElastic": "graspdef.shell.materials",
    "Shell": "graspdef.shell.model",
    "LinearSolution": "graspdef.solve.linear",
    "solve_linear": "graspdef.solve.linear",
    "view": "graspdef.viewer",
}
#: the rooms (ARCHITECTURE.md) reachable as ``graspdef.<room>``, imported on first use (not cli, testing)
_SUBPACKAGES = {"units", "runtime", "compiled", "config", "geometry", "runs", "subdivision", "shell", "axisym", "problem", "solve",
                "contact", "sim", "scans", "registration", "objects", "viewer", "report", "pipeline", "ranking",
                "fit", "sweep", "bench"}

__all__ = sorted(["GraspdefError", "MeshError", "ProblemError", "SolverError", "SupportError", *_LAZY])


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    if name in _SUBPACKAGES:
        return importlib.import_module(f"graspdef.{name}")
    raise AttributeError(f"module 'graspdef' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__) | _SUBPACKAGES)
