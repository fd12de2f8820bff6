"""Point-to-surface distances with open3d's ray-casting scene, made exact to float64 precision.

``RaycastingScene`` works in float32: on a 5 cm object in metres its distances were off by up to
59 µm (../shared/MEASURED.md).  So queries are made in millimetres about the surface's centroid
(float32 then resolves ~1e-5 mm on a 10 cm object), and the distance is recomputed in float64
from the closest point it returns.
"""

from __future__ import annotations

import numpy as np

from graspdef.geometry import TriMesh


class SurfaceDistance:
    """Distance queries to one triangle surface.

    Parameters
    ----------
    mesh : TriMesh
        The surface [m]; faces oriented outward (the sign convention of :meth:`signed`).
    """

    def __init__(self, mesh: TriMesh):
        from graspdef.registration.icp import _o3d

        o3d = _o3d()

        self.mesh = mesh
        self._origin = mesh.vertices.mean(axis=0)
        local = (mesh.vertices - self._origin) * 1e3
        self._scene = o3d.t.geometry.RaycastingScene()
        self._scene.add_triangles(o3d.core.Tensor(local.astype(np.float32)),
                                  o3d.core.Tensor(mesh.faces.astype(np.uint32)))
        self._o3c = o3d.core

    def closest(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Closest surface points [m], face normals there, and face ids, for points (n, 3) [m]."""
        local = ((np.asarray(points, dtype=np.float64) - self._origin) * 1e3).astype(np.float32)
        ans = self._scene.compute_closest_points(self._o3c.Tensor(local))
        closest = ans["points"].numpy().astype(np.float64) * 1e-3 + self._origin
        return closest, ans["primitive_normals"].numpy().astype(np.float64), \
            ans["primitive_ids"].numpy().astype(np.int64)

    def unsigned(self, points: np.ndarray) -> np.ndarray:
        """Unsigned distance [m] from each point to the surface, shape (n,)."""
        closest = self.closest(points)[0]
        return np.linalg.norm(np.asarray(points, dtype=np.float64) - closest, axis=1)

    def signed(self, points: np.ndarray) -> np.ndarray:
        """Signed distance [m]: positive outside (on the side the closest face's normal points
        to), negative inside, shape (n,)."""
        points = np.asarray(points, dtype=np.float64)
        closest, normals, _ = self.closest(points)
        diff = points - closest
        dist = np.linalg.norm(diff, axis=1)
        sign = np.where(np.einsum("ij,ij->i", diff, normals) < 0.0, -1.0, 1.0)
        return sign * dist
