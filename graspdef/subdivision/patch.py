"""The regular Loop patch: 12 quartic box-spline basis functions on one triangle.

The chart of a face ``(A, B, C)`` is ``x(v, w)`` with ``A`` at (0, 0), ``B`` at (1, 0) and ``C`` at
(0, 1) (so ``(1-v-w, v, w)`` are barycentric coordinates).  With the lattice directions
(1, 0), (0, 1), (1, -1), the 12 control vertices sit at the integer lattice points ``LATTICE`` below;
the polynomials are those of Stam (1998), whose ordering this is.  Partition of unity and linear
precision (``sum N_i LATTICE_i = (v, w)``) are asserted in the tests.
"""
from __future__ import annotations

import numpy as np

#: lattice coordinates (v, w) of the 12 control vertices of a regular patch
LATTICE = np.array(
    [[0, -1], [-1, 0], [1, -1], [0, 0], [-1, 1], [2, -1],
     [1, 0], [0, 1], [-1, 2], [2, 0], [1, 1], [0, 2]], dtype=np.int64)

#: exponents (a, b) of the monomials v^a w^b, degree <= 4
_MONOMIALS = np.array([(a, d - a) for d in range(5) for a in range(d, -1, -1)], dtype=np.int64)

#: 12 * coefficient of each monomial in each basis function (Stam 1998, Appendix)
_COEFFS = np.array([
    [1, -2, -4, 0, 6, 6, 2, 0, -6, -4, -1, -2, 0, 2, 1],
    [1, -4, -2, 6, 6, 0, -4, -6, 0, 2, 1, 2, 0, -2, -1],
    [1, 2, -2, 0, -6, 0, -4, 0, 6, 2, 2, 4, 0, -2, -1],
    [6, 0, 0, -12, -12, -12, 8, 12, 12, 8, -1, -2, 0, -2, -1],
    [1, -2, 2, 0, -6, 0, 2, 6, 0, -4, -1, -2, 0, 4, 2],
    [0, 0, 0, 0, 0, 0, 2, 0, 0, 0, -1, -2, 0, 0, 0],
    [1, 4, 2, 6, 6, 0, -4, -6, -12, -4, -1, -2, 0, 4, 2],
    [1, 2, 4, 0, 6, 6, -4, -12, -6, -4, 2, 4, 0, -2, -1],
    [0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0, -2, -1],
    [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 2, 0, 0, 0],
    [0, 0, 0, 0, 0, 0, 2, 6, 6, 2, -1, -2, 0, -2, -1],
    [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 1],
], dtype=float) / 12.0


def _powers(x: np.ndarray, k: np.ndarray) -> np.ndarray:
    """x**k with 0**negative -> 0 (used for derivative monomials)."""
    out = np.zeros(np.broadcast(x, k).shape)
    ok = k >= 0
    out[..., :] = np.where(ok, np.power(x, np.maximum(k, 0)), 0.0)
    return out


def regular_basis(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Values and chart derivatives of the 12 regular basis functions.

    Parameters
    ----------
    points : (..., 2)
        Chart coordinates (v, w).

    Returns
    -------
    N : (..., 12)
    dN : (..., 12, 2)        d/dv, d/dw
    ddN : (..., 12, 3)       d2/dv2, d2/dw2, d2/dvdw
    """
    p = np.asarray(points, dtype=float)
    v = p[..., 0:1]
    w = p[..., 1:2]
    a = _MONOMIALS[:, 0]
    b = _MONOMIALS[:, 1]

    def mono(da: int, db: int) -> np.ndarray:
        fac = np.ones(len(a))
        for m in range(da):
            fac = fac * (a - m)
        for m in range(db):
            fac = fac * (b - m)
        return fac * _powers(v, a - da) * _powers(w, b - db)       # (..., 15)

    N = mono(0, 0) @ _COEFFS.T
    dN = np.stack([mono(1, 0) @ _COEFFS.T, mono(0, 1) @ _COEFFS.T], axis=-1)
    ddN = np.stack([mono(2, 0) @ _COEFFS.T, mono(0, 2) @ _COEFFS.T, mono(1, 1) @ _COEFFS.T], axis=-1)
    return N, dN, ddN
