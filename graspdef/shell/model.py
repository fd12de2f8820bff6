"""A shell: ghosted control mesh + Loop basis + material + thickness, with rest quantities."""
from __future__ import annotations

import functools

from dataclasses import dataclass, field

import numpy as np

from ..errors import ProblemError
from ..subdivision.basis import LoopBasis, build_basis
from ..subdivision.evaluate import SurfaceEvaluator
from ..subdivision.ghosts import GhostedMesh, add_ghost_layer
from .kinematics import fundamental_forms, normal
from .materials import LinearElastic


#: how many keys :meth:`Shell.derived` keeps per shell
DERIVED_KEPT = 8


def surface_derivatives(stencils: np.ndarray, dN: np.ndarray, ddN: np.ndarray, x: np.ndarray) -> np.ndarray:
    """y = (a1, a2, a11, a22, a12) at quadrature points, (n_faces, n_quad, 5, 3)."""
    X = x[stencils]                                              # (f, S, 3)
    D = np.concatenate([dN, ddN], axis=-1)                       # (f|1, q, S, 5)
    return np.einsum("fqsk,fsd->fqkd", np.broadcast_to(D, (len(stencils),) + D.shape[1:]), X)


@dataclass(frozen=True)
class RestGroup:
    """Per face group: rest forms, contravariant metric, area weights and thickness."""

    rest_a: np.ndarray          # (f, q, 3)
    rest_b: np.ndarray          # (f, q, 3)
    rest_inv: np.ndarray        # (f, q, 3)  A^11, A^22, A^12
    weights: np.ndarray         # (f, q)  quadrature weight x rest area element
    thickness: np.ndarray       # (f, 1)


@dataclass(frozen=True)
class Shell:
    """Thin shell on the limit surface of a Loop control mesh.

    Parameters
    ----------
    vertices : (n_vertices, 3) float [m]
    faces : (n_faces, 3) int, oriented
    material : LinearElastic (or any object with ``density``)
    thickness : float or (n_faces,) [m]
    n_quad : int   Gauss points per face (3, 6 or 12; one point leaves spurious zero-energy modes).
    interpolate : bool or None
        Move the control points so that the limit surface passes through the given vertices.
        Otherwise the vertices are the control points and the limit surface lies slightly inside
        a convex mesh (by O(h^2): 0.36 % of the radius of a 2,562-vertex icosphere, which makes
        the pressurised-sphere displacement 0.7 % low; interpolated: 0.07 %).  Default (None):
        only closed meshes are interpolated -- on an open mesh the ghost extrapolation shapes the
        limit surface at the edge, and interpolating there degraded the pinched hemisphere from
        -0.14 % to -1.6 % (4,921 vertices).
    """

    vertices: np.ndarray
    faces: np.ndarray
    material: LinearElastic
    thickness: float | np.ndarray
    n_quad: int = 3
    interpolate: bool | None = None
    mesh: GhostedMesh = field(init=False, repr=False)
    basis: LoopBasis = field(init=False, repr=False)
    rest: tuple[RestGroup, ...] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        t = np.asarray(self.thickness, dtype=float)
        if t.ndim not in (0, 1) or (t.ndim == 1 and len(t) != len(self.faces)):
            raise ProblemError("thickness must be a number or one value per face")
        if not np.all(np.isfinite(t)) or np.any(t <= 0):
            raise ProblemError(f"thickness must be positive and finite, got {self.thickness!r}")
        if self.n_quad not in (3, 6, 12):
            raise ProblemError(f"n_quad must be 3, 6 or 12 Gauss points per face, got {self.n_quad} "
                               "(one point leaves spurious zero-energy modes)")
        mesh = add_ghost_layer(self.vertices, self.faces)
        if self.interpolate or (self.interpolate is None and len(mesh.boundary_edges) == 0):
            mesh = mesh.interpolating()
        basis = build_basis(mesh.faces, mesh.n_control, np.arange(mesh.n_real_faces), self.n_quad)
        rest = []
        for g in basis.groups:
            y = surface_derivatives(g.stencils, g.dN, g.ddN, mesh.vertices)
            a, b = fundamental_forms(y)
            det = a[..., 0] * a[..., 1] - a[..., 2] ** 2
            inv = np.stack([a[..., 1] / det, a[..., 0] / det, -a[..., 2] / det], -1)
            _, j = normal(y)
            tg = np.broadcast_to(t, (len(self.faces),))[g.faces][:, None] if t.ndim else np.full((len(g.faces), 1), float(t))
            rest.append(RestGroup(a, b, inv, j * basis.qweights, tg))
        object.__setattr__(self, "mesh", mesh)
        object.__setattr__(self, "basis", basis)
        object.__setattr__(self, "rest", tuple(rest))

    @property
    def n_control(self) -> int:
        return self.mesh.n_control

    @functools.cached_property
    def evaluator(self) -> SurfaceEvaluator:
        """Limit-surface evaluation at any (face, point) of this shell's control mesh (built on
        first use and kept: a derived, immutable property of the immutable shell)."""
        return SurfaceEvaluator(self.mesh.faces, self.mesh.n_control)

    @functools.cached_property
    def block_pattern(self):
        """The sparsity pattern of the shell's Hessian blocks (graspdef.shell.energy.BlockPattern),
        built on first use and shared by the energy, the enclosed volume and the other terms."""
        from .energy import BlockPattern

        return BlockPattern(self)

    def derived(self, key, make):
        """``make()``, computed once per hashable ``key`` and kept with this immutable shell: set-up
        data that several terms derive from the shell alike (a fingertip's contact samples, read by
        its barrier, its friction and its report).  ``make`` must depend on nothing but the shell and
        what ``key`` names.  The last :data:`DERIVED_KEPT` keys are kept (a sweep over grasp
        positions on one shell does not accumulate them)."""
        kept = self.__dict__.setdefault("_derived", {})
        if key in kept:
            kept[key] = kept.pop(key)                   # most recently used last
            return kept[key]
        value = make()
        kept[key] = value
        while len(kept) > DERIVED_KEPT:
            kept.pop(next(iter(kept)))
        return value

    @functools.cached_property
    def face_schedules(self) -> tuple:
        """Each face group's parallel schedule (graspdef.shell.energy._Schedule: faces in blocks
        coloured so that blocks of one colour share no control vertex), built on first use and shared
        by the compiled energy assembly and the enclosed volume (0.3 s each at 20k faces)."""
        from .energy import _Schedule

        X = np.asarray(self.rest_positions, dtype=float)
        return tuple(_Schedule(np.ascontiguousarray(g.stencils, dtype=np.int64), X) for g in self.basis.groups)

    @property
    def has_block_pattern(self) -> bool:
        """Whether :attr:`block_pattern` has been built (and is held)."""
        return "block_pattern" in self.__dict__

    def release_block_pattern(self) -> None:
        """Drop the held :attr:`block_pattern` (built again on next use): a caller that needed one
        Hessian (a linear solve) gives its element maps back -- at 100k control vertices 0.3 GB."""
        self.__dict__.pop("block_pattern", None)

    @property
    def n_dofs(self) -> int:
        return 3 * self.mesh.n_control

    @property
    def rest_positions(self) -> np.ndarray:
        return self.mesh.vertices

    def area(self) -> float:
        """Rest area of the limit surface [m^2]."""
        return float(sum(r.weights.sum() for r in self.rest))
