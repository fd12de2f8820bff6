"""Dense exact samples of a closed Loop limit surface: the limit points of the vertices of the
control mesh refined ``level`` times.

Every sample is an exact limit-surface point with an exact sparse weight row over the control
points (``W``: Loop refinement ``level`` times, then the limit masks), so a force placed at a
sample is an exact point load of the limit surface and a displacement read there is exact.  The
samples are the vertices of a triangle mesh (``faces``) whose spacing is the control mesh's edge
length / 2^level; the first ``n_control`` samples are the limit points of the control vertices.

Used where many points must be located fast (``graspdef rank``: thousands of contacts), where
projecting each onto the limit surface (``project_point``: a Gauss-Newton per face with the
exact extraordinary-vertex basis) would cost ~0.5 s a point.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError
from .halfedge import interior_mask
from .rules import limit_matrix, refine


@dataclass(frozen=True)
class LimitSamples:
    """``W`` (n_samples, n_control) csr: samples = W @ control points; ``faces`` (m, 3) the
    refined triangles over the samples; ``level`` refinements; ``vertex_faces`` (n_samples, m)
    csr incidence."""

    W: sp.csr_matrix
    faces: np.ndarray
    level: int
    vertex_faces: sp.csr_matrix

    @property
    def n(self) -> int:
        return self.W.shape[0]

    def points(self, x: np.ndarray) -> np.ndarray:
        """Sample positions (n_samples, 3) of control points ``x`` (n_control, 3)."""
        return self.W @ x

    def normals(self, P: np.ndarray) -> np.ndarray:
        """Unit area-weighted vertex normals (n_samples, 3) of the sample mesh at positions ``P``."""
        f = self.faces
        fn = np.cross(P[f[:, 1]] - P[f[:, 0]], P[f[:, 2]] - P[f[:, 0]])
        vn = self.vertex_faces @ fn
        return vn / np.linalg.norm(vn, axis=1, keepdims=True)

    def areas(self, P: np.ndarray) -> np.ndarray:
        """Area [m^2] belonging to each sample (a third of each incident triangle's)."""
        f = self.faces
        a = 0.5 * np.linalg.norm(np.cross(P[f[:, 1]] - P[f[:, 0]], P[f[:, 2]] - P[f[:, 0]]), axis=1)
        return (self.vertex_faces @ a) / 3.0


def limit_samples(faces: np.ndarray, n_control: int, level: int) -> LimitSamples:
    """Samples of the limit surface of the closed control mesh ``faces`` after ``level`` (0-4)
    refinements."""
    f = np.asarray(faces, dtype=np.int64)
    if not 0 <= int(level) <= 4:
        raise MeshError(f"sample level must be 0 to 4, got {level}")
    if not interior_mask(f, n_control).all():
        raise MeshError("limit samples need a closed control mesh (a vertex has an open one-ring)")
    S = sp.identity(n_control, format="csr")
    n = n_control
    for _ in range(int(level)):
        R, f = refine(f, n)
        S = (R @ S).tocsr()
        n = R.shape[0]
    W = (limit_matrix(f, n, np.arange(n)) @ S).tocsr()
    W.eliminate_zeros()
    m = len(f)
    vf = sp.csr_matrix((np.ones(3 * m), (f.ravel(), np.repeat(np.arange(m), 3))), shape=(n, m))
    return LimitSamples(W, f, int(level), vf)


def level_for(n_control: int, target: int = 100_000) -> int:
    """Refinements giving about ``target`` samples (each multiplies the count by ~4), 1 to 3."""
    level = int(np.ceil(np.log(max(target, 1) / max(n_control, 1)) / np.log(4.0)))
    return int(min(max(level, 1), 3))
