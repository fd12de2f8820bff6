"""Ready-made problems: the thesis's hemispheres (Chapter 4) and spheres for cross-checks with the 3-D solver.

The thesis's examples are nondimensional: t0 = 1, C1 = 1, R0 = R0/t0 = 10, Mooney-Rivlin gamma = C2/C1 = 0.1,
"unrestrained edges" (the edge node is free to move radially and to rotate; its vertical position is held to
remove the rigid-body translation).  Loads are per radian of circumference (thesis 2.81: f = F/(t0^2 C1)) with a
unit reference value, so the load factor Lam is the thesis's nondimensional load.
"""
import numpy as np

from graspdef.errors import ProblemError

from .assembly import DistributedLoad, Model, Node, NodalLoad, Segment
from .continuation import solve_path
from .material import AxisymMaterial


def _sphere_nodes(R, angles, fix_edge):
    """Nodes on a sphere of radius R centred at the origin at polar angles (rad, from the top pole)."""
    nodes = []
    for a in angles:
        nodes.append(Node(R * np.sin(a), R * np.cos(a), -a))
    nodes[-1].fix = fix_edge
    return nodes


def hemisphere_example(case, R_over_t=10.0, gamma=0.1, ring_angle=np.pi / 6, max_piece=0.6, rk_steps=1,
                       volume_factor=False, load_basis="deformed", edge_sense=-1.0):
    """The thesis's hemisphere (apex up, edge at the equator, z of the edge held, r and phi of the edge free).

    case: "edge_couple" (unit couple per radian at the edge turning the edge inward, toward the axis -- the sense
    that reproduces the thesis's limit load 3.363; edge_sense=+1 turns it outward),
    "ring" (downward unit ring force per radian at polar angle ring_angle), "uniform" (downward uniform vertical
    load of unit intensity per unit deformed area, or undeformed area with load_basis="reference")."""
    mat = AxisymMaterial("mooney_rivlin", C1=1.0, gamma=gamma, volume_factor=volume_factor)
    R = float(R_over_t)
    angles = [0.0, np.pi / 2] if case != "ring" else [0.0, ring_angle, np.pi / 2]
    nodes = _sphere_nodes(R, angles, (False, True, False))
    segs = [Segment(k, k + 1, kappa=-1.0 / R) for k in range(len(nodes) - 1)]
    nl, dl = [], []
    if case == "edge_couple":
        nl = [NodalLoad(len(nodes) - 1, M=float(edge_sense))]
    elif case == "ring":
        nl = [NodalLoad(1, V=-1.0)]
    elif case == "uniform":
        dl = [DistributedLoad(qV=-1.0)] if load_basis == "deformed" else [DistributedLoad(QV=-1.0)]
    else:
        raise ProblemError(f"unknown hemisphere case {case!r}")
    return Model(mat, 1.0, nodes, segs, nl, dl, max_piece=max_piece, rk_steps=rk_steps, name=f"hemisphere_{case}")


def _graded_sphere(R, t, material, first_angle, fix_equator, fine=None, max_piece=1.0):
    """Nodes and segments of the upper hemisphere graded toward the pole: pieces of ~ell/12 within one bending
    length ell = sqrt(R t)/(3(1 - nu^2))^(1/4) (nu = 1/2) of the pole, ~ell/5 up to 6 ell, ~ell/2.5 beyond, and
    never longer than max_piece * t (large membrane tension makes long shooting pieces ill-conditioned)."""
    ell = np.sqrt(R * t) / 1.5 ** 0.5
    fine = fine or ell / 12
    s_pole = R * first_angle
    marks = [0.0, s_pole] if first_angle > 0 else [0.0]
    for s_ in (s_pole + ell, s_pole + 6 * ell):
        if s_ < 0.9 * R * np.pi / 2:
            marks.append(s_)
    marks.append(R * np.pi / 2)
    angles = [m_ / R for m_ in marks]
    nodes = _sphere_nodes(R, angles, fix_equator)
    sizes = [fine, fine, ell / 5, ell / 2.5] if first_angle > 0 else [fine, ell / 5, ell / 2.5]
    segs = []
    for k in range(len(nodes) - 1):
        L = marks[k + 1] - marks[k]
        h = min(sizes[min(k, len(sizes) - 1)], max_piece * t)
        segs.append(Segment(k, k + 1, kappa=-1.0 / R, n_sub=max(1, int(np.ceil(L / h)))))
    return nodes, segs


def pinched_sphere(R, t, material, F=1.0, contact_radius=None, rk_steps=2, max_piece=1.0):
    """Closed sphere squeezed by two opposite forces of magnitude F (reference load, N) at its poles.

    By symmetry the upper hemisphere is modelled: equator node with z and phi held, r free.  A point force on
    the axis is singular in shell theory, so each force is applied as a ring load on the circle of undeformed radius
    contact_radius (default t/4) around the pole; as contact_radius -> 0 the pole displacement converges (Reissner).
    Load factor Lam multiplies F.  The apex (pole) displacement is ``nodes[0, 1] * t - R`` (AxisymEquilibrium.nodes is
    nondimensional)."""
    a = contact_radius if contact_radius is not None else 0.25 * t
    if not 0 < a < 0.5 * R:
        raise ProblemError(f"contact radius {a} must lie in (0, R/2)")
    nodes, segs = _graded_sphere(R, t, material, np.arcsin(a / R), (False, True, True), fine=min(a, 0.5 * t),
                                 max_piece=max_piece)
    return Model(material, t, nodes, segs, [NodalLoad.ring(1, Fz=-F)], [], rk_steps=rk_steps,
                 name="pinched_sphere")


def inflated_sphere(R, t, material, p=1.0, rk_steps=2, max_piece=1.0):
    """Closed sphere under internal pressure p (reference load, Pa; follower).  Upper hemisphere by symmetry."""
    nodes, segs = _graded_sphere(R, t, material, 0.0, (False, True, True), max_piece=max_piece)
    return Model(material, t, nodes, segs, [], [DistributedLoad(p=p)], rk_steps=rk_steps, name="inflated_sphere")


def sphere_apex_curve(model, ds=0.5, max_steps=60, stop=None, lam_max=None):
    """Load factor vs apex (pole) displacement of a sphere model (pinched_sphere / inflated_sphere).

    Returns (Lam array, apex displacement array in m, PathResult); displacement positive upward."""
    path = solve_path(model, ds=ds, max_steps=max_steps, stop=stop, lam_max=lam_max)
    z0 = model.nodes[0].z
    t0 = model.thickness
    apex = np.array([p.nodes[0, 1] * t0 - z0 for p in path.points])
    return path.lam, apex, path
