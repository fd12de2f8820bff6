"""graspdef: robot-grasp deformation simulator.

Kirchhoff-Love thin shells on Loop-subdivision limit surfaces (Cirak, Ortiz & Schroeder 2000), as
used by Tian & Jia (2010) for shells grasped by a robot hand.  SI units inside.

>>> import graspdef as gd
>>> mesh = gd.geometry.icosphere(radius=0.0325, subdivisions=3)
>>> shell = gd.Shell(mesh.vertices, mesh.faces, gd.LinearElastic(E=1e6, nu=0.45), thickness=2.5e-3)
>>> problem = gd.Problem(shell, loads=[gd.Pressure(1e3)], supports=[gd.RigidModes()])
>>> sol = gd.solve_linear(problem)
>>> round(sol.max_displacement() * 1e6, 1)   # um; membrane theory p R^2 (1-nu)/(2 E t): 116.2 (R/t = 13)
116.6
"""
import os as _os

# Two OpenMP runtimes share the cores: numba's kernels (GNU OpenMP) and MKL PARDISO (Intel
# OpenMP).  By default each one's idle threads spin after a parallel region and take the cores
# from the other (the 10k-vertex sphere path: 32.2 -> 24.9 s with passive waiting).  Set before
# either runtime starts; a value the user has set is kept.
_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from . import geometry as geometry  # noqa: E402
from .errors import GraspdefError as GraspdefError
from .errors import MeshError as MeshError
from .errors import ProblemError as ProblemError
from .errors import SolverError as SolverError
from .errors import SupportError as SupportError
from .problem.config import load_problem as load_problem
from .problem.loads import BodyForce as BodyForce
from .problem.loads import PointLoad as PointLoad
from .problem.loads import Pressure as Pressure
from .problem.problem import Problem as Problem
from .problem.problem import SurfacePoint as SurfacePoint
from .problem.supports import EdgeSupport as EdgeSupport
from .problem.supports import PointSupport as PointSupport
from .problem.supports import RigidModes as RigidModes
from .shell.energy import ShellEnergy as ShellEnergy
from .shell.materials import LinearElastic as LinearElastic
from .shell.model import Shell as Shell
from .solve.linear import LinearSolution as LinearSolution
from .solve.linear import solve_linear as solve_linear

__version__ = "0.1.0"


def __getattr__(name: str):
    if name == "view":                      # the viewer pulls in viser: import it on first use
        from .viewer import view

        return view
    raise AttributeError(f"module 'graspdef' has no attribute {name!r}")
