"""Configuration-dependent loads of the nonlinear solver, each as a potential of the control
points so that the tangent stays symmetric and exact.

* :class:`FollowerPressure` -- pressure along the current normal of a closed surface: potential
  ``-lam p V(x)`` with the enclosed volume V (``graspdef.shell.volume``).
* :class:`EnclosedGas` -- a closed shell holding an ideal gas at initial gauge pressure p0,
  isothermal (p_abs V = const): potential ``-P0 V0 ln(V/V0) + p_atm (V - V0)`` whose derivative is
  minus the current gauge pressure; its Hessian has a rank-one part c g g^T (g = dV/dx), returned
  separately so that sparse factorisations stay sparse.
* :class:`EdgeMoment` -- a follower couple m [N m / m] on free boundary edges turning the edge's
  cross-section about a fixed axis e: potential ``-lam m int theta ds`` with theta the rotation of
  the surface tangent across the edge about e (exact for the rolling-up cantilever).

Each is a specification; ``build(shell, evaluator)`` returns a ready energy term of it (a new
object, :mod:`graspdef.problem.terms` protocol): ``evaluate(x, lam, order, u)`` returns a
:class:`~graspdef.problem.terms.TermValue` (value, gradient, Hessian, rank-one parts) and
``load(x)`` the generalised force -d(gradient)/d(lam) that the load factor scales (zero for the
gas).  States change branch only through ``commit(x)`` at a converged step (the edge rotation is
tracked continuously past +-pi); ``record(x)`` gives the numbers of the path record.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.sparse as sp

from ..errors import ProblemError
from ..shell.model import Shell
from ..shell.volume import EnclosedVolume
from ..subdivision.evaluate import SurfaceEvaluator
from .edges import boundary_edge_mask
from .terms import TermBase, TermValue

#: standard atmosphere [Pa]
P_ATM = 101_325.0

_CORNERS = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


#: the value type of every term (kept under its earlier name for the potentials' callers)
PotentialTerms = TermValue


def _require_closed(shell: Shell, what: str) -> None:
    if len(shell.mesh.boundary_edges):
        raise ProblemError(f"{what} needs a closed surface (its potential is the enclosed volume); this "
                           f"mesh has {len(shell.mesh.boundary_edges)} boundary edges")


@dataclass
class FollowerPressure(TermBase):
    """Pressure p [Pa] that follows the deformed normal of a closed surface (positive: along
    the outward normal of an outward-oriented surface, i.e. inflating)."""

    p: float

    def build(self, shell: Shell, ev: SurfaceEvaluator) -> "FollowerPressure":
        """A ready term of this specification on ``shell`` (a new object; this one is unchanged)."""
        return copy.copy(self)._setup(shell, ev)

    def _setup(self, shell: Shell, ev: SurfaceEvaluator) -> "FollowerPressure":
        if not np.isfinite(self.p):
            raise ProblemError(f"follower pressure must be finite, got {self.p!r}")
        _require_closed(shell, "a follower pressure")
        self._vol = EnclosedVolume(shell)
        return self

    def scaled(self) -> bool:
        return True

    def evaluate(self, x: np.ndarray, lam: float, order: int = 2, u: np.ndarray | None = None) -> PotentialTerms:
        if order == 0:
            return PotentialTerms(-lam * self.p * self._vol.value(x), None, None)
        if order < 2:
            V, g = self._vol.gradient(x)
            return PotentialTerms(-lam * self.p * V, -lam * self.p * g, None)
        V, g, H = self._vol.hessian(x, scale=-lam * self.p)
        return PotentialTerms(-lam * self.p * V, -lam * self.p * g, H)

    def hessian_rows(self, x: np.ndarray, lam: float, region) -> tuple:
        return region.volume.hessian(x, scale=-lam * self.p)[2], []

    def load(self, x: np.ndarray) -> np.ndarray:
        return self.p * self._vol.gradient(x)[1]

    def commit(self, x: np.ndarray) -> None:
        pass


@dataclass
class EnclosedGas(TermBase):
    """Ideal gas sealed inside a closed shell at initial gauge pressure ``p0`` [Pa] (relative
    to ``p_atm`` outside), isothermal: (p_atm + p) V = (p_atm + p0) V0."""

    p0: float
    p_atm: float = P_ATM
    record_name = "gas"                 # path-record columns gas<i>_volume_m3, gas<i>_gauge_pressure_Pa

    def build(self, shell: Shell, ev: SurfaceEvaluator) -> "EnclosedGas":
        """A ready term of this specification on ``shell`` (a new object; this one is unchanged)."""
        return copy.copy(self)._setup(shell, ev)

    def _setup(self, shell: Shell, ev: SurfaceEvaluator) -> "EnclosedGas":
        if not (np.isfinite(self.p0) and np.isfinite(self.p_atm)) or self.p_atm <= 0 or self.p_atm + self.p0 <= 0:
            raise ProblemError(f"enclosed gas: need p_atm > 0 and p_atm + p0 > 0 (absolute pressure), got "
                               f"p0={self.p0!r}, p_atm={self.p_atm!r}")
        _require_closed(shell, "an enclosed gas")
        self._vol = EnclosedVolume(shell)
        self._last = None                               # (x, V, dV/dx) of the last evaluation (hessian_rows)
        self.V0 = self._vol.value(shell.rest_positions)
        if self.V0 <= 0:
            raise ProblemError(f"enclosed gas: the surface encloses a non-positive volume ({self.V0:.3g} m^3); "
                               "orient the faces outward")
        return self

    def scaled(self) -> bool:
        return False

    def gauge_pressure(self, V: float) -> float:
        """Gauge pressure [Pa] at volume V [m^3]."""
        return (self.p_atm + self.p0) * self.V0 / V - self.p_atm

    def _value(self, V: float) -> float:
        if V <= 0:
            return np.inf
        return -(self.p_atm + self.p0) * self.V0 * np.log(V / self.V0) + self.p_atm * (V - self.V0)

    def evaluate(self, x: np.ndarray, lam: float, order: int = 2, u: np.ndarray | None = None) -> PotentialTerms:
        if order == 0:
            return PotentialTerms(self._value(self._vol.value(x)), None, None)
        if order < 2:
            V, g = self._vol.gradient(x)
            self._last = (x.copy(), V, g)
            return PotentialTerms(self._value(V), -self.gauge_pressure(V) * g, None)
        V, g, H = self._vol.hessian(x)
        self._last = (x.copy(), V, g)
        pg = self.gauge_pressure(V)
        H.data *= -pg
        return PotentialTerms(self._value(V), -pg * g, H, [(self._stiffness(V), g)])

    def _stiffness(self, V: float) -> float:
        """-dp/dV [Pa/m^3]: the coefficient of the rank-one Hessian part (dp/dV) grad V grad V^T."""
        return (self.p_atm + self.p0) * self.V0 / V ** 2

    def hessian_rows(self, x: np.ndarray, lam: float, region) -> tuple:
        # the pressure and the rank-one part are the whole volume's: those of the last evaluation
        # when it was at this x (a local correction's rows follow its iterate's gradient), else computed
        last = self._last
        V, g = last[1:] if last is not None and np.array_equal(last[0], x) else self._vol.gradient(x)
        H = region.volume.hessian(x, scale=-self.gauge_pressure(V))[2]
        return H, [(self._stiffness(V), g)]

    def load(self, x: np.ndarray) -> np.ndarray:
        return np.zeros(3 * len(x))

    def record(self, x: np.ndarray) -> dict:
        """The gas's volume [m^3] and gauge pressure [Pa] at ``x`` (for the path record)."""
        V = self._vol.value(x)
        return {"volume_m3": V, "gauge_pressure_Pa": self.gauge_pressure(V)}

    def commit(self, x: np.ndarray) -> None:
        pass


