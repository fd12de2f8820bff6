"""Geometric contact: a rigid fingertip pressed onto the shell with a given force, penetration-free.

The fingertip is an analytic rigid obstacle in the object frame (:class:`Capsule` for a pin,
:class:`RoundedBox` for a pad), taken from the MuJoCo scene at equilibrium.  It may translate
along its finger's closing axis ``e`` (the slide joint); everything else about it is fixed.

**Gap.**  Samples of the shell's *mid*-surface limit surface, p_k = sum_i N_i(k) x_i, are kept out of
the obstacle *inflated by t/2*: d_k = phi(p_k - s e) - t/2, with phi the obstacle's distance
function and s its advance along e.  Where the shell touches the obstacle its normal is the
obstacle's normal, and there the gap of the outer skin (p + t/2 n) to the obstacle equals d_k;
elsewhere the two differ by O(t/2 * angle^2), inside the barrier's reach d_hat only where the
surfaces are nearly parallel anyway.  Inflating the obstacle keeps p_k linear in the control
points (no normal derivatives), so the barrier's Hessian is exact and cheap.

The term is three pieces: the samples (:mod:`graspdef.contact.sampling`), the barrier over them
(:class:`FingerContact`, here) and the condensed finger advance
(:mod:`graspdef.contact.condensation`); the fingertip shapes are :mod:`graspdef.contact.obstacles`.

**Samples.**  The faces within the obstacle's reach (laterally, about its axis) are cut into
L x L sub-triangles of their parameter domain, sampled at the sub-triangle centroids with weight
|a1 x a2| / (2 L^2) (their rest area; the sum is the patch's limit-surface area); L is chosen so
that the samples are closer than a third of the obstacle's smallest radius of curvature.

**Barrier** (IPC, Li et al. 2020): B(x, s) = kappa sum_k w_k b(d_k), b(d) = -(d - dh)^2 ln(d/dh)
for 0 < d < dh, 0 beyond, +inf at d <= 0.  kappa sets the contact pressure: -kappa b'(dh/2) =
``pressure_scale`` (default: the shell's Young's modulus, i.e. the barrier layer is as stiff as a
dh-thick layer of the shell's own material).  The pressure on the shell is p_k = -kappa b'(d_k) > 0
exactly where d_k < dh; the **contact area** is the sampled area with d_k < dh (pressure > 0).

**Force control.**  The finger is pushed by the force F (= load factor x target) along e, so its
advance s is an unknown with potential B(x, s) - F s.  It is eliminated exactly: s*(x) solves
dB/ds = F (a scalar safeguarded Newton solve at every evaluation) and the potential of the control
points is Pi(x) = B(x, s*(x)) - F s*(x), whose gradient is dB/dx (envelope theorem) and whose
Hessian is B_xx - B_xs B_xs^T / B_ss (a rank-one part with a negative coefficient, which the
nonlinear solver handles by the Woodbury identity).  So at every equilibrium the finger's contact
force along its axis is exactly F, and no configuration can penetrate: for any x the finger sits
where the barrier force equals F, in front of every sample.  (An obstacle at a prescribed
position would need a feasible-step limit in the line search; the force-controlled finger does
not.)  The generalised load of the load factor is -d(grad Pi)/d lam = -B_xs F_target / B_ss.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import ProblemError
from ..problem.terms import TermBase
from .obstacles import Capsule, RoundedBox  # noqa: F401  (the fingertip shapes, used with FingerContact)
from .condensation import ForceControlledAdvance, NoPosition, condensed_load, condensed_rank_one
from .sampling import SampleOperator, sample_faces, select_faces
from ..problem.terms import TermValue as PotentialTerms


#: Newton settings of load paths with finger contact (graspdef.solve.nonlinear.PathOptions fields).
#: Contact paths take a few more Newton iterations per step (the barrier stiffens as the patch
#: grows): let the step grow unless a step took more than 8; and they pass close to bifurcations (a
#: ball between two pins may roll), where the branch a load-controlled path follows depends on its
#: steps: refresh a stale tangent at contraction worse than 1/2 and factorise every converged point
#: (the settings the contact tables were made with; the solver's defaults for smooth paths,
#: reuse_ratio 0.9 and inertia_rtol 1e-4, stop the pinned ball at 12.9 of 20.37 N); no inexact
#: (GMRES) Newton steps either (``krylov`` 0): on these branch-sensitive paths the iterates, hence
#: possibly the branch, would differ from those the contact tables were made with (not yet tried).
#: A grasp that reaches a limit point of the finger force stops there (``limit_points`` "stop"):
#: which state a gripper snaps to is a question for its dynamics, not for this quasi-static path.
#: Each step starts from the linear tangent predictor (``predictor`` "linear"): the contact set
#: changes from step to step, so u(lam) has kinks, and the solver's default curvature term
#: overshoots them (2026-11-27, the same equilibria to 1e-10: the tennis ball's pads 54 -> 45
#: factorisations, its pins at 21.48 N 27 -> 23; the YCB can at 0.76 N, whose path stopped at 0.97
#: of the force on a step rejected as a jump, runs to the end in 12).
CONTACT_PATH = {"desired_iterations": 8, "reuse_ratio": 0.5, "inertia_rtol": 0.0, "krylov": 0,
                "limit_points": "stop", "predictor": "linear"}


# ---------------------------------------------------------------------------------------------
# the barrier function
def log_barrier(d: np.ndarray, dhat: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """b(d) = -(d - dh)^2 ln(d / dh) and its first two derivatives (zero for d >= dh; b = +inf
    for d <= 0).  Shapes: d (k,) -> three (k,) arrays."""
    d = np.asarray(d, float)
    b = np.zeros_like(d)
    b1 = np.zeros_like(d)
    b2 = np.zeros_like(d)
    act = (d > 0) & (d < dhat)
    x = d[act]
    r = x - dhat
    lg = np.log(x / dhat)
    b[act] = -r * r * lg
    b1[act] = -2 * r * lg - r * r / x
    b2[act] = -2 * lg - 4 * r / x + r * r / (x * x)
    b[d <= 0] = np.inf
    return b, b1, b2


@dataclass
class FingerContact(TermBase):
    """A force-controlled rigid fingertip against the shell (see the module docstring).

    Parameters
    ----------
    obstacle : Capsule | RoundedBox, object frame, at the finger's reference position (s = 0)
    axis : (3,) closing direction of the finger (from the finger into the object)
    force : target force [N] along ``axis`` at load factor 1
    offset : [m] the obstacle is inflated by this (half the wall thickness: the outer skin)
    dhat : [m] barrier reach (default: 5 % of 2 * offset, or 0.1 mm without an offset)
    pressure_scale : [Pa] contact pressure at gap dhat/2 (default: the shell's E)
    reach : [m] lateral sampling radius about the axis (faces whose control centroid is within
        it; default: the obstacle's lateral extent plus one control-mesh edge)
    depth : [m] samples are taken on faces at most this far behind the obstacle's front
        (default: half the shell's extent along the axis)
    spacing : [m] largest sample spacing (default: a third of the obstacle's smallest radius
        of curvature, inflated)
    name : label (e.g. the finger)
    """

    obstacle: object
    axis: tuple
    force: float
    offset: float = 0.0
    dhat: float | None = None
    pressure_scale: float | None = None
    reach: float | None = None
    depth: float | None = None
    spacing: float | None = None
    name: str = "finger"

    # ---- set-up ------------------------------------------------------------------------------
    def build(self, shell, ev) -> "FingerContact":
        """A ready contact term on ``shell`` (a new object; this specification is unchanged)."""
        return copy.copy(self)._setup(shell, ev)

    def _setup(self, shell, ev) -> "FingerContact":
        e = np.asarray(self.axis, float)
        if e.shape != (3,) or not np.all(np.isfinite(e)) or np.linalg.norm(e) == 0:
            raise ProblemError(f"finger contact '{self.name}': axis must be a non-zero 3-vector, got {self.axis!r}")
        if not (np.isfinite(self.force) and self.force >= 0):
            raise ProblemError(f"finger contact '{self.name}': force must be a non-negative number [N], got {self.force!r}")
        self._e = e / np.linalg.norm(e)
        self._obs = self.obstacle.inflated(self.offset) if self.offset else self.obstacle
        self._dh = float(self.dhat if self.dhat is not None else (0.1 * self.offset if self.offset else 1e-4))
        if not self._dh > 0:
            raise ProblemError(f"finger contact '{self.name}': dhat must be positive, got {self._dh!r}")
        mat = shell.material
        E = getattr(mat, "E", None)
        if E is None and hasattr(mat, "mu"):
            E = 3.0 * float(mat.mu)
        p = float(self.pressure_scale if self.pressure_scale is not None else (E or 1e6))
        self._kappa = p / (-float(log_barrier(np.array([self._dh / 2]), self._dh)[1][0]))
        X = shell.rest_positions

        def samples():
            faces, L = select_faces(shell, self._obs, self._e, self.reach, self.depth, self.spacing, self.name)
            st, N, w = sample_faces(shell, ev, faces, L)
            for a in (faces, st, N, w):
                a.flags.writeable = False              # shared by every term built from them
            return faces, L, st, N, w, SampleOperator(st, N, shell.n_control, shell.block_pattern)

        # the same samples for this fingertip's barrier, its friction term and its report: made once
        key = ("finger samples", self._obs, tuple(self._e), self.reach, self.depth, self.spacing)
        made = shell.derived(key, samples) if ev is shell.evaluator else samples()
        self._faces, self._L, self._st, self._N, self._w, self._ops = made
        self._n = shell.n_control
        self._kw = self._kappa * self._w.ravel()                 # barrier weight per sample
        self._shell, self._ev = shell, ev
        x_s = self._points(X)
        phi = self._phi(x_s, 0.0, False)[0]
        if phi.min() <= -0.5 * self._obs.feature_radius:
            raise ProblemError(f"finger contact '{self.name}': the fingertip starts {-phi.min():.3g} m inside the shell "
                               "(its reference position must touch the outer surface)")
        # start where the obstacle no longer reaches any sample (retracted by the overlap + dhat)
        s0 = min(0.0, float(phi.min()) - self._dh)
        self._s0 = s0 - 2 * self._dh - 0.5 * float(np.ptp(X @ self._e))
        self._cond = ForceControlledAdvance(self._obs, self._e, self._dh, log_barrier, self.name, s0,
                                            sums=getattr(self._obs, "log_barrier_sums", None))
        return self

    # ---- kinematics --------------------------------------------------------------------------
    def _points(self, x: np.ndarray) -> np.ndarray:
        """Sample points (F, q, 3) of control points x (n, 3)."""
        return self._ops.points(x).reshape(self._N.shape[:2] + (3,))

    def _phi(self, pts: np.ndarray, s: float, hessian: bool = True):
        shp = pts.shape[:-1]
        out = self._obs.distance(pts.reshape(-1, 3) - s * self._e, hessian)
        return tuple(o.reshape(shp + o.shape[1:]) for o in out)

    def advance(self, x: np.ndarray, F: float) -> float:
        """The finger's advance s* [m] where the barrier force along e equals F [N] (F > 0):
        graspdef.contact.condensation.ForceControlledAdvance over this term's samples."""
        return self._cond.solve(self._ops.points(x), self._kw, F)

    # ---- potential interface ---------------------------------------------------------------------
    def scaled(self) -> bool:
        return True

    def _terms(self, x, F, order, s_at=None):
        """(s*, value, gradient (3n,), Hessian B_xx or None, B_ss, B_xs (3n,)) at force F > 0;
        order 0: value only, 1: + gradient, 2: + B_ss and B_xs, 3: + B_xx.  Only the samples
        within the barrier's reach (d < dhat, including any at d <= 0, where b = +inf) enter."""
        key = getattr(self, "_key", None)
        window = None                       # the advance's final window: only its samples can be active
        if s_at is not None:                                    # a given advance (the first touch)
            s = s_at
        elif key is not None and key[1] == F and np.array_equal(key[0], x):
            s, window = key[2], key[3]
        else:
            s = self.advance(x, F)
            window = self._cond.window
            self._key = (x.copy(), F, s, window)
        P = self._ops.points(x)
        cand = self._cond.active_candidates(s, window)
        d, n, _, _ = self._obs.along(P if cand is None else P[cand], s * self._e, self._e)
        near = np.flatnonzero(d < self._dh)
        act = near if cand is None else cand[near]
        d, n, P = d[near], n[near], P[act] - s * self._e
        b, b1, b2 = log_barrier(d, self._dh)
        kw = self._kw[act]
        value = float((kw * b).sum()) - F * s
        if order < 1:
            return s, value, None, None, None, None
        grad = self._ops.gradient((kw * b1)[:, None] * n, act)          # dB/dp_k scattered
        if order < 2:
            return s, value, grad, None, None, None
        ds = -(n @ self._e)
        along = getattr(self._obs, "hessian_along", None)            # H e without the (k, 3, 3) Hessians
        He = along(P, self._e) if along is not None else self._obs.distance(P, True)[2] @ self._e
        Bss = float((kw * (b2 * ds * ds + b1 * (He @ self._e))).sum())
        vk = (kw * b2 * ds)[:, None] * n - (kw * b1)[:, None] * He     # d2B/dp_k ds
        v = self._ops.gradient(vk, act)
        if order < 3:
            return s, value, grad, None, Bss, v
        H = self._obs.distance(P, True)[2]
        Hk = (kw * b2)[:, None, None] * n[:, :, None] * n[:, None, :] + (kw * b1)[:, None, None] * H
        return s, value, grad, self._ops.hessian(Hk, act), Bss, v

    def evaluate(self, x: np.ndarray, lam: float, order: int = 2, u: np.ndarray | None = None) -> PotentialTerms:
        F = lam * self.force
        self._last = (x.copy(), F, None)
        if F <= 0:                                          # no push: the finger is retracted
            z = sp.csr_matrix((3 * self._n, 3 * self._n)) if order >= 2 else None
            return PotentialTerms(0.0, np.zeros(3 * self._n) if order >= 1 else None, z)
        try:
            s, value, grad, Hm, Bss, v = self._terms(x, F, 3 if order >= 2 else (2 if order == 1 else 0))
        except NoPosition:                                 # infeasible: the solver backs off
            return PotentialTerms(np.inf, None if order == 0 else np.full(3 * self._n, np.nan),
                                  sp.csr_matrix((3 * self._n, 3 * self._n)) if order >= 2 else None)
        if order == 0:
            return PotentialTerms(value, None, None)
        self._last = (self._last[0], F, (Bss, v))
        if order < 2:
            return PotentialTerms(value, grad, None)
        return PotentialTerms(value, grad, Hm, condensed_rank_one(Bss, v))

    def load(self, x: np.ndarray) -> np.ndarray:
        """-d(grad Pi)/d lam = -B_xs F_target / B_ss at the force of the last evaluation; with no
        push yet, the same at the first touch: the fingertip retracted by dhat / 2 from where it
        touches x, so that the samples within its barrier's reach share the force (the load path's
        first predictor; a single sample's point force would start a pad's path from a dimple)."""
        last = getattr(self, "_last", None)
        F = last[1] if last is not None and np.array_equal(last[0], x) else None
        if self.force == 0:
            return np.zeros(3 * self._n)
        if F is None or F <= 0:
            # the condensed load of a fingertip that just touches: retracted by dhat / 2 from the
            # first touch, where the samples within its barrier's reach carry a small force
            s = self.touch(x) - 0.5 * self._dh
            _, _, _, _, Bss, v = self._terms(x, 0.0, 2, s_at=s)
            return condensed_load(Bss, v, self.force)
        if last[2] is not None:
            Bss, v = last[2]
        else:
            try:
                _, _, _, _, Bss, v = self._terms(x, F, 2)
            except NoPosition:
                return np.full(3 * self._n, np.nan)
        return condensed_load(Bss, v, self.force)

    def commit(self, x: np.ndarray) -> None:
        pass

    def touch(self, x: np.ndarray, tol: float = 1e-9) -> float:
        """The advance [m] at which the (inflated) fingertip first touches the samples of control
        points x (n, 3): sphere tracing from the retracted position (|d d/d s| <= 1, so stepping
        by the smallest gap never passes through the surface)."""
        P = self._points(x).reshape(-1, 3)
        s = self._s0
        for _ in range(10000):
            dm = float(self._obs.along(P, s * self._e, self._e)[0].min())
            if dm <= tol:
                return s
            s += dm
        return s

    # ---- per-sample contact state (for the friction term, graspdef.contact.friction) ----------
    @property
    def closing_axis(self) -> np.ndarray:
        """The unit closing axis e (3,) of the finger (object frame)."""
        return self._e.copy()

    @property
    def gap_reach(self) -> float:
        """The barrier's reach dhat [m] (the default resolved)."""
        return self._dh

    @property
    def samples(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The samples: stencils (F, S), basis values N (F, q, S) and rest weights (F, q) [m^2];
        sample point p_fq = sum_s N[f, q, s] x[stencils[f, s]]."""
        return self._st, self._N, self._w

    @property
    def sample_operator(self) -> SampleOperator:
        """The samples as a sparse operator (graspdef.contact.sampling.SampleOperator), rows in the
        (face, sample) order of :attr:`samples`."""
        return self._ops

    def sample_forces(self, x: np.ndarray, F: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """At control points x (n, 3) with the finger pushed by F [N]: the sample points (F, q, 3)
        [m], the normal contact force of each sample (F, q) [N] (barrier pressure x rest weight,
        >= 0; zero for F <= 0) and the fingertip's unit outward normal at each sample's closest
        point (F, q, 3) (the direction of the force on the shell)."""
        pts = self._points(x)
        if F <= 0:
            d, n = self._phi(pts, 0.0, False)
            return pts, np.zeros(d.shape), n
        s = self.advance(x, F)
        d, n = self._phi(pts, s, False)
        _, b1, _ = log_barrier(d.ravel(), self._dh)
        return pts, -self._kappa * b1.reshape(d.shape) * self._w, n

    # ---- reporting ---------------------------------------------------------------------------
    def report(self, x: np.ndarray, lam: float, check_level: int = 3) -> dict:
        """Finger advance, contact force (vector and along the axis), contact area (sampled area
        with gap < dhat, i.e. pressure > 0), peak and mean pressure, smallest gap at the samples
        and on a ``check_level`` times finer grid (x: control points (n, 3))."""
        F = lam * self.force
        base = {"name": self.name, "target_force_N": F, "dhat_m": self._dh, "axis": self._e.tolist(),
                "n_samples": int(self._w.size), "samples_per_face": int(self._w.shape[1])}
        if F <= 0:
            return dict(base, advance_m=0.0, contact_area_m2=0.0)
        s = self.advance(x, F)
        d, n = self._phi(self._points(x), s, False)
        _, b1, _ = log_barrier(d.ravel(), self._dh)
        p = -self._kappa * b1.reshape(d.shape)                    # pressure on the shell [Pa]
        f = ((p * self._w)[..., None] * n).reshape(-1, 3).sum(axis=0)   # force on the shell
        act = d < self._dh
        area = float(self._w[act].sum())
        st, N, _ = sample_faces(self._shell, self._ev, self._faces, self._L * check_level)
        d_fine = self._phi(N @ x[st], s, False)[0]
        return dict(base, advance_m=s, contact_force_N=f.tolist(), contact_force_along_axis_N=float(f @ self._e),
                    contact_area_m2=area, peak_pressure_Pa=float(p.max()),
                    mean_pressure_Pa=float(F / area) if area > 0 else 0.0,
                    min_gap_m=float(d.min()), min_gap_fine_m=float(d_fine.min()), n_active=int(act.sum()))
