"""The nondimensional first-order system of the thesis (2.84)-(2.87) and its Jacobian (rate equations 2.90).

State y = (rho, eps, phi, U, V, M) as functions of the undeformed meridional arc length sigma = s0/t0:
    rho = r/t0, eps = z/t0, phi = meridian angle,
    U = rho*h = r H/(t0^2 C1), V = rho*v = r V/(t0^2 C1)  (horizontal / vertical stress resultant per radian),
    M = rho*m_xi = r M_xi/(t0^3 C1)                         (meridional couple per radian).
With the stretches l1 = lambda_xi = ds/ds0, l2 = lambda_theta = rho/rho0 and the "curvature type" strains
c1 = dphi/dsigma, c2 = sin(phi)/rho0 (thesis 2.29, 2.30):

    rho' = l1 cos(phi)          eps' = l1 sin(phi)          phi' = c1
    U'   = n_theta0 - l1 rho P_H
    V'   = - l1 rho P_V
    M'   = m_theta0 cos(phi) + l1 (U sin(phi) - V cos(phi))       (= m_theta0 cos(phi) - l1 rho q)

where (n_xi0, n_theta0, m_xi0, m_theta0) = grad phi(l1, l2, c1, c2) are the stress resultants and couples per unit
*undeformed* length (thesis 2.62-2.67, 2.76) and (l1, c1) are found from
    d phi/d l1 = n_xi0 = (U cos(phi) + V sin(phi))/rho0,   d phi/d c1 = m_xi0 = M/rho0.
Distributed loads (per radian and unit sigma), all proportional to the load factor Lam:
    l1 rho P_H = Lam [ qH l1 rho + QH rho0 - p l1 rho sin(phi) ]
    l1 rho P_V = Lam [ qV l1 rho + QV rho0 + p l1 rho cos(phi) ]
with qH, qV per unit deformed area, QH, QV per unit undeformed area (dead, conservative) and p a pressure along
the deformed normal e_n = -sin(phi) e_r + cos(phi) k (a follower load); all divided by C1.
"""
import numpy as np

from . import meridian


def rhs(material, y, geom, loads, lam, guess, jac=True):
    """Right-hand side (6, K) and, with jac, the Jacobian (6, 6, K) and d/dLam (6, K).

    geom = (rho0, phi0, k1, k2) at the points; loads = (qH, qV, QH, QV, p) arrays (K,); guess (2, K) strains.
    Returns (f, J, fl, strains(2, K))."""
    rho, eps, phi, U, V, M = y
    rho0, phi0, k1, k2 = geom
    qH, qV, QH, QV, p = loads
    c, s = np.cos(phi), np.sin(phi)
    inv0 = 1.0 / rho0
    l2 = rho * inv0
    c2 = s * inv0
    n1 = (U * c + V * s) * inv0
    m1 = M * inv0
    a, c1, _, g, H = material.invert(n1, m1, l2, c2, k1, k2, guess)
    nt, mt = g[1], g[3]
    FH1 = qH * a * rho + QH * rho0 - p * a * rho * s
    FV1 = qV * a * rho + QV * rho0 + p * a * rho * c
    f = np.array([a * c, a * s, c1, nt - lam * FH1, -lam * FV1, mt * c + a * (U * s - V * c)])
    if not jac:
        return f, None, None, np.array([a, c1])
    K = rho.shape[0]
    z = np.zeros(K)
    # dt/dy, db/dy (2, 6, K)
    dt = np.array([[z, z, (-U * s + V * c) * inv0, c * inv0, s * inv0, z], [z, z, z, z, z, inv0]])
    db = np.array([[inv0, z, z, z, z, z], [z, z, c * inv0, z, z, z]])
    Hqq = np.array([[H[0, 0], H[0, 2]], [H[2, 0], H[2, 2]]])
    Hqb = np.array([[H[0, 1], H[0, 3]], [H[2, 1], H[2, 3]]])
    Hbq = np.array([[H[1, 0], H[1, 2]], [H[3, 0], H[3, 2]]])
    Hbb = np.array([[H[1, 1], H[1, 3]], [H[3, 1], H[3, 3]]])
    rhs_q = dt - np.einsum("ijk,jlk->ilk", Hqb, db)
    det = Hqq[0, 0] * Hqq[1, 1] - Hqq[0, 1] * Hqq[1, 0]
    inv = np.array([[Hqq[1, 1], -Hqq[0, 1]], [-Hqq[1, 0], Hqq[0, 0]]]) / det
    dq = np.einsum("ijk,jlk->ilk", inv, rhs_q)
    dnm = np.einsum("ijk,jlk->ilk", Hbq, dq) + np.einsum("ijk,jlk->ilk", Hbb, db)
    da, dc1 = dq
    e = np.eye(6)[:, :, None] * np.ones(K)
    e_rho, e_phi, e_U, e_V = e[0], e[2], e[3], e[4]
    dFH = qH * (rho * da + a * e_rho) - p * (rho * s * da + a * s * e_rho + a * rho * c * e_phi)
    dFV = qV * (rho * da + a * e_rho) + p * (rho * c * da + a * c * e_rho - a * rho * s * e_phi)
    J = np.empty((6, 6, K))
    J[0] = c * da - a * s * e_phi
    J[1] = s * da + a * c * e_phi
    J[2] = dc1
    J[3] = dnm[0] - lam * dFH
    J[4] = -lam * dFV
    J[5] = dnm[1] * c - mt * s * e_phi + da * (U * s - V * c) + a * (s * e_U - c * e_V + (U * c + V * s) * e_phi)
    fl = np.array([z, z, z, -FH1, -FV1, z])
    return f, J, fl, np.array([a, c1])


def geometry_at(seg, s):
    """(rho0, phi0, k1, k2) of the batch's pieces at local arc length s (K,)."""
    rho0, _, phi0, k1, k2 = meridian.evaluate(seg["rho_a"], seg["eps_a"], seg["phi_a"], seg["kappa"], s)
    return rho0, phi0, k1, k2
