"""Nitsche's method for rotation-fixed edges (clamped, symmetry) at finite deformation.

At each Gauss point of such an edge the rotation measure is theta = n0 . du/dnu with the rest
normal n0 and the rest outward conormal nu.  It is linear in the displacement and *exact* at any
deformation: the edge keeps its rest slope (clamped, symmetry) exactly when the deformed tangent
across the edge has no component along n0.  The energy term is

    Pi_N(x) = sum_q w_q [ -m_nn(x) theta(x) + gamma D / (2 h) theta(x)^2 ]

with the bending moment m_nn = m^ab nu_a nu_b of the *current* state (m^ab = dW/dk_ab from the
material) -- the consistency term that makes the weak form exact at any deformation -- and the
penalty gamma D / h (D = E t^3 / (12 (1 - nu^2)) with the material's small-strain moduli, h the
edge length).  At rest its Hessian is the linear Nitsche matrix (``Problem.boundary_stiffness``).
In the Hessian, the term theta * (third derivative of W) is formed from central differences of
the material tangent (zero for Saint Venant-Kirchhoff; it vanishes at the exact solution,
theta = 0, in any case); everything else is analytic.  Using the *linearised* moment instead (the
linear Nitsche matrix as a quadratic energy) leaves a spurious edge moment m_lin(u) - m(x) at
large deformation that does not vanish under mesh refinement.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..shell.kinematics import fundamental_forms, normal, strain_hessian_contract, strain_jacobian, strains
from ..shell.model import Shell
from ..subdivision.evaluate import SurfaceEvaluator
from .supports import EdgeSupport

_CORNERS = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


class NitscheRotation:
    """The term above for every rotation-fixed edge of ``supports`` (empty if there is none)."""

    def __init__(self, shell: Shell, supports: list, ev: SurfaceEvaluator, gamma: float = 20.0, n_points: int = 3):
        self.shell = shell
        mesh = shell.mesh
        X = shell.rest_positions
        xv = np.asarray(shell.vertices, float)
        mat = shell.material
        thick = np.broadcast_to(np.asarray(shell.thickness, float), (mesh.n_real_faces,))
        t_gl, w_gl = np.polynomial.legendre.leggauss(n_points)
        taus, wts = 0.5 * (t_gl + 1.0), 0.5 * w_gl
        st_l, D_l, d_l, n0_l, c_l, w_l, pen_l, t_l = [], [], [], [], [], [], [], []
        for sup in supports:
            if not isinstance(sup, EdgeSupport) or not sup.directions()[1]:
                continue
            ab = mesh.boundary_edges
            mask = np.asarray(sup.where(xv[ab[:, 0]]), bool) & np.asarray(sup.where(xv[ab[:, 1]]), bool)
            for e in np.flatnonzero(mask):
                a, b = ab[e]
                f = int(mesh.boundary_faces[e])
                i = int(np.flatnonzero(mesh.faces[f] == a)[0])
                pts = (1 - taus)[:, None] * _CORNERS[i] + taus[:, None] * _CORNERS[(i + 1) % 3]
                st, _, dN, ddN = ev.basis(f, pts)
                h = float(np.linalg.norm(X[b] - X[a]))
                t = float(thick[f])
                Dplate = mat.E * t ** 3 / (12.0 * (1.0 - mat.nu ** 2))
                chart = _CORNERS[(i + 1) % 3] - _CORNERS[i]
                for q in range(len(taus)):
                    Dm = np.concatenate([dN[q], ddN[q]], axis=1)               # (S, 5)
                    y = Dm.T @ X[st]
                    a1, a2 = y[0], y[1]
                    n0 = np.cross(a1, a2)
                    n0 /= np.linalg.norm(n0)
                    te = chart[0] * a1 + chart[1] * a2
                    ds = np.linalg.norm(te)
                    nu_out = np.cross(te / ds, n0)
                    A = np.array([[a1 @ a1, a1 @ a2], [a1 @ a2, a2 @ a2]])
                    nu_cov = np.array([nu_out @ a1, nu_out @ a2])
                    nu_con = np.linalg.solve(A, nu_cov)
                    st_l.append(st)
                    D_l.append(Dm)
                    d_l.append(dN[q] @ nu_con)                                  # theta = n0 . sum_s d_s u_s
                    n0_l.append(n0)
                    c_l.append([nu_cov[0] ** 2, nu_cov[1] ** 2, 2.0 * nu_cov[0] * nu_cov[1]])
                    w_l.append(wts[q] * ds)
                    pen_l.append(gamma * Dplate / h)
                    t_l.append(t)
        self.n_points = len(st_l)
        self._n = shell.n_control
        if not self.n_points:
            return
        S = max(len(s) for s in st_l)
        K = self.n_points
        self._st = np.zeros((K, S), np.int64)
        self._D = np.zeros((K, S, 5))
        self._d = np.zeros((K, S))
        for k, (s, Dm, d) in enumerate(zip(st_l, D_l, d_l)):
            self._st[k, : len(s)] = s
            self._D[k, : len(s)] = Dm
            self._d[k, : len(s)] = d
        self._n0 = np.asarray(n0_l)
        self._c = np.asarray(c_l)
        self._w = np.asarray(w_l)
        self._pen = np.asarray(pen_l)
        self._t = np.asarray(t_l)[:, None]
        y0 = np.einsum("ksK,ksd->kKd", self._D, X[self._st])
        self._rest_a, self._rest_b = fundamental_forms(y0)
        a = self._rest_a
        det = a[:, 0] * a[:, 1] - a[:, 2] ** 2
        self._rest_inv = np.stack([a[:, 1] / det, a[:, 0] / det, -a[:, 2] / det], -1)
        self._X = X

    def _tangent_derivative(self, s: np.ndarray) -> np.ndarray | None:
        """d/ds of c . d2W/dk ds by central differences (None for a quadratic W)."""
        mat = self.shell.material
        if getattr(mat, "is_quadratic", False) or type(mat).__name__ == "LinearElastic":
            return None
        scale = np.where(np.arange(6) < 3, 1e-3, 1e-3 / self._t)              # strain, curvature scales
        h = 1e-5 * (np.abs(s) + scale)
        T = np.empty((len(s), 6, 6))
        for j in range(6):
            sp_, sm = s.copy(), s.copy()
            sp_[:, j] += h[:, j]
            sm[:, j] -= h[:, j]
            ap = np.einsum("ki,kij->kj", self._c, mat.density(sp_[:, None, :], self._rest_inv[:, None, :], self._t)[2][:, 0, 3:, :])
            am = np.einsum("ki,kij->kj", self._c, mat.density(sm[:, None, :], self._rest_inv[:, None, :], self._t)[2][:, 0, 3:, :])
            T[:, :, j] = (ap - am) / (2 * h[:, j:j + 1])
        return T

    def __bool__(self) -> bool:
        return self.n_points > 0

    def evaluate(self, x: np.ndarray, order: int = 2):
        """Value [J], gradient (3n,) and (order 2) Hessian (3n, 3n) at control points x."""
        n = self._n
        if not self.n_points:
            return 0.0, np.zeros(3 * n), (sp.csr_matrix((3 * n, 3 * n)) if order == 2 else None)
        X = x[self._st]                                                    # (K, S, 3)
        y = np.einsum("ksK,ksd->kKd", self._D, X)
        s = strains(y, self._rest_a, self._rest_b)
        _, dW, ddW = self.shell.material.density(s[:, None, :], self._rest_inv[:, None, :], self._t)
        dW, ddW = dW[:, 0], ddW[:, 0]
        m_nn = (self._c * dW[:, 3:]).sum(1)
        u = x - self._X
        dtheta = self._d[:, :, None] * self._n0[:, None, :]                  # (K, S, 3)
        theta = np.einsum("ksa,ksa->k", dtheta, u[self._st])
        J = strain_jacobian(y)                                             # (K, 6, 5, 3)
        G = np.einsum("kiKa,ksK->kisa", J, self._D)                        # ds/dx (K, 6, S, 3)
        cm = np.einsum("ki,kij->kj", self._c, ddW[:, 3:, :])               # d m_nn / ds (K, 6)
        dm = np.einsum("kj,kjsa->ksa", cm, G)
        w, pen = self._w, self._pen
        value = float((w * (-m_nn * theta + 0.5 * pen * theta ** 2)).sum())
        ge = w[:, None, None] * (-dm * theta[:, None, None] - m_nn[:, None, None] * dtheta
                                 + (pen * theta)[:, None, None] * dtheta)
        grad = np.zeros((n, 3))
        np.add.at(grad, self._st, ge)
        if order < 2:
            return value, grad.ravel(), None
        outer = lambda p, q: p[:, :, None, :, None] * q[:, None, :, None, :]  # noqa: E731  (K,S,S,3,3)
        blocks = w[:, None, None, None, None] * (-(outer(dm, dtheta) + outer(dtheta, dm))
                                                 + pen[:, None, None, None, None] * outer(dtheta, dtheta))
        # -theta d2 m_nn: through d2 s (analytic) and through d3 W (differences of the tangent)
        Hg = strain_hessian_contract(y, cm * (-w * theta)[:, None])        # (K, 5, 3, 5, 3)
        blocks += np.einsum("ksK,kaKLb,ktL->kstab", self._D, Hg.transpose(0, 2, 1, 3, 4), self._D)
        T = self._tangent_derivative(s)                                    # d cm / ds (K, 6, 6)
        if T is not None:
            T = 0.5 * (T + T.transpose(0, 2, 1)) * (-w * theta)[:, None, None]
            blocks += np.einsum("kjl,kjsa,kltb->kstab", T, G, G)
        rows = np.broadcast_to(3 * self._st[:, :, None, None, None] + np.arange(3)[:, None], blocks.shape).ravel()
        cols = np.broadcast_to(3 * self._st[:, None, :, None, None] + np.arange(3), blocks.shape).ravel()
        H = sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(3 * n, 3 * n))
        return value, grad.ravel(), H
