"""The Loop-subdivision basis of a control mesh, evaluated at quadrature points.

Regular faces (three vertices of valence 6) use the 12-function box-spline patch.  A face with one
or more extraordinary vertices is evaluated exactly by local subdivision: the face is split into
its four children until the child holding the point is regular, and the regular patch there is
mapped back through the products of the local subdivision matrices (Stam 1998 without the
eigen-decomposition; exact, since every quadrature point lies at a finite depth).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError
from .halfedge import HalfEdges, face_counts, interior_mask
from .patch import regular_basis
from .quadrature import triangle_rule
from .rules import refine

_MAX_DEPTH = 48
#: most local patches an ``irregular_basis`` cache holds (cleared when full)
_CACHE_SIZE = 4096


def vertex_faces(faces: np.ndarray, n_vertices: int) -> sp.csr_matrix:
    """(n_vertices, n_faces) incidence matrix."""
    f = np.asarray(faces, dtype=np.int64)
    rows = f.ravel()
    cols = np.repeat(np.arange(len(f)), 3)
    return sp.csr_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(n_vertices, len(f)))


def regular_stencils(he: HalfEdges, tri: np.ndarray) -> np.ndarray:
    """12 control vertices of each regular face ``(A, B, C)`` in the order of ``patch.LATTICE``."""
    A, B, C = tri[:, 0], tri[:, 1], tri[:, 2]
    ra = he.rings(A, B, 6)   # B, C, (-1,1), (-1,0), (0,-1), (1,-1)
    rb = he.rings(B, C, 6)   # C, A, (1,-1), (2,-1), (2,0), (1,1)
    rc = he.rings(C, A, 6)   # A, B, (1,1), (0,2), (-1,2), (-1,1)
    st = np.stack([ra[:, 4], ra[:, 3], ra[:, 5], A, ra[:, 2], rb[:, 3],
                   B, C, rc[:, 4], rb[:, 4], rb[:, 5], rc[:, 3]], axis=1)
    if (st < 0).any():
        raise MeshError("a regular face has an incomplete one-ring (open boundary without ghosts?)")
    return st


def _is_regular(tri: np.ndarray, counts: np.ndarray, inner: np.ndarray) -> np.ndarray:
    return np.all((counts[tri] == 6) & inner[tri], axis=-1)


def _child_coords(pts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Which child (0..3) of the face holds each chart point, its chart coordinates in that child
    and the sign s of d(child)/d(parent) = 2 s I."""
    v, w = pts[:, 0], pts[:, 1]
    child = np.where(v + w <= 0.5, 0, np.where(v >= 0.5, 1, np.where(w >= 0.5, 2, 3)))
    local = np.empty_like(pts)
    sign = np.ones(len(pts))
    for k, (off, s) in enumerate([((0.0, 0.0), 1.0), ((1.0, 0.0), 1.0), ((0.0, 1.0), 1.0), ((1.0, 1.0), -1.0)]):
        m = child == k
        local[m] = s * (2.0 * pts[m] - np.array(off))
        sign[m] = s
    return child, local, sign


