"""External loads as work-conjugate force vectors on the control points.

The potential of a dead load is ``-f . u``; a point force F at a surface point with basis values
N_i gives f_i = N_i F, so total force and moment about any point are kept exactly
(sum_i N_i = 1 and sum_i N_i x_i = x).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ProblemError
from ..shell.model import Shell, surface_derivatives
from ..subdivision.evaluate import SurfaceEvaluator
from .edges import boundary_edge_mask


def _finite_vector(name: str, v, n: int = 3) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise ProblemError(f"{name} must be {n} finite numbers, got {v!r}")
    return a


@dataclass(frozen=True)
class PointLoad:
    """Force [N] at the limit point of ``face`` with barycentric coordinates ``bary``."""

    face: int
    bary: tuple[float, float, float]
    force: tuple[float, float, float]

    def vector(self, shell: Shell, ev: SurfaceEvaluator) -> np.ndarray:
        F = _finite_vector("point force", self.force)
        st, w = ev.values(self.face, np.asarray(self.bary, dtype=float))
        f = np.zeros((shell.n_control, 3))
        np.add.at(f, st, w[:, None] * F[None, :])
        return f


@dataclass(frozen=True)
class Pressure:
    """Uniform pressure p [Pa] along the rest normal a1 x a2 / |a1 x a2| (positive = along the
    face orientation's normal: outward for an outward-oriented closed surface).  Dead load.
    ``faces``: optional boolean mask over the real faces."""

    p: float
    faces: np.ndarray | None = None

    def vector(self, shell: Shell, ev: SurfaceEvaluator) -> np.ndarray:
        if not np.isfinite(self.p):
            raise ProblemError(f"pressure must be finite, got {self.p!r}")
        f = np.zeros((shell.n_control, 3))
        for g in shell.basis.groups:
            y = surface_derivatives(g.stencils, g.dN, g.ddN, shell.rest_positions)
            m = np.cross(y[..., 0, :], y[..., 1, :]) * shell.basis.qweights[None, :, None]
            if self.faces is not None:
                m = m * np.asarray(self.faces, bool)[g.faces][:, None, None]
            fe = self.p * np.einsum("fqs,fqd->fsd", g.full("N"), m)
            np.add.at(f, g.stencils, fe)
        return f


@dataclass(frozen=True)
class BodyForce:
    """Body force of density rho [kg/m^3] in the acceleration field g [m/s^2] (e.g. gravity)."""

    density: float
    g: tuple[float, float, float]

    def vector(self, shell: Shell, ev: SurfaceEvaluator) -> np.ndarray:
        if not np.isfinite(self.density) or self.density < 0:
            raise ProblemError(f"density must be a non-negative number, got {self.density!r}")
        acc = _finite_vector("gravity vector", self.g)
        f = np.zeros((shell.n_control, 3))
        for g, r in zip(shell.basis.groups, shell.rest):
            mass = self.density * r.thickness * r.weights                 # (f, q) kg
            fe = np.einsum("fqs,fq->fs", g.full("N"), mass)
            np.add.at(f, g.stencils, fe[:, :, None] * acc[None, None, :])
        return f


@dataclass(frozen=True)
class EdgeLoad:
    """Dead line load ``force`` [N/m] (per unit rest length) on the boundary edges whose two end
    vertices satisfy ``where`` (callable (n, 3) -> (n,) bool on rest positions [m]) and, if ``side``
    is given, whose owning face's centroid satisfies ``side`` (one lip of a slit;
    ``graspdef.problem.edges``); integrated along the limit boundary curve with ``n_points``
    Gauss points per edge."""

    where: object
    force: tuple[float, float, float]
    name: str = "edge_load"
    n_points: int = 3
    side: object = None

    def vector(self, shell: Shell, ev: SurfaceEvaluator) -> np.ndarray:
        F = _finite_vector(f"edge load '{self.name}' force", self.force)
        mesh = shell.mesh
        ab = mesh.boundary_edges
        if len(ab) == 0:
            raise ProblemError(f"edge load '{self.name}': the surface has no boundary edges")
        mask = boundary_edge_mask(shell, self.where, self.side)
        if not mask.any():
            raise ProblemError(f"edge load '{self.name}': its region{'' if self.side is None else ' and side'} select{'s' if self.side is None else ''} no boundary edge")
        t_gl, w_gl = np.polynomial.legendre.leggauss(self.n_points)
        taus, wts = 0.5 * (t_gl + 1.0), 0.5 * w_gl
        corners = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
        X = shell.rest_positions
        f = np.zeros((shell.n_control, 3))
        for e in np.flatnonzero(mask):
            face = int(mesh.boundary_faces[e])
            i = int(np.flatnonzero(mesh.faces[face] == ab[e, 0])[0])
            chart = corners[(i + 1) % 3] - corners[i]
            pts = (1 - taus)[:, None] * corners[i] + taus[:, None] * corners[(i + 1) % 3]
            st, N, dN, _ = ev.basis(face, pts)
            for q in range(len(taus)):
                ds = np.linalg.norm((dN[q] @ chart) @ X[st])
                np.add.at(f, st, (wts[q] * ds * N[q])[:, None] * F[None, :])
        return f


Load = PointLoad | Pressure | BodyForce | EdgeLoad


def load_vector(shell: Shell, loads: list, ev: SurfaceEvaluator) -> np.ndarray:
    """Sum of all loads as (3 n_control,) [N]."""
    f = np.zeros((shell.n_control, 3))
    for load in loads:
        f += load.vector(shell, ev)
    return f.ravel()
