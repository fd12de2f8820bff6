"""Kirchhoff-Love kinematics of the limit surface (Cirak, Ortiz & Schroeder 2000, Sec. 2).

All functions act on ``y`` of shape (..., 5, 3): the surface derivatives
``(a_1, a_2, a_11, a_22, a_12)`` at quadrature points, linear in the control points.
The strain vector (Voigt) is ``s = (e_11, e_22, 2 e_12, k_11, k_22, 2 k_12)`` with the membrane
strain ``e = (a - A)/2`` (Green-Lagrange, covariant) and the bending strain ``k = b - B`` where
``b_ab = a_ab . n`` and capitals denote the rest state.
"""
from __future__ import annotations

import numpy as np

#: which y-block (0..4) is the second derivative a_ab for the curvature entries k_11, k_22, k_12
_CURV = ((2, 1.0), (3, 1.0), (4, 2.0))


def skew(v: np.ndarray) -> np.ndarray:
    """Cross-product matrices [v]x, (..., 3, 3)."""
    z = np.zeros(v.shape[:-1])
    return np.stack([
        np.stack([z, -v[..., 2], v[..., 1]], -1),
        np.stack([v[..., 2], z, -v[..., 0]], -1),
        np.stack([-v[..., 1], v[..., 0], z], -1)], -2)


def normal(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit normal n = a1 x a2 / |a1 x a2| (..., 3) and the area element j = |a1 x a2| (...)."""
    m = np.cross(y[..., 0, :], y[..., 1, :])
    j = np.linalg.norm(m, axis=-1)
    return m / j[..., None], j


def fundamental_forms(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Metric (a11, a22, a12) and curvature (b11, b22, b12) coefficients, each (..., 3)."""
    a1, a2 = y[..., 0, :], y[..., 1, :]
    n, _ = normal(y)
    a = np.stack([(a1 * a1).sum(-1), (a2 * a2).sum(-1), (a1 * a2).sum(-1)], -1)
    b = np.stack([(y[..., k, :] * n).sum(-1) for k in (2, 3, 4)], -1)
    return a, b


def strains(y: np.ndarray, rest_a: np.ndarray, rest_b: np.ndarray) -> np.ndarray:
    """Strain vector s (..., 6); ``rest_a``/``rest_b`` are the rest (a11, a22, a12), (b11, b22, b12)."""
    a, b = fundamental_forms(y)
    e = 0.5 * (a - rest_a)
    k = b - rest_b
    return np.concatenate([e[..., :2], 2.0 * e[..., 2:], k[..., :2], 2.0 * k[..., 2:]], -1)


def strain_jacobian(y: np.ndarray) -> np.ndarray:
    """ds/dy, (..., 6, 5, 3)."""
    a1, a2 = y[..., 0, :], y[..., 1, :]
    n, j = normal(y)
    J = np.zeros(y.shape[:-2] + (6, 5, 3))
    J[..., 0, 0, :] = a1
    J[..., 1, 1, :] = a2
    J[..., 2, 0, :] = a2
    J[..., 2, 1, :] = a1
    P = np.eye(3) - n[..., :, None] * n[..., None, :]
    for i, (blk, fac) in enumerate(_CURV):
        c = y[..., blk, :]
        g = np.einsum("...ij,...j->...i", P, c) / j[..., None]        # d(c.n)/dm
        J[..., 3 + i, blk, :] = fac * n
        J[..., 3 + i, 0, :] = fac * np.cross(a2, g)
        J[..., 3 + i, 1, :] = fac * np.cross(g, a1)
    return J


def strain_hessian_contract(y: np.ndarray, sig: np.ndarray) -> np.ndarray:
    """sum_i sig_i d2 s_i / dy2, (..., 5, 3, 5, 3), for weights ``sig`` (..., 6)."""
    a1, a2 = y[..., 0, :], y[..., 1, :]
    n, j = normal(y)
    eye = np.eye(3)
    H = np.zeros(y.shape[:-2] + (5, 3, 5, 3))
    H[..., 0, :, 0, :] += sig[..., 0, None, None] * eye
    H[..., 1, :, 1, :] += sig[..., 1, None, None] * eye
    H[..., 0, :, 1, :] += sig[..., 2, None, None] * eye
    H[..., 1, :, 0, :] += sig[..., 2, None, None] * eye
    P = eye - n[..., :, None] * n[..., None, :]
    A1, A2 = skew(a1), skew(a2)
    nn = n[..., :, None] * n[..., None, :]
    for i, (blk, fac) in enumerate(_CURV):
        wgt = (fac * sig[..., 3 + i])[..., None, None]
        c = y[..., blk, :]
        cn = (c * n).sum(-1)[..., None, None]
        g = np.einsum("...ij,...j->...i", P, c) / j[..., None]
        cnT = c[..., :, None] * n[..., None, :]
        Hm = (-cnT - np.swapaxes(cnT, -1, -2) - cn * eye + 3.0 * cn * nn) / (j ** 2)[..., None, None]
        H11 = -A2 @ Hm @ A2
        H22 = -A1 @ Hm @ A1
        H12 = -skew(g) + A2 @ Hm @ A1
        Hc1 = -(P @ A2) / j[..., None, None]
        Hc2 = (P @ A1) / j[..., None, None]
        H[..., 0, :, 0, :] += wgt * H11
        H[..., 1, :, 1, :] += wgt * H22
        H[..., 0, :, 1, :] += wgt * H12
        H[..., 1, :, 0, :] += wgt * np.swapaxes(H12, -1, -2)
        H[..., blk, :, 0, :] += wgt * Hc1
        H[..., 0, :, blk, :] += wgt * np.swapaxes(Hc1, -1, -2)
        H[..., blk, :, 1, :] += wgt * Hc2
        H[..., 1, :, blk, :] += wgt * np.swapaxes(Hc2, -1, -2)
    return H
