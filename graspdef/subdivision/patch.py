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


def _derivative_monomials(da: int, db: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """d^(da+db)/dv^da dw^db of the monomials v^a w^b: (factor (15,), exponent of v (15,), of w
    (15,)), the factor zero and the exponents clipped to 0 where a derivative removes the monomial."""
    a, b = _MONOMIALS[:, 0], _MONOMIALS[:, 1]
    fac = np.ones(len(a))
    for m in range(da):
        fac = fac * (a - m)
    for m in range(db):
        fac = fac * (b - m)
    return fac, np.maximum(a - da, 0), np.maximum(b - db, 0)


#: (factor, v exponent, w exponent) of the value, d/dv, d/dw, d2/dv2, d2/dw2, d2/dvdw monomials
_DERIVATIVES = [_derivative_monomials(*d) for d in ((0, 0), (1, 0), (0, 1), (2, 0), (0, 2), (1, 1))]
_EXPONENTS = np.arange(5)


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
    vp = np.power(p[..., 0:1], _EXPONENTS)           # v^0 .. v^4 (..., 5), once for all six
    wp = np.power(p[..., 1:2], _EXPONENTS)
    C = _COEFFS.T
    out = [(fac * vp[..., ia] * wp[..., ib]) @ C for fac, ia, ib in _DERIVATIVES]
    return out[0], np.stack(out[1:3], axis=-1), np.stack(out[3:], axis=-1)
