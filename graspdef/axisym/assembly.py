"""Model description (nodes, segments, restraints, loads, material) and the assembly of the nodal forces and the
system stiffness [K] from the segments' [KL] (thesis 3.20-3.28, "Extension to shell structures").

SI inputs, nondimensional inside (see the package docstring): lengths / t0, nodal forces per radian / (t0^2 C1),
nodal couples per radian / (t0^3 C1), distributed loads / C1.

Each user segment (a piece of constant meridional curvature between two nodes) is split into ``n_sub`` pieces
joined at internal, unloaded nodes -- the thesis's method with more nodes, which keeps every shooting interval
short (the integration is ill-conditioned over more than a few bending lengths sqrt(R t)).  Pole nodes (r = 0) carry
no degrees of freedom: the pole piece starts from the regular series solution at the axis (shooting unknowns: pole
stretch and curvature), and the pole's vertical position is an output.
"""
from dataclasses import dataclass, field

import numpy as np

from graspdef.errors import ProblemError, SupportError

from . import meridian
from .material import AxisymMaterial

TWO_PI = 2.0 * np.pi


@dataclass
class Node:
    """Node on the meridian: r, z in m, phi = meridian tangent angle in rad (e_xi = cos(phi) e_r + sin(phi) e_z).
    fix = (r, z, phi) restraint flags (True = that coordinate is held at its undeformed value)."""

    r: float
    z: float
    phi: float
    fix: tuple = (False, False, False)


@dataclass
class Segment:
    """Meridian piece of constant curvature kappa (1/m; 0 = straight, -1/R for a dome traversed from its top pole)
    from node i to node j (traversed i -> j).  n_sub: number of shooting pieces (None = automatic)."""

    i: int
    j: int
    kappa: float = 0.0
    n_sub: int | None = None


@dataclass
class NodalLoad:
    """Reference nodal load per radian of circumference at a node: H, V in N/rad, M in N m/rad (conjugate to
    the node's r, z, phi; thesis P^H, P^V, P^M).  A ring force of total F (N) is F/(2 pi) per radian; an edge
    couple m (N m per m of undeformed circumference) at radius r0 is m r0 per radian."""

    node: int
    H: float = 0.0
    V: float = 0.0
    M: float = 0.0

    @classmethod
    def ring(cls, node, Fr=0.0, Fz=0.0):
        """Ring load given as total forces over the whole circle (N)."""
        return cls(node, H=Fr / TWO_PI, V=Fz / TWO_PI)


@dataclass
class DistributedLoad:
    """Reference distributed load on segment(s) (Pa): qH, qV per unit deformed area, QH, QV per unit undeformed
    area (dead), p pressure along the deformed normal e_n = -sin(phi) e_r + cos(phi) e_z (follower).
    segments: list of user segment indices, or None for all."""

    qH: float = 0.0
    qV: float = 0.0
    QH: float = 0.0
    QV: float = 0.0
    p: float = 0.0
    segments: list | None = None


@dataclass
class Model:
    """A shell of revolution: material, undeformed thickness t0 (m), nodes, segments, reference loads (all scaled
    by the load factor Lam), discretisation controls (max_piece: longest shooting piece in units of t0;
    rk_steps: RK4 steps per piece)."""

    material: AxisymMaterial
    thickness: float
    nodes: list
    segments: list
    nodal_loads: list = field(default_factory=list)
    distributed_loads: list = field(default_factory=list)
    max_piece: float = 0.6
    rk_steps: int = 2
    name: str = "axisym"

    # ------------------------------------------------------------------ discretisation
    def build(self):
        """Validate and discretise; returns a Discrete model (nondimensional arrays)."""
        return Discrete(self)