def _local_eval(faces: np.ndarray, nv: int, target: int, pts: np.ndarray, depth: int):
    """Basis of the local control points on face ``target`` at chart points ``pts``.

    Returns dense N (q, nv), dN (q, nv, 2), ddN (q, nv, 3)."""
    if depth > _MAX_DEPTH:
        raise MeshError("Loop evaluation did not reach a regular patch (point at an extraordinary vertex?)")
    S, new_faces = refine(faces, nv)
    S = S.toarray()
    n_new = S.shape[0]
    counts = face_counts(new_faces, n_new)
    inner = interior_mask(new_faces, n_new)
    he = HalfEdges.build(new_faces, n_new)
    q = len(pts)
    N = np.zeros((q, nv))
    dN = np.zeros((q, nv, 2))
    ddN = np.zeros((q, nv, 3))
    child, local, sign = _child_coords(pts)
    for k in range(4):
        m = np.flatnonzero(child == k)
        if len(m) == 0:
            continue
        cf = new_faces[4 * target + k]
        if _is_regular(cf[None], counts, inner)[0]:
            st = regular_stencils(he, cf[None])[0]
            n12, d12, dd12 = regular_basis(local[m])
            Ssub = S[st]
            N[m] = n12 @ Ssub
            dN[m] = np.einsum("qsd,sv->qvd", d12, Ssub)
            ddN[m] = np.einsum("qsd,sv->qvd", dd12, Ssub)
        else:
            sel = np.flatnonzero(np.isin(new_faces, cf).any(axis=1))
            verts, remap = np.unique(new_faces[sel], return_inverse=True)
            sub_faces = remap.reshape(-1, 3)
            sub_target = int(np.flatnonzero(sel == 4 * target + k)[0])
            n_, d_, dd_ = _local_eval(sub_faces, len(verts), sub_target, local[m], depth + 1)
            Ssub = S[verts]
            N[m] = n_ @ Ssub
            dN[m] = np.einsum("qsd,sv->qvd", d_, Ssub)
            ddN[m] = np.einsum("qsd,sv->qvd", dd_, Ssub)
        dN[m] *= 2.0 * sign[m, None, None]
        ddN[m] *= 4.0
    return N, dN, ddN


def _canonical_patch(lf: np.ndarray, target: int) -> tuple[tuple, np.ndarray]:
    """A numbering of a local patch that depends on its connectivity only.

    Breadth-first over the faces of ``lf`` (k, 3) from face ``target`` across shared edges, each
    face entered through the edge it shares with the face it is reached from; vertices are
    numbered as they first appear.  Returns (key: the renumbered faces in visiting order, each
    starting at its entry edge -- equal keys mean the same patch up to renumbering;
    order: local vertex index of each new number).  Faces not reached are appended as they are."""
    nf = len(lf)
    across = {}
    for fi in range(nf):
        a, b, c = (int(v) for v in lf[fi])
        across[(a, b)] = fi
        across[(b, c)] = fi
        across[(c, a)] = fi
    label: dict[int, int] = {}
    seen = np.zeros(nf, bool)
    key = []
    queue = [(target, tuple(int(v) for v in lf[target]))]
    seen[target] = True
    head = 0
    while head < len(queue):
        fi, tri = queue[head]
        head += 1
        for v in tri:
            if v not in label:
                label[v] = len(label)
        key.append(tuple(label[v] for v in tri))
        for e in range(3):
            a, b = tri[e], tri[(e + 1) % 3]
            g = across.get((b, a))
            if g is not None and not seen[g]:
                seen[g] = True
                t = [int(v) for v in lf[g]]
                r = t.index(b)
                queue.append((g, (t[r], t[(r + 1) % 3], t[(r + 2) % 3])))
    for fi in np.flatnonzero(~seen):              # not edge-connected (not expected): as it is
        for v in lf[fi]:
            if int(v) not in label:
                label[int(v)] = len(label)
        key.append(tuple(label[int(v)] for v in lf[fi]))
    order = np.empty(len(label), np.int64)
    for v, k in label.items():
        order[k] = v
    return tuple(key), order


def irregular_basis(faces: np.ndarray, vf: sp.csr_matrix, face: int, pts: np.ndarray,
                    cache: dict | None = None):
    """Exact basis of one face with extraordinary vertices at chart points ``pts`` (q, 2).

    Returns (stencil (S,), N (q, S), dN (q, S, 2), ddN (q, S, 3)); the stencil is the union of the
    one-rings of the face's vertices, in increasing order.

    ``cache``: a dict shared between calls.  The basis depends only on the connectivity of the
    local patch (the faces around the face's three vertices) and on ``pts``, so faces whose
    patches are the same up to the numbering of their vertices (:func:`_canonical_patch`) share
    one local subdivision; the cached arrays are only permuted back to each face's vertices."""
    tri = faces[face]
    sel = np.unique(np.concatenate([vf.indices[vf.indptr[t]:vf.indptr[t + 1]] for t in tri]))
    verts, remap = np.unique(faces[sel], return_inverse=True)
    target = int(np.flatnonzero(sel == face)[0])
    lf = remap.reshape(-1, 3)
    pts = np.asarray(pts, float)
    if cache is None:
        N, dN, ddN = _local_eval(lf, len(verts), target, pts, 0)
        return verts, N, dN, ddN
    key, order = _canonical_patch(lf, target)
    ck = (key, pts.shape, pts.tobytes())
    hit = cache.get(ck)
    if hit is None:
        canon = np.empty(len(order), np.int64)
        canon[order] = np.arange(len(order))
        hit = _local_eval(canon[lf], len(order), target, pts, 0)
        if len(cache) >= _CACHE_SIZE:
            cache.clear()
        cache[ck] = hit
    N, dN, ddN = hit
    # canonical number k is local vertex order[k]; return columns in local (= sorted global) order
    inv = np.empty(len(order), np.int64)
    inv[order] = np.arange(len(order))
    return verts, N[:, inv], dN[:, inv], ddN[:, inv]


