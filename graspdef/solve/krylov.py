"""GMRES for the inexact Newton steps of :mod:`graspdef.solve.nonlinear`.

The Newton system of the current tangent is solved by GMRES preconditioned by the factorisation
of an earlier tangent (the one the modified-Newton iterations reuse): a handful of
back-substitutions instead of a fresh factorisation when the stale tangent alone contracts too
slowly.  Plain (unrestarted) GMRES with modified Gram-Schmidt (reorthogonalised once) and the small
least-squares problem solved directly: the bases are short (tens of vectors), the cost is the
operator (a sparse product and a back-substitution per iteration).
"""
from __future__ import annotations

from typing import Callable

import numpy as np


def gmres(apply: Callable[[np.ndarray], np.ndarray], b: np.ndarray, atol: float, maxiter: int,
          precondition: Callable[[np.ndarray], np.ndarray] | None = None) -> tuple[np.ndarray, int, float, bool]:
    """Right-preconditioned GMRES: minimise the true residual |b - A x| over x = M^-1 (Krylov space
    of A M^-1 and b) (x0 = 0) until it is at most ``atol``.

    Returns (x, iterations, residual norm, converged).  ``apply(v)`` is A v, ``precondition(v)``
    M^-1 v (identity if None; its images are kept, so x costs no further application).  With
    ``converged`` False, x is still the best of the ``maxiter``-dimensional space."""
    beta = float(np.linalg.norm(b))
    if beta <= atol or maxiter < 1:
        return np.zeros_like(b), 0, beta, beta <= atol
    V = [b / beta]
    Z = []
    Hs = np.zeros((maxiter + 1, maxiter))
    res = beta
    k = 0
    y = np.zeros(0)
    for j in range(maxiter):
        Z.append(V[j] if precondition is None else precondition(V[j]))
        w = apply(Z[j])
        for _ in range(2):                         # modified Gram-Schmidt, twice
            for i in range(j + 1):
                h = float(w @ V[i])
                Hs[i, j] += h
                w = w - h * V[i]
        Hs[j + 1, j] = float(np.linalg.norm(w))
        k = j + 1
        e1 = np.zeros(k + 1)
        e1[0] = beta
        y, *_ = np.linalg.lstsq(Hs[:k + 1, :k], e1, rcond=None)
        res = float(np.linalg.norm(e1 - Hs[:k + 1, :k] @ y))
        if res <= atol or Hs[j + 1, j] <= 1e-14 * beta:   # converged, or the space is invariant
            break
        V.append(w / Hs[j + 1, j])
    x = np.stack(Z[:k], 1) @ y
    return x, k, res, res <= atol
