"""The fingertips as analytic rigid obstacles in the object frame: :class:`Capsule` (a pin) and
:class:`RoundedBox` (a pad), each with its distance function phi (>= 0 outside), gradient and
Hessian (graspdef.contact.barrier keeps the shell's samples out of them)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Capsule:
    """A capsule (a pin): segment a-b [m] with ``radius`` [m].  Object-frame coordinates."""

    a: tuple
    b: tuple
    radius: float

    def inflated(self, r: float) -> "Capsule":
        return Capsule(self.a, self.b, self.radius + r)

    @property
    def feature_radius(self) -> float:
        return self.radius

    def reach(self) -> float:
        """Lateral extent about the closing axis [m]."""
        return self.radius

    def _nearest(self, p: np.ndarray):
        """For points p (k, 3): the distance r (k,) to the axis segment (>= 1e-300), the unit
        normal n (k, 3), whether the nearest axis point is inside the segment (k,), and the
        segment's unit direction u (3,)."""
        a, b = np.asarray(self.a, float), np.asarray(self.b, float)
        ab = b - a
        L2 = ab @ ab
        t = np.clip(((p - a) @ ab) / L2, 0.0, 1.0)
        v = p - (a + t[:, None] * ab)
        r = np.maximum(np.sqrt(np.einsum("ki,ki->k", v, v)), 1e-300)
        return r, v / r[:, None], (t > 0) & (t < 1), ab / np.sqrt(L2)

    def distance(self, p: np.ndarray, hessian: bool = True):
        """phi (k,), grad (k, 3) and (``hessian``) Hessian (k, 3, 3) of the distance to the
        capsule surface at points p (k, 3) outside it."""
        r, n, side, u = self._nearest(p)
        if not hessian:
            return r - self.radius, n
        P = np.eye(3)[None] - n[:, :, None] * n[:, None, :]
        if side.any():                                          # distance to the axis line
            P[side] -= np.outer(u, u)[None]
        return r - self.radius, n, P / r[:, None, None]

    def hessian_along(self, p: np.ndarray, e: np.ndarray) -> np.ndarray:
        """H e (k, 3): the distance's Hessian at points p (k, 3) outside the capsule times the
        vector e (3,) -- :meth:`distance`'s Hessian applied to e, without the (k, 3, 3) array."""
        r, n, side, u = self._nearest(p)
        e = np.asarray(e, float)
        He = e[None] - n * (n @ e)[:, None]
        if side.any():                                          # distance to the axis line
            He[side] -= (u @ e) * u[None]
        return He / r[:, None]

    def along(self, p: np.ndarray, shift: np.ndarray, e: np.ndarray):
        """At the points p - shift (p (k, 3) outside the capsule): phi (k,), the unit normal (k, 3)
        and phi's first two derivatives when the capsule advances by s along the unit vector e (the
        points move by -s e): -n.e and e.H.e (k,) -- what the condensed finger advance needs,
        without the (k, 3, 3) Hessians (compiled: graspdef.contact._kernels)."""
        from ._kernels import capsule_distance

        return capsule_distance(np.ascontiguousarray(p, dtype=float), np.asarray(shift, float),
                                np.asarray(self.a, float), np.asarray(self.b, float), float(self.radius),
                                np.asarray(e, float))

    def log_barrier_sums(self, p: np.ndarray, kw: np.ndarray, shift: np.ndarray, e: np.ndarray, dhat: float):
        """(B_s, B_ss, smallest gap) of the log barrier of reach dhat over the points p - shift
        with weights kw, the capsule advancing along e (graspdef.contact.condensation; compiled:
        graspdef.contact._kernels.capsule_barrier_sums)."""
        from ._kernels import capsule_barrier_sums

        return capsule_barrier_sums(np.ascontiguousarray(p, dtype=float), np.ascontiguousarray(kw, dtype=float),
                                    np.asarray(shift, float), np.asarray(self.a, float), np.asarray(self.b, float),
                                    float(self.radius), np.asarray(e, float), float(dhat))


