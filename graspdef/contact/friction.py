"""Coulomb friction between a fingertip and the shell: IPC's lagged, smoothed friction potential
(Li et al. 2020, "Incremental Potential Contact", section 5; ipc-toolkit's ``friction`` module).

The term works on the samples of a :class:`~graspdef.contact.barrier.FingerContact` (the same
limit-surface points p_k, the same rest weights) and adds, at load factor lam,

    D(x) = mu * lam * sum_k Lam_k f0(|u_k|),        u_k = A_k (p_k(x) - p_k^n)   (2-vector)

* **Lagged normal force.**  Lam_k is the sample's normal contact force (the barrier's pressure x
  the sample's rest weight) at the last converged state, *per unit load factor*: Lam_k =
  lambda_k(x^n, lam^n) / lam^n.  The fingers are force-controlled, so their contact force is
  lam x target at every equilibrium; scaling the lagged distribution by the current lam keeps the
  total normal force of the friction term equal to the current finger force (sum_k lam Lam_k =
  lam F for a flat pad) and lags only its *distribution* by one step.  At the path's start
  (lam^n = 0) the distribution is the barrier's against the unloaded shell pushed with the full
  target force.  (Plain lagging, lambda_k at lam^n, would leave the first step frictionless and
  every step one load increment short of friction.)
* **Lagged tangent basis.**  T_k (3 x 2): two orthonormal tangents of the fingertip's surface at
  the sample's closest point at the last converged state.  The finger moves only along its
  closing axis e (its advance s is condensed out by the barrier), so the slip is measured in the
  plane normal to e: A_k = T_k^T (I - e e^T).  For a pad whose face normal is e (the gripper's
  pads) this is exactly T_k^T; on a curved fingertip (a pin, a pad's rounded edge) it is exact
  when the shell point follows the finger along e (sticking) and otherwise drops the slip's
  component along e.
* **Slip.**  u_k is the tangential slip of sample k since the last converged state p_k^n.
* **Smoothed Coulomb law.**  f0 is IPC's C1 mollifier of |u|: f0' = f1, f1(y) = -y^2/eps_v^2 +
  2 y/eps_v for y < eps_v and 1 beyond (f0(0) = eps_v/3, so f0 is continuous).  The friction
  force on sample k is mu lam Lam_k f1(|u_k|) in the direction opposite to the slip: full
  Coulomb sliding force for |u_k| >= eps_v (**slip**), proportional to the slip below
  (**stick**; the slip per load step stays below eps_v).

Gradient and Hessian are exact for the lagged potential: f0(|u|) is convex in u (f0 convex and
non-decreasing), so the Hessian mu lam Lam_k A_k^T [f1'(y) uu^T/y^2 + f1(y)/y (I - uu^T/y^2)] A_k
is positive semi-definite as it is; no projection is applied.

**Lagging.**  Lam_k, T_k and p_k^n are updated at every converged load step (``commit``): the
result is the lagged (semi-implicit) friction with **one lagging pass per load step** (no extra
fixed-point passes at a step; IPC's converged friction would repeat each step until Lam, T stop
changing).  Because p^n moves with every committed step, a stuck contact under a constant
tangential load creeps by a fraction of eps_v per load step (f1(y) = f/(mu lambda) needs y > 0).

The load factor scales the term (D is linear in lam), so its generalised load is -D_x / lam.
"""
from __future__ import annotations

import copy
from collections import deque
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import ProblemError
from ..problem.terms import TermBase, TermValue
from .barrier import FingerContact

#: default slip length eps_v as a fraction of the barrier's reach dhat (dhat: 5 % of the wall
#: thickness by default, so eps_v = 0.5 % of t: 10 um for a 2 mm wall)
EPS_V_PER_DHAT = 0.1


