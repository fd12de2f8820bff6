"""Symmetric Gauss rules on the reference triangle {v, w >= 0, v + w <= 1} (area 1/2)."""
from __future__ import annotations

import numpy as np


def triangle_rule(n_points: int) -> tuple[np.ndarray, np.ndarray]:
    """Points (n, 2) in chart coordinates and weights (n,) summing to 1/2.

    ``n_points`` = 1 (degree 1), 3 (degree 2), 6 (degree 4) or 12 (degree 6, Dunavant).
    """
    if n_points == 1:
        return np.array([[1 / 3, 1 / 3]]), np.array([0.5])
    if n_points == 3:
        return np.array([[1 / 6, 1 / 6], [2 / 3, 1 / 6], [1 / 6, 2 / 3]]), np.full(3, 1 / 6)
    if n_points == 6:
        a, wa = 0.445948490915965, 0.223381589678011
        b, wb = 0.091576213509771, 0.109951743655322
        pts = [[a, a], [1 - 2 * a, a], [a, 1 - 2 * a], [b, b], [1 - 2 * b, b], [b, 1 - 2 * b]]
        return np.array(pts), 0.5 * np.array([wa] * 3 + [wb] * 3)
    if n_points == 12:
        sets = [(0.249286745170910, 0.116786275726379), (0.063089014491502, 0.050844906370207)]
        pts, wts = [], []
        for a, wa in sets:
            pts += [[a, a], [1 - 2 * a, a], [a, 1 - 2 * a]]
            wts += [wa] * 3
        c1, c2, wc = 0.310352451033785, 0.053145049844816, 0.082851075618374
        for p in [(c1, c2), (c2, c1), (1 - c1 - c2, c1), (c1, 1 - c1 - c2), (1 - c1 - c2, c2), (c2, 1 - c1 - c2)]:
            pts.append(list(p))
            wts.append(wc)
        return np.array(pts), 0.5 * np.array(wts)
    raise ValueError(f"no triangle rule with {n_points} points (use 1, 3, 6 or 12)")
