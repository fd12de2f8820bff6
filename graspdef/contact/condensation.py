"""The force-controlled finger: its advance s along the closing axis e is not an unknown of the
solver but is condensed out exactly (graspdef.contact.barrier's module docstring): for control
points x, s*(x) solves dB/ds = F, found here by a safeguarded scalar Newton iteration; the
condensed Hessian is B_xx - B_xs B_xs^T / B_ss (a rank-one part with a negative coefficient) and
the load direction -B_xs F_target / B_ss."""
from __future__ import annotations

import numpy as np

from ..errors import ProblemError


class NoPosition(ProblemError):
    """No finger advance balances the force for this configuration (a sample point went
    through the fingertip): the potential is +inf there."""


class ForceControlledAdvance:
    """The condensed degree of freedom: the advance s [m] of an obstacle along the unit axis e
    where the barrier force of the samples equals F.  ``barrier``: the function b(d) -> (b, b',
    b'') of the gap; ``dhat``: its reach; ``s``: the starting advance (kept: each solve starts
    from the last solution); ``sums``: the obstacle's compiled (B_s, B_ss, smallest gap) of the
    same barrier (e.g. ``RoundedBox.log_barrier_sums`` for graspdef.contact.barrier.log_barrier),
    or None: :meth:`derivatives` then sums the barrier's values in numpy."""

    def __init__(self, obstacle, e: np.ndarray, dhat: float, barrier, name: str, s: float = 0.0, sums=None):
        self._obs, self._e, self._dh, self._barrier, self.name = obstacle, e, dhat, barrier, name
        self._sums = sums
        self.s = s
        self.window = None          # (centre, sample indices) of the last solve's final window

    def derivatives(self, pts, kw, s):
        """(B_s, B_ss, feasible, smallest gap (inf for none)) at advance s for flat sample points
        pts (k, 3), weights kw (k,)."""
        if self._sums is not None:
            g, gs, dmin = self._sums(pts, kw, s * self._e, self._e, self._dh)
            return g, gs, dmin > 0, dmin
        d, _, ds, dss = self._obs.along(pts, s * self._e, self._e)
        dmin = float(d.min()) if d.size else np.inf
        if dmin <= 0:
            return np.inf, 0.0, False, dmin
        act = d < self._dh
        if not act.any():
            return 0.0, 0.0, True, dmin
        _, b1, b2 = self._barrier(d[act], self._dh)
        ds, dss, kw = ds[act], dss[act], kw[act]
        return float((kw * b1 * ds).sum()), float((kw * (b2 * ds * ds + b1 * dss)).sum()), True, dmin

    def solve(self, P: np.ndarray, KW: np.ndarray, F: float) -> float:
        """The advance s* [m] where the barrier force along e of the sample points P (k, 3) with
        weights KW (k,) equals F [N] (F > 0).

        Safeguarded Newton on G(s) = dB/ds - F from the last solution (usually close to the new
        one: from a converged advance, one evaluation), over the samples that can reach the
        barrier within a window |s - s_c| < W around a centre s_c (|d d/d s| <= 1, so the others
        are inactive and feasible there); the window moves when an iterate leaves it.  Each
        iterate's sign of G narrows a bracket [lo, hi] of the root; a Newton step that leaves it
        is replaced by its midpoint, and before the root is bracketed from above an advance never
        exceeds 0.9 of the smallest gap (the fingertip cannot jump over a sample; with no sample
        within reach, that is the step itself: sphere tracing).  An infeasible iterate (a sample
        through the fingertip) counts as G = +inf.  The final window is kept (:attr:`window`: its
        centre and sample indices; the samples outside it are out of the barrier's reach at the
        solution)."""
        W = self.reach
        sel = {}

        def window(sc):
            d = self._obs.along(P, sc * self._e, self._e)[0]
            idx = np.flatnonzero(d < self._dh + W)
            sel.update(c=sc, idx=idx, p=P[idx], kw=KW[idx], at=None, dc=float(d.min()) if d.size else np.inf)

        def G(t):
            if abs(t - sel["c"]) >= W:
                window(t)
            g, gs, ok, dm = self.derivatives(sel["p"], sel["kw"], t)
            sel["at"] = (t, dm)                  # the window's smallest gap at t (for dmin)
            return (g - F if ok else np.inf), gs, ok

        def dmin(t):
            """A lower bound of the smallest gap at t: within the window, the window's smallest
            gap or, if smaller, max(dhat + W, d_c) - |t - s_c| (the least gap a sample outside it
            can have there: it had d >= dhat + W and d >= d_c, the smallest gap of all samples,
            at s_c); elsewhere the smallest gap of all samples."""
            off = abs(t - sel["c"])
            if off < W:
                bound = max(self._dh + W, sel["dc"]) - off
                if len(sel["p"]):
                    at = sel["at"]
                    gap = at[1] if at is not None and at[0] == t else \
                        float(self._obs.along(sel["p"], t * self._e, self._e)[0].min())
                    bound = min(bound, gap)
                return bound
            return float(self._obs.along(P, t * self._e, self._e)[0].min())

        def settle(s):
            """The root from s, or None when no feasible advance balances F from there (the reason
            in ``sel["why"]``)."""
            window(s)
            lo, hi = -np.inf, np.inf
            Gs, gs, ok = G(s)
            back = self._dh                      # a retreat without a Newton step, doubled each time
            while not ok:                        # a sample through the fingertip: retreat
                hi = s
                s -= max(back, 0.5 * self._dh - sel["at"][1])      # (its gap grows like the retreat)
                back *= 2
                if back > 2 ** 60 * self._dh:
                    sel["why"] = "a shell point is behind the fingertip"
                    return None
                Gs, gs, ok = G(s)
            for _ in range(200):
                if abs(Gs) <= 1e-12 * F:
                    break
                if Gs < 0:
                    lo = s
                else:
                    hi = s
                if hi - lo <= 1e-15 * max(abs(s), self._dh):      # (inf while unbracketed)
                    break
                # Newton on log(dB/ds) = log F: the barrier's force grows like a power of the
                # inverse gap, nearly exponentially in s, which the logarithm makes nearly linear
                g = Gs + F
                t = s - np.log(g / F) * g / gs if g > 0 and gs > 0 else np.nan
                if np.isinf(hi):                 # advancing, the root not yet bounded above
                    dm = dmin(s)
                    cap = s + (0.9 * dm if g > 0 or dm < self._dh else dm - 0.5 * self._dh)
                    if not t < cap:              # (also for t = nan: sphere tracing, or with no
                        t = cap                  # sample within reach, to half the reach)
                elif not lo < t < hi:
                    if np.isfinite(lo):
                        t = 0.5 * (lo + hi)
                    else:                        # retreating, the root not yet bounded below
                        t, back = s - back, 2 * back
                Gt, gt, okt = G(t)
                if not okt:
                    hi = min(hi, t)
                    continue
                small = abs(t - s) <= 1e-13 * self._dh
                s, Gs, gs = t, Gt, gt
                if small:
                    break
            else:
                sel["why"] = f"no convergence in 200 iterations (|dB/ds - F| = {abs(Gs):.3g} N)"
                return None
            return s

        s = settle(self.s)
        if s is None:
            s = settle(0.0)
        if s is None:
            raise NoPosition(f"finger contact '{self.name}': no finger position balances {F:.6g} N "
                             f"({sel['why']})")
        self.s = s
        self.window = (sel["c"], sel["idx"]) if abs(s - sel["c"]) < W else None
        return s

    @property
    def reach(self) -> float:
        """The half-width W [m] of a window of advances: 8 dhat."""
        return 8 * self._dh

    def active_candidates(self, s: float, window) -> np.ndarray | None:
        """The indices of the samples that can be within the barrier's reach at advance s: those
        of ``window`` (a :attr:`window` of the solve at these points) when s lies inside it, else
        None (all).  A sample outside the window had d >= dhat + W at its centre s_c, and
        |d d/ds| <= 1, so d > dhat at any |s - s_c| < W."""
        if window is None or not abs(s - window[0]) < self.reach:
            return None
        return window[1]


def condensed_rank_one(Bss: float, v: np.ndarray) -> list:
    """The rank-one Hessian part -B_xs B_xs^T / B_ss of the condensed advance ([] when B_ss <= 0)."""
    return [(-1.0 / Bss, v)] if Bss > 0 else []


def condensed_load(Bss: float, v: np.ndarray, force: float) -> np.ndarray:
    """-d(grad Pi)/d lam = -B_xs F_target / B_ss (zero when B_ss <= 0)."""
    if not Bss > 0:
        return np.zeros_like(v)
    return -v * force / Bss