@dataclass(frozen=True)
class RoundedBox:
    """A box with rounded edges (a pad): centre [m], rotation (3, 3) whose columns are the box
    axes in the object frame, half extents [m] of the full box, edge radius ``rounding`` [m]."""

    center: tuple
    rotation: tuple
    half_extents: tuple
    rounding: float

    def inflated(self, r: float) -> "RoundedBox":
        return RoundedBox(self.center, self.rotation, tuple(h + r for h in self.half_extents), self.rounding + r)

    @property
    def feature_radius(self) -> float:
        return self.rounding

    def reach(self) -> float:
        h = np.sort(np.asarray(self.half_extents, float))
        return float(np.hypot(h[1], h[2]))

    def _nearest(self, p: np.ndarray):
        """For points p (k, 3), in the box's axes: the excess q (k, 3) of |coordinates| over the
        inner box, the distance r (k,) to the inner box (0 inside), and the unit normal nl (k, 3)
        (with r >= 1e-300 in its division)."""
        R = np.asarray(self.rotation, float)
        loc = (p - np.asarray(self.center, float)) @ R
        q = np.abs(loc) - (np.asarray(self.half_extents, float) - self.rounding)   # inner box
        m = np.maximum(q, 0.0)
        r = np.sqrt(np.einsum("ki,ki->k", m, m))
        return q, r, np.where(loc < 0, -1.0, 1.0) * m / np.maximum(r, 1e-300)[:, None]

    def distance(self, p: np.ndarray, hessian: bool = True):
        """phi (k,), grad (k, 3) and (``hessian``) Hessian (k, 3, 3) of the distance to the
        rounded box's surface at points p (k, 3) outside it."""
        R = np.asarray(self.rotation, float)
        q, r, nl = self._nearest(p)
        inside = r <= 0
        r = np.maximum(r, 1e-300)
        phi = np.where(inside, q.max(axis=1), r) - self.rounding
        n = nl @ R.T
        if not hessian:
            return phi, n
        D = (q > 0).astype(float)
        Hl = (D[:, :, None] * np.eye(3)[None] - nl[:, :, None] * nl[:, None, :]) / r[:, None, None]
        return phi, n, R[None] @ Hl @ R.T[None]

    def hessian_along(self, p: np.ndarray, e: np.ndarray) -> np.ndarray:
        """H e (k, 3): the distance's Hessian at points p (k, 3) outside the rounded box times the
        vector e (3,) -- :meth:`distance`'s Hessian applied to e, without the (k, 3, 3) array."""
        R = np.asarray(self.rotation, float)
        q, r, nl = self._nearest(p)
        el = np.asarray(e, float) @ R                                  # e in the box's axes
        Hel = (np.where(q > 0, el[None], 0.0) - nl * (nl @ el)[:, None]) / np.maximum(r, 1e-300)[:, None]
        return Hel @ R.T

    def along(self, p: np.ndarray, shift: np.ndarray, e: np.ndarray):
        """At the points p - shift (p (k, 3) outside the box): phi (k,), the unit normal (k, 3) and
        phi's first two derivatives when the box advances by s along the unit vector e (the points
        move by -s e): -n.e and e.H.e (k,) (compiled: graspdef.contact._kernels)."""
        from ._kernels import box_distance

        return box_distance(np.ascontiguousarray(p, dtype=float), np.asarray(shift, float),
                            np.asarray(self.center, float), np.asarray(self.rotation, float),
                            np.asarray(self.half_extents, float) - self.rounding, float(self.rounding),
                            np.asarray(e, float))

    def log_barrier_sums(self, p: np.ndarray, kw: np.ndarray, shift: np.ndarray, e: np.ndarray, dhat: float):
        """(B_s, B_ss, smallest gap) of the log barrier of reach dhat over the points p - shift
        with weights kw, the box advancing along e (graspdef.contact.condensation; compiled:
        graspdef.contact._kernels.box_barrier_sums)."""
        from ._kernels import box_barrier_sums

        return box_barrier_sums(np.ascontiguousarray(p, dtype=float), np.ascontiguousarray(kw, dtype=float),
                                np.asarray(shift, float), np.asarray(self.center, float),
                                np.asarray(self.rotation, float), np.asarray(self.half_extents, float) - self.rounding,
                                float(self.rounding), np.asarray(e, float), float(dhat))