def mollifier(y: np.ndarray, eps: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """IPC's f0(y), f1(y)/y and f1'(y) for slips y >= 0 (f1 = f0'); f1(y)/y is finite at 0."""
    y = np.asarray(y, float)
    st = y < eps
    f0 = np.where(st, -y ** 3 / (3 * eps * eps) + y * y / eps + eps / 3, y)
    f1y = np.where(st, -y / (eps * eps) + 2 / eps, 1 / np.where(st, 1.0, y))
    df1 = np.where(st, -2 * y / (eps * eps) + 2 / eps, 0.0)
    return f0, f1y, df1


def check_mu(mu, what: str = "friction coefficient") -> float:
    """A friction coefficient mu: a finite number >= 0 (else ProblemError, one line)."""
    try:
        m = float(mu)
    except (TypeError, ValueError):
        raise ProblemError(f"{what} must be a number >= 0, got {mu!r}") from None
    if not np.isfinite(m) or m < 0:
        raise ProblemError(f"{what} must be a finite number >= 0, got {mu!r}")
    return m


def tangent_basis(n: np.ndarray) -> np.ndarray:
    """Two orthonormal tangents (..., 3, 2) normal to the unit vectors n (..., 3)."""
    a = np.zeros_like(n)
    ax = np.argmin(np.abs(n), axis=-1)
    np.put_along_axis(a, ax[..., None], 1.0, axis=-1)
    t1 = np.cross(n, a)
    t1 /= np.linalg.norm(t1, axis=-1, keepdims=True)
    t2 = np.cross(n, t1)
    return np.stack([t1, t2], axis=-1)


@dataclass
class FingerFriction(TermBase):
    """Coulomb friction of a fingertip on the shell (module docstring): an energy term built from
    a :class:`FingerContact` specification (same samples) and the friction coefficient.

    Parameters
    ----------
    contact : the finger's FingerContact (specification; built here again on the same shell)
    mu : Coulomb friction coefficient (>= 0; 0 gives an identically zero term)
    eps_v : [m] slip length of the smoothed Coulomb law (default: ``EPS_V_PER_DHAT`` x the
        barrier's reach dhat, i.e. 0.5 % of the wall thickness)
    """

    contact: FingerContact
    mu: float
    eps_v: float | None = None

    def __post_init__(self) -> None:
        self.mu = check_mu(self.mu, f"finger friction '{getattr(self.contact, 'name', '?')}': mu")
        if not isinstance(self.contact, FingerContact):
            raise ProblemError(f"finger friction: contact must be a FingerContact, got {type(self.contact).__name__}")
        if self.eps_v is not None and not (np.isfinite(self.eps_v) and self.eps_v > 0):
            raise ProblemError(f"finger friction '{self.contact.name}': eps_v must be a positive length [m], "
                               f"got {self.eps_v!r}")

    @property
    def name(self) -> str:
        return self.contact.name

    @property
    def record_name(self) -> str:
        return f"friction_{self.contact.name}_"

    # ---- set-up ------------------------------------------------------------------------------
    def build(self, shell, ev) -> "FingerFriction":
        """A ready friction term on ``shell`` (a new object; this specification is unchanged)."""
        t = copy.copy(self)
        t._fc = self.contact.build(shell, ev)
        t._ops = t._fc.sample_operator
        e = t._fc.closing_axis
        t._Pe = np.eye(3) - np.outer(e, e)
        t._eps = float(self.eps_v if self.eps_v is not None else EPS_V_PER_DHAT * t._fc.gap_reach)
        t._n = shell.n_control
        t._lag = None              # (points p^n (F, q, 3), Lam (F, q) [N per unit lam], A (F, q, 2, 3))
        t._seen = deque(maxlen=8)  # recent (x, lam) of evaluations: commit/record find their lam
        t._unit = None             # (x, gradient at lam = 1) of the last evaluation (the load)
        t.last_step = {}
        return t

    def _lam_of(self, x: np.ndarray) -> float:
        for y, lam in reversed(self._seen):
            if np.array_equal(y, x):
                return lam
        return self._seen[-1][1] if self._seen else 0.0

    def lag(self, x: np.ndarray, lam: float) -> None:
        """Set the lagged state at control points x (n, 3) and load factor lam: the points p^n, the
        normal force per unit load factor Lam (at lam = 0: that of the full target force) and the
        slip operators A = T^T (I - e e^T) from the fingertip's normal at each sample."""
        F = lam * self._fc.force if lam > 0 else self._fc.force
        pts, fn, nrm = self._fc.sample_forces(x, F)
        Lam = fn.ravel() / (lam if lam > 0 else 1.0)
        act = np.flatnonzero(Lam > 0)                                  # samples in contact
        T = tangent_basis(nrm.reshape(-1, 3)[act])                     # (k, 3, 2)
        A = np.einsum("kia,ij->kaj", T, self._Pe)                      # (k, 2, 3)
        self._lag = (act, pts.reshape(-1, 3)[act].copy(), Lam[act], A)

    def _slip(self, x: np.ndarray):
        """The samples in contact at the lagged state (k,), their slips u (k, 2), Lam (k,) and
        A (k, 2, 3)."""
        act, P, Lam, A = self._lag
        dp = self._ops.points(x, act) - P
        return act, np.einsum("kaj,kj->ka", A, dp), Lam, A

    # ---- energy-term protocol ----------------------------------------------------------------
    def evaluate(self, x: np.ndarray, lam: float, order: int = 2, u: np.ndarray | None = None) -> TermValue:
        self._seen.append((x.copy(), float(lam)))
        n3 = 3 * self._n
        if self._lag is None:                      # used before any commit: lag at this state
            self.lag(x, lam)
        if self.mu == 0 or lam <= 0:
            self._unit = None
            g = np.zeros(n3) if order >= 1 else None
            return TermValue(0.0, g, sp.csr_matrix((n3, n3)) if order >= 2 else None)
        af, uk, Lam, A = self._slip(x)
        y = np.linalg.norm(uk, axis=-1)
        f0, f1y, df1 = mollifier(y, self._eps)
        c = self.mu * Lam                                              # per unit load factor
        value = lam * float((c * f0).sum())
        if order == 0:
            return TermValue(value, None, None)
        gp = np.einsum("kaj,ka->kj", A, (c * f1y)[:, None] * uk)      # dD/dp_k at lam = 1
        g1 = self._ops.gradient(gp, af)
        self._unit = (x.copy(), g1)
        if order < 2:
            return TermValue(value, lam * g1, None)
        # Hessian in the slip plane: f1/y I + (f1' - f1/y) uu^T / y^2
        ysafe = np.where(y > 0, y, 1.0)
        w = np.where(y < self._eps, -1.0 / (self._eps * self._eps * ysafe), -1.0 / ysafe ** 3)
        w = np.where(y > 0, w, 0.0)
        Hu = (f1y[:, None, None] * np.eye(2) + w[:, None, None] * uk[:, :, None] * uk[:, None, :])
        Hp = (lam * c)[:, None, None] * (np.transpose(A, (0, 2, 1)) @ (Hu @ A))   # A^T Hu A (k, 3, 3)
        H = self._ops.hessian(Hp, af)
        return TermValue(value, lam * g1, H)

    def load(self, x: np.ndarray) -> np.ndarray | None:
        """-d(gradient)/d lam = -(gradient at lam = 1): D is linear in lam."""
        if self.mu == 0:
            return None
        if self._unit is None or not np.array_equal(self._unit[0], x):
            if self._lag is None:
                return np.zeros(3 * self._n)
            self.evaluate(x, 1.0, 1)
            self._seen.pop()
        return -self._unit[1]

    def commit(self, x: np.ndarray) -> None:
        """A converged state: keep its step's numbers (``last_step``), then lag Lam, T and p^n there."""
        lam = self._lam_of(x)
        if self._lag is not None:
            self.last_step = self.step_report(x, lam)
        self.lag(x, lam)

    def record(self, x: np.ndarray) -> dict:
        """mu, stick and slip sample counts, the friction force on the shell (sum, its magnitude
        and the magnitude of its part normal to the closing axis [N]), the normal force it is
        lagged from [N] and the largest slip [m] of the step that ends at x."""
        if self._lag is None:
            return {}
        r = self.step_report(x, self._lam_of(x))
        return {k: v for k, v in r.items() if not isinstance(v, (str, list))}

    def step_report(self, x: np.ndarray, lam: float) -> dict:
        """The step from the lagged state to control points x (n, 3) at load factor lam (see
        :meth:`record`); samples with a lagged normal force count as stick (slip < eps_v) or slip."""
        af, uk, Lam, A = self._slip(x)
        y = np.linalg.norm(uk, axis=-1)
        act = Lam > 0
        _, f1y, _ = mollifier(y, self._eps)
        fp = -np.einsum("kaj,ka->kj", A, (self.mu * lam * Lam * f1y)[:, None] * uk)   # force on the shell
        f = fp.sum(axis=0) if fp.size else np.zeros(3)
        e = self._fc.closing_axis
        return {"mu": self.mu, "eps_v_m": self._eps, "n_stick": int((act & (y < self._eps)).sum()),
                "n_slip": int((act & (y >= self._eps)).sum()),
                "tangential_force_N": float(np.linalg.norm(f - (f @ e) * e)),
                "friction_force_x_N": float(f[0]), "friction_force_y_N": float(f[1]), "friction_force_z_N": float(f[2]),
                "lagged_normal_force_N": float(lam * Lam.sum()), "max_slip_m": float(y.max()) if y.size else 0.0}
