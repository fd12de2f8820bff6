"""Shared checks for the shell tests (imported by name: pytest puts this folder on sys.path)."""
from __future__ import annotations

import numpy as np

from graspdef.testing import FD_FLOOR, assert_fd_rate  # noqa: F401  (re-exported for the tests)


def random_rotation(rng):
    """Uniformly random proper rotation (QR of a Gaussian matrix, sign-fixed)."""
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def rigid_modes(x):
    """(3n, 6) infinitesimal rigid motions of points x (n, 3): three translations and the
    rotations omega x x about the three axes."""
    n = len(x)
    modes = []
    for k in range(3):
        u = np.zeros((n, 3))
        u[:, k] = 1.0
        modes.append(u.ravel())
    for k in range(3):
        w = np.zeros(3)
        w[k] = 1.0
        modes.append(np.cross(w, x).ravel())
    return np.array(modes).T
