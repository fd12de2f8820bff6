"""A region of a shell's control vertices, and the rows of its terms' Hessians there.

A :class:`Region` is a set R of control vertices with the faces whose stencils touch R.  Its
``view`` is that face subset in the form the energy kernels read (basis groups, rest groups,
material, parallel schedules, block pattern), so :class:`~graspdef.shell.energy.ShellEnergy` and
:class:`~graspdef.shell.volume.EnclosedVolume` evaluated on it visit only those faces.  Its block
pattern writes the element blocks of rows in R into a CSR matrix of those rows (3|R| x 3n, global
columns) and every other block into scratch: the result is the rows of R of the whole shell's
Hessian, the same numbers up to the order of summation (every face that couples a vertex of R to
anything is in the subset).

The path solver uses it for local corrections (graspdef.solve.nonlinear, ``PathOptions.local_rings``):
where a tangent changes only near the point loads, the exact Hessian of that region costs a few
per cent of the whole one (on the 10k ball 16-22 ms against 160-260 ms for the 1,000-1,800
unknowns within 15-20 degrees of the poles).
"""
from __future__ import annotations

import functools
from types import SimpleNamespace

import numpy as np
import scipy.sparse as sp

from ._kernels import scalar_pattern
from .energy import ShellEnergy, _Schedule
from .model import RestGroup, Shell
from .volume import EnclosedVolume


def _adjacency(shell: Shell) -> sp.csr_matrix:
    """The control mesh's vertex adjacency (n, n), int8."""
    n = shell.n_control
    F = np.asarray(shell.mesh.faces)
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    A = sp.csr_matrix((np.ones(len(e), np.int8), (e[:, 0], e[:, 1])), shape=(n, n))
    return ((A + A.T) > 0).astype(np.int8).tocsr()


def vertex_rings(shell: Shell, seeds: np.ndarray, rings: int) -> np.ndarray:
    """Boolean mask of the control vertices within ``rings`` edges of the ``seeds`` (a boolean
    mask or indices) on the control mesh."""
    n = shell.n_control
    mask = np.zeros(n, bool)
    mask[seeds] = True
    A = shell.derived("vertex_adjacency", lambda: _adjacency(shell))
    for _ in range(int(rings)):
        grown = mask | (A @ mask.astype(np.int8) > 0)
        if np.array_equal(grown, mask):
            break
        mask = grown
    return mask


class _RowsPattern:
    """The block pattern of a region's view: element blocks (r, c) with r in R go to a CSR matrix of
    the rows of R (local rows, global columns), all other blocks that the view's faces touch to a
    scratch area after it (one slot each: blocks of one colour touch distinct slots)."""

    def __init__(self, pattern, vmask: np.ndarray, gmasks: list[np.ndarray], sizes: list[int]):
        n = pattern.n
        R = np.flatnonzero(vmask)
        loc = np.full(n, -1, np.int64)
        loc[R] = np.arange(len(R))
        rows = np.repeat(np.arange(n, dtype=np.int64), np.diff(pattern.indptr))
        inR = vmask[rows]
        pR = np.flatnonzero(inR)
        indptr = np.zeros(len(R) + 1, np.int64)
        np.add.at(indptr, loc[rows[pR]] + 1, 1)
        indptr = np.cumsum(indptr)
        self.n_rows = len(R)
        self.n_cols = n
        self.nnzb_rows = len(pR)
        itype = pattern.scalar_indptr.dtype
        self.scalar_indptr = np.empty(3 * len(R) + 1, itype)
        self.scalar_indices = np.empty(9 * len(pR), itype)
        base_r, stride_r = scalar_pattern(indptr, np.ascontiguousarray(pattern.cols[pR]),
                                          self.scalar_indptr, self.scalar_indices)
        touched = np.zeros(pattern.nnzb, bool)
        self.maps = []
        for m, gm, S in zip(pattern.maps, gmasks, sizes):
            if not gm.any():
                continue
            ms = np.ascontiguousarray(m.reshape(len(gm), S * S)[gm].ravel())
            self.maps.append(ms)
            touched[ms] = True
        junk = np.flatnonzero(touched & ~inR)
        self.base = np.zeros(pattern.nnzb, np.int64)
        self.stride = np.zeros(pattern.nnzb, np.int64)
        self.base[pR], self.stride[pR] = base_r, stride_r
        self.base[junk] = 9 * len(pR) + 9 * np.arange(len(junk), dtype=np.int64)
        self.stride[junk] = 3
        self.nnzb = len(pR) + len(junk)              # the data array's length / 9

    def csr(self, data: np.ndarray) -> sp.csr_matrix:
        M = sp.csr_matrix((data[: 9 * self.nnzb_rows], self.scalar_indices, self.scalar_indptr),
                          shape=(3 * self.n_rows, 3 * self.n_cols))
        M.has_canonical_format = True
        return M