class Discrete:
    """Nondimensional, discretised model: pieces (batch arrays), node table, dof map."""

    def __init__(self, model: Model):
        m = model
        if not (np.isfinite(m.thickness) and m.thickness > 0):
            raise ProblemError(f"shell thickness must be positive, got {m.thickness}")
        if len(m.nodes) < 2 or not m.segments:
            raise ProblemError("a model needs at least two nodes and one segment")
        if m.rk_steps < 1 or m.max_piece <= 0:
            raise ProblemError("rk_steps must be >= 1 and max_piece > 0")
        t0, C1 = m.thickness, m.material.C1
        self.model, self.t0, self.C1 = m, t0, C1
        nn = len(m.nodes)
        for k, nd in enumerate(m.nodes):
            if not all(np.isfinite([nd.r, nd.z, nd.phi])):
                raise ProblemError(f"node {k} has non-finite coordinates")
            if nd.r < 0:
                raise ProblemError(f"node {k} has negative radius r = {nd.r}")
        used_start, used_end = {}, {}
        nodes = [(nd.r / t0, nd.z / t0, nd.phi) for nd in m.nodes]
        fix = [tuple(bool(f) for f in nd.fix) for nd in m.nodes]
        pieces = []  # (rho_a, eps_a, phi_a, kappa, L, pole, user segment, node_a, node_b)
        seg_of_piece = []
        for k, sg in enumerate(m.segments):
            if not (0 <= sg.i < nn and 0 <= sg.j < nn) or sg.i == sg.j:
                raise ProblemError(f"segment {k} connects invalid nodes {sg.i} -> {sg.j}")
            if sg.i in used_start or sg.j in used_end:
                raise ProblemError(f"segment {k}: node {sg.i if sg.i in used_start else sg.j} already starts/ends "
                                   f"another segment (the meridian must be one chain listed in order)")
            used_start[sg.i], used_end[sg.j] = k, k
            kap = sg.kappa * t0
            a, b = nodes[sg.i], nodes[sg.j]
            L, mis = meridian.arc_through(a, b, kap)
            if abs(L) < 1e-9 * (1 + abs(a[0]) + abs(a[1])):
                raise ProblemError(f"segment {k} (nodes {sg.i} -> {sg.j}) has zero length")
            if L < 0:
                raise ProblemError(f"meridian data not monotone: segment {k} runs backwards from node {sg.i} to "
                                   f"node {sg.j} (arc length {L * t0:.4g} m); list nodes in meridian order")
            if mis > 1e-6 * (1 + L):
                raise ProblemError(f"segment {k} (nodes {sg.i} -> {sg.j}): node {sg.j} does not lie on the piece of "
                                   f"curvature {sg.kappa:g} 1/m starting at node {sg.i} with its angle "
                                   f"(mismatch {mis * t0:.3g} m); check the nodes' r, z, phi")
            rr, _, _, _, _ = meridian.evaluate(a[0], a[1], a[2], kap, np.linspace(0, L, 257))
            if np.any(rr[1:] <= 0):
                raise ProblemError(f"segment {k} crosses the axis (r <= 0 inside the segment)")
            if b[0] < 1e-12:
                raise ProblemError(f"segment {k} ends on the axis at node {sg.j}; list pole segments from the pole")
            pole = a[0] < 1e-12
            if pole and abs(np.angle(np.exp(1j * a[2]))) > 1e-9:
                raise ProblemError(f"segment {k} starts on the axis at node {sg.i} with phi = {a[2]:.4g}; a pole needs "
                                   "phi = 0 (meridian leaving the axis radially)")
            n = sg.n_sub or max(1, int(np.ceil(L / m.max_piece)))
            sl = np.linspace(0.0, L, n + 1)
            r_, z_, p_, _, _ = meridian.evaluate(a[0], a[1], a[2], kap, sl)
            for q in range(n):
                pieces.append((r_[q], z_[q], p_[q], kap, sl[q + 1] - sl[q], pole and q == 0, k, q))
                seg_of_piece.append(k)
        # node table: user nodes first, then internal nodes
        node_xyz = list(nodes)
        node_fix = list(fix)
        a_idx, b_idx = [], []
        internal_of = {}
        for pc in pieces:
            k, q = pc[6], pc[7]
            sg = m.segments[k]
            n = sum(1 for p2 in pieces if p2[6] == k)
            a_node = sg.i if q == 0 else internal_of[(k, q)]
            if q == n - 1:
                b_node = sg.j
            else:
                b_node = len(node_xyz)
                internal_of[(k, q + 1)] = b_node
                r_, z_, p_, _, _ = meridian.evaluate(pc[0], pc[1], pc[2], pc[3], pc[4])
                node_xyz.append((float(r_), float(z_), float(p_)))
                node_fix.append((False, False, False))
            a_idx.append(a_node)
            b_idx.append(b_node)
        P = np.array(pieces, dtype=object)
        K = len(pieces)
        pole = np.array([bool(p[5]) for p in pieces])
        L = np.array([p[4] for p in pieces], float)
        delta = 1e-3 * L
        s0 = np.where(pole, delta, 0.0)
        self.batch = dict(
            rho_a=np.array([p[0] for p in pieces], float), eps_a=np.array([p[1] for p in pieces], float),
            phi_a=np.array([p[2] for p in pieces], float), kappa=np.array([p[3] for p in pieces], float),
            s0=s0, h=(L - s0) / m.rk_steps, L=L, pole=pole,
            qH=np.zeros(K), qV=np.zeros(K), QH=np.zeros(K), QV=np.zeros(K), p=np.zeros(K))
        del P
        self.seg_of_piece = np.array(seg_of_piece)
        for dl in m.distributed_loads:
            segs = range(len(m.segments)) if dl.segments is None else dl.segments
            for k in segs:
                if not 0 <= k < len(m.segments):
                    raise ProblemError(f"distributed load on unknown segment {k}")
                sel = self.seg_of_piece == k
                for key in ("qH", "qV", "QH", "QV", "p"):
                    self.batch[key][sel] += getattr(dl, key) / C1
        self.a_idx, self.b_idx = np.array(a_idx), np.array(b_idx)
        self.X0 = np.array(node_xyz, float)  # (nnodes, 3) nondimensional undeformed positions
        self.nnodes = len(node_xyz)
        self.pole_nodes = sorted({a_idx[k] for k in np.flatnonzero(pole)})
        self.pole_piece = {a_idx[k]: k for k in np.flatnonzero(pole)}
        # dofs
        fixed = np.zeros((self.nnodes, 3), bool)
        fixed[:] = np.array(node_fix, bool)
        has_dof = np.ones(self.nnodes, bool)
        has_dof[self.pole_nodes] = False
        for pn in self.pole_nodes:
            if any(node_fix[pn]):
                raise ProblemError(f"node {pn} is a pole: its r and phi are fixed by symmetry and a vertical "
                                   "restraint there would carry a point force (singular); restrain another node")
        self.has_dof = has_dof
        dof_nodes = np.flatnonzero(has_dof)
        self.dof_of_node = -np.ones(self.nnodes, int)
        self.dof_of_node[dof_nodes] = np.arange(dof_nodes.size)
        self.ndof = 3 * dof_nodes.size
        fx = fixed[dof_nodes].ravel()
        self.free = np.flatnonzero(~fx)
        self.fixed = np.flatnonzero(fx)
        # unsupported rigid-body motion: the vertical translation must be restrained somewhere
        if not fixed[dof_nodes, 1].any():
            raise SupportError("unsupported rigid-body motion: no node restrains the vertical position z, so the "
                               "stiffness [K] is singular (vertical translation); restrain z at one node "
                               "(the thesis: at least three restraints counting the axis conditions r = phi = 0)")
        # reference nodal loads
        self.Pref = np.zeros(self.ndof)
        for ld in m.nodal_loads:
            if not 0 <= ld.node < len(m.nodes):
                raise ProblemError(f"nodal load on unknown node {ld.node}")
            if not has_dof[ld.node]:
                raise ProblemError(f"nodal load at pole node {ld.node}: a point force on the axis is singular in shell "
                                   "theory; apply it as a ring load on a small circle (see problems.pinched_sphere)")
            d = 3 * self.dof_of_node[ld.node]
            self.Pref[d:d + 3] += [ld.H / (t0 * t0 * C1), ld.V / (t0 * t0 * C1), ld.M / (t0 ** 3 * C1)]
        self.nsteps = m.rk_steps
        self.material = m.material
        # piece -> dof indices (6 per piece, -1 where none)
        idx = -np.ones((K, 6), int)
        for k in range(K):
            for e, nd in enumerate((a_idx[k], b_idx[k])):
                if has_dof[nd]:
                    idx[k, 3 * e:3 * e + 3] = 3 * self.dof_of_node[nd] + np.arange(3)
        self.piece_dofs = idx
        self.nuser_segments = len(m.segments)

    # ------------------------------------------------------------------ helpers
    def positions(self, x):
        """Node table (nnodes, 3) from the dof vector x (pole nodes: r = phi = 0, z filled in later)."""
        X = self.X0.copy()
        d = np.flatnonzero(self.has_dof)
        X[d] = x.reshape(-1, 3)
        return X

    def x0(self):
        return self.X0[self.has_dof].ravel().copy()

    def ends(self, x):
        X = self.positions(x)
        X1 = X[self.a_idx].T.copy()
        X2 = X[self.b_idx].T.copy()
        return X1, X2

    def initial_u(self):
        """Unloaded state: zero end forces, pole stretch 1 and the undeformed pole curvature."""
        u = np.zeros((3, len(self.a_idx)))
        pole = self.batch["pole"]
        u[0, pole] = 1.0
        u[1, pole] = self.batch["kappa"][pole]
        return u

    def assemble(self, P, KL=None, C=None):
        """Nodal internal forces F (ndof), and if given, [K] (ndof, ndof) and dF/dLam (ndof)."""
        F = np.zeros(self.ndof)
        idx = self.piece_dofs
        m = idx >= 0
        np.add.at(F, idx[m], P[m])
        if KL is None:
            return F, None, None
        K = np.zeros((self.ndof, self.ndof))
        Cv = np.zeros(self.ndof)
        for k in range(idx.shape[0]):
            ii = idx[k]
            sel = np.flatnonzero(ii >= 0)
            K[np.ix_(ii[sel], ii[sel])] += KL[k][np.ix_(sel, sel)]
            Cv[ii[sel]] += C[k][sel]
        return F, K, Cv

    def piece_name(self, k):
        seg = int(self.seg_of_piece[k])
        sg = self.model.segments[seg]
        return f"segment {seg} (nodes {sg.i} -> {sg.j}), piece at node {self.a_idx[k]} -> {self.b_idx[k]}"
