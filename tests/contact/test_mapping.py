"""Contacts -> point loads keep the total force and moment to round-off (issue 5).

Statics: a force may slide along its line of action without changing its moment, so a contact
force applied where its line of action pierces the shell's limit surface is statically
equivalent to the contact; the point loads then enter through basis values that sum to one
(force) and reproduce the point (moment).  Here the contact points are deliberately off the
surface (1.25 mm outside: the outer skin of a 2.5 mm wall) and carry friction."""
import numpy as np
import pytest

from graspdef.contact import ContactSet, Pose, map_contacts
from graspdef.geometry import icosphere
from graspdef.problem.problem import Problem
from graspdef.problem.supports import RigidModes
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell

R, T = 0.0325, 0.0025


@pytest.fixture(scope="module")
def shell():
    m = icosphere(radius=R, subdivisions=2)
    return Shell(m.vertices, m.faces, LinearElastic(1e6, 0.45), T)


def _contacts(rng, n):
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    pos = (R + T / 2) * d                                      # on the outer skin
    fn = rng.uniform(1, 20, size=n)
    tang = rng.normal(size=(n, 3))
    tang -= (tang * d).sum(1, keepdims=True) * d
    forces = -fn[:, None] * d + 0.3 * tang                     # pushing in, with friction
    torques = -0.002 * fn[:, None] * d * rng.uniform(-1, 1, size=(n, 1))   # torsional friction about the normal
    return ContactSet(pos, -d, forces, fn, np.linalg.norm(0.3 * tang, axis=1), tuple(f"c{i % 2}" for i in range(n)),
                      torques=torques)


@pytest.mark.parametrize("n", [2, 4])
def test_total_force_and_moment_kept(shell, n):
    cs = _contacts(np.random.default_rng(n), n)
    mp = map_contacts(shell, cs)
    scale = np.abs(cs.forces).sum()
    assert np.allclose(mp.force_out, cs.net_force(), atol=1e-14 * scale)
    assert np.allclose(mp.moment_out, cs.net_moment(), atol=1e-14 * scale * R)
    # the loads themselves: force and moment of the assembled load vector (basis values N_i)
    pr = Problem(shell, mp.loads, [RigidModes()])
    f = pr.load_vector().reshape(-1, 3)
    x = shell.rest_positions
    assert np.allclose(f.sum(axis=0), cs.net_force(), atol=1e-13 * scale)
    assert np.allclose(np.cross(x, f).sum(axis=0), cs.net_moment(), atol=1e-13 * scale * R)
    # the forces moved along their lines of action; the corrections are the torsional couples
    # (at the auxiliary points, 3 mm from each contact), not the main forces
    assert np.abs(mp.correction[:n] - mp.correction[:n].mean(axis=0)).max() < 0.5 * np.abs(cs.torques).max() / 3e-3
    assert np.all(mp.distances < T)


def test_moment_would_be_lost_at_the_nearest_point(shell):
    """Why the line of action: with friction the nearest limit point changes the moment."""
    cs = _contacts(np.random.default_rng(5), 2)
    cs = ContactSet(cs.positions, cs.normals, cs.forces, cs.normal_force, cs.friction_force, cs.finger)
    pr = Problem(shell, [], [RigidModes()])
    near = np.array([pr.evaluator.point(shell.rest_positions, sp.face, np.asarray(sp.bary))
                     for sp in (pr.locate(p) for p in cs.positions)])
    dm = np.cross(near, cs.forces).sum(axis=0) - cs.net_moment()
    assert np.linalg.norm(dm) > 1e-5                            # N m: what the mapping avoids


def test_pose_round_trip():
    rng = np.random.default_rng(0)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.linalg.det(q))
    pose = Pose(rng.normal(size=3), q)
    x = rng.normal(size=(5, 3))
    assert np.allclose(pose.to_world(pose.to_object(x)), x)
    w, *v = pose.quat
    assert abs(np.linalg.norm(pose.quat) - 1) < 1e-12


def test_no_contacts_is_an_error(shell):
    from graspdef.errors import ProblemError
    empty = ContactSet(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0), ())
    with pytest.raises(ProblemError, match="no contacts"):
        map_contacts(shell, empty)
    far = ContactSet(np.array([[0, 0, 2 * R]]), np.array([[0, 0, -1.0]]), np.array([[0, 0, -1.0]]),
                     np.ones(1), np.zeros(1), ("a",))
    with pytest.raises(ProblemError, match="off the surface"):
        map_contacts(shell, far)
