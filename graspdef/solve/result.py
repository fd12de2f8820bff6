"""What every solution offers on top of its control-point displacements ``u`` (n_control, 3)."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..subdivision.rules import limit_matrix


class DisplacementField:
    """Mixin: probes, limit-surface displacements and the deformed surface of ``self.u``
    (control-point displacements [m]) on ``self.problem``."""

    def probe(self, name: str, u: np.ndarray | None = None) -> np.ndarray:
        """Displacement (3,) [m] of the named probe point."""
        if name not in self.problem.probes:
            raise KeyError(f"no probe named '{name}' (probes: {', '.join(self.problem.probes) or 'none'})")
        sp_ = self.problem.probes[name]
        st, w = self.problem.evaluator.values(sp_.face, np.asarray(sp_.bary))
        return w @ (self.u if u is None else u)[st]

    def limit_map(self) -> sp.csr_matrix:
        mesh = self.problem.shell.mesh
        return limit_matrix(mesh.faces, mesh.n_control, np.arange(mesh.n_real))

    def vertex_displacements(self) -> np.ndarray:
        """Limit displacements at the real control vertices, (n_vertices, 3) [m]."""
        return self.limit_map() @ self.u

    def deformed_surface(self, scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """Limit points of the real vertices after deformation, and the real faces."""
        mesh = self.problem.shell.mesh
        return self.limit_map() @ (mesh.vertices + scale * self.u), mesh.faces[: mesh.n_real_faces]

    def max_displacement(self) -> float:
        """Largest limit-surface vertex displacement [m]."""
        return float(np.linalg.norm(self.vertex_displacements(), axis=1).max())
