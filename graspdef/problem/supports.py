"""Supports as linear constraints on the limit surface, ``C u = 0``.

Each supported boundary edge contributes collocation points (Gauss-Legendre along the edge's
limit curve).  At each point the limit displacement ``u = sum N_i u_i`` is constrained in the
support's directions at two Gauss points per edge (the default).  Between the points the
residual is small and falls fast with refinement (measured on a simply supported plate: at most
8e-4 of the maximum displacement on the edges next to a corner and 1.3e-5 elsewhere at 8 x 8
cells, 1.8e-5 and 1.6e-7 at 32 x 32: order 3-4).  Three points per edge make the constraint
hold identically along the whole limit curve, but then the corners lock (the same plate: 12 %
too stiff at 8 x 8, 5 % at 16 x 16, against 0.01 % with two points), so two it is.  Dependent
rows (closed loops) are dropped (``independent_rows``), and so are nearly dependent ones (long
closed loops: singular values falling as N^-3 in the number of edges) where each lies within 1 %
of the kept rows' span -- elsewhere they are replaced by an orthonormal basis of their row space
(``well_conditioned_rows``).  The constraints are imposed by Lagrange multipliers (``graspdef.solve``);
ghost control vertices stay free, so natural boundary conditions come out of the energy.

The rotation about the edge (``clamped``, ``symmetry``) is imposed by Nitsche's method
(``graspdef.problem.nitsche``): imposing it exactly as well would leave the box-spline space no curvature
at the edge (measured: first-order convergence of the clamped plate), while Nitsche's consistent
weak form keeps the full convergence rate.

=================  =====================================  ==================
kind               displacement constrained               rotation about edge
=================  =====================================  ==================
free               nothing                                free
simply_supported   all three components (hinge)           free
clamped            all three components                   fixed
symmetry           component along the plane normal       fixed
diaphragm          the two components in the diaphragm    free
                   plane (normal to ``normal``)
=================  =====================================  ==================
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.sparse as sp

from ..errors import ProblemError, SupportError
from ..shell.model import Shell
from ..subdivision.evaluate import SurfaceEvaluator
from ..subdivision.patch import regular_basis
from .edges import boundary_edge_mask

KINDS = ("free", "simply_supported", "clamped", "symmetry", "diaphragm")


def _unit(name: str, v) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) == 0:
        raise ProblemError(f"{name} must be a non-zero 3-vector, got {v!r}")
    return a / np.linalg.norm(a)


@dataclass(frozen=True)
class EdgeSupport:
    """Support on the boundary edges whose two end vertices satisfy ``where``.

    Parameters
    ----------
    kind : one of ``KINDS``
    where : callable (n, 3) -> (n,) bool, evaluated on rest vertex positions [m]
    normal : plane normal (symmetry) or diaphragm-plane normal (diaphragm)
    name : label used in messages
    side : callable, optional: keeps only the edges whose owning face's centroid satisfies it
        (one lip of a slit; ``graspdef.problem.edges``)
    """

    kind: str
    where: Callable[[np.ndarray], np.ndarray]
    normal: tuple[float, float, float] | None = None
    name: str = "support"
    side: Callable[[np.ndarray], np.ndarray] | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ProblemError(f"support '{self.name}': unknown kind '{self.kind}' (valid: {', '.join(KINDS)})")
        if self.kind in ("symmetry", "diaphragm") and self.normal is None:
            raise ProblemError(f"support '{self.name}': kind '{self.kind}' needs a 'normal' vector")

    def directions(self) -> tuple[np.ndarray, bool]:  # noqa: D401
        """Constrained displacement directions (k, 3) and whether the rotation is fixed."""
        if self.kind == "free":
            return np.zeros((0, 3)), False
        if self.kind in ("simply_supported", "clamped"):
            return np.eye(3), self.kind == "clamped"
        n = _unit(f"support '{self.name}' normal", self.normal)
        if self.kind == "symmetry":
            return n[None, :], True
        # diaphragm: the plane normal to n
        basis = np.linalg.svd(np.eye(3) - np.outer(n, n))[0][:, :2].T
        return basis, False


@dataclass(frozen=True)
class PointSupport:
    """Displacement of one limit-surface point fixed along ``directions`` (k, 3).

    ``displacement`` (k,) [m], optional: prescribed displacement along each direction at load
    factor 1 (displacement control; scaled by the load factor in nonlinear solves).  Default 0."""

    face: int
    bary: tuple[float, float, float]
    directions: tuple[tuple[float, float, float], ...] = ((1, 0, 0), (0, 1, 0), (0, 0, 1))
    name: str = "point"
    displacement: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        if self.displacement is not None:
            d = np.asarray(self.displacement, dtype=float)
            if d.shape != (len(self.directions),) or not np.all(np.isfinite(d)):
                raise ProblemError(f"support '{self.name}': displacement needs one finite value per direction "
                                   f"({len(self.directions)}), got {self.displacement!r}")


@dataclass(frozen=True)
class RigidModes:
    """Removes the six rigid-body modes of an unsupported body without picking vertices: the
    limit surface's area-weighted mean displacement and mean (linearised) rotation about its
    area centroid are held at zero (:func:`surface_mean_rows`).  The six rows are invariant to
    the numbering of the vertices and symmetric under every symmetry of the mesh, and they touch
    no point in particular.  Their reactions are the net force and moment that the loads leave
    unbalanced in the current configuration (zero for self-equilibrated loads at any
    deformation, as for any statically determinate support); they are reported by the solver."""

    name: str = "rigid_modes"


Support = EdgeSupport | PointSupport | RigidModes


def surface_mean_rows(shell: Shell) -> tuple[np.ndarray, np.ndarray]:
    """The six rows of :class:`RigidModes` as dense (6, 3 n_control) arrays, each of unit norm:
    the mean displacement (1/A) int u dA and the mean rotation int (X - c) x u dA of the rest limit
    surface (area A, centroid c), integrated with the shell's own quadrature
    (u = sum_i N_i u_i, so the rows are sum_i m_i u_i and sum_i a_i x u_i with m_i = int N_i dA,
    a_i = int N_i (X - c) dA).  Returns (rows, the 3 x 3 second moment int |X-c|^2 I - (X-c)(X-c)^T dA)."""
    n = shell.n_control
    x = shell.rest_positions
    m = np.zeros(n)
    first = np.zeros((n, 3))
    area = 0.0
    cen = np.zeros(3)
    parts = []
    for g, r in zip(shell.basis.groups, shell.rest):
        N = np.broadcast_to(g.N, (len(g.stencils),) + g.N.shape[-2:])             # (f, q, S)
        Xq = np.einsum("fqs,fsd->fqd", N, x[g.stencils])                            # limit points
        parts.append((g, N, Xq, r.weights))
        area += float(r.weights.sum())
        cen += np.einsum("fq,fqd->d", r.weights, Xq)
    if area <= 0:
        raise SupportError("rigid_modes: the surface has no area")
    cen /= area
    J = np.zeros((3, 3))
    for g, N, Xq, w in parts:
        wN = w[..., None] * N                                                       # (f, q, S)
        np.add.at(m, g.stencils, wN.sum(axis=1))
        d = Xq - cen
        np.add.at(first, g.stencils, np.einsum("fqs,fqd->fsd", wN, d))
        J += np.einsum("fq,fqd,fqe->de", w, d, d)
    J = np.trace(J) * np.eye(3) - J
    rows = np.zeros((6, n, 3))
    for k in range(3):
        rows[k, :, k] = m
        e = np.eye(3)[k]
        # (a x u)_k = e_k . (a x u) = u . (e_k x a)
        rows[3 + k] = np.cross(e, first)
    rows = rows.reshape(6, -1)
    rows /= np.linalg.norm(rows, axis=1, keepdims=True)
    return rows, J


def rigid_modes(x: np.ndarray) -> np.ndarray:
    """Unit-norm rigid-body modes of control points ``x`` as columns, (3 n, 6):
    translations x, y, z then rotations about x, y, z through the centroid."""
    c = x - x.mean(axis=0)
    cols = [np.tile(e, (len(x), 1)).ravel() for e in np.eye(3)]
    cols += [np.cross(e, c).ravel() for e in np.eye(3)]
    R = np.stack(cols, axis=1)
    return R / np.linalg.norm(R, axis=0)


def _edge_points(n_col: int) -> np.ndarray:
    t, _ = np.polynomial.legendre.leggauss(n_col)
    return 0.5 * (t + 1.0)


_CORNERS = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


def constraint_rows(shell: Shell, supports: list, ev: SurfaceEvaluator, n_col: int = 2,
                    with_targets: bool = False):
    """Assemble C (m, 3 n_control) and a per-row label list.

    Returns (C csr, labels: one string per row naming the support and edge) and, with
    ``with_targets``, the prescribed values g (m,) [m] of C u = g at load factor 1."""
    x = shell.rest_positions
    n = shell.n_control
    rows, cols, vals, labels = [], [], [], []
    targets: dict[int, float] = {}
    m = 0

    def add(st, weights, direction, label):
        nonlocal m
        rows.append(np.full(3 * len(st), m))
        cols.append((3 * st[:, None] + np.arange(3)).ravel())
        vals.append((weights[:, None] * direction[None, :]).ravel())
        labels.append(label)
        m += 1

    taus = _edge_points(n_col)
    mesh = shell.mesh
    any_edge = False
    for sup in supports:
        if isinstance(sup, EdgeSupport):
            dirs, rot = sup.directions()
            ab = mesh.boundary_edges
            if len(ab) == 0:
                raise SupportError(f"support '{sup.name}': the surface has no boundary edges")
            mask = boundary_edge_mask(shell, sup.where, sup.side)
            if not mask.any():
                raise SupportError(f"support '{sup.name}' ({sup.kind}): "
                                   f"its region{'' if sup.side is None else ' and side'} select{'s' if sup.side is None else ''} no boundary edge")
            any_edge = True
            edges = np.flatnonzero(mask)
            faces = mesh.boundary_faces[edges]
            corner = np.argmax(mesh.faces[faces] == ab[edges, 0][:, None], axis=1)   # edge a -> b starts here
            pts = [(1 - taus)[:, None] * _CORNERS[i] + taus[:, None] * _CORNERS[(i + 1) % 3] for i in range(3)]
            reg = ev.is_regular(faces)
            if reg.any():                                   # box-spline patches: all at once
                table = np.stack([regular_basis(p)[0] for p in pts])            # (3, q, 12)
                st = ev.regular_stencils(faces[reg])                             # (R, 12)
                W = table[corner[reg]]                                           # (R, q, 12)
                R, q = W.shape[:2]
                k = len(dirs)
                v = W[:, :, None, :, None] * dirs[None, None, :, None, :]        # (R, q, k, 12, 3)
                c = np.broadcast_to((3 * st[:, None, None, :, None] + np.arange(3)), v.shape)
                r = m + np.arange(R * q * k).reshape(R, q, k, 1, 1)
                rows.append(np.broadcast_to(r, v.shape).ravel())
                cols.append(c.ravel())
                vals.append(v.ravel())
                labels += [f"{sup.name}: edge {a}-{b}" for a, b in ab[edges[reg]] for _ in range(q * k)]
                m += R * q * k
            for e, f, i in zip(edges[~reg], faces[~reg], corner[~reg]):
                st, N, _, _ = ev.basis(int(f), pts[i])
                for qq in range(len(taus)):
                    for d in dirs:
                        add(st, N[qq], d, f"{sup.name}: edge {ab[e, 0]}-{ab[e, 1]}")
        elif isinstance(sup, PointSupport):
            st, w = ev.values(sup.face, np.asarray(sup.bary, float))
            disp = np.zeros(len(sup.directions)) if sup.displacement is None else np.asarray(sup.displacement, float)
            for d, val in zip(np.asarray(sup.directions, dtype=float), disp):
                dn = _unit(f"support '{sup.name}' direction", d)
                if val != 0.0:
                    targets[m] = float(val)
                add(st, w, dn, f"{sup.name}: u.{d.tolist()}")
        elif isinstance(sup, RigidModes):
            R, _ = surface_mean_rows(shell)
            names = ["mean translation x", "mean translation y", "mean translation z",
                     "mean rotation x", "mean rotation y", "mean rotation z"]
            for c in range(6):
                rows.append(np.full(3 * n, m))
                cols.append(np.arange(3 * n))
                vals.append(R[c])
                labels.append(f"{sup.name}: {names[c]}")
                m += 1
        else:
            raise ProblemError(f"unknown support object {sup!r}")
    del any_edge
    g = np.zeros(m)
    for i, val in targets.items():
        g[i] = val
    if m == 0:
        C = sp.csr_matrix((0, 3 * n))
    else:
        C = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(m, 3 * n))
        C.sum_duplicates()
        C.eliminate_zeros()          # structural zeros would merge independent clusters
    return (C, labels, g) if with_targets else (C, labels)


def check_rigid_modes(C: sp.csr_matrix, x: np.ndarray, rtol: float = 1e-8, Kb: sp.spmatrix | None = None) -> None:
    """Raise SupportError naming any rigid-body motion that the constraints C (and the Nitsche
    rotation terms Kb, if given) leave free."""
    R = rigid_modes(x)
    CR = C @ R if C.shape[0] else np.zeros((0, 6))
    M = CR.T @ CR
    M = M / max(np.linalg.eigvalsh(M).max(initial=0.0), 1e-300) if M.any() else M
    if Kb is not None and Kb.nnz:
        Mk = R.T @ (Kb @ R)
        Mk = 0.5 * (Mk + Mk.T)
        M = M + Mk / max(np.abs(np.linalg.eigvalsh(Mk)).max(), 1e-300)
    w, V = np.linalg.eigh(M)
    free = [V[:, i] for i in range(6) if w[i] <= rtol ** 2 * max(w.max(), 1e-300) or w[i] <= 0.0]
    if free:
        desc = []
        for v in free:
            v = v / np.abs(v).max()
            t, r = np.round(v[:3], 3), np.round(v[3:], 3)
            part = []
            if np.abs(t).max() > 1e-3:
                part.append(f"translation along {t.tolist()}")
            if np.abs(r).max() > 1e-3:
                part.append(f"rotation about {r.tolist()}")
            desc.append(" + ".join(part))
        raise SupportError(
            f"under-supported: {len(free)} rigid-body mode(s) are free ({'; '.join(desc)}). "
            "Add supports, or RigidModes ('remove_rigid_modes = true') for a body held only by loads.")


def _row_clusters(C: sp.csr_matrix, dense_row: int):
    """Rows of C with more than ``dense_row`` non-zeros (rigid-mode rows: kept as they are), and the
    connected clusters of the other rows (rows sharing columns): per cluster its row indices in C,
    its columns and its dense block."""
    from scipy.sparse.csgraph import connected_components

    nnz = np.diff(C.indptr)
    dense = np.flatnonzero(nnz > dense_row)
    sparse_rows = np.flatnonzero(nnz <= dense_row)
    Cs = C[sparse_rows]
    P = Cs.copy()
    P.data = np.ones_like(P.data)
    ncomp, label = connected_components(P @ P.T, directed=False)
    clusters = []
    for c in range(ncomp):
        rows = np.flatnonzero(label == c)
        sub = Cs[rows]
        cols = np.unique(sub.indices)
        clusters.append((sparse_rows[rows], cols, sub[:, cols].toarray()))
    return dense, clusters


def _rank_qr(A: np.ndarray, rtol: float):
    """Pivoted QR of A^T: (|diag R|, pivots, numerical rank at ``rtol``)."""
    from scipy.linalg import qr

    R, piv = qr(A.T, mode="r", pivoting=True)
    diag = np.abs(np.diag(R))
    rank = int((diag > rtol * diag[0]).sum()) if len(diag) else 0
    return diag, piv, rank


def independent_rows(C: sp.csr_matrix, rtol: float = 1e-9, dense_row: int = 10_000) -> np.ndarray:
    """Indices of a maximal linearly independent subset of the rows of C.

    Collocation with more points than the limit curve's spline space has dimensions is exactly
    rank-deficient, so dependent rows are dropped by a pivoted QR on each connected cluster of
    rows that share columns.  Rows with more than
    ``dense_row`` non-zeros (rigid-mode rows) are kept as they are."""
    if C.shape[0] == 0:
        return np.zeros(0, np.int64)
    dense, clusters = _row_clusters(C, dense_row)
    keep = [dense]
    for rows, _, A in clusters:
        _, piv, rank = _rank_qr(A, rtol)
        keep.append(rows[np.sort(piv[:rank])])
    return np.sort(np.concatenate(keep))


#: Largest condition number sigma_max / sigma_min of a cluster of constraint rows that is kept as
#: it is.  PARDISO perturbs pivots below 1e-8 of the KKT matrix's norm (``graspdef.solve.sparse``)
#: and a constraint pivot of the KKT matrix scales as sigma^2, so rows conditioned worse than
#: 1e4 = (1e-8)^(-1/2) are made well conditioned: nearly dependent rows dropped, or re-based
#: (:func:`well_conditioned_rows`).
ROW_COND_MAX = 1e4


def _leading_rows(U: np.ndarray, k: int, tie: float = 1e-8) -> np.ndarray:
    """k rows of U (r, k) that carry most of its columns' span: column-pivoted Gram-Schmidt on the
    rows, each pivot the largest remaining row norm -- ties (within ``tie``, relative) broken by the
    lowest index.  A symmetric boundary loop makes many rows tie exactly; a pivoted QR would then pick
    among them by round-off, which differs with the BLAS's thread count, and so would the rows
    dropped (:func:`well_conditioned_rows`) and the solution (by 1e-9 on the 1/8 soda can)."""
    W = np.array(U, dtype=float)
    chosen = []
    for _ in range(k):
        nrm = np.einsum("ij,ij->i", W, W)
        nrm[chosen] = -1.0
        i = int(np.flatnonzero(nrm >= (1.0 - tie) * nrm.max())[0])
        chosen.append(i)
        q = W[i] / np.sqrt(nrm[i])
        W -= np.outer(W @ q, q)
    return np.array(chosen, dtype=np.int64)


def _split(G: np.ndarray, cond_max: float) -> np.ndarray | None:
    """The rows of a cluster that carry its nearly dependent directions, from the Gram matrix of its
    rows G = A A^T (r, r): the k directions are G's eigenvectors U_S of the eigenvalues below
    lambda_max / ``cond_max``^2 (singular values of A below sigma_max / cond_max, exactly dependent
    ones included), and the k rows that carry most of them (:func:`_leading_rows`) are chosen -- the
    rest no longer hold such a combination.  Doubles k until the rest is conditioned within
    ``cond_max``.

    Returns the mask (r,) of the chosen rows (none: the cluster is independent and well
    conditioned), or None if every row would have to go.

    Only the split at eigenvalues 1e-8 of the largest is used, resolved to ~1e-16 / 1e-8 by eigh;
    the directions below it only choose the rows."""
    lam, U = np.linalg.eigh(G)                    # ascending: the smallest first
    r = len(lam)
    k = int((lam < lam[-1] / cond_max ** 2).sum())
    drop = np.zeros(r, bool)
    if k == 0:
        return drop
    while k < r:
        drop[:] = False
        drop[_leading_rows(U[:, :k], k)] = True
        lm = np.linalg.eigvalsh(G[np.ix_(~drop, ~drop)])
        if lm[-1] <= cond_max ** 2 * lm[0]:
            return drop
        k *= 2
    return None


def _distance_from_kept(G: np.ndarray, drop: np.ndarray) -> np.ndarray:
    """Distance of each chosen row (``drop``) from the span of the other rows, relative to the
    row's norm, from the Gram matrix G = A A^T: the diagonal of the Schur complement
    G_dd - G_dk G_kk^-1 G_kd (G_kk conditioned within ROW_COND_MAX^2 by :func:`_split`)."""
    from scipy.linalg import cho_factor, solve_triangular

    keep = ~drop
    L = cho_factor(G[np.ix_(keep, keep)], lower=True)[0]
    X = solve_triangular(L, G[np.ix_(keep, drop)], lower=True)
    gd = np.diag(G)[drop]
    return np.sqrt(np.clip(gd - np.einsum("ij,ij->j", X, X), 0.0, None) / gd)


def _rebased(A: np.ndarray, cond_max: float) -> tuple[np.ndarray, np.ndarray]:
    """A well-conditioned basis of the row space of the independent rows ``A`` (r, c): most rows
    kept as they are, a few replaced by dense orthonormal ones.

    The rows that carry the nearly dependent directions (:func:`_split`) are dropped and replaced
    by an orthonormal basis of the part of the row space orthogonal to the kept rows (at worst
    every row is replaced).

    Returns (indices of the rows kept, (k, c) replacement rows)."""
    # A = R^T Q^T (QR of A^T, Q's r columns an orthonormal basis of the row space): everything
    # below works on the r x r matrix R^T in that basis
    Q, R = np.linalg.qr(A.T)
    Rt = R.T
    r = len(Rt)
    drop = _split(Rt @ R, cond_max)
    if drop is None:
        return np.zeros(0, np.int64), Q.T
    k = int(drop.sum())
    if k == 0:
        return np.arange(r), np.zeros((0, A.shape[1]))
    # an orthonormal basis of the part of the row space orthogonal to the kept rows: the last k
    # columns of the complete QR of M^T, back in A's coordinates
    W = np.linalg.qr(Rt[~drop].T, mode="complete")[0][:, r - k:]
    return np.flatnonzero(~drop), W.T @ Q.T


#: Largest relative distance of a dropped nearly dependent constraint row from the span of the rows
#: kept in its cluster (:func:`well_conditioned_rows`): a constraint ``a . u = 0`` whose row lies
#: within delta |a| of the kept rows' span holds to delta |a| |u| wherever the kept rows hold.
#: Measured on the 10k pinched cylinder's diaphragm rings: delta <= 1.6e-3 (20 of 280 rows per
#: ring), the dropped rows then met to 2.1e-6 of max |u|.  A cluster whose rows cannot be dropped
#: within it is re-based instead (the same row space, dense rows).
DROP_DISTANCE_MAX = 1e-2


def well_conditioned_rows(C: sp.csr_matrix, labels: list, g: np.ndarray, rtol: float = 1e-9,
                          dense_row: int = 10_000, cond_max: float = ROW_COND_MAX,
                          drop_max: float = DROP_DISTANCE_MAX):
    """The constraints ``C u = g`` reduced to independent rows (as :func:`independent_rows`), with
    every ill-conditioned cluster of rows made well conditioned: its nearly dependent rows dropped,
    or, where that is not possible, the cluster re-based onto an orthonormal basis of its row space.

    Two-point collocation on a closed boundary loop of N edges is nearly dependent: the
    collocation functionals of the limit curve's spline space (two per edge) are exactly
    dependent for the alternating mode (dropped) and nearly so for the modes next to it, with
    singular values falling as N^-3 (measured on a 256-edge circle: sigma / sigma_max = 8.4e-8,
    6.7e-7, 2.3e-6, 5.4e-6 for the first four mode pairs, ratios 1 : 8 : 27 : 64).  Kept as they
    are, the KKT matrix's constraint pivots reach PARDISO's pivot perturbation and the inertia is
    lost (a simply supported disk at 2,652 vertices: 1511 negative pivots for 1533 constraints).
    For every cluster the rows that carry its dependent and nearly dependent directions (singular
    values below sigma_max / ``cond_max``) are chosen from the Gram matrix of its rows
    (:func:`_split`) so that the rest is conditioned within ``cond_max``, and

    * dropped, if each lies within ``drop_max`` (relative) of the kept rows' row space: the
      constraints they state then hold to that fraction wherever the kept ones hold (measured:
      2.1e-6 of max |u| on the 10k pinched cylinder, well below the support's residual between
      its collocation points), and the KKT matrix stays as sparse as the rows (at 100k control
      vertices the Gram-matrix route takes 0.95 s against 2.5 s for the QR route below);
    * otherwise (rows independent by a pivoted QR, as :func:`independent_rows`) replaced by the dense orthonormal rows that complete the kept rows to the
      cluster's row space (the same constrained displacements; each dense row couples the
      whole loop, which doubled the 100k pinched cylinder's factorisation: 34.5 against 17.5 s).

    Clusters with prescribed values (``g`` non-zero: their reactions are reported per row) and
    well-conditioned clusters keep their rows.

    Returns (C csr, labels, g)."""
    g = np.asarray(g, float)
    if C.shape[0] == 0:
        return C, list(labels), g
    dense, clusters = _row_clusters(C, dense_row)
    keep = [dense]
    new_rows, new_cols, new_vals, new_labels = [], [], [], []
    for rows, cols, A in clusters:
        if not np.any(g[rows] != 0.0):
            G = A @ A.T
            drop = _split(G, cond_max)
            if drop is not None and (not drop.any() or _distance_from_kept(G, drop).max() <= drop_max):
                keep.append(rows[~drop])
                continue
        diag, piv, rank = _rank_qr(A, rtol)
        if rank < 2 or diag[0] <= cond_max * diag[rank - 1] or np.any(g[rows] != 0.0):
            keep.append(rows[np.sort(piv[:rank])])
            continue
        sel = np.sort(piv[:rank])
        local, extra = _rebased(A[sel], cond_max)
        keep.append(rows[sel[local]])
        names = sorted({str(labels[i]).split(":")[0] for i in rows})
        for k in range(len(extra)):
            nz = np.flatnonzero(extra[k])
            new_rows.append(np.full(len(nz), len(new_labels)))
            new_cols.append(cols[nz])
            new_vals.append(extra[k, nz])
            new_labels.append(f"{', '.join(names)}: combination {k + 1}/{len(extra)} of {len(rows)} "
                              "nearly dependent rows")
    stay = np.sort(np.concatenate(keep))
    if not new_labels:
        return C[stay], [labels[i] for i in stay], g[stay]
    B = sp.csr_matrix((np.concatenate(new_vals), (np.concatenate(new_rows), np.concatenate(new_cols))),
                      shape=(len(new_labels), C.shape[1]))
    B.eliminate_zeros()
    return (sp.vstack([C[stay], B], format="csr"), [labels[i] for i in stay] + new_labels,
            np.concatenate([g[stay], np.zeros(len(new_labels))]))
