"""Nitsche's method for rotation-fixed edges (clamped, symmetry) at finite deformation.

At each Gauss point of such an edge the rotation measure theta is zero exactly when the edge keeps
its slope, at any deformation.  Clamped: theta = n0 . du/dnu with the rest normal n0 and the rest
outward conormal nu -- linear in the displacement and exact because the edge does not move, so
the deformed tangent across it may have no component along n0.  Symmetry: the edge moves and
turns *within* the plane (normal N), and the surface must meet the plane at right angles, i.e.
its deformed normal must lie in the plane; theta = m(x) . a_nu(x) with m = unit(a_t x N) of the
deformed edge tangent a_t (= n0 at rest up to the O(h) tilt of a coarse limit surface, see
_theta; the linearisation at rest is the clamped one, so linear solves are unchanged).  The clamped
measure n0 . du/dnu is not enough there: it leaves the tangent across the edge free in the
span of N and the *rest* edge tangent, so once the edge has turned in the plane the surface can
tilt out of it -- a partial hinge that makes a symmetry model too soft at large deformation
(the 1/8 pinched cylinder of Sze, Liu & Lo 2004, benchmarks/nonlinear).  The energy term is

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
from .edges import boundary_edge_mask
from .supports import EdgeSupport

_CORNERS = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


#: default dimensionless Nitsche penalty gamma (penalty gamma D / h); a problem file's
#: ``[solver] nitsche_gamma``
NITSCHE_GAMMA = 20.0


class NitscheRotation:
    """The term above for every rotation-fixed edge of ``supports`` (empty if there is none).

    ``gamma``: the dimensionless penalty.  The consistency term -m_nn theta is bounded by the
    penalty only while gamma D / h exceeds the *current* bending tangent's edge contribution; D is
    the small-strain one, and a hyperelastic law stiffens (the incompressible neo-Hookean's 1/d
    term under in-plane compression), so at large strain near an edge the term can lose that
    bound: the tangent gets a spurious soft mode at the edge and the energy is unbounded below
    along it.  Measured on the neo-Hookean pinched cylinder (1/8 model, 48 x 48, load point on two
    symmetry edges): with gamma = 20 the path stalls at -W_A = 20.3, where the softest mode's
    curvature is +1.54 from the shell and -1.51 from this term; with 100 and 300 it stalls later
    (load factors 0.806, 0.9575) on such modes, with 1000 it runs to the end.  The path solver
    names this term where it makes the tangent soft (``NitscheTerm.remedy``)."""

    def __init__(self, shell: Shell, supports: list, ev: SurfaceEvaluator, gamma: float = NITSCHE_GAMMA,
                 n_points: int = 3):
        self.shell = shell
        self.gamma = float(gamma)
        mesh = shell.mesh
        X = shell.rest_positions
        mat = shell.material
        thick = np.broadcast_to(np.asarray(shell.thickness, float), (mesh.n_real_faces,))
        t_gl, w_gl = np.polynomial.legendre.leggauss(n_points)
        taus, wts = 0.5 * (t_gl + 1.0), 0.5 * w_gl
        st_l, D_l, d_l, n0_l, c_l, w_l, pen_l, t_l = [], [], [], [], [], [], [], []
        tv_l, plane_l = [], []
        for sup in supports:
            if not isinstance(sup, EdgeSupport) or not sup.directions()[1]:
                continue
            dirs, _ = sup.directions()
            plane = dirs[0] if sup.kind == "symmetry" else np.zeros(3)
            ab = mesh.boundary_edges
            mask = boundary_edge_mask(shell, sup.where, sup.side)
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
                    d_l.append(dN[q] @ nu_con)                                  # a_nu = sum_s d_s x_s
                    tv_l.append(dN[q] @ chart)                                  # a_t = sum_s tv_s x_s
                    plane_l.append(plane)
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
        self._tv = np.zeros((K, S))
        for k, (s, Dm, d, tv) in enumerate(zip(st_l, D_l, d_l, tv_l)):
            self._st[k, : len(s)] = s
            self._D[k, : len(s)] = Dm
            self._d[k, : len(s)] = d
            self._tv[k, : len(s)] = tv
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
        # symmetry points: theta = (alpha m(x) + beta N) . a_nu(x) with m = sigma unit(a_t x N);
        # sigma = +-1 and n0 = alpha m(X) + beta N (see _theta)
        self._plane = np.asarray(plane_l, float)
        self._sym = np.flatnonzero(np.linalg.norm(self._plane, axis=1) > 0)
        if len(self._sym):
            k = self._sym
            at = np.einsum("ks,ksd->kd", self._tv[k], X[self._st[k]])
            c = np.cross(at, self._plane[k])
            c /= np.linalg.norm(c, axis=1)[:, None]
            self._sigma = np.where(np.einsum("kd,kd->k", c, self._n0[k]) >= 0, 1.0, -1.0)
            self._alpha = np.abs(np.einsum("kd,kd->k", c, self._n0[k]))
            self._beta = np.einsum("kd,kd->k", self._plane[k], self._n0[k])

    def _theta(self, x: np.ndarray, order: int = 0):
        """Rotation measure theta (K,), its gradient (K, S, 3) and (order 2) the second
        derivatives of the symmetry points' theta, (K_sym, S, S, 3, 3) for ``self._sym``.

        Clamped edges: theta = n0 . (a_nu - A_nu), exact because the edge stays in place.
        Symmetry edges: the plane (normal N) may not be crossed, so the deformed surface must meet
        it at right angles, i.e. its normal n = a_t x a_nu / |..| must lie in the plane; then
        a_nu lies in span(a_t, N) of the *deformed* edge tangent a_t (which turns within the plane
        at finite deformation).  m . a_nu with m = sigma unit(a_t x N) measures exactly that
        (m . a_nu = -sigma (n . N) |a_t x a_nu| / |a_t x N|); n0 . a_nu (the clamped measure)
        would instead leave a_nu free in span(t0, N) of the rest tangent t0 and let the surface
        tilt out of the plane once the edge turns.  The limit surface of a coarse arc meets the
        plane only nearly at right angles at rest (n0 . N = O(h)), so the rest normal is split,
        n0 = alpha m(X) + beta N, and theta = (alpha m(x) + beta N) . a_nu: zero at rest, and
        its linearisation there is the clamped one, n0 . du/dnu (d m / d a_t . A_nu = 0 because
        A_nu lies in span(m, N)) -- the linear Nitsche matrix is unchanged."""
        u = x - self._X
        xs = x[self._st]
        grad = self._d[:, :, None] * self._n0[:, None, :]                    # clamped: n0 d_s
        theta = np.einsum("ksa,ksa->k", grad, u[self._st])
        k = self._sym
        if not len(k):
            return theta, grad, (np.zeros((0,) + grad.shape[1:2] * 2 + (3, 3)) if order == 2 else None)
        N = self._plane[k]
        d, tv = self._d[k], self._tv[k]
        an = np.einsum("ks,ksd->kd", d, xs[k])
        at = np.einsum("ks,ksd->kd", tv, xs[k])
        c = self._sigma[:, None] * np.cross(at, N)
        r = np.linalg.norm(c, axis=1)
        m = c / r[:, None]
        vm = np.einsum("kd,kd->k", an, m)
        al, be = self._alpha, self._beta
        theta = theta.copy()
        theta[k] = al * vm + be * np.einsum("kd,kd->k", an, N)
        P_an = an - vm[:, None] * m                                          # (I - m m) a_nu
        # c = A a_t with A v = sigma (v x N) = -sigma N x v;  A^T w = sigma N x w
        g_t = self._sigma[:, None] * np.cross(N, P_an) / r[:, None]         # d (m . a_nu) / d a_t
        grad = grad.copy()
        grad[k] = (d[:, :, None] * (al[:, None] * m + be[:, None] * N)[:, None, :]
                   + tv[:, :, None] * (al[:, None] * g_t)[:, None, :])
        if order < 2:
            return theta, grad, None
        eye = np.eye(3)
        # A as a matrix: A e_j = sigma (e_j x N)
        A = self._sigma[:, None, None] * np.cross(eye[None, :, :], N[:, None, :]).transpose(0, 2, 1)
        P = eye - m[:, :, None] * m[:, None, :]
        J = np.einsum("kab,kbc->kac", P, A) / r[:, None, None]               # d m / d a_t = d2 theta / d a_nu d a_t
        hh = -(an[:, :, None] * m[:, None, :] + m[:, :, None] * an[:, None, :]
               + vm[:, None, None] * (eye - 3.0 * m[:, :, None] * m[:, None, :])) / (r ** 2)[:, None, None]
        Htt = np.einsum("kab,kbc,kcd->kad", A.transpose(0, 2, 1), hh, A)
        H = al[:, None, None, None, None] * (
             d[:, :, None, None, None] * tv[:, None, :, None, None] * J[:, None, None, :, :]
             + tv[:, :, None, None, None] * d[:, None, :, None, None] * J.transpose(0, 2, 1)[:, None, None, :, :]
             + tv[:, :, None, None, None] * tv[:, None, :, None, None] * Htt[:, None, None, :, :])
        return theta, grad, H

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
        theta, dtheta, Htheta = self._theta(x, order)                      # (K,), (K, S, 3)
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
        k = self._sym
        if len(k):                                                         # (pen theta - m_nn) d2 theta
            blocks[k] += (w * (pen * theta - m_nn))[k][:, None, None, None, None] * Htheta
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
