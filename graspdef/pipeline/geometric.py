"""Geometric contact in the grasp chain (``graspdef grasp ... --contact geometric``).

Each active finger's tip becomes a rigid obstacle in the object frame (graspdef.contact.barrier:
a capsule for a pin, a box with 1 mm rounded edges for a pad; MuJoCo's geom at the settled
grasp), pushed along its slide axis by the target force (force control: the finger's contact
force along its axis equals the target at every equilibrium).  What MuJoCo's contacts carry
besides that axial force -- friction, the tilt of the contact normal, the torsional-friction
couples -- stays a dead load: the mapped point loads (graspdef.contact.mapping) minus their
components along the finger axis, applied at the same surface points.  With the weight as a body
force the loads then balance up to the difference between the barrier's lateral force and
MuJoCo's (zero for a symmetric contact; reported as the residual).

The linear analysis with geometric contact is the same path with the shell energy replaced by its
rest-state quadratic form 1/2 u.K0 u (the linear shell; contact is nonlinear by nature).
"""
from __future__ import annotations


import numpy as np

from ..contact.barrier import FingerContact
from ..contact.obstacles import Capsule, RoundedBox
from ..errors import ProblemError
from ..problem.loads import PointLoad
from ..solve.nonlinear import PathSolver, PathStopped

#: edge radius given to MuJoCo's sharp box pads [m] (the barrier needs a C1 surface)
PAD_ROUNDING = 1e-3


def fingertip_obstacle(tip: dict, pose):
    """MuJoCo fingertip record (graspdef.sim.grasp: world frame) -> (obstacle, axis) in the object
    frame of ``pose``."""
    R = pose.rotation.T @ np.asarray(tip["rotation"], float)
    c = pose.to_object(np.asarray(tip["position"], float)[None])[0]
    e = pose.vector_to_object(np.asarray(tip["axis"], float))
    size = np.asarray(tip["size"], float)
    if tip["type"] == "capsule":
        z = R[:, 2] * size[1]
        obs = Capsule(tuple(c - z), tuple(c + z), float(size[0]))
    elif tip["type"] == "sphere":
        obs = Capsule(tuple(c), tuple(c + 1e-9 * e), float(size[0]))
    elif tip["type"] == "box":
        obs = RoundedBox(tuple(c), tuple(map(tuple, R)), tuple(size[:3]), min(PAD_ROUNDING, 0.5 * float(size[:3].min())))
    else:
        raise ProblemError(f"geometric contact: fingertip '{tip['geom']}' is a MuJoCo {tip['type']}; "
                           "supported: capsule, sphere, box")
    return obs, e / np.linalg.norm(e)


def finger_contacts(mapping, g, targets: dict, thickness: float, dhat: float | None = None,
                    pressure_scale: float | None = None) -> tuple[list, list]:
    """(dead point loads, FingerContact potentials) replacing the point loads of ``mapping``.

    The dead loads are the mapped loads with, at each finger's contacts, the component along the
    finger's axis removed (it is the contact potential's force); the auxiliary couple points
    keep their loads."""
    tips = g.info.get("fingertips", {})
    loads, fingers = [], []
    axes = {}
    for side, F in targets.items():
        if F <= 0:
            continue
        if side not in tips:
            raise ProblemError(f"geometric contact: no fingertip record for the {side} finger")
        obs, e = fingertip_obstacle(tips[side], g.pose)
        axes[side] = e
        fingers.append(FingerContact(obs, tuple(e), float(F), offset=thickness / 2, dhat=dhat,
                                     pressure_scale=pressure_scale, name=side))
    n_main = len(mapping.contact_points)
    for i, (ld, f) in enumerate(zip(mapping.loads, mapping.forces)):
        side = mapping.finger[i]
        if i < n_main and side in axes:
            e = axes[side]
            f = f - (f @ e) * e
        loads.append(PointLoad(ld.face, ld.bary, tuple(float(v) for v in f)))
    return loads, fingers


def solve_contact(problem, options, linear: bool, progress=None):
    """The load path of a problem with finger contacts; ``linear``: the linear shell (rest-state
    stiffness) instead of the finite-deformation one.  Raises PathStopped like solve_nonlinear.
    ``progress``: called with each converged point's info (as solve_nonlinear's)."""
    ps = PathSolver(problem, options, progress=progress,
                    terms=problem.energy_terms("rest" if linear else "finite"))
    sol = ps.run()
    if not sol.completed:
        raise PathStopped(f"the load path stopped at load factor {sol.load_factor:.6g} after "
                          f"{len(sol.path) - 1} steps: {sol.stop_reason}", sol)
    return sol


def contact_reports(shell, fingers: list, u: np.ndarray, lam: float, u_ref: np.ndarray | None = None) -> dict:
    """Per-finger contact report (graspdef.contact.FingerContact.report) at control-point
    displacements u (n, 3) and load factor lam, with ``touch_advance_m``: where the fingertip
    touches the unloaded shell (control-point displacements ``u_ref``, default the rest shape)."""
    x = shell.rest_positions + u
    x0 = shell.rest_positions + (0.0 if u_ref is None else u_ref)
    out = {}
    for fc in fingers:
        b = fc.build(shell, shell.evaluator)
        out[fc.name] = dict(b.report(x, lam), touch_advance_m=b.touch(x0))
    return out
