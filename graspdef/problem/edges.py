"""Which boundary edges a region selects: the one rule shared by edge supports, edge loads,
edge moments and the Nitsche rotation terms.

An edge is selected when both its end vertices satisfy the region's predicate (evaluated on the
given vertex positions [m]).  The two lips of a slit (``annulus(..., slit=...)``) have the same
vertex positions, so a predicate of position alone selects both; the optional ``side`` predicate
is evaluated at the centroid of the real face that owns each boundary edge -- the face on the
edge's inner side -- and keeps only the edges whose face satisfies it.  At a slit along
``theta = 0`` the faces of one lip have centroids at small positive ``theta`` and those of the
other at small negative ``theta``, so ``side = "theta > 0"`` picks the first lip.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..shell.model import Shell

Predicate = Callable[[np.ndarray], np.ndarray]


def face_centroids(shell: Shell, faces: np.ndarray | None = None) -> np.ndarray:
    """Centroids (k, 3) [m] of the given real faces (all by default) on the given vertices."""
    xv = np.asarray(shell.vertices, float)
    real = shell.mesh.faces[: shell.mesh.n_real_faces]
    return xv[real if faces is None else real[np.asarray(faces, np.int64)]].mean(axis=1)


def boundary_edge_mask(shell: Shell, where: Predicate, side: Predicate | None = None) -> np.ndarray:
    """Boolean mask over ``shell.mesh.boundary_edges``: both end vertices satisfy ``where`` and,
    if ``side`` is given, the centroid of the edge's owning face satisfies ``side``."""
    mesh = shell.mesh
    ab = mesh.boundary_edges
    xv = np.asarray(shell.vertices, float)
    mask = np.asarray(where(xv[ab[:, 0]]), bool) & np.asarray(where(xv[ab[:, 1]]), bool)
    if side is not None and mask.any():
        mask &= np.asarray(side(face_centroids(shell, mesh.boundary_faces)), bool)
    return mask
