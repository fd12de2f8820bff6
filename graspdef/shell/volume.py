"""Enclosed volume of a closed limit surface as a function of the control points.

    V(x) = 1/3 int x . n dA = 1/3 sum_faces sum_q w_q  x_q . (a1_q x a2_q)

(divergence theorem; w_q are the chart quadrature weights).  V is the potential of a follower
pressure (-p V) and the state variable of an enclosed gas.  The value, gradient and Hessian are
those of this one discrete functional, so Newton's method sees an exactly consistent tangent.
For an oriented closed surface with outward normals V > 0.

Hessian block of control points (s, t): the skew matrix [v_st]_x with
    v_st = sum_q w_q/3 [ a2 (dN1_s N_t - N_s dN1_t) + a1 (N_s dN2_t - dN2_s N_t)
                         + x (dN2_s dN1_t - dN1_s dN2_t) ],
antisymmetric in (s, t), so the assembled Hessian is symmetric.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .energy import BlockPattern
from .kinematics import skew
from .model import Shell

_CHUNK = 4096


class EnclosedVolume:
    """Volume functional of a shell's limit surface (all real faces, or a boolean face mask)."""

    def __init__(self, shell: Shell, pattern: BlockPattern | None = None):
        self.shell = shell
        self._pattern = pattern

    @property
    def pattern(self) -> BlockPattern:
        if self._pattern is None:
            self._pattern = BlockPattern(self.shell)
        return self._pattern

    def _chunks(self):
        for g in self.shell.basis.groups:
            for start in range(0, len(g.faces), _CHUNK):
                sl = slice(start, min(len(g.faces), start + _CHUNK))
                N = g.N if g.N.shape[0] == 1 else g.N[sl]
                dN = g.dN if g.dN.shape[0] == 1 else g.dN[sl]
                yield g, sl, N, dN

    def _fields(self, g, sl, N, dN, x):
        X = x[g.stencils[sl]]                                     # (f, S, 3)
        nf = len(X)
        N = np.broadcast_to(N, (nf,) + N.shape[1:])
        dN = np.broadcast_to(dN, (nf,) + dN.shape[1:])
        p = np.einsum("fqs,fsd->fqd", N, X)
        a1 = np.einsum("fqs,fsd->fqd", dN[..., 0], X)
        a2 = np.einsum("fqs,fsd->fqd", dN[..., 1], X)
        return N, dN, p, a1, a2

    def value(self, x: np.ndarray) -> float:
        """V [m^3] at control points ``x`` (n_control, 3) [m]."""
        w = self.shell.basis.qweights / 3.0
        V = 0.0
        for g, sl, N, dN in self._chunks():
            _, _, p, a1, a2 = self._fields(g, sl, N, dN, x)
            V += float(np.einsum("fqd,fqd,q->", p, np.cross(a1, a2), w))
        return V

    def gradient(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """V and dV/dx (3 n_control,) [m^2]."""
        w = self.shell.basis.qweights / 3.0
        V = 0.0
        grad = np.zeros((self.shell.n_control, 3))
        for g, sl, N, dN in self._chunks():
            N, dN, p, a1, a2 = self._fields(g, sl, N, dN, x)
            m = np.cross(a1, a2)
            V += float(np.einsum("fqd,fqd,q->", p, m, w))
            ge = (np.einsum("fqs,fqd,q->fsd", N, m, w)
                  + np.einsum("fqs,fqd,q->fsd", dN[..., 0], np.cross(a2, p), w)
                  + np.einsum("fqs,fqd,q->fsd", dN[..., 1], np.cross(p, a1), w))
            np.add.at(grad, g.stencils[sl], ge)
        return V, grad.ravel()

    def hessian(self, x: np.ndarray) -> tuple[float, np.ndarray, sp.csr_matrix]:
        """V, dV/dx and d2V/dx2 (3 n_control, 3 n_control) [m] on the shell's block pattern."""
        w = self.shell.basis.qweights / 3.0
        V = 0.0
        grad = np.zeros((self.shell.n_control, 3))
        blocks: list[list] = [[] for _ in self.shell.basis.groups]
        gi_of = {id(g): i for i, g in enumerate(self.shell.basis.groups)}
        for g, sl, N, dN in self._chunks():
            N, dN, p, a1, a2 = self._fields(g, sl, N, dN, x)
            m = np.cross(a1, a2)
            V += float(np.einsum("fqd,fqd,q->", p, m, w))
            d1, d2 = dN[..., 0], dN[..., 1]
            ge = (np.einsum("fqs,fqd,q->fsd", N, m, w)
                  + np.einsum("fqs,fqd,q->fsd", d1, np.cross(a2, p), w)
                  + np.einsum("fqs,fqd,q->fsd", d2, np.cross(p, a1), w))
            np.add.at(grad, g.stencils[sl], ge)
            wa2 = a2 * w[None, :, None]
            wa1 = a1 * w[None, :, None]
            wp = p * w[None, :, None]
            A = np.einsum("fqs,fqt,fqd->fstd", d1, N, wa2)
            B = np.einsum("fqs,fqt,fqd->fstd", N, d2, wa1)
            Cc = np.einsum("fqs,fqt,fqd->fstd", d2, d1, wp)
            v = (A - A.transpose(0, 2, 1, 3)) + (B - B.transpose(0, 2, 1, 3)) + (Cc - Cc.transpose(0, 2, 1, 3))
            blocks[gi_of[id(g)]].append((sl, np.ascontiguousarray(skew(v))))
        return V, grad.ravel(), self.pattern.assemble(blocks)