@dataclass(frozen=True)
class FaceGroup:
    """Faces sharing one stencil size.  ``N`` etc. have a leading axis of 1 when shared by all.

    Attributes
    ----------
    faces : (n,)          indices of the integrated faces.
    stencils : (n, S)     control-vertex indices (padding: index 0 with zero weights).
    N : (n|1, n_quad, S); dN : (n|1, n_quad, S, 2); ddN : (n|1, n_quad, S, 3)
    """

    faces: np.ndarray
    stencils: np.ndarray
    N: np.ndarray
    dN: np.ndarray
    ddN: np.ndarray

    def full(self, name: str) -> np.ndarray:
        arr = getattr(self, name)
        return np.broadcast_to(arr, (len(self.faces),) + arr.shape[1:])


@dataclass(frozen=True)
class LoopBasis:
    """Loop basis at the quadrature points of the integrated faces of a control mesh.

    Attributes
    ----------
    groups : tuple of FaceGroup      regular faces first, then irregular ones.
    qpoints : (n_quad, 2)            chart coordinates; ``qweights`` (n_quad,) sum to 1/2.
    n_control : int
    """

    groups: tuple[FaceGroup, ...]
    qpoints: np.ndarray
    qweights: np.ndarray
    n_control: int

    @property
    def n_faces(self) -> int:
        return sum(len(g.faces) for g in self.groups)


def build_basis(faces: np.ndarray, n_control: int, active: np.ndarray | None = None,
                n_quad: int = 3) -> LoopBasis:
    """Evaluate the basis on the ``active`` faces (default: all) of an oriented control mesh.

    Every vertex of an active face must have a closed one-ring (add a ghost layer first)."""
    f = np.asarray(faces, dtype=np.int64)
    act = np.arange(len(f)) if active is None else np.asarray(active, dtype=np.int64)
    counts = face_counts(f, n_control)
    inner = interior_mask(f, n_control)
    if not inner[f[act]].all():
        raise MeshError("an integrated face has a vertex with an open one-ring")
    he = HalfEdges.build(f, n_control)
    qp, qw = triangle_rule(n_quad)
    reg = _is_regular(f[act], counts, inner)
    groups = []
    rf = act[reg]
    if len(rf):
        n12, d12, dd12 = regular_basis(qp)
        groups.append(FaceGroup(rf, regular_stencils(he, f[rf]), n12[None], d12[None], dd12[None]))
    irr = act[~reg]
    if len(irr):
        vf = vertex_faces(f, n_control)
        cache: dict = {}                      # faces with the same local patch share one evaluation
        evals = [irregular_basis(f, vf, int(i), qp, cache) for i in irr]
        smax = max(len(e[0]) for e in evals)
        nq = len(qp)
        st = np.zeros((len(irr), smax), np.int64)
        N = np.zeros((len(irr), nq, smax))
        dN = np.zeros((len(irr), nq, smax, 2))
        ddN = np.zeros((len(irr), nq, smax, 3))
        for k, (s, n_, d_, dd_) in enumerate(evals):
            st[k, : len(s)] = s
            N[k, :, : len(s)] = n_
            dN[k, :, : len(s)] = d_
            ddN[k, :, : len(s)] = dd_
        groups.append(FaceGroup(irr, st, N, dN, ddN))
    return LoopBasis(tuple(groups), qp, qw, n_control)
