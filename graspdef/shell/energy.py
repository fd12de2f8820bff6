"""Total elastic energy of a shell, its gradient and its Hessian, from one code path.

E(x) = sum_faces sum_q w_q J_q W(s(y(x)))  with y linear in the control points x (n_control, 3).
Gradient and Hessian apply the chain rule through ``kinematics``; the Hessian is assembled into a
3x3-block sparse matrix through an index map built once.  The linear problem is this Hessian at
the rest state.

Two implementations of the same sums:

* the compiled path (``energy``, ``gradient``, ``hessian``): ``_kernels.point_strains`` gives
  y and the strains, the material's ``density`` (numpy) their energy density and derivatives,
  and ``_kernels.assemble_elements`` forms per quadrature point the 15 x 15 Hessian with respect
  to y and contracts it with the basis derivatives, writing straight into the CSR data (faces in
  spatially compact blocks, blocks coloured so that blocks of one colour share no control
  vertex and run in parallel);
* the numpy reference path (``_local``, used by the ``_*_reference`` methods and the tests),
  through ``kinematics.strain_jacobian`` / ``strain_hessian_contract`` and
  ``_kernels.material_hessian_blocks``.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ._kernels import (
    assemble_elements,
    block_positions,
    material_hessian_blocks,
    point_strains,
    scalar_pattern,
    scatter_blocks,
)
from .kinematics import strain_hessian_contract, strain_jacobian, strains
from .model import Shell, surface_derivatives

_CHUNK = 8192

#: faces per block of the compiled assembly (blocks of one colour run in parallel)
_BLOCK = 128


def _morton_order(points: np.ndarray) -> np.ndarray:
    """Permutation sorting points (n, 3) along a Z-order (Morton) curve of 2^10 cells per axis."""
    lo = points.min(0)
    ext = float((points.max(0) - lo).max())
    cell = np.clip(((points - lo) / (ext if ext > 0 else 1.0) * 1023.0).astype(np.int64), 0, 1023)

    def spread(v):                                   # 10 bits -> every third of 30 bits
        v = (v | (v << 16)) & 0x030000FF
        v = (v | (v << 8)) & 0x0300F00F
        v = (v | (v << 4)) & 0x030C30C3
        return (v | (v << 2)) & 0x09249249

    code = spread(cell[:, 0]) | (spread(cell[:, 1]) << 1) | (spread(cell[:, 2]) << 2)
    return np.argsort(code, kind="stable")


class _Schedule:
    """Parallel schedule of one face group: faces in Morton order of their stencil centroids, cut
    into blocks of ``_BLOCK`` faces; blocks greedily coloured so that two blocks of one colour
    share no control vertex (their element matrices touch disjoint rows)."""

    def __init__(self, stencils: np.ndarray, x0: np.ndarray):
        nf = len(stencils)
        self.order = _morton_order(x0[stencils].mean(1)).astype(np.int64)
        nb = max(1, -(-nf // _BLOCK))
        self.bstart = np.minimum(np.arange(nb + 1) * _BLOCK, nf).astype(np.int64)
        block_of = np.empty(nf, np.int64)
        block_of[self.order] = np.arange(nf) // _BLOCK
        S = stencils.shape[1]
        inc = sp.csr_matrix((np.ones(nf * S, np.int8), (np.repeat(block_of, S), stencils.ravel())),
                            shape=(nb, int(stencils.max()) + 1 if nf else 1))
        inc.data[:] = 1
        adj = (inc.astype(np.int32) @ inc.T.astype(np.int32)).tocsr()
        colour = np.full(nb, -1, np.int64)
        for b in range(nb):                          # greedy, in curve order
            used = colour[adj.indices[adj.indptr[b]:adj.indptr[b + 1]]]
            c = 0
            taken = set(used[used >= 0].tolist())
            while c in taken:
                c += 1
            colour[b] = c
        self.cblocks = np.argsort(colour, kind="stable").astype(np.int64)
        self.cstart = np.searchsorted(colour[self.cblocks], np.arange(colour.max() + 2)).astype(np.int64)
        self.n_colours = int(colour.max() + 1)


class _GroupData:
    """Contiguous basis derivatives of one face group for the kernels and its schedule."""

    def __init__(self, g, schedule: "_Schedule"):
        self.stencils = np.ascontiguousarray(g.stencils, dtype=np.int64)
        self.D = np.ascontiguousarray(np.concatenate([g.dN, g.ddN], axis=-1), dtype=float)   # (f|1, q, S, 5)
        S = self.D.shape[2]
        self.Dt = np.zeros(self.D.shape[:2] + (5, -(-S // 4) * 4))                          # (f|1, q, 5, S4)
        self.Dt[..., :S] = np.swapaxes(self.D, -1, -2)
        self.dstride = 0 if g.dN.shape[0] == 1 else 1
        self.schedule = schedule


class BlockPattern:
    """Sparsity pattern of the control-point coupling (vertex pairs sharing a stencil)."""

    def __init__(self, shell: Shell):
        n = shell.n_control
        rows, cols, off = [], [], 0
        for g in shell.basis.groups:                  # face-vertex incidence P; pattern = P P^T
            rows.append(g.stencils.ravel())
            cols.append(np.repeat(np.arange(off, off + len(g.stencils)), g.stencils.shape[1]))
            off += len(g.stencils)
        P = sp.csr_matrix((np.ones(sum(len(r) for r in rows), np.int32),
                           (np.concatenate(rows), np.concatenate(cols))), shape=(n, off))
        G = (P @ P.T).tocsr()
        G.sort_indices()
        self.indptr = G.indptr.astype(np.int64)
        self.cols = G.indices.astype(np.int64)
        self.maps = [block_positions(np.ascontiguousarray(g.stencils), self.indptr, self.cols)
                     for g in shell.basis.groups]
        self.n = n
        self.nnzb = len(self.cols)
        # scalar CSR of the 3x3-block pattern: block p (row r, k-th in its row, L blocks in the
        # row) holds entry (a, b) at  9 indptr[r] + 3 L a + 3 k + b  (_kernels.scalar_pattern)
        # index arrays in the dtype scipy keeps (int32 when it fits), so that every CSR matrix on
        # this pattern shares them: sums on the same pattern are then cheap (see solve.equilibrium)
        itype = np.int32 if 9 * self.nnzb < 2 ** 31 else np.int64
        self.scalar_indptr = np.empty(3 * n + 1, itype)
        self.scalar_indices = np.empty(9 * self.nnzb, itype)
        self.base, self.stride = scalar_pattern(self.indptr, self.cols, self.scalar_indptr, self.scalar_indices)

    def csr(self, data: np.ndarray) -> sp.csr_matrix:
        """The (3 n, 3 n) CSR matrix of this pattern with ``data`` (in CSR order), flagged as in
        canonical format -- sorted, no duplicate entries: so the pattern is built (G's sorted block
        columns, 3 x 3 blocks written row by row), and scipy would otherwise check it with a pass over
        the indices of every matrix (the round-off level and the tangent's one-pass sum need it)."""
        M = sp.csr_matrix((data, self.scalar_indices, self.scalar_indptr), shape=(3 * self.n, 3 * self.n))
        M.has_canonical_format = True
        return M

    def assemble(self, group_blocks: list[list[tuple[np.ndarray, np.ndarray]]]) -> sp.csr_matrix:
        """Sum element blocks into a CSR matrix; ``group_blocks[g]`` lists (face_slice, blocks
        (nf, S, S, 3, 3)) chunks in face order."""
        data = np.zeros(9 * self.nnzb)
        for gi, chunks in enumerate(group_blocks):
            m = self.maps[gi]
            for sl, blk in chunks:
                S = blk.shape[1]
                scatter_blocks(data, m[sl.start * S * S: sl.stop * S * S], blk, self.base, self.stride)
        return self.csr(data)


def block_pattern(shell: Shell) -> BlockPattern:
    """The shell's :class:`BlockPattern` (``Shell.block_pattern``: built once per immutable shell,
    shared by the energy, the enclosed volume and the other terms of one problem)."""
    return shell.block_pattern


class ShellEnergy:
    """Elastic energy of a :class:`Shell` as a function of the control points."""

    def __init__(self, shell: Shell):
        self.shell = shell
        self._pattern: BlockPattern | None = None
        self._gdata: list[_GroupData] | None = None

    @property
    def pattern(self) -> BlockPattern:
        if self._pattern is None:
            self._pattern = block_pattern(self.shell)
        return self._pattern

    def concurrent(self) -> bool:
        """Whether an evaluation runs in serial code only -- every kernel on its ahead-of-time
        build, which releases the GIL (graspdef.compiled), the material's density there or in
        numpy -- so that it may run in a thread beside other terms' evaluations: never where a
        kernel would take numba's parallel build (two threads launching parallel regions at once
        is not safe on every numba threading layer)."""
        serial_at = getattr(self.shell.material, "serial_at", None)      # (numpy materials: always)
        for gd, r in zip(self._groups, self.shell.rest):
            nf = gd.stencils.shape[0]
            if not (point_strains.ahead_of_time(nf) and assemble_elements.ahead_of_time(nf)):
                return False
            if serial_at is not None and not serial_at(int(np.prod(r.weights.shape))):
                return False
        return True

    def _chunks(self):
        for g, r in zip(self.shell.basis.groups, self.shell.rest):
            nf = len(g.faces)
            for start in range(0, nf, _CHUNK):
                sl = slice(start, min(nf, start + _CHUNK))
                yield g, r, sl

    def _local(self, g, r, sl, x, order: int):
        st = g.stencils[sl]
        dN = g.dN if g.dN.shape[0] == 1 else g.dN[sl]
        ddN = g.ddN if g.ddN.shape[0] == 1 else g.ddN[sl]
        y = surface_derivatives(st, dN, ddN, x)
        s = strains(y, r.rest_a[sl], r.rest_b[sl])
        W, dW, ddW = self.shell.material.density(s, r.rest_inv[sl], r.thickness[sl])
        w = r.weights[sl]
        if order == 0:
            return (w * W).sum()
        D = np.broadcast_to(np.concatenate([dN, ddN], axis=-1), (len(st),) + dN.shape[1:3] + (5,))
        nf, nq, S = D.shape[:3]
        J = strain_jacobian(y)                                            # (f, q, 6, 5, 3) ds/dy
        dstride = 0 if dN.shape[0] == 1 else 1
        Dc = np.concatenate([dN, ddN], axis=-1)                           # (f|1, q, S, 5)
        if np.any(dW):
            ge = np.einsum("fqi,fqiKa,fqsK->fsa", dW * w[..., None], J, D, optimize=True)
        else:                                                             # at rest: no stress
            ge = np.zeros((nf, S, 3))
        if order == 1:
            return (w * W).sum(), ge
        if np.any(dW):                                                    # geometric (stress) part
            Hg = strain_hessian_contract(y, dW * w[..., None])            # (f, q, 5, 3, 5, 3)
            He = material_hessian_blocks(np.ascontiguousarray(Dc), J, ddW * w[..., None, None], dstride,
                                         np.ascontiguousarray(Hg))
        else:
            He = material_hessian_blocks(np.ascontiguousarray(Dc), J, ddW * w[..., None, None], dstride)
        return (w * W).sum(), ge, He

    # -------------------------------------------------------------------- compiled path
    @property
    def _groups(self) -> list[_GroupData]:
        if self._gdata is None:
            self._gdata = [_GroupData(g, sch) for g, sch in zip(self.shell.basis.groups, self.shell.face_schedules)]
        return self._gdata

    def _points(self, x: np.ndarray, order: int):
        """Per group: (group data, rest group, y, W, dW, ddW) at control points x; dW, ddW may be
        None below ``order`` 1, 2 (materials with ``_evaluate`` compute only what is asked)."""
        x = np.ascontiguousarray(x, dtype=float).reshape(self.shell.n_control, 3)
        mat = self.shell.material
        evaluate = getattr(mat, "_evaluate", None)
        for gd, r in zip(self._groups, self.shell.rest):
            y, s = point_strains(x, gd.stencils, gd.D, gd.dstride, r.rest_a, r.rest_b)
            if evaluate is not None:
                W, dW, ddW = evaluate(s, r.rest_inv, r.thickness, order)
            else:
                W, dW, ddW = mat.density(s, r.rest_inv, r.thickness)
            yield gd, r, y, W, dW, ddW

    def _assemble(self, x: np.ndarray, hess: bool):
        E = 0.0
        grad = np.zeros((self.shell.n_control, 3))
        pat = self.pattern if hess else None
        bdata = np.zeros(9 * pat.nnzb) if hess else np.zeros(1)
        empty = np.zeros(1, np.int64)
        base, stride = (pat.base, pat.stride) if hess else (empty, empty)
        for gi, (gd, r, y, W, dW, ddW) in enumerate(self._points(x, 2 if hess else 1)):
            E += (r.weights * W).sum()
            dW = np.ascontiguousarray(dW, dtype=float)
            ddW = np.ascontiguousarray(ddW, dtype=float) if hess else np.zeros((1, 1, 6, 6))
            sc = gd.schedule
            assemble_elements(y, np.ascontiguousarray(r.weights, dtype=float), dW, ddW, gd.D, gd.Dt,
                              gd.dstride, gd.stencils, sc.order, sc.bstart, sc.cblocks, sc.cstart,
                              pat.maps[gi] if hess else empty, base, stride, grad, bdata, hess)
        return float(E), grad, bdata

    def _csr(self, data: np.ndarray) -> sp.csr_matrix:
        """The pattern's CSR matrix with ``data`` (already in CSR order: see ``assemble_elements``)."""
        return self.pattern.csr(data)

    def energy(self, x: np.ndarray) -> float:
        """Total elastic energy [J] at control points ``x`` (n_control, 3) [m]."""
        return float(sum((r.weights * W).sum() for _, r, _, W, _, _ in self._points(x, 0)))

    def face_energies(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Elastic energy [J] and rest area [m^2] of every face of the control mesh (faces
        without quadrature -- ghosts -- get 0)."""
        nf = len(self.shell.mesh.faces)
        E, A = np.zeros(nf), np.zeros(nf)
        for (_, r, _, W, _, _), g in zip(self._points(x, 0), self.shell.basis.groups):
            E[g.faces] = (r.weights * W).sum(axis=1)
            A[g.faces] = r.weights.sum(axis=1)
        return E, A

    def vertex_energy_density(self, x: np.ndarray) -> np.ndarray:
        """Strain energy per unit rest area [J/m^2] at each real control vertex: a third of the
        energy of each incident real face over a third of its rest area (so that the density
        times the vertex's area sums to the total energy)."""
        mesh = self.shell.mesh
        E, A = self.face_energies(x)
        faces = mesh.faces[: mesh.n_real_faces]
        num, den = np.zeros(mesh.n_real), np.zeros(mesh.n_real)
        np.add.at(num, faces, np.repeat(E[: mesh.n_real_faces, None] / 3, 3, axis=1))
        np.add.at(den, faces, np.repeat(A[: mesh.n_real_faces, None] / 3, 3, axis=1))
        return num / np.where(den > 0, den, 1.0)

    def gradient(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """Energy and gradient (3 n_control,) [N]."""
        E, grad, _ = self._assemble(x, False)
        return E, grad.ravel()

    def hessian(self, x: np.ndarray) -> tuple[float, np.ndarray, sp.csr_matrix]:
        """Energy, gradient and Hessian (3 n_control, 3 n_control) [N/m] at ``x``."""
        E, grad, bdata = self._assemble(x, True)
        return E, grad.ravel(), self._csr(bdata)

    # -------------------------------------------------------------------- numpy reference path
    def _energy_reference(self, x: np.ndarray) -> float:
        return float(sum(self._local(g, r, sl, x, 0) for g, r, sl in self._chunks()))

    def _gradient_reference(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        E = 0.0
        grad = np.zeros((self.shell.n_control, 3))
        for g, r, sl in self._chunks():
            e, ge = self._local(g, r, sl, x, 1)
            E += e
            np.add.at(grad, g.stencils[sl], ge)
        return float(E), grad.ravel()

    def _hessian_reference(self, x: np.ndarray) -> tuple[float, np.ndarray, sp.csr_matrix]:
        E = 0.0
        grad = np.zeros((self.shell.n_control, 3))
        blocks: list[list] = [[] for _ in self.shell.basis.groups]
        gi_of = {id(g): i for i, g in enumerate(self.shell.basis.groups)}
        for g, r, sl in self._chunks():
            e, ge, He = self._local(g, r, sl, x, 2)
            E += e
            np.add.at(grad, g.stencils[sl], ge)
            blocks[gi_of[id(g)]].append((sl, He))
        return float(E), grad.ravel(), self.pattern.assemble(blocks)
