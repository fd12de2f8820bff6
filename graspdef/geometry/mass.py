"""Mass properties of a grasped object: a thin shell (areal density over its surface) or a solid
(density over its enclosed volume).  SI: kg, m, kg m^2."""
from __future__ import annotations

import numpy as np


def shell_inertia(vertices: np.ndarray, faces: np.ndarray, areal_density: float):
    """Mass [kg], centre of mass [m] and inertia tensor about it [kg m^2] of a thin shell of
    areal density rho * t [kg/m^2] spread over the triangle surface (exact for the triangles:
    int x x^T dA over a triangle = A/12 (sum_i v_i v_i^T + s s^T), s = sum_i v_i)."""
    tri = np.asarray(vertices, float)[np.asarray(faces)]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    s = tri.sum(axis=1)
    m = areal_density * area.sum()
    com = areal_density * (area[:, None] * s / 3).sum(axis=0) / m
    S = areal_density * np.einsum("f,fij->ij", area / 12,
                                  np.einsum("fvi,fvj->fij", tri, tri) + np.einsum("fi,fj->fij", s, s))
    S -= m * np.outer(com, com)
    return float(m), com, np.trace(S) * np.eye(3) - S


def solid_inertia(vertices: np.ndarray, faces: np.ndarray, density: float):
    """Mass [kg], centre of mass [m] and inertia tensor about it [kg m^2] of the solid a closed,
    outward-oriented triangle surface encloses, of uniform ``density`` [kg/m^3] (trimesh)."""
    import trimesh  # here, not at import (start-up)

    mesh = trimesh.Trimesh(vertices, faces, process=False)
    mesh.density = density
    return float(mesh.mass), np.asarray(mesh.center_mass), np.asarray(mesh.moment_inertia)