@dataclass
class EdgeMoment(TermBase):
    """Follower couple of ``moment`` [N m per m of edge] on the boundary edges selected by
    ``where`` (both end vertices), turning the cross-section about the fixed ``axis`` (unit;
    the sense is right-handed about it).  The rotation theta at an edge point is the angle,
    about ``axis``, of the surface tangent across the edge (the conormal derivative), measured
    continuously from the rest state."""

    where: Callable[[np.ndarray], np.ndarray]
    moment: float
    axis: tuple[float, float, float]
    name: str = "edge_moment"
    n_points: int = 3
    side: Callable[[np.ndarray], np.ndarray] | None = None     # one lip of a slit (problem.edges)

    def build(self, shell: Shell, ev: SurfaceEvaluator) -> "EdgeMoment":
        """A ready term of this specification on ``shell`` (a new object; this one is unchanged)."""
        return copy.copy(self)._setup(shell, ev)

    def _setup(self, shell: Shell, ev: SurfaceEvaluator) -> "EdgeMoment":
        if not np.isfinite(self.moment):
            raise ProblemError(f"edge moment '{self.name}': moment must be finite, got {self.moment!r}")
        e = np.asarray(self.axis, float)
        if e.shape != (3,) or not np.all(np.isfinite(e)) or np.linalg.norm(e) == 0:
            raise ProblemError(f"edge moment '{self.name}': axis must be a non-zero 3-vector, got {self.axis!r}")
        self._e = e / np.linalg.norm(e)
        mesh = shell.mesh
        ab = mesh.boundary_edges
        if len(ab) == 0:
            raise ProblemError(f"edge moment '{self.name}': the surface has no boundary edges")
        mask = boundary_edge_mask(shell, self.where, self.side)
        if not mask.any():
            raise ProblemError(f"edge moment '{self.name}': its region{'' if self.side is None else ' and side'} select{'s' if self.side is None else ''} no boundary edge")
        t_gl, w_gl = np.polynomial.legendre.leggauss(self.n_points)
        taus, wts = 0.5 * (t_gl + 1.0), 0.5 * w_gl
        X = shell.rest_positions
        st_all, d_all, w_all = [], [], []
        for e_i in np.flatnonzero(mask):
            a, _ = ab[e_i]
            f = int(mesh.boundary_faces[e_i])
            i = int(np.flatnonzero(mesh.faces[f] == a)[0])
            chart = _CORNERS[(i + 1) % 3] - _CORNERS[i]
            pts = (1 - taus)[:, None] * _CORNERS[i] + taus[:, None] * _CORNERS[(i + 1) % 3]
            st, _, dN, _ = ev.basis(f, pts)
            for q in range(len(taus)):
                a1, a2 = dN[q, :, 0] @ X[st], dN[q, :, 1] @ X[st]
                te = chart[0] * a1 + chart[1] * a2
                ds = np.linalg.norm(te)
                n = np.cross(a1, a2)
                n /= np.linalg.norm(n)
                nu = np.cross(te / ds, n)                   # outward conormal (rest)
                A = np.array([[a1 @ a1, a1 @ a2], [a1 @ a2, a2 @ a2]])
                dpar = np.linalg.solve(A, np.array([nu @ a1, nu @ a2]))   # chart direction of nu
                st_all.append(st)
                d_all.append(dN[q] @ dpar)                  # t = sum_s d_s x_s (conormal derivative)
                w_all.append(wts[q] * ds)
        S = max(len(s) for s in st_all)
        self._st = np.zeros((len(st_all), S), np.int64)
        self._d = np.zeros((len(st_all), S))
        for k, (s, d) in enumerate(zip(st_all, d_all)):
            self._st[k, : len(s)] = s
            self._d[k, : len(s)] = d
        self._w = np.asarray(w_all)
        self._n = shell.n_control
        t0 = self._tangents(X)
        self._t_ref = t0
        self._theta_ref = np.zeros(len(t0))
        if np.any(np.linalg.norm(t0 - (t0 @ self._e)[:, None] * self._e, axis=1) < 1e-9 * np.linalg.norm(t0, axis=1)):
            raise ProblemError(f"edge moment '{self.name}': the axis is parallel to the surface tangent across "
                               "the edge (it must lie along the edge)")
        return self

    def _tangents(self, x: np.ndarray) -> np.ndarray:
        return np.einsum("ks,ksd->kd", self._d, x[self._st])

    def angles(self, x: np.ndarray) -> np.ndarray:
        """Rotation theta [rad] at each edge quadrature point, continuous from the rest state."""
        t = self._tangents(x)
        e = self._e
        return self._theta_ref + np.arctan2(np.cross(self._t_ref, t) @ e, (self._t_ref * t).sum(1))

    def scaled(self) -> bool:
        return True

    def _derivs(self, x):
        t = self._tangents(x)
        e = self._e
        tp = t - (t @ e)[:, None] * e
        r2 = (tp * tp).sum(1)
        u = np.cross(e, t)                                  # r * (direction of increasing theta)
        g = u / r2[:, None]                                 # d theta / d t
        return t, tp, r2, u, g

    def _scatter(self, per_point: np.ndarray) -> np.ndarray:
        out = np.zeros((self._n, 3))
        np.add.at(out, self._st, self._d[:, :, None] * per_point[:, None, :])
        return out.ravel()

    def evaluate(self, x: np.ndarray, lam: float, order: int = 2, u: np.ndarray | None = None) -> PotentialTerms:
        c = -lam * self.moment * self._w                    # potential = sum c_k theta_k
        theta = self.angles(x)
        _, tp, r2, u, g = self._derivs(x)
        grad = self._scatter(c[:, None] * g)
        if order < 2:
            return PotentialTerms(float(c @ theta), grad, None)
        # d2 theta / dt2 = -(u v^T + v u^T) / r^2 with unit u, v: here -(u tp^T + tp u^T) / r^4
        Ht = -(u[:, :, None] * tp[:, None, :] + tp[:, :, None] * u[:, None, :]) / (r2 ** 2)[:, None, None]
        Ht *= c[:, None, None]
        K, S = self._st.shape
        blocks = self._d[:, :, None, None, None] * self._d[:, None, :, None, None] * Ht[:, None, None, :, :]
        rows = (3 * self._st[:, :, None, None, None] + np.arange(3)[None, None, None, :, None])
        cols = (3 * self._st[:, None, :, None, None] + np.arange(3)[None, None, None, None, :])
        rows = np.broadcast_to(rows, blocks.shape).ravel()
        cols = np.broadcast_to(cols, blocks.shape).ravel()
        H = sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(3 * self._n, 3 * self._n))
        return PotentialTerms(float(c @ theta), grad, H)

    def load(self, x: np.ndarray) -> np.ndarray:
        _, _, _, _, g = self._derivs(x)
        return self._scatter((self.moment * self._w)[:, None] * g)

    def commit(self, x: np.ndarray) -> None:
        """Re-base the continuous angle on the converged state ``x``."""
        self._theta_ref = self.angles(x)
        self._t_ref = self._tangents(x)


Potential = FollowerPressure | EnclosedGas | EdgeMoment


def is_potential(load) -> bool:
    """The three potentials above, or any specification with their interface (build, evaluate,
    load, commit), e.g. a contact term of a higher layer (graspdef.contact.FingerContact)."""
    return isinstance(load, (FollowerPressure, EnclosedGas, EdgeMoment)) or all(
        callable(getattr(load, m, None)) for m in ("build", "evaluate", "load", "commit"))
