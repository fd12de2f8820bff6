"""Where to grasp: a linear screen of many antipodal grasp candidates on an object's shell.

One factorisation of the free shell's stiffness at rest (rigid modes removed by orthogonality,
exact for the self-equilibrated pair of finger forces), then one back-substitution per candidate:
the finger at ``first`` pushes +F d, the one at ``second`` -F d (d the unit chord from first to
second).  With b = (load vector of the unit pair), u = F K^-1 b and, per candidate,

* closing displacement delta = b.u = F b^T K^-1 b (the two contact points' approach [m]),
  indentation per finger delta / 2, grasp stiffness F / delta [N/m];
* work spent deforming the object to reach F: W = F delta / 2 = u^T K u / 2 [J] (linear: the
  strain energy) -- the minimal-work metric of Xu et al. for hollow deformable objects;
* max displacement over the limit surface [m];
* the rigid-object baseline: the friction margin atan(mu) - (antipodal angle) [deg] and the
  weight's torque about the grasp line against the torsional friction of the two contacts.

Candidates come from :func:`graspdef.objects.placement.antipodal_candidates`.  SI throughout.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..objects.placement import Grasp
from ..problem.loads import PointLoad, load_vector
from ..problem.problem import Problem
from ..problem.supports import RigidModes
from ..solve.linear import rest_stiffness
from ..solve.sparse import KKTSystem
from ..subdivision.rules import limit_matrix

#: torsional friction of a fingertip contact [m] (MuJoCo condim 4: torque = this x normal force;
#: the scenes' 0.005)
TORSIONAL_FRICTION = 0.005
G = 9.81


@dataclass(frozen=True)
class Screened:
    """One candidate's linear-screen figures (SI)."""

    index: int
    grasp: Grasp
    closing_m: float
    work_J: float
    stiffness_N_per_m: float
    max_displacement_m: float
    friction_margin_deg: float
    torque_ratio: float

    def row(self) -> dict:
        g = self.grasp
        return {"candidate": self.index, "first_x_m": g.first[0], "first_y_m": g.first[1], "first_z_m": g.first[2],
                "second_x_m": g.second[0], "second_y_m": g.second[1], "second_z_m": g.second[2],
                "width_m": g.width, "antipodal_angle_deg": g.angle_deg, "indentation_per_finger_m": self.closing_m / 2,
                "work_J": self.work_J, "grasp_stiffness_N_per_m": self.stiffness_N_per_m,
                "max_displacement_m": self.max_displacement_m, "friction_margin_deg": self.friction_margin_deg,
                "weight_torque_ratio": self.torque_ratio}


class LinearScreen:
    """The free shell's stiffness at rest, factorised once; :meth:`evaluate` a candidate per
    back-substitution."""

    def __init__(self, shell, backend: str = "auto"):
        self.shell = shell
        self.problem = Problem(shell, [], [RigidModes()])
        C, _, _ = self.problem.constraints(with_targets=True)
        self.kkt = KKTSystem(C, backend)
        t = time.perf_counter()
        self.kkt.factor(rest_stiffness(self.problem))
        self.seconds_factor = time.perf_counter() - t
        mesh = shell.mesh
        self.L = limit_matrix(mesh.faces, mesh.n_control, np.arange(mesh.n_real))
        self.tol = 2.0 * shell.thickness + 0.5 * float(np.linalg.norm(
            shell.rest_positions[mesh.faces[:, 1]] - shell.rest_positions[mesh.faces[:, 0]], axis=1).mean())

    def unit_pair(self, g: Grasp) -> np.ndarray:
        """The load vector of the unit finger pair of ``g`` on the mid-surface (the contacts on the
        outer surface projected onto it)."""
        p = self.problem.locate(g.first, "first contact", tol=self.tol)
        q = self.problem.locate(g.second, "second contact", tol=self.tol)
        d = tuple(float(c) for c in g.axis)
        return load_vector(self.shell, [PointLoad(p.face, p.bary, d), PointLoad(q.face, q.bary, tuple(-c for c in d))],
                           self.problem.evaluator)

    def evaluate(self, index: int, g: Grasp, force: float, friction: float, mass: float,
                 centre_of_mass) -> Screened:
        b = self.unit_pair(g)
        u, _, _ = self.kkt.solve(force * b)
        closing = float(b @ u)                        # = F b^T K^-1 b
        ul = self.L @ u.reshape(-1, 3)
        off = float(np.linalg.norm(np.cross(np.asarray(centre_of_mass) - g.first, g.axis)))
        torque_ratio = mass * G * off / (2.0 * TORSIONAL_FRICTION * force)
        return Screened(index, g, closing, 0.5 * force * closing, force / closing if closing > 0 else math.inf,
                        float(np.linalg.norm(ul, axis=1).max()), math.degrees(math.atan(friction)) - g.angle_deg,
                        torque_ratio)

    def close(self) -> None:
        self.kkt.close()


def rank(rows: list[Screened]) -> list[Screened]:
    """Held candidates (friction margin > 0, weight's torque below the contacts' torsional friction)
    first, by least work; then the others, by least work."""
    return sorted(rows, key=lambda r: (not (r.friction_margin_deg > 0 and r.torque_ratio < 1.0), r.work_J, r.index))
