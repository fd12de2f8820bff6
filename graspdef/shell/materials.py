"""Shell materials: energy density per unit rest area as a function of the strain vector.

A material receives the strain vector ``s = (e11, e22, 2e12, k11, k22, 2k12)`` (see
``kinematics``), the contravariant rest metric ``A^{ab}`` as (A^11, A^22, A^12) and the thickness,
and returns the density W and its first and second derivatives with respect to ``s``.  Materials
never see indices or control points (libshell's split).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ProblemError


def _check_finite_positive(name: str, value: float) -> None:
    if not np.isfinite(value) or value <= 0:
        raise ProblemError(f"{name} must be a positive finite number, got {value!r}")


def plane_stress_tensor(E: float, nu: float, rest_inv: np.ndarray) -> np.ndarray:
    """Voigt matrix (..., 3, 3) of C^{abcd} = E/(1-nu^2) [nu A^ab A^cd + (1-nu)/2 (A^ac A^bd + A^ad A^bc)]
    acting on (e11, e22, 2 e12)."""
    A11, A22, A12 = rest_inv[..., 0], rest_inv[..., 1], rest_inv[..., 2]
    c = E / (1.0 - nu * nu)
    h = 0.5 * (1.0 - nu)
    Aab = {(0, 0): A11, (1, 1): A22, (0, 1): A12, (1, 0): A12}
    idx = [(0, 0), (1, 1), (0, 1)]
    H = np.empty(rest_inv.shape[:-1] + (3, 3))
    for I, (a, b) in enumerate(idx):
        for K, (cc, d) in enumerate(idx):
            H[..., I, K] = c * (nu * Aab[a, b] * Aab[cc, d] + h * (Aab[a, cc] * Aab[b, d] + Aab[a, d] * Aab[b, cc]))
    return H


@dataclass(frozen=True)
class LinearElastic:
    """Isotropic plane-stress Saint Venant-Kirchhoff (Koiter) shell material.

    W = t/2 e:C:e + t^3/24 k:C:k with Green-Lagrange membrane strain e and curvature change k;
    its Hessian at rest is linear Kirchhoff-Love shell theory.

    Parameters
    ----------
    E : float   Young's modulus [Pa].
    nu : float  Poisson's ratio, 0 <= nu <= 0.5 (plane stress; 0.5 is allowed).
    """

    E: float
    nu: float

    def __post_init__(self) -> None:
        _check_finite_positive("Young's modulus E", self.E)
        if not np.isfinite(self.nu) or not (0.0 <= self.nu <= 0.5):
            raise ProblemError(f"Poisson's ratio nu must lie in [0, 0.5], got {self.nu!r}")

    def tangent(self, rest_inv: np.ndarray, thickness: np.ndarray) -> np.ndarray:
        """D (..., 6, 6) = blockdiag(t H, t^3/12 H)."""
        H = plane_stress_tensor(self.E, self.nu, rest_inv)
        t = np.asarray(thickness, dtype=float)[..., None, None]
        D = np.zeros(H.shape[:-2] + (6, 6))
        D[..., :3, :3] = t * H
        D[..., 3:, 3:] = t ** 3 / 12.0 * H
        return D

    def density(self, s: np.ndarray, rest_inv: np.ndarray, thickness: np.ndarray):
        """W (...), dW/ds (..., 6), d2W/ds2 (..., 6, 6) per unit rest area."""
        D = self.tangent(rest_inv, thickness)
        ds = np.einsum("...ij,...j->...i", D, s)
        return 0.5 * (s * ds).sum(-1), ds, D
