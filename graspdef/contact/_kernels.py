"""Compiled distance kernels of the fingertip obstacles (numba), for the many evaluations of the
condensed finger advance over thousands of samples.  Pure functions of arrays; the numpy methods
of graspdef.contact.obstacles compute the same quantities and tests/contact compares the two.

Each takes the points P (k, 3) and a shift (3,) subtracted from every point (the obstacle's
advance s e), so no shifted copy of P is made."""
from __future__ import annotations

import numba as nb
import numpy as np


@nb.njit(cache=True, fastmath=False)
def box_distance(P, shift, c, R, h, rounding, e):
    """Rounded box (centre c, axes = columns of R, inner half extents h, edge radius rounding):
    phi (k,), outward unit normal n (k, 3), and along the unit vector e the derivatives of
    phi(p - s e) in s: -n.e (k,) and e.H.e (k,)."""
    k = P.shape[0]
    phi = np.empty(k)
    n = np.empty((k, 3))
    d1 = np.empty(k)
    d2 = np.empty(k)
    el = np.empty(3)
    for j in range(3):
        el[j] = R[0, j] * e[0] + R[1, j] * e[1] + R[2, j] * e[2]
    loc = np.empty(3)
    q = np.empty(3)
    sm = np.empty(3)
    for i in range(k):
        for j in range(3):
            loc[j] = ((P[i, 0] - shift[0] - c[0]) * R[0, j] + (P[i, 1] - shift[1] - c[1]) * R[1, j]
                      + (P[i, 2] - shift[2] - c[2]) * R[2, j])
        r2 = 0.0
        qmax = -np.inf
        dee = 0.0
        for j in range(3):
            q[j] = abs(loc[j]) - h[j]
            m = q[j] if q[j] > 0.0 else 0.0
            r2 += m * m
            sm[j] = -m if loc[j] < 0.0 else m
            if q[j] > qmax:
                qmax = q[j]
            if q[j] > 0.0:
                dee += el[j] * el[j]
        r = np.sqrt(r2)
        inside = r <= 0.0
        if r < 1e-300:
            r = 1e-300
        ne = (sm[0] * el[0] + sm[1] * el[1] + sm[2] * el[2]) / r
        phi[i] = (qmax if inside else r) - rounding
        for a in range(3):
            n[i, a] = (R[a, 0] * sm[0] + R[a, 1] * sm[1] + R[a, 2] * sm[2]) / r
        d1[i] = -ne
        d2[i] = (dee - ne * ne) / r
    return phi, n, d1, d2


@nb.njit(cache=True, fastmath=False)
def capsule_distance(P, shift, a, b, radius, e):
    """Capsule (segment a-b, radius): phi (k,), outward unit normal n (k, 3), and along the unit
    vector e the derivatives of phi(p - s e) in s: -n.e (k,) and e.H.e (k,)."""
    k = P.shape[0]
    phi = np.empty(k)
    n = np.empty((k, 3))
    d1 = np.empty(k)
    d2 = np.empty(k)
    ab = b - a
    L2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]
    ue = (ab[0] * e[0] + ab[1] * e[1] + ab[2] * e[2]) / np.sqrt(L2)
    ee = e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
    v = np.empty(3)
    for i in range(k):
        t = 0.0
        for j in range(3):
            t += (P[i, j] - shift[j] - a[j]) * ab[j]
        t /= L2
        t = min(max(t, 0.0), 1.0)
        r2 = 0.0
        for j in range(3):
            v[j] = P[i, j] - shift[j] - (a[j] + t * ab[j])
            r2 += v[j] * v[j]
        r = np.sqrt(r2)
        if r < 1e-300:
            r = 1e-300
        ne = (v[0] * e[0] + v[1] * e[1] + v[2] * e[2]) / r
        for j in range(3):
            n[i, j] = v[j] / r
        phi[i] = r - radius
        d1[i] = -ne
        d2[i] = (ee - ne * ne - (ue * ue if (t > 0.0 and t < 1.0) else 0.0)) / r
    return phi, n, d1, d2
