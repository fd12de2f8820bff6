"""Linearised strains of the shell at rest: a sparse operator from control-point displacements
to the strain vector at every quadrature point, and the principal strains and von Mises stress on
the two faces of the wall.

With ``y`` = (a1, a2, a11, a22, a12) linear in the control points, the strain vector
s = (e11, e22, 2 e12, k11, k22, 2 k12) (graspdef.shell.kinematics) linearised at rest is
s(u) = (ds/dy)(y0) . D u: one sparse matrix for all displacement fields.  The strain at the
distance z from the mid-surface is E_ab(z) = e_ab - z k_ab (covariant); its principal values are
the eigenvalues of the mixed tensor A^ac E_cb (A^ab the rest metric's inverse).  The plane-stress
von Mises stress of a linear elastic wall is then sigma_vm = sqrt(s1^2 - s1 s2 + s2^2) with
s1 = E (e1 + nu e2) / (1 - nu^2), s2 = E (e2 + nu e1) / (1 - nu^2).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .kinematics import strain_jacobian
from .model import Shell, surface_derivatives


@dataclass(frozen=True)
class StrainOperator:
    """``matrix`` (6 n_points, 3 n_control) csr: strain vectors (row 6 p + i) of a displacement;
    ``rest_inv`` (n_points, 3): A^11, A^22, A^12; ``half_thickness`` (n_points,) [m]."""

    matrix: sp.csr_matrix
    rest_inv: np.ndarray
    half_thickness: np.ndarray

    @property
    def n_points(self) -> int:
        return len(self.half_thickness)

    def principal(self, U: np.ndarray) -> np.ndarray:
        """Principal strains (2 faces, n_points, 2, k) of the displacements ``U`` (3 n_control, k)."""
        U = U.reshape(U.shape[0], -1)
        s = (self.matrix @ U).reshape(self.n_points, 6, -1)
        A11, A22, A12 = (self.rest_inv[:, i, None] for i in range(3))
        out = []
        for z in (self.half_thickness[:, None], -self.half_thickness[:, None]):
            e11 = s[:, 0] - z * s[:, 3]
            e22 = s[:, 1] - z * s[:, 4]
            e12 = 0.5 * (s[:, 2] - z * s[:, 5])
            tr = A11 * e11 + 2.0 * A12 * e12 + A22 * e22
            det = (A11 * A22 - A12 ** 2) * (e11 * e22 - e12 ** 2)
            r = np.sqrt(np.maximum(0.25 * tr ** 2 - det, 0.0))
            out.append(np.stack([0.5 * tr + r, 0.5 * tr - r], 1))
        return np.stack(out)

    def peaks(self, U: np.ndarray, E: float, nu: float) -> tuple[np.ndarray, np.ndarray]:
        """(largest principal strain magnitude (k,), largest von Mises stress [Pa] (k,)) over
        the quadrature points and both faces, for a linear elastic wall (``E`` [Pa], ``nu``)."""
        p = self.principal(U)
        e1, e2 = p[:, :, 0], p[:, :, 1]
        c = E / (1.0 - nu ** 2)
        s1, s2 = c * (e1 + nu * e2), c * (e2 + nu * e1)
        vm = np.sqrt(np.maximum(s1 ** 2 - s1 * s2 + s2 ** 2, 0.0))
        return np.abs(p).max(axis=(0, 1, 2)), vm.max(axis=(0, 1))


def linear_strain_operator(shell: Shell) -> StrainOperator:
    """The rest-state strain operator of ``shell`` at its quadrature points."""
    x0 = shell.rest_positions
    rows, cols, vals, inv, ht = [], [], [], [], []
    p0 = 0
    for g, r in zip(shell.basis.groups, shell.rest):
        nf, nq = len(g.faces), len(shell.basis.qpoints)
        y0 = surface_derivatives(g.stencils, g.dN, g.ddN, x0)                  # (f, q, 5, 3)
        J = strain_jacobian(y0)                                                  # (f, q, 6, 5, 3)
        D = np.broadcast_to(np.concatenate([g.dN, g.ddN], -1), (nf,) + g.dN.shape[1:3] + (5,))
        M = np.einsum("fqikd,fqsk->fqisd", J, D)                                 # (f, q, 6, S, 3)
        pts = p0 + np.arange(nf * nq).reshape(nf, nq)
        row = (6 * pts[:, :, None, None, None] + np.arange(6)[None, None, :, None, None])
        col = 3 * g.stencils[:, None, None, :, None] + np.arange(3)[None, None, None, None, :]
        rows.append(np.broadcast_to(row, M.shape).ravel())
        cols.append(np.broadcast_to(col, M.shape).ravel())
        vals.append(M.ravel())
        inv.append(r.rest_inv.reshape(-1, 3))
        ht.append(np.broadcast_to(0.5 * r.thickness, (nf, nq)).ravel())
        p0 += nf * nq
    mat = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                        shape=(6 * p0, shell.n_dofs))
    mat.eliminate_zeros()
    return StrainOperator(mat, np.concatenate(inv), np.concatenate(ht))
