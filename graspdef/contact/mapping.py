"""Contacts -> point loads on the shell's limit surface, keeping the total force and moment.

A rigid-body contact reports a point p on the *outer* surface of the (rigid) proxy and a force F;
the shell is the *mid*-surface, t/2 inside, and its limit surface differs from the proxy by the
discretisation.  Moving F to the nearest limit point q changes the moment by (q - p) x F, which
is not zero in general (q - p is along the surface normal, F is not when there is friction, and
the proxy and the shell are different surfaces).  A force may slide along its own line of action
without changing its moment, so each force is applied where its line of action p + s F/|F|
pierces the limit surface (a fixed-point iteration of "project onto the surface, then back onto
the line", exact in one step when F is normal to the surface).  What remains -- the
projection's tolerance, a line that misses the surface -- is removed by the smallest
(least-squares) set of force corrections dF_i at the load points with sum dF_i = 0 and
sum x_i x dF_i = the moment defect; the corrections and the final defects are reported
(round-off in the tests).  Contact torques (MuJoCo's torsional friction, condim 4) cannot be
carried by forces at two points (a torque about the line through them); so each contact with a
torque gets two auxiliary load points on the surface 3 mm to either side of it, with zero force
before the correction, and the correction puts the couple there.  Point loads then enter the shell through the basis values N_i at the
load point, which preserve force and moment exactly (graspdef.problem.loads).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ProblemError
from ..problem.loads import PointLoad
from ..problem.problem import SurfacePoint, locate
from .records import ContactSet


@dataclass
class LoadMapping:
    """The point loads and the bookkeeping of the mapping (object frame, SI).

    Shapes: points, forces, contact_points (n, 3); distances, line_shift (n,)."""

    loads: list
    surface_points: list
    points: np.ndarray
    forces: np.ndarray
    contact_points: np.ndarray
    finger: tuple
    distances: np.ndarray
    line_shift: np.ndarray
    correction: np.ndarray
    force_in: np.ndarray
    moment_in: np.ndarray
    force_out: np.ndarray
    moment_out: np.ndarray

    def record(self) -> dict:
        return {
            "n_loads": len(self.loads),
            "net_force_N": self.force_in.tolist(),
            "net_moment_Nm": self.moment_in.tolist(),
            "force_defect_N": (self.force_out - self.force_in).tolist(),
            "moment_defect_Nm": (self.moment_out - self.moment_in).tolist(),
            "max_contact_to_surface_m": float(self.distances.max(initial=0.0)),
            "max_line_shift_m": float(np.abs(self.line_shift).max(initial=0.0)),
            "max_force_correction_N": float(np.linalg.norm(self.correction, axis=1).max(initial=0.0)),
        }


def _line_surface(shell, ev, p, d, tol, iters=30):
    """The point where the line p + s d meets the limit surface (fixed point of
    project-then-back-onto-the-line), or the nearest point if it does not converge."""
    x0 = shell.rest_positions
    s = 0.0
    sp, dist = locate(shell, ev, p, "contact", tol)
    for _ in range(iters):
        q = ev.point(x0, sp.face, np.asarray(sp.bary))
        s_new = float((q - p) @ d)
        # 1e-10 m off the line: the least-squares correction in map_contacts removes the rest
        if abs(s_new - s) < 1e-11 and np.linalg.norm(q - (p + s_new * d)) < 1e-10:
            return sp, s_new, dist
        s = s_new
        sp, _ = locate(shell, ev, p + s * d, "contact", tol, n_candidates=3)
    return locate(shell, ev, p, "contact", tol)[0], 0.0, dist


def _skew(x):
    return np.array([[0, -x[2], x[1]], [x[2], 0, -x[0]], [-x[1], x[0], 0]])


def map_contacts(shell, contacts: ContactSet, tol: float = 5e-3, about=(0.0, 0.0, 0.0),
                 evaluator=None, couple_arm: float = 3e-3) -> LoadMapping:
    """Point loads on ``shell`` equivalent to ``contacts`` (object frame, same as the shell's).

    Parameters
    ----------
    shell : Shell
    contacts : ContactSet in the shell's frame (``ContactSet.transformed(pose)``)
    tol : [m] largest allowed distance from a contact point to the limit surface (a contact
        farther away means the proxy and the shell disagree): ProblemError
    about : reference point of the reported moments
    couple_arm : [m] distance of the auxiliary points that carry contact torques

    Returns
    -------
    LoadMapping with ``loads`` (list of PointLoad) and the force/moment bookkeeping."""
    if len(contacts) == 0:
        raise ProblemError("no contacts to map onto the shell")
    ev = shell.evaluator if evaluator is None else evaluator
    x0 = shell.rest_positions
    c = np.asarray(about, float)
    sps, pts, dists, shifts = [], [], [], []
    for i in range(len(contacts)):
        p, F = contacts.positions[i], contacts.forces[i]
        nF = np.linalg.norm(F)
        if nF > 0:
            sp, s, dist = _line_surface(shell, ev, p, F / nF, tol)
        else:
            (sp, dist), s = locate(shell, ev, p, "contact", tol), 0.0
        sps.append(sp)
        pts.append(ev.point(x0, sp.face, np.asarray(sp.bary)))
        dists.append(dist)
        shifts.append(s)
    F = np.array(contacts.forces, float)
    fingers = list(contacts.finger)
    if contacts.torques is not None:
        for i in np.flatnonzero(np.linalg.norm(contacts.torques, axis=1) > 0):
            n = np.asarray(contacts.normals[i], float)
            a = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
            a *= couple_arm / np.linalg.norm(a)
            for sgn in (1, -1):
                sp, dist = locate(shell, ev, contacts.positions[i] + sgn * a, "contact couple point", tol)
                sps.append(sp)
                pts.append(ev.point(x0, sp.face, np.asarray(sp.bary)))
                dists.append(dist)
                shifts.append(0.0)
                fingers.append(contacts.finger[i])
                F = np.vstack([F, np.zeros(3)])
    X = np.array(pts)
    f_in = F.sum(axis=0)
    m_in = contacts.net_moment(c)
    # smallest corrections restoring force and moment (6 equations, 3n unknowns)
    A = np.zeros((6, 3 * len(X)))
    for i, x in enumerate(X):
        A[:3, 3 * i:3 * i + 3] = np.eye(3)
        A[3:, 3 * i:3 * i + 3] = _skew(x - c)
    b = np.r_[f_in - F.sum(axis=0), m_in - np.cross(X - c, F).sum(axis=0)]
    dF = np.linalg.lstsq(A, b, rcond=None)[0].reshape(-1, 3)
    Fo = F + dF
    loads = [PointLoad(sp.face, sp.bary, tuple(float(v) for v in f)) for sp, f in zip(sps, Fo)]
    return LoadMapping(loads, sps, X, Fo, np.asarray(contacts.positions), tuple(fingers), np.array(dists),
                       np.array(shifts), dF, f_in, m_in, Fo.sum(axis=0), np.cross(X - c, Fo).sum(axis=0))


__all__ = ["LoadMapping", "SurfacePoint", "map_contacts"]