class Region:
    """Control vertices ``vmask`` (boolean, n_control) of ``shell`` and the faces whose stencils
    touch them (see the module docstring)."""

    def __init__(self, shell: Shell, vmask: np.ndarray):
        vmask = np.asarray(vmask, bool)
        if vmask.shape != (shell.n_control,) or not vmask.any():
            raise ValueError("a region needs a non-empty boolean mask over the control vertices")
        self.vertices = np.flatnonzero(vmask)
        self.dofs = (3 * self.vertices[:, None] + np.arange(3)).ravel()
        groups, rest, gmasks = [], [], []
        for g, r in zip(shell.basis.groups, shell.rest):
            gm = np.any(vmask[g.stencils], axis=1)
            gmasks.append(gm)
            if not gm.any():
                continue

            def sub(a, gm=gm):
                return a if a.shape[0] == 1 else a[gm]
            groups.append(SimpleNamespace(faces=g.faces[gm], stencils=np.ascontiguousarray(g.stencils[gm]),
                                          N=sub(g.N), dN=sub(g.dN), ddN=sub(g.ddN)))
            rest.append(RestGroup(r.rest_a[gm], r.rest_b[gm], r.rest_inv[gm], r.weights[gm], r.thickness[gm]))
        X = np.asarray(shell.rest_positions, float)
        self.n_faces = sum(len(g.faces) for g in groups)
        self.view = SimpleNamespace(
            basis=SimpleNamespace(groups=tuple(groups), qweights=shell.basis.qweights), rest=tuple(rest),
            material=shell.material, n_control=shell.n_control, mesh=shell.mesh, rest_positions=X,
            face_schedules=tuple(_Schedule(np.ascontiguousarray(g.stencils, dtype=np.int64), X) for g in groups),
            block_pattern=_RowsPattern(shell.block_pattern, vmask, gmasks,
                                       [g.stencils.shape[1] for g in shell.basis.groups]))
        # the rows' entries in the columns of R: the region's own block (local numbering)
        inR = np.zeros(shell.n_dofs, bool)
        inR[self.dofs] = True
        pat = self.view.block_pattern
        keep = inR[pat.scalar_indices]
        self._rr_pos = np.flatnonzero(keep)
        local = np.full(shell.n_dofs, -1, np.int64)
        local[self.dofs] = np.arange(len(self.dofs))
        kept = np.concatenate([[0], np.cumsum(keep, dtype=np.int64)])
        self._rr_indptr = kept[pat.scalar_indptr].astype(pat.scalar_indptr.dtype)
        self._rr_indices = local[pat.scalar_indices[keep]].astype(pat.scalar_indices.dtype)

    @functools.cached_property
    def energy(self) -> ShellEnergy:
        """The shell energy on the region's faces."""
        return ShellEnergy(self.view)

    @functools.cached_property
    def volume(self) -> EnclosedVolume:
        """The enclosed-volume functional on the region's faces."""
        return EnclosedVolume(self.view, self.view.block_pattern)

    def own_block(self, rows: sp.csr_matrix) -> sp.csr_matrix:
        """The R x R block (local numbering) of a matrix of the region's rows (this region's
        pattern, as :attr:`energy` and :attr:`volume` return it)."""
        m = len(self.dofs)
        A = sp.csr_matrix((rows.data[self._rr_pos], self._rr_indices, self._rr_indptr), shape=(m, m))
        A.has_canonical_format = True
        return A
