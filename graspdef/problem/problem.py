"""The Problem: a shell with loads, supports and named probe points; what every solver receives."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ProblemError
from ..shell.model import Shell
from ..subdivision.evaluate import SurfaceEvaluator, project_point
from .loads import PointLoad, load_vector
from .potentials import EnclosedGas, is_potential
from .nitsche import NITSCHE_GAMMA, NitscheRotation

#: net dead load, relative to the loads' magnitude, above which a body held only by rigid_modes is
#: refused (loads given to 4 digits balance to ~1e-5; MuJoCo's settled grasps to ~1e-6)
SELF_EQUILIBRIUM_RTOL = 1e-3
from .terms import DeadLoads, NitscheTerm, RestQuadratic, ShellElastic
from .supports import RigidModes, check_rigid_modes, constraint_rows, well_conditioned_rows


#: sparse solver back-ends a problem may ask for (graspdef.solve.sparse implements them)
BACKENDS = ("auto", "pardiso", "pardiso-ooc", "superlu")     # pardiso-ooc: PARDISO out of core (graspdef.solve.sparse)
PRECISIONS = ("auto", "double", "mixed")     # a linear solve's factor (graspdef.solve.sparse.KKTSystem)


@dataclass(frozen=True)
class SurfacePoint:
    """A point of the limit surface: real face index and barycentric coordinates."""

    face: int
    bary: tuple[float, float, float]


def locate(shell: Shell, ev: SurfaceEvaluator | None, point, name: str = "point", tol: float | None = None,
           n_candidates: int = 8, faces: np.ndarray | None = None) -> tuple[SurfacePoint, float]:
    """Closest limit-surface point to ``point`` [m], on the real faces where the boolean mask
    ``faces`` is true if it is given (one lip of a slit: ``graspdef.problem.edges``).

    Raises ProblemError when it is farther than ``tol`` (default: half the mean edge length of
    the control mesh) -- a probe or load off the surface."""
    ev = shell.evaluator if ev is None else ev
    p = np.asarray(point, dtype=float)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ProblemError(f"{name}: position must be three finite numbers, got {point!r}")
    x = shell.rest_positions
    real = shell.mesh.faces[: shell.mesh.n_real_faces]
    allowed = np.arange(len(real))
    if faces is not None:
        allowed = np.flatnonzero(np.asarray(faces, bool))
        if len(allowed) == 0:
            raise ProblemError(f"{name}: its side region selects no face")
    cent = x[real[allowed]].mean(axis=1)
    k = min(n_candidates, len(allowed))
    # the k nearest centroids by one pass over them (a KD-tree built for one query costs more, and
    # importing scipy.spatial took 0.12 s of every solve's start-up); nearest first, ties by index
    d2 = ((cent - p) ** 2).sum(axis=1)
    near = np.argpartition(d2, k - 1)[:k] if k < len(d2) else np.arange(len(d2))
    cand = allowed[near[np.lexsort((near, d2[near]))]]
    face, bary, dist = project_point(ev, x, p, np.atleast_1d(cand))
    if tol is None:
        e = x[real[:, [1, 2, 0]]] - x[real]
        tol = 0.5 * float(np.linalg.norm(e, axis=-1).mean())
    if dist > tol:
        raise ProblemError(f"{name}: point {p.tolist()} is off the surface (nearest limit-surface point "
                           f"is {dist:.3g} m away; tolerance {tol:.3g} m)")
    return SurfacePoint(face, tuple(float(b) for b in bary)), dist


@dataclass
class Problem:
    """Shell + loads + supports + probes.

    Parameters
    ----------
    shell : Shell
    loads : list of PointLoad | Pressure | BodyForce
    supports : list of EdgeSupport | PointSupport | RigidModes
    probes : name -> SurfacePoint, where displacements are reported
    n_collocation : collocation points per supported boundary edge
    nitsche_gamma : dimensionless penalty of the Nitsche rotation terms of clamped / symmetry
        edges (penalty gamma D / h, :class:`~graspdef.problem.nitsche.NitscheRotation`)
    """

    shell: Shell
    loads: list
    supports: list
    probes: dict[str, SurfacePoint] = field(default_factory=dict)
    n_collocation: int = 2
    nitsche_gamma: float = NITSCHE_GAMMA

    def __post_init__(self) -> None:
        self.evaluator = self.shell.evaluator
        g = self.nitsche_gamma
        if (isinstance(g, bool) or not isinstance(g, (int, float, np.integer, np.floating))
                or not (np.isfinite(g) and g > 0)):
            raise ProblemError(f"nitsche_gamma (the Nitsche rotation penalty, dimensionless) must be a positive "
                               f"number, got {g!r}")
        n_real = self.shell.mesh.n_real_faces
        for ld in self.loads:
            if isinstance(ld, PointLoad) and not (0 <= ld.face < n_real):
                raise ProblemError(f"point load on face {ld.face}: the mesh has faces 0..{n_real - 1}")
        for name, sp_ in self.probes.items():
            if not (0 <= sp_.face < n_real):
                raise ProblemError(f"probe '{name}' on face {sp_.face}: the mesh has faces 0..{n_real - 1}")
        if not self.supports:
            raise ProblemError("no supports: add supports, or RigidModes for a body held only by loads")

    def locate(self, point, name: str = "point", tol: float | None = None) -> SurfacePoint:
        """Closest limit-surface point to ``point`` [m] (see :func:`locate`)."""
        return locate(self.shell, self.evaluator, point, name, tol)[0]

    def dead_load_vector(self) -> np.ndarray:
        """Sum of the dead (configuration-independent) loads, (3 n_control,) [N]."""
        return load_vector(self.shell, [ld for ld in self.loads if not is_potential(ld)], self.evaluator)

    def net_load(self) -> tuple[np.ndarray, np.ndarray, float]:
        """(net force [N], net moment about the origin [N m], sum of the control-point force
        magnitudes [N]) of the dead loads at rest.  Exact for the limit surface: the Loop basis
        reproduces affine fields, so sum_i x_i x f_i is the moment of the loads where they act."""
        f = self.dead_load_vector().reshape(-1, 3)
        return f.sum(axis=0), np.cross(self.shell.rest_positions, f).sum(axis=0), float(np.linalg.norm(f, axis=1).sum())

    def check_self_equilibrated(self, rtol: float = SELF_EQUILIBRIUM_RTOL, where: str = "problem") -> None:
        """Refuse dead loads that are not in equilibrium when only ``rigid_modes`` hold the body
        (nothing would carry the net force: the solution would be the rigid-mode projection's
        artefact).  Tolerance: ``rtol`` of the loads' magnitude (moment: times the body's size)."""
        from .supports import RigidModes

        if not self.supports or not all(isinstance(s, RigidModes) for s in self.supports):
            return
        F, M, scale = self.net_load()
        if scale == 0.0:
            return
        size = float(np.ptp(self.shell.rest_positions, axis=0).max())
        c = self.shell.rest_positions.mean(axis=0)
        Mc = M - np.cross(c, F)                              # about the centroid
        if np.linalg.norm(F) > rtol * scale or np.linalg.norm(Mc) > rtol * scale * size:
            raise ProblemError(
                f"{where}: the loads are not in equilibrium, and only rigid_modes hold the body: net force "
                f"({', '.join(f'{v:.4g}' for v in F)}) N, net moment about the centroid "
                f"({', '.join(f'{v:.4g}' for v in Mc)}) N m (tolerance {rtol:g} of the loads, {rtol * scale:.3g} N); "
                "balance the loads or add supports")

    def potentials(self) -> list:
        """The configuration-dependent loads as ready energy terms on this shell (fresh state)."""
        return [ld.build(self.shell, self.evaluator) for ld in self.loads if is_potential(ld)]

    def energy_terms(self, elastic: str = "finite") -> list:
        """The total potential of the nonlinear solver as a list of energy terms
        (:mod:`graspdef.problem.terms`), in the order they are summed: the shell's elastic energy
        (``elastic``: "finite" deformation, or "rest": the linear shell's quadratic energy), the
        Nitsche terms of rotation-fixed edges, the dead loads, the configuration-dependent loads."""
        if elastic not in ("finite", "rest"):
            raise ProblemError(f"elastic must be 'finite' or 'rest', got {elastic!r}")
        terms = [ShellElastic(self.shell) if elastic == "finite" else RestQuadratic(self.shell)]
        nitsche = NitscheRotation(self.shell, self.supports, self.evaluator, self.nitsche_gamma)
        if nitsche:
            terms.append(NitscheTerm(nitsche))
        terms.append(DeadLoads(self.dead_load_vector(), self.shell.rest_positions))
        return terms + self.potentials()

    def load_vector(self) -> np.ndarray:
        """External force vector of linear theory (3 n_control,) [N]: the dead loads plus the
        configuration-dependent loads evaluated at rest.  An enclosed gas has no linear load."""
        f = self.dead_load_vector()
        x = self.shell.rest_positions
        for pot in self.potentials():
            if isinstance(pot, EnclosedGas):
                raise ProblemError("an enclosed gas couples pressure and volume nonlinearly: use the nonlinear "
                                   "solver (solver.type = \"nonlinear\")")
            f = f + pot.load(x)
        return f

    def boundary_stiffness(self):
        """Nitsche terms for rotation-fixed edges, (3 n_control, 3 n_control) sparse."""
        return NitscheRotation(self.shell, self.supports, self.evaluator, self.nitsche_gamma).evaluate(self.shell.rest_positions)[2]

    def constraints(self, with_targets: bool = False):
        """C (m, 3 n_control) and row labels (and, ``with_targets``, the prescribed values g (m,)
        [m] of C u = g at load factor 1); raises SupportError if rigid modes stay free.
        RigidModes are the six surface-mean rows (:func:`graspdef.problem.supports.surface_mean_rows`),
        in linear and nonlinear solves alike."""
        C, labels, g = constraint_rows(self.shell, self.supports, self.evaluator, self.n_collocation,
                                       with_targets=True)
        C, labels, g = well_conditioned_rows(C, labels, g)
        check_rigid_modes(C, self.shell.rest_positions, Kb=self.boundary_stiffness())
        return (C, labels, g) if with_targets else (C, labels)
