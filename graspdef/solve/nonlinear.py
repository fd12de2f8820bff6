"""Nonlinear equilibrium paths: Newton's method with load stepping, and arc-length continuation.

* Load (or displacement) control: the load factor lam goes from 0 to ``max_load`` in adaptive
  steps; Newton's method with an energy line search at each; a step that fails is halved, and
  easy steps grow.  Requested ``targets`` are landed on exactly.  The predicted increment grows
  by ``max_growth`` at most over the last one (so steps shrink where the response softens
  towards a limit point), and a step whose increment differs from the trapezoid rule of the
  tangents du/dlam at its two ends by more than ``jump_ratio`` of itself is rejected and
  halved: it jumped -- over a limit point, or onto another branch -- which the stability of the
  points alone does not show (both ends may be stable).  Once a limit point is suspected, each
  step aims 0.9 of the way to its load as extrapolated from the tangents (|du/dlam|^-2 falls
  linearly to zero there: :func:`fold_estimate`), and the attempts beyond it get
  ``desired_iterations`` Newton iterations.  Where the halved
  steps stall (cut below ``min_step``) at such a limit point of the load, the path snaps as a
  loaded structure does (``limit_points = "jump"``): it takes the equilibrium past the limit
  point, records the limit point as passed by a jump (``critical_points``) and goes on; or it
  stops there (``"stop"``).  Arc-length continuation follows the unstable part instead.
* Arc-length (Crisfield's cylindrical constraint |du|^2 = dl^2, root closest to the previous
  direction; predictor sign from the previous increment): passes limit points and snap-backs; the
  arc length adapts to the number of Newton iterations.  Requested load levels crossed on the way
  are solved exactly by a load-controlled Newton from the interpolated state.
* Every converged point carries its stability (the inertia of the Hessian on the constraint null
  space, from the factorisation's negative pivots); a change between points is reported as a
  limit point (the load factor turns) or a bifurcation point (it does not).
* Nothing unconverged is ever returned as a result: when the path cannot continue (the step is
  cut below its minimum, the iteration limit on every retry) :class:`PathStopped` is raised with
  the converged part of the path attached (or, with ``allow_partial``, the solution is returned
  with ``completed = False`` and the reason).
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import ProblemError, SolverError
from ..problem.potentials import EnclosedGas
from ..problem.problem import Problem
from .equilibrium import Equilibrium
from .result import DisplacementField

log = logging.getLogger(__name__)

METHODS = ("load", "arc_length")
BIFURCATION = ("report", "locate", "switch")
LIMIT_POINTS = ("jump", "stop")
PREDICTORS = ("quadratic", "linear", "cubic")
#: options read by load-controlled paths only (PathSolver._load_control); an arc-length path
#: refuses them rather than ignore them
LOAD_CONTROL_ONLY = ("max_step", "jump_ratio", "predictor", "limit_points")


def _refuse_load_control_options(names) -> None:
    if names:
        raise ProblemError(f"{', '.join(names)} {'is an option' if len(names) == 1 else 'are options'} of "
                           "load-controlled paths (method 'load'); an arc-length path sets its steps by arc "
                           "length (steps, max_growth, desired_iterations) and follows limit points itself")
#: Forcing term of a Newton step solved with a single-precision factor (PathSolver.newton's
#: ``direction``): its relative residual is at most this times min(rel, 0.1) of the projected one
NEWTON_FORCING = 0.1
#: ... and of one on a reused (earlier) tangent, which contracts the residual by ~0.01-0.9 per step
STALE_FORCING = 1e-3
#: Halvings of a local correction's step (PathOptions.local_rings) whose energy does not decrease,
#: before the tangent is factorised at that iterate instead
LOCAL_BACKTRACKS = 4
#: ... and the factor by which its rings grow, once per Newton solve, when a local correction's step
#: does not contract by ``reuse_ratio``
LOCAL_GROWTH = 2

#: First Newton iteration at which a residual grown tenfold over the first iterate's ends the
#: attempt (PathSolver.newton).  Measured over 19 load-controlled paths of the nonlinear benchmark
#: set (2026-11-28, 579 Newton solves): no solve that converged had a residual above ten
#: times its first (relative or absolute) from iteration 4 on; of the 40 that failed, 8 had, most
#: of them from their first step on (up to 5e8 times), and ran on to their 25 iterations.
DIVERGENCE_ITERATIONS = 4

#: An Anderson-mixed step whose iterate's residual is more than this many times the residual where
#: it started is taken back, and a plain step on the reused tangent is taken from there
#: (PathSolver.newton; a safeguard of the kind of Zhang, O'Donoghue & Boyd, SIAM J. Optim. 30
#: (2020) 3170).  Measured 2026-11-28 (factorisations of whole paths, without -> with): slit
#: annular plate 241 -> 213, 48 x 48 pinched cylinder 200 -> 194, 32-ring hemisphere 71 -> 68,
#: 10k ball (quadratic predictor) 22 -> 21, SVK pull-out 92 -> 93; the cantilever and the ball
#: with the cubic predictor the same.  10 instead of 2: only the 48 x 48 changes (190).
ANDERSON_GROWTH = 2.0

#: Loosest forcing term of an inexact Newton step (|F + J s| <= eta |F|; Eisenstat & Walker 1996)
KRYLOV_ETA_MAX = 0.1

#: A back-tracked Newton step on its iterate's own tangent takes one more energy trial, at the
#: minimum of the parabola through the trials (:func:`parabola_step`), when that lies more than this
#: fraction of the halved step away from it.  Measured 2026-12-07 (factorisations of whole grasp
#: paths with fingertip contact, without -> with; the same final states to the printed digits): the
#: tennis ball's pads at 21.48 N 45 -> 38, at 10 N 37 -> 32, at 30 N 63 -> 43, with 8 and 16 initial
#: steps 52 -> 46 and 49 -> 47; its pins 23 -> 19; the duck at 0.5 N 90 -> 71; the soda can 11 -> 11.
#: An exact line search (bounded Brent to 1e-3) gives 39 on the pads: one trial takes most of it.
#: Not better everywhere: a 162-vertex linear-elastic sphere crushed between pads at 2 N (a snap)
#: 102 -> 145.  Not in the patient descent past a limit point (``newton(patient=True)``), which
#: back-tracks by halving alone: with the parabola there the paper duck at 0.5 N (point loads) lost
#: its jump past the limit point at load factor 0.712 and stopped there instead of at 0.846.
PARABOLA_MIN_MOVE = 0.1


def parabola_step(e0: float, slope: float, a: float, ea: float, e2a: float = np.inf) -> float | None:
    """The step length at the minimum of the parabola through the energies of a back-tracking line
    search: E(0) = ``e0`` and E(a) = ``ea`` with, when finite, E(2a) = ``e2a`` (the trial rejected before
    ``a``), else the slope E'(0) = ``slope``; clamped to [a/2, 2a] (the back-tracking's bracket: the
    parabola is a model there only).  None when the parabola is not convex or its minimum lies within
    :data:`PARABOLA_MIN_MOVE` x a of ``a`` (not worth a trial)."""
    if np.isfinite(e2a):
        c2 = (e2a - 2.0 * ea + e0) / (2.0 * a * a)
        c1 = (4.0 * ea - e2a - 3.0 * e0) / (2.0 * a)
    else:
        c1, c2 = slope, (ea - e0 - slope * a) / (a * a)
    if not (np.isfinite(c1) and np.isfinite(c2)) or c2 <= 0:
        return None
    aq = min(max(-c1 / (2.0 * c2), 0.5 * a), 2.0 * a)
    return aq if abs(aq - a) > PARABOLA_MIN_MOVE * a else None


class PathStopped(SolverError):
    """The load path could not continue; ``.solution`` holds the converged part."""

    def __init__(self, message: str, solution: "NonlinearSolution"):
        super().__init__(message)
        self.solution = solution


#: a step that approaches a limit point aims this fraction of the way to its estimated load
FOLD_SHORT = 0.9

#: where a bisection step that locates a change of stability tries its point, as fractions of
#: the bracket from its stable end, in this order (:meth:`PathSolver._locate`)
LOCATE_SPLITS = (0.5, 0.25, 0.75)

#: the ``action`` of the event a critical point's bracket that could not be narrowed leaves
BRACKET_NOT_NARROWED = "critical point's bracket not narrowed further"


def fold_estimate(lam1: float, n1: float, lam2: float, n2: float) -> float | None:
    """The load factor of a limit point ahead, from the tangent norms n = |du/dlam| at two
    converged points approaching it: near a (quadratic) fold lam_c - lam ~ (u - u_c)^2, so
    |du/dlam|^-2 falls linearly to zero at lam_c; None unless the tangent grows towards lam2."""
    if not (n1 > 0 and n2 > n1 and lam2 != lam1):
        return None
    y1, y2 = n1 ** -2, n2 ** -2
    return lam2 + y2 * (lam2 - lam1) / (y1 - y2)


def extrapolate(u: np.ndarray, t: np.ndarray, step: float, u_back: np.ndarray, h: float,
                t_back: np.ndarray | None = None, kind: str = "quadratic") -> np.ndarray:
    """The first iterate of a load step from a converged point (u, with the tangent t = du/dlam
    there) to lam + step, given the previous point u_back at lam - h (and its tangent ``t_back``):
    the polynomial u(lam + tau h) = u + tau h t + a tau^2 + b tau^3 through them, at tau = step / h.

    "linear": a = b = 0 (the tangent alone); "quadratic": b = 0, a = u_back - u + h t (through
    u_back); "cubic": the Hermite cubic that also has the tangent t_back at u_back, a = 3 d +
    h (t_back - t) and b = 2 d + h (t_back - t) with d = u_back - u + h t.  Each is exact on paths
    that are polynomials of its degree in lam; the extrapolation error of a smooth path is
    O(step^2), O(step^3) and O(step^4)."""
    tau = step / h
    u0 = u + step * t
    if kind == "linear":
        return u0
    d = u_back - u + h * t
    if kind == "quadratic":
        return u0 + tau ** 2 * d
    if t_back is None:
        raise ValueError("the cubic predictor needs the tangent at the previous point")
    b = 2 * d + h * (t_back - t)
    if abs(tau) * float(np.linalg.norm(b)) > float(np.linalg.norm(d)):
        # the cubic term outgrows the quadratic one: the last two points do not resolve the
        # path's curvature here (its extrapolation is not converging), so the quadratic
        return u0 + tau ** 2 * d
    return u0 + tau ** 2 * (d + b) + tau ** 3 * b


@dataclass(frozen=True)
class PathOptions:
    """Settings of a nonlinear solve.

    method : "load" (load or displacement control) or "arc_length"
    max_load : final load factor (loads and prescribed displacements are multiplied by it)
    steps : initial number of steps to ``max_load`` (the step then adapts)
    targets : load factors to land on exactly (e.g. tabulated loads)
    max_steps : cap on accepted steps;  max_iterations : Newton iterations per attempt
    tol : relative residual (|grad Pi + C^T mu| / force scale) for convergence
    min_step : smallest load (or arc-length) fraction before the path stops
    desired_iterations : the step adapts towards this many Newton iterations (8: most of them are
        cheap modified-Newton iterations on a reused tangent; 5 before, which kept steps from growing)
    max_growth : largest factor by which a step grows
    max_step : largest load-factor increment of a load-controlled step (None: no cap; the step
        grows after easy steps).  A path compared as a curve by interpolation between its points
        (graspdef.bench, ``compare = "curve"``) is capped at max_load / steps
    line_search : energy back-tracking in load control (halving; a step back-tracked on its own
        tangent then takes one trial at the minimum of the parabola through its trials,
        :func:`parabola_step` -- not in the patient descent past a limit point)
    max_probe_displacement : [m] the path also ends (completed) once a probe has moved this far
        (for paths whose load never reaches ``max_load``, e.g. past a pressure maximum)
    reuse_factorisation, reuse_ratio : in load control, reuse a factorised tangent (the previous
        converged point's) while the residual contracts by reuse_ratio per iteration (modified Newton)
    anderson : depth of the Anderson mixing of the modified-Newton corrections (0: plain)
    krylov, krylov_rtol : where the reused tangent contracts too slowly, first try an inexact Newton
        step -- the Newton system at the iterate solved by GMRES preconditioned by the reused
        factorisation (tangent products by gradient differences) to krylov_rtol times its residual --
        and factorise only when GMRES needs more than ``krylov`` iterations (e.g. 10; 0, the
        default: always factorise -- the inexact steps pay on the 10k-vertex air-filled ball, 22 ->
        12 factorisations, but not on the slit annular plate nor on the 18,624-vertex pinched
        cylinder, 229 -> 261 factorisations); see :meth:`PathSolver.newton`
    inertia_rtol : the stability of a point is the inertia of a Hessian factorised within this
        relative residual of it (0: at the converged state itself); see :meth:`PathSolver.newton`
    local_rings : local corrections on a reused tangent (0: none): the Newton steps on the previous
        point's factorisation are each preceded by an exact Newton step in the region where the
        first iterate's residual sits (the fewest control vertices holding 99 % of its square, grown
        by this many rings of the control mesh; :meth:`Equilibrium.local_step`), as long as they
        contract by ``reuse_ratio``; only where every energy term gives its Hessian's rows
        (``hessian_rows``: the shell, dead and point loads, pressure, enclosed gas) and the region
        holds at most a quarter of the control vertices; see :meth:`PathSolver.newton`
    bifurcation : what a load-controlled path does at a change of stability that is not a limit
        point -- "report" (the bracket of the two path points), "locate" (bisect the load step
        ``refine_critical`` times: the bracket shrinks by 2^-refine_critical) or "switch" (locate,
        then leave the fundamental path along the critical eigenvector -- inverse iteration on the
        tangent at the critical point -- and follow the secondary branch by arc length to
        ``max_load``)
    refine_critical : arc-length bisections that narrow a change of stability down (each halves
        the bracket; the load factor at a limit point is then accurate to O(bracket^2))
    jump_ratio : a load step from (u_a, lam_a) to (u_b, lam_b) is rejected (and halved) when
        |du - h (t_a + t_b) / 2| > jump_ratio |du| (du = u_b - u_a, h = lam_b - lam_a, t the
        tangents du/dlam at the two ends, t_b from the factorisation the next step's predictor
        uses anyway): along a continuous path the trapezoid rule's error is O(h^2) of du, across
        a jump it is O(1).  Measured: 0.0007-0.12 on resolved steps (a hinged roof, the 48 x 48
        pinched cylinder, the ball's grasps), up to 0.22 on steps ending next to a limit point;
        0.58 and 0.92 on steps that jumped over one unnoticed.  Not applied to the first step
        nor to the first after a jump (no curvature term to go with them); 0: no check
    predictor : the first iterate of a load-controlled step (:func:`extrapolate`) --
        "cubic" (the default since 2026-11-28, eighteenth session): the Hermite cubic through the
        last two points with the tangents at both, on a plain stretch of the path (not towards a
        limit point nor past a jumped one) and where its cubic term is smaller than its quadratic
        one, else the quadratic; "quadratic" (the default before): the tangent du/dlam plus the
        curvature of the last step (u(lam) through the last two points with the tangent at the
        last); "linear": the tangent alone.  Factorisations of whole paths, cubic against quadratic
        (710ca72, one run each; counts do not depend on the machine's load): the 10k ball's pinch 19
        against 21 (11.9 against 13.0 s in one hour's alternating runs), the 32-ring hemispheres 47 / 59 against 68 / 71, the slit
        annular plate 163 against 213, the cantilevers 67 / 31 against 82 / 37, the neo-Hookean
        pull-out 73 against 83, the 192 x 96 pinched cylinder 202 against 268; more on the SVK
        pull-out (96 against 93), the hinged roof (17 against 16) and the neo-Hookean 48 x 48
        pinched cylinder (166 against 144); the same on the 48 x 48 (194).  The displacement-
        controlled pinched cylinders cross trains of bifurcations after their snap, where the count
        follows the iterates' last bits (the 192 x 96's quadratic path took 177 before the Anderson
        safeguard, ANDERSON_GROWTH, and 268 with it; the cubic 220 and 202; with graspdef bench's
        step cap, max_step = max_load / steps: 48 x 48 195 against 202, neo-Hookean 319 against
        336, pull-outs 95 / 84 against 103 / 91, 192 x 96 262 against 237): docs/speed.md,
        "Eighteenth session".
        Where the contact set changes from step to step (graspdef's finger-contact paths) u(lam)
        has a kink at each change and the curvature term overshoots: on the tennis ball's pads the
        linear predictor needs 45 factorisations instead of 54 for the same equilibria (to 1e-10)
    limit_points : what load control does where its steps stall (halved below ``min_step``) at
        a limit point of the load -- "jump" (the default): snap, as the loaded structure does,
        to the equilibrium that the smallest jumping step reached (or, if every attempt failed,
        the one that Newton finds from the last point at the load of one initial step further),
        record it in ``critical_points`` (kind "limit point (jumped)", with the bracket and the
        jump) and go on; "stop": end the path there (graspdef's finger-contact paths stop)

    max_step, jump_ratio, predictor and limit_points are read by load-controlled paths only: with
    ``method = "arc_length"`` a value other than the default is refused (ProblemError), and so is
    any of them in a problem file's [solver] table (:func:`path_options`).
    """

    method: str = "load"
    max_load: float = 1.0
    steps: int = 10
    targets: tuple[float, ...] = ()
    max_steps: int = 400
    max_iterations: int = 25
    tol: float = 1e-8
    min_step: float = 1e-6
    desired_iterations: int = 8
    max_growth: float = 2.0
    max_step: float | None = None
    line_search: bool = True
    max_probe_displacement: float | None = None
    refine_critical: int = 12
    bifurcation: str = "report"
    reuse_factorisation: bool = True
    reuse_ratio: float = 0.9
    anderson: int = 5
    inertia_rtol: float = 1e-4
    local_rings: int = 5
    krylov: int = 0
    krylov_rtol: float = 1e-2
    jump_ratio: float = 0.3
    limit_points: str = "jump"
    predictor: str = "cubic"

    def __post_init__(self) -> None:
        if self.method not in METHODS:
            raise ProblemError(f"unknown path method '{self.method}' (valid: {', '.join(METHODS)})")
        if not np.isfinite(self.max_load) or self.max_load == 0:
            raise ProblemError(f"max_load must be a non-zero number, got {self.max_load!r}")
        for name in ("steps", "max_steps", "max_iterations", "desired_iterations"):
            v = getattr(self, name)
            if not isinstance(v, (int, np.integer)) or v < 1:
                raise ProblemError(f"{name} must be a positive integer, got {v!r}")
        if not (0 < self.tol < 1e-2):
            raise ProblemError(f"tol must lie in (0, 1e-2), got {self.tol!r}")
        if not (0 < self.min_step < 1):
            raise ProblemError(f"min_step must lie in (0, 1), got {self.min_step!r}")
        if not isinstance(self.anderson, (int, np.integer)) or self.anderson < 0:
            raise ProblemError(f"anderson must be a non-negative integer, got {self.anderson!r}")
        if self.bifurcation not in BIFURCATION:
            raise ProblemError(f"bifurcation must be one of {', '.join(BIFURCATION)}, got {self.bifurcation!r}")
        if self.bifurcation == "switch" and self.method == "arc_length":
            # an arc-length path narrows every change of stability down itself (refine_critical)
            # and stays on the branch it is on: the switch would be silently not made
            raise ProblemError("bifurcation 'switch' is made by load-controlled paths (method 'load'), which "
                               "then follow the new branch by arc length; an arc-length path stays on its branch")
        if self.method == "arc_length":
            # set to other than their defaults (path_options also refuses them when given at all)
            _refuse_load_control_options([k for k in LOAD_CONTROL_ONLY
                                          if getattr(self, k) != PathOptions.__dataclass_fields__[k].default])
        if self.predictor not in PREDICTORS:
            raise ProblemError(f"predictor must be one of {', '.join(PREDICTORS)}, got {self.predictor!r}")
        if not (0 <= self.inertia_rtol < 1e-2):
            raise ProblemError(f"inertia_rtol must lie in [0, 1e-2), got {self.inertia_rtol!r}")
        if not isinstance(self.krylov, (int, np.integer)) or self.krylov < 0:
            raise ProblemError(f"krylov must be a non-negative integer, got {self.krylov!r}")
        if not isinstance(self.local_rings, (int, np.integer)) or isinstance(self.local_rings, bool) or self.local_rings < 0:
            raise ProblemError(f"local_rings must be a non-negative integer, got {self.local_rings!r}")
        if not (0 < self.krylov_rtol < 1):
            raise ProblemError(f"krylov_rtol must lie in (0, 1), got {self.krylov_rtol!r}")
        if not (0 < self.reuse_ratio < 1):
            raise ProblemError(f"reuse_ratio must lie in (0, 1), got {self.reuse_ratio!r}")
        if not self.max_growth > 1:
            raise ProblemError(f"max_growth must exceed 1, got {self.max_growth!r}")
        if self.max_step is not None and not (0 < self.max_step <= abs(self.max_load) * (1 + 1e-12)):
            raise ProblemError(f"max_step must lie in (0, |max_load|] (a load-factor increment), got {self.max_step!r}")
        if (isinstance(self.jump_ratio, bool) or not isinstance(self.jump_ratio, (int, float, np.integer, np.floating))
                or not (np.isfinite(self.jump_ratio) and self.jump_ratio >= 0)):
            raise ProblemError(f"jump_ratio must be a non-negative number (0: no check), got {self.jump_ratio!r}")
        if self.limit_points not in LIMIT_POINTS:
            raise ProblemError(f"limit_points must be one of {', '.join(LIMIT_POINTS)}, got {self.limit_points!r}")
        if self.max_probe_displacement is not None and not self.max_probe_displacement > 0:
            raise ProblemError(f"max_probe_displacement must be positive [m], got {self.max_probe_displacement!r}")
        t = np.asarray(self.targets, float)
        if t.size and (not np.all(np.isfinite(t)) or np.any(t * np.sign(self.max_load) <= 0)
                       or np.any(np.abs(t) > abs(self.max_load) * (1 + 1e-12))):
            raise ProblemError(f"targets must lie between 0 and max_load={self.max_load}, got {self.targets!r}")


def path_options(table: dict) -> PathOptions:
    """PathOptions from a problem file's [solver] table (values already in SI; the keys that are
    not path options -- type, backend, collocation -- are ignored).  A load-control option in
    an arc-length path's table is refused, even at its default value."""
    keys = set(PathOptions.__dataclass_fields__)
    if table.get("method") == "arc_length":
        _refuse_load_control_options([k for k in LOAD_CONTROL_ONLY if k in table])
    return PathOptions(**{k: v for k, v in table.items() if k in keys})


@dataclass
class PathPoint:
    """One converged equilibrium of the path."""

    load_factor: float
    u: np.ndarray                    # (n_control, 3) [m]
    energy: float                    # total potential energy Pi [J]
    iterations: int                  # Newton iterations of the step that produced it
    instability: int | None          # negative eigenvalues on the constraint null space (0: stable)
    kind: str = "step"               # "step", "target" (landed exactly on a requested load),
    #                                  "refine" (narrowing a critical point), "branch" (first point
    #                                  after a branch switch), "start"
    probes: dict = field(default_factory=dict)
    extra: dict = field(default_factory=dict)
    converged_by: str = ""           # "residual", "round-off floor" (see PathSolver._converged), "start"

    @property
    def stable(self) -> bool | None:
        return None if self.instability is None else self.instability == 0


@dataclass
class NonlinearSolution(DisplacementField):
    """The converged path of a nonlinear solve; ``u`` is its last point.

    Attributes
    ----------
    path : list of PathPoint (start state first)
    completed : whether ``max_load`` was reached;  stop_reason : why not
    critical_points : detected limit and bifurcation points (dicts)
    events : every attempt that failed and was cut (from, to, reason): with each point's
        ``extra["converged_by"]`` the path says why every step stopped where it did
    timings : seconds;  n_factorisations : tangent factorisations;  n_hessians : Hessian
        evaluations;  n_back_substitutions : back-substitutions (each right-hand side);
        n_back_calls : back-substitution calls (a block of right-hand sides in one call costs about
        what one column does, graspdef.solve.sparse.KKTSystem.certify_inertia_along);
        n_krylov : GMRES iterations of inexact Newton steps;  n_inexact : inexact Newton steps;
        n_local : Newton steps with a local correction (``PathOptions.local_rings``);
        n_parabola : line-search trials at a parabola's minimum after back-tracking (:func:`parabola_step`);
        n_single : of the factorisations, single-precision ones (``precision`` "mixed", or "auto"
        from 20,000 unknowns; the rest double);  n_certificates : inertias of single-precision
        factors certified (graspdef.solve.sparse.KKTSystem.certify_inertia)
    """

    problem: Problem
    options: PathOptions
    path: list = field(default_factory=list)
    completed: bool = False
    stop_reason: str | None = None
    critical_points: list = field(default_factory=list)
    events: list = field(default_factory=list)        # every failed attempt: load factor, step, reason
    timings: dict = field(default_factory=dict)
    n_factorisations: int = 0
    n_hessians: int = 0
    n_back_substitutions: int = 0
    n_back_calls: int = 0
    n_krylov: int = 0
    n_inexact: int = 0
    n_local: int = 0
    n_parabola: int = 0
    n_single: int = 0
    n_certificates: int = 0

    @property
    def u(self) -> np.ndarray:
        return self.path[-1].u

    @property
    def load_factor(self) -> float:
        return self.path[-1].load_factor

    def load_factors(self) -> np.ndarray:
        return np.array([p.load_factor for p in self.path])

    def probe_path(self, name: str) -> np.ndarray:
        """Displacement (k, 3) [m] of a probe at every path point."""
        return np.array([p.probes[name] for p in self.path])

    def at(self, load_factor: float, rtol: float = 1e-9) -> PathPoint:
        """The path point converged exactly at ``load_factor`` (a target or a step end)."""
        for p in self.path:
            if abs(p.load_factor - load_factor) <= rtol * max(1.0, abs(load_factor)):
                return p
        raise KeyError(f"no converged point at load factor {load_factor} (add it to the targets)")

    def iterations(self) -> list[int]:
        return [p.iterations for p in self.path[1:]]

    def convergence(self) -> dict:
        """How the path went, JSON-ready, for the run records (``graspdef solve``, grasps, patch
        models): the last load factor, the points, Newton iterations per point, factorisations,
        the Newton steps with a local correction (``PathOptions.local_rings``), the ``events``
        (every attempt cut, every bracket not narrowed, in words) and the ``critical_points``
        (their probes as lists)."""
        return {"load_factor": self.load_factor, "n_points": len(self.path), "newton_iterations": self.iterations(),
                "n_factorisations": self.n_factorisations, "n_single_precision_factorisations": self.n_single,
                "n_local_corrections": self.n_local,
                "events": [dict(e) for e in self.events],
                "critical_points": [dict(cp, probes={k: np.asarray(v).tolist() for k, v in cp["probes"].items()})
                                    for cp in self.critical_points]}


class _Failed(Exception):
    diagnosed = False             # the softest-mode diagnosis ran already (its finding, if any, is in the message)


def _first_split(attempt: Callable[[float], tuple]):
    """(f, attempt(f)) for the first fraction f of a critical point's bracket in ``LOCATE_SPLITS``
    at which ``attempt`` converges -- the midpoint; where Newton fails there (the tangent is nearly
    singular at a critical load: a perfect sphere under pressure loses stability in 2l+1 modes at
    once), a quarter of the way in from either end -- or (None, why the last one failed)."""
    why = ""
    for f in LOCATE_SPLITS:
        try:
            return f, attempt(f)
        except (_Failed, SolverError) as exc:
            why = str(exc)
    return None, why


class PathSolver:
    """Runs one path (see the module docstring); use :func:`solve_nonlinear`."""

    def __init__(self, problem: Problem, options: PathOptions, backend: str = "auto",
                 progress: Callable[[dict], None] | None = None, terms: list | None = None,
                 precision: str = "auto"):
        """``terms``: the energy terms to follow (default ``problem.energy_terms()``; e.g.
        ``problem.energy_terms("rest")`` for the linear shell with contact).  ``precision``: the
        tangents' factors ("auto": single precision from 20,000 unknowns on, each inertia reported
        from one certified first; :class:`graspdef.solve.equilibrium.Equilibrium`)."""
        self.problem = problem
        self.opt = options
        self.progress = progress
        self.eq = Equilibrium(problem, backend, terms, precision)
        self.gas = [t for t in self.eq.terms if isinstance(t, EnclosedGas)]   # pre-loaded at lam = 0
        self.q_norm = 0.0
        self.inertia_residual = 0.0
        self.floor = 0.0                  # round-off level of the residual [N] (the latest Hessian's)
        self.converged_by: str | None = None
        self.residual = (0.0, 0.0)        # (relative residual, relative floor) of the last test
        self.residual_norm = 0.0          # |projected residual| of the last test [N]
        self.last_step = np.inf           # |last correction| / |u| of the current Newton solve
        self.switched = False             # a branch switch has been made (one per path)
        self.n_inexact = 0                # inexact (GMRES) Newton steps taken
        self.n_anderson_rejected = 0      # Anderson steps taken back (ANDERSON_GROWTH)
        self.n_parabola = 0               # line-search trials at a parabola's minimum (parabola_step)
        self.jumps: list[dict] = []       # limit points passed by a jump (load control)
        self._ahead = None                # (factorisation count, load, du/dlam) solved with a Newton step

    # ---------------------------------------------------------------------------------------
    def _record(self, u, lam, state, its, inst, kind="step") -> PathPoint:
        x_u = u.reshape(-1, 3)
        pt = PathPoint(float(lam), x_u.copy(), float(state.energy), int(its), inst, kind)
        # relative residual of the iterate whose factorisation gave the stability (0: this point)
        pt.extra["inertia_residual"] = float(self.inertia_residual)
        # why Newton stopped here: "residual" (below tol x force scale), "round-off floor" or "start";
        # path.csv carries the numbers (at_roundoff_floor 1/0)
        pt.converged_by = self.converged_by or kind
        pt.extra["at_roundoff_floor"] = float(self.converged_by == "round-off floor")
        pt.extra["residual_relative"] = float(self.residual[0])
        pt.extra["roundoff_floor_relative"] = float(self.residual[1])
        if self.eq.m and np.any(self.eq.g):               # reactions of prescribed displacements
            _, mu = self.eq.projected_residual(state.gradient)
            for i in np.flatnonzero(self.eq.g):
                pt.extra[f"reaction[{self.eq.labels[i]}]"] = float(-mu[i])
        ev = self.problem.evaluator
        for name, sp_ in self.problem.probes.items():
            st, w = ev.values(sp_.face, np.asarray(sp_.bary))
            pt.probes[name] = w @ x_u[st]
        counts: dict[str, int] = {}
        for term, rec in self.eq.records(u):          # e.g. gas0_volume_m3, gas0_gauge_pressure_Pa
            name = getattr(term, "record_name", type(term).__name__.lower())
            i = counts[name] = counts.get(name, -1) + 1
            for k, v in rec.items():
                pt.extra[f"{name}{i}_{k}"] = v
        return pt

    def _converged(self, state, u, lam) -> tuple[bool, float]:
        """Whether (u, lam) is an equilibrium, and the relative residual.

        The residual |grad Pi + C^T mu| (reactions mu by least squares) is compared with the
        problem's own force scale: the largest of the applied load, the internal (elastic and
        support) forces and the reactions -- and accepted below ``tol`` times it ("residual") or
        below the round-off level of the forces themselves ("round-off floor",
        :func:`graspdef.solve.equilibrium.roundoff_floor`, from the latest Hessian: for a thin stiff
        shell at small loads the relative residual cannot fall below ~1e-5, and no tolerance
        should have to be loosened by hand for it).  Sets ``self.converged_by``."""
        self.floor = self.eq.floor
        r, mu = self.eq.projected_residual(state.gradient)
        scale = max(abs(lam) * float(np.linalg.norm(state.load)), float(np.linalg.norm(state.internal)),
                    float(np.linalg.norm(self.eq.C.T @ mu)) if self.eq.m else 0.0, 1e-300)
        rn = float(np.linalg.norm(r))
        cres = self.eq.constraint_residual(u, lam)
        cscale = max(float(np.linalg.norm(lam * self.eq.g)), float(np.linalg.norm(u)), 1e-300)
        how = None
        if rn <= self.opt.tol * scale:
            how = "residual"
        elif rn <= self.floor and self.last_step <= self.opt.tol:
            how = "round-off floor"       # and the last correction moved nothing: |du| <= tol |u|
        elif rn <= 1e-13 * max(self.q_norm, 1e-300):
            how = "absolute"
        ok = how is not None and float(np.linalg.norm(cres)) <= 1e-9 * cscale
        self.converged_by = how if ok else None
        self.residual = (rn / scale, self.floor / scale)
        self.residual_norm = rn
        return ok, rn / scale

    def newton(self, u0: np.ndarray, lam: float, factored: bool = False, patient: bool = False,
               budget: int | None = None):
        """Equilibrium at fixed load factor from u0; returns (u, state, iterations, instability).

        Modified Newton with Anderson acceleration: a factorised tangent is reused (a gradient
        and a back-substitution per iteration) as long as the residual contracts by
        ``reuse_ratio`` per iteration, and the corrections of the iterations since the last
        factorisation are combined by Anderson mixing (depth ``anderson``; the least-squares
        combination of the preconditioned residuals, Walker & Ni 2011), which turns the linear
        convergence of the stale tangent into nearly the Newton rate.  A fresh tangent is
        factorised when the contraction is poor (every iteration when ``reuse_factorisation``
        is off).  ``factored``: the current factorisation (of a nearby state, e.g. the previous
        converged point) may serve from the first iteration.

        The reported stability is the inertia of a Hessian factorised at the converged state or
        at an iterate of this solve whose relative residual is at most ``inertia_rtol`` (as in
        the arc-length corrector and in most codes: the last iterate's tangent): once the
        residual falls below it on a tangent from elsewhere, the tangent is refreshed there, and
        that factorisation finishes the iterations, gives the stability and is the next step's
        predictor and tangent.  With ``inertia_rtol = 0`` the converged state itself is always
        factorised (one more factorisation per point).  ``patient``: four times ``max_iterations``
        and no divergence test (the energy descent from a point past a limit point).  ``budget``:
        at most this many iterations instead of ``max_iterations`` (the attempts that bracket a
        limit point).

        Divergence ends an attempt (its step is then halved): from iteration
        :data:`DIVERGENCE_ITERATIONS` on, a residual ten times the first iterate's, relative to the
        problem's force scale or in absolute terms -- a wild step's iterate has huge internal forces
        of its own, so its relative residual stays near 1 while the residual grows 1e4-1e8-fold
        (the full pinched cylinder's failed steps, which otherwise ran their 25 iterations, most
        with a fresh tangent).

        Inexact Newton (``krylov`` > 0): where the reused tangent contracts poorly (or its step
        raises the energy) above ``inertia_rtol``, the Newton system at the iterate is solved by
        GMRES preconditioned by the reused factorisation, the tangent's products by differences of
        gradients (:meth:`Equilibrium.inexact_step`), to a forcing term between 0.1 and
        ``krylov_rtol`` (Eisenstat & Walker's choice 2: loose while Newton itself contracts
        slowly); the following iterations do the same (a gradient and a back-substitution per
        GMRES iteration; no Hessian, no factorisation) until the residual is below
        ``inertia_rtol`` -- where the tangent is factorised as above, for the stability -- or
        GMRES needs more than ``krylov`` iterations or a step to ``krylov_rtol`` does not contract
        by ``reuse_ratio`` (a looser one that does not is first retried to ``krylov_rtol``): then
        the tangent is factorised there, as without them.  Once a step on a tangent factorised at
        its own iterate has not contracted by ``reuse_ratio`` (Newton is still far from the
        solution: the inexact steps would only repeat what the exact one failed to do), this solve
        takes no more inexact steps (the 891-vertex slit annular plate with ``krylov`` 10: 34 -> 23 s;
        the 10k ball's path unchanged).  An inexact step never gives a stability: that comes only
        from factorisations, as above.

        Local corrections (``local_rings`` > 0): at the first step on a reused tangent the region
        where the residual sits is found (:meth:`Equilibrium.local_region`; none if it is not local
        or a term gives no Hessian rows), and every step on that tangent above ``inertia_rtol`` is
        then :meth:`Equilibrium.local_step` -- an exact Newton step in the region, with the
        Hessian's rows there only, and the reused factorisation's step for the residual left.  Such
        a step whose energy rises is back-tracked (``LOCAL_BACKTRACKS`` halvings) before the
        tangent is factorised instead; one that does not contract by ``reuse_ratio`` gets, once, a
        region of ``LOCAL_GROWTH`` times the rings; they are not Anderson-mixed; any factorisation
        in this solve ends them.  On the 10k ball's pinch every point then reaches
        ``inertia_rtol`` on the previous point's factorisation, and its one factorisation is its
        stability's (19 -> 11 for the path)."""
        eq, opt = self.eq, self.opt
        u = u0.copy()
        first = prev = rn_first = None
        need_h = not (factored and opt.reuse_factorisation)
        hist: list[tuple[np.ndarray, np.ndarray]] = []      # (u_k, du_k) since the factorisation
        back = None                                          # state before an Anderson step
        near = None                 # inertia of a factorisation at an iterate within inertia_rtol
        inexact = False             # the iterations since the last factorisation are GMRES steps
        eta = None                  # forcing term of the last inexact step
        exact = False               # the last step was on a tangent factorised at its iterate
        far = False                 # a step on a fresh tangent did not contract: no inexact steps
        local = None                # the region of local corrections on the reused tangent (local_rings)
        local_tried = not opt.local_rings
        local_grown = False         # the region was grown once (LOCAL_GROWTH)
        self.last_step = np.inf

        def grow(st):
            """A region of LOCAL_GROWTH times the rings around the residual at this iterate (once)."""
            nonlocal local, local_grown
            local_grown = True
            wider = eq.local_region(eq.projected_residual(st.gradient)[0], LOCAL_GROWTH * opt.local_rings)
            if wider is not None:
                local = wider
            return wider is not None

        def ahead(st, cres):
            """The right-hand sides of ``direction``'s solve on a factorisation that gives the
            stability, the Newton step and the load tangent (told to :meth:`Equilibrium.factor`
            beforehand, which refines them in the certificate's steps); None with a double factor."""
            if not eq.kkt.single:
                return None
            return np.stack([-st.gradient, st.load], 1), np.stack([cres, eq.g], 1)

        def direction(st, cres, fresh=True, stability=None):
            """The Newton step on the last factorisation: with a single-precision factor, solved to
            a forcing tolerance (an inexact Newton step, |F + J s| <= eta |F|; Dembo, Eisenstat &
            Steihaug 1982) instead of refined to a double solve's backward error: on a tangent
            factorised at this iterate (``fresh``) eta = NEWTON_FORCING min(rel, 0.1) of the
            projected residual, below Newton's own O(|F|^2) term; on a reused one eta =
            STALE_FORCING, below what the stale tangent itself leaves.  A double factor's solve is
            as always.  ``stability``: the factorisation was just made to give the point's stability,
            and this is what :func:`ahead` gave it (the load tangent is solved along, see below)."""
            if not eq.kkt.single:
                return eq.solve(-st.gradient, cres)
            if stability is not None:
                # the factorisation that gives the stability (just made) is, once converged, the next step's
                # predictor: its tangent du/dlam = A^-1 q rides in this step's back-substitutions
                # (:meth:`_load_tangent`), and both started in the certificate's (``ahead``)
                both = eq.solve(*stability, exact=False)
                self._ahead = (eq.n_factorisations, st.load.copy(), both[:, 1])
                return both[:, 0]
            return eq.solve(-st.gradient, cres, rtol=forcing(st, fresh), exact=False)

        def forcing(st, fresh):
            """The relative residual a single-precision factor's Newton step is solved to (``direction``)."""
            gn = max(float(np.linalg.norm(st.gradient)), 1e-300)
            eta_n = NEWTON_FORCING * min(rel, 0.1) if fresh else STALE_FORCING
            return min(max(1e-8, eta_n * self.residual_norm / gn), 0.1)

        def refresh(u, st, cres, tight=False, keep_near=False):
            """A step on the tangent at u (``st`` its state): inexact (GMRES) if it converges
            within ``krylov`` iterations (to krylov_rtol if ``tight``), else on a fresh
            factorisation (which gives the stability if within inertia_rtol, unless ``keep_near``:
            the line search's refresh, which never did); returns (state, du, exact)."""
            nonlocal near, hist, inexact, eta, local
            if opt.krylov and near is None and not far:
                # forcing term (Eisenstat & Walker 1996, choice 2): loose while Newton itself
                # contracts slowly, down to krylov_rtol as it reaches its quadratic rate
                e = KRYLOV_ETA_MAX if prev is None else 0.9 * (rel / prev) ** 2
                if eta is not None and 0.9 * eta ** 2 > 0.1:
                    e = max(e, 0.9 * eta ** 2)
                eta = opt.krylov_rtol if tight else float(np.clip(e, opt.krylov_rtol,
                                                                  max(KRYLOV_ETA_MAX, opt.krylov_rtol)))
                du = direction(st, cres, fresh=False)
                di = eq.inexact_step(u, lam, st, -st.gradient, du, eta, opt.krylov)
                if di is not None:
                    self.n_inexact += 1
                    inexact, hist = True, []
                    return st, di, False
            if st.hessian is None:
                st = eq.evaluate(u, lam, 2)
            stab = not keep_near and rel <= opt.inertia_rtol
            rhs = ahead(st, cres) if stab else None
            local = None
            inst = eq.factor(st, inertia=stab, ahead=rhs)
            if not keep_near:
                near = (inst, rel) if rel <= opt.inertia_rtol else None
            inexact, hist = False, []
            return st, direction(st, cres, stability=rhs), True

        max_it = 4 * opt.max_iterations if patient else opt.max_iterations if budget is None else budget
        trial = None                # (alpha, state at u + alpha du) of the last step's energy test

        def trial_at(a):
            """The energy at u + a du, its state kept as ``trial`` (the next iterate's if that step is taken)."""
            nonlocal trial
            trial = (a, eq.evaluate(u + a * du, lam, 1))
            return trial[1].energy

        for it in range(max_it + 1):
            st = trial[1] if trial is not None and not need_h else eq.evaluate(u, lam, 2 if need_h else 1)
            trial = None
            if not np.isfinite(st.energy) or not np.all(np.isfinite(st.gradient)):
                if back is None:
                    raise _Failed(f"non-finite energy or forces at load factor {lam:.6g}")
                (u, st, _), back, hist = back, None, []    # e.g. through a contact barrier: plain step
            ok, rel = self._converged(st, u, lam)
            if not ok and back is not None and self.residual_norm > ANDERSON_GROWTH * back[2]:
                # the Anderson step raised the residual: back to where it started, a plain step from there
                (u, st, _), back, hist = back, None, []
                ok, rel = self._converged(st, u, lam)
                self.n_anderson_rejected += 1
            if ok:
                if near is not None:
                    self.inertia_residual = near[1]
                    return u, st, it, near[0]
                if st.hessian is None:
                    st = eq.evaluate(u, lam, 2)
                inst = eq.factor(st)
                self.inertia_residual = 0.0
                return u, st, it, inst
            if it == max_it:
                break
            if first is None:
                first, rn_first = rel, self.residual_norm
            grown = self.residual_norm / max(rn_first, 1e-300)
            if it >= DIVERGENCE_ITERATIONS and (rel > 10 * first or grown > 10) and not patient:
                raise _Failed(f"Newton diverges at load factor {lam:.6g} (residual {rel:.2e}, "
                              f"{grown:.3g} times the first iterate's)")
            poor = prev is not None and rel > opt.reuse_ratio * prev
            if exact and poor:
                far = True
            fresh = False                 # du is a step on this iterate's tangent (exact or GMRES)
            cres = eq.constraint_residual(u, lam)
            if not need_h and (near is None and rel <= opt.inertia_rtol
                               or inexact and poor and eta <= opt.krylov_rtol):
                # nearly converged on a tangent from elsewhere (its factorisation at this iterate
                # gives the stability and the final iterations), or an inexact step to the tightest
                # tolerance that did not contract: fresh tangent
                if st.hessian is None:
                    st = eq.evaluate(u, lam, 2)
                need_h = True
            elif not need_h and poor and local is not None and not local_grown and grow(st):
                # a local correction that did not contract: the tangent changed beyond its region;
                # once per solve, a region of LOCAL_GROWTH times the rings around where the residual is now
                hist = []
            elif not need_h and (inexact or poor):
                # poor contraction of the reused tangent: this iterate's tangent, by GMRES if it can
                # (to krylov_rtol if a looser inexact step did not contract)
                st, du, need_h = refresh(u, st, cres, tight=inexact and poor)
                fresh = True
            rhs = None                    # the stability's right-hand sides, when this iteration factorises for it
            if need_h and not fresh:
                rhs = ahead(st, cres) if rel <= opt.inertia_rtol else None
                inst = eq.factor(st, inertia=rel <= opt.inertia_rtol, ahead=rhs)
                near = (inst, rel) if rel <= opt.inertia_rtol else None
                hist, inexact, local = [], False, None
            stepped_local = False         # du is a local correction's step (Equilibrium.local_step)
            if not fresh:
                du = None
                if not need_h and near is None and not inexact:
                    if not local_tried:
                        # the first step on the reused tangent: where does its residual sit?
                        local_tried = True
                        local = eq.local_region(eq.projected_residual(st.gradient)[0], opt.local_rings)
                    if local is not None:
                        du = eq.local_step(u, lam, st, cres, local,
                                           rtol=forcing(st, False) if eq.kkt.single else 1e-8)
                        if du is None:
                            local = None
                        stepped_local = du is not None
                if du is None:
                    du = direction(st, cres, fresh=need_h, stability=rhs)
            # the supports hold to solve precision: the step need not restore them, and the energy
            # is a merit function along it
            feasible = float(np.linalg.norm(cres)) <= 1e-8 * max(float(np.linalg.norm(u)), float(np.linalg.norm(du)),
                                                                 1e-300)
            alpha = 1.0
            step = du
            back = None                   # the state an Anderson step starts from (taken back above)
            if feasible and opt.anderson and hist:
                # Anderson mixing (type II) of the fixed-point map u -> u + du
                dU = np.stack([u - hu for hu, _ in hist], 1)
                dF = np.stack([du - hf for _, hf in hist], 1)
                gam, *_ = np.linalg.lstsq(dF, du, rcond=None)
                step = du - (dU + dF) @ gam
                back = (u, st, self.residual_norm)
            elif opt.line_search and feasible:
                back = None
                slope = float(st.gradient @ du)
                # energy differences below ~1e-10 |Pi| are round-off: the Armijo test is then
                # meaningless (it would cut steps at random), and near the solution the Newton
                # step is accepted as it is
                if slope < 0 and -slope > 1e-10 * abs(st.energy):
                    # each trial's energy comes from a gradient evaluation: the state of the step
                    # taken is the next iterate's (on the 10k ball's pinch one evaluation fewer per
                    # Newton step; tests/solve/test_path_reuse.py)
                    e_new = trial_at(1.0)
                    if not (need_h or fresh) and not (np.isfinite(e_new) and e_new <= st.energy + 1e-4 * slope):
                        if stepped_local:
                            # a local correction's step that overshoots (the dimple's stiffness
                            # changes fast): back-tracked first
                            for _ in range(LOCAL_BACKTRACKS):
                                alpha *= 0.5
                                e_new = trial_at(alpha)
                                if np.isfinite(e_new) and e_new <= st.energy + 1e-4 * alpha * slope:
                                    break
                            else:
                                alpha, local = 1.0, None
                        if not stepped_local or local is None:
                            # a reused tangent whose step does not decrease the energy: this iterate's
                            # tangent (by GMRES if it can, else factorised here)
                            st, du, need_h = refresh(u, st, cres, keep_near=True)
                            slope = float(st.gradient @ du)
                            e_new = trial_at(1.0)
                    e_twice = np.inf                     # the energy at 2 alpha (the trial rejected last)
                    for _ in range(8):
                        if np.isfinite(e_new) and e_new <= st.energy + 1e-4 * alpha * slope:
                            break
                        e_twice = e_new
                        alpha *= 0.5
                        e_new = trial_at(alpha)
                    else:
                        alpha = 1.0                      # no decrease found: plain Newton step
                    if alpha < 1 and (need_h or fresh) and not patient:
                        # a damped step on this iterate's own tangent (contact paths: samples that enter
                        # the barrier during the step are not in its linearisation): one more trial, at
                        # the parabola's minimum, taken if its energy is lower still; not in the patient
                        # descent past a limit point (PARABOLA_MIN_MOVE)
                        aq = parabola_step(st.energy, slope, alpha, e_new, e_twice)
                        if aq is not None:
                            kept = trial
                            e_q = trial_at(aq)
                            self.n_parabola += 1
                            if np.isfinite(e_q) and e_q < e_new and e_q <= st.energy + 1e-4 * aq * slope:
                                alpha, e_new = aq, e_q
                            else:
                                trial = kept
                step = alpha * du
                if trial is not None and trial[0] != alpha:
                    trial = None
            if feasible and opt.reuse_factorisation and not inexact and not stepped_local:
                # (a local correction's step is not mixed: on the 10k ball's pinch, mixed, the path's
                # longest step stalled and took 4 factorisations instead of 1)
                hist = ([(u, du)] + hist)[: opt.anderson]
            log.debug("  newton it %d lam %.6g rel %.2e (floor %.2e) alpha %.3g |du| %.3e tangent %s%s", it, lam, rel, self.residual[1], alpha,
                      float(np.linalg.norm(du)),
                      "new" if need_h else f"inexact ({eq.last_krylov} GMRES, eta {eta:.1e})" if inexact else
                      "reused, local correction" if stepped_local else "reused",
                      f" (Anderson {len(hist) - 1})" if len(hist) > 1 else "")
            u = u + step
            prev = rel
            exact = need_h or (fresh and not inexact)
            self.last_step = float(np.linalg.norm(step)) / max(float(np.linalg.norm(u)), 1e-300)
            need_h = not opt.reuse_factorisation
        raise _Failed(f"Newton did not converge in {max_it} iterations at load factor "
                      f"{lam:.6g} (relative residual {rel:.2e})")

    def _far(self, pt) -> bool:
        lim = self.opt.max_probe_displacement
        return lim is not None and any(float(np.linalg.norm(v)) >= lim for v in pt.probes.values())

    def _load_tangent(self, st):
        """du/dlam = A^-1 q at a converged state on the last factorisation: the one solved along
        with the Newton step on it (``newton``'s direction) if that was this factorisation and
        this load (to the bit), else a solve now."""
        a, self._ahead = self._ahead, None
        if a is not None and a[0] == self.eq.n_factorisations and np.array_equal(a[1], st.load):
            return a[2]
        return self.eq.solve(st.load, self.eq.g)

    def _tangent(self, u, lam):
        st = self.eq.evaluate(u, lam, 2)
        self.eq.factor(st, inertia=False)
        return self.eq.solve(st.load, self.eq.g)

    def _emit(self, sol, pt, dl=None):
        if self.progress is not None:
            info = {"step": len(sol.path) - 1, "load_factor": pt.load_factor, "iterations": pt.iterations,
                    "stable": pt.stable, "kind": pt.kind, "seconds": time.perf_counter() - self._t0}
            if dl is not None:
                info["arc_length"] = dl
            self.progress(info)

    @staticmethod
    def _detect(sol):
        """Every change of stability between consecutive path points."""
        for i in range(1, len(sol.path)):
            if sol.path[i].kind == "branch":       # the first point after a branch switch
                continue
            a, b = sol.path[i - 1].instability, sol.path[i].instability
            if a is not None and b is not None and a != b:
                sol.critical_points.append({"index": i, "instability_before": a, "instability_after": b})

    @staticmethod
    def _classify(sol):
        """Limit point if the load factor has an extremum at the change, else bifurcation."""
        lam = sol.load_factors()
        for cp in sol.critical_points:
            i = cp.pop("index")
            turned = False
            if i >= 2 and i + 1 < len(lam):
                up = lam[i - 1] - lam[i - 2]
                turned = up * (lam[i + 1] - lam[i]) < 0
            if turned:
                k = (i - 1) if (lam[i - 1] >= lam[i]) == (up > 0) else i
            cp["kind"] = "limit point" if turned else "bifurcation point"
            cp["load_factor"] = float(lam[k]) if turned else float(0.5 * (lam[i - 1] + lam[i]))
            cp["bracket"] = [float(lam[i - 1]), float(lam[i])]
            p = sol.path[k] if turned else sol.path[i]
            cp["probes"] = {name: np.asarray(v).tolist() for name, v in p.probes.items()}
            cp["branch_switched"] = (not turned and any(q.kind == "branch" for q in sol.path[i:]))
            log.info("%s at load factor %.6g (negative eigenvalues %d -> %d)", cp["kind"], cp["load_factor"],
                     cp["instability_before"], cp["instability_after"])

    # ---------------------------------------------------------------------------------------
    def run(self) -> NonlinearSolution:
        opt = self.opt
        self._t0 = time.perf_counter()
        sol = NonlinearSolution(self.problem, opt)
        n = self.eq.n
        u = np.zeros(n)
        # with a gas the start is Newton's first iterate (its Hessian is evaluated there): no Hessian here
        st0 = self.eq.evaluate(u, 0.0, 1 if self.gas else 2)
        self.q_norm = float(np.linalg.norm(st0.load))
        if self.q_norm == 0 and not np.any(self.eq.g) and not self.gas:
            raise ProblemError("the problem has no load: add loads, a prescribed displacement or an enclosed gas")
        try:
            if self.gas:                          # gas pre-load: equilibrium at lam = 0 first
                u, st0, its, inst = self.newton(u, 0.0)
            else:
                inst = self.eq.factor(st0)
                its = 0
        except (_Failed, SolverError) as exc:
            raise PathStopped(f"no equilibrium at zero load: {exc}", sol) from None
        if inst is not None and inst > 0:
            # a path cannot start from an unstable state: a mechanism, or a term not convex at rest
            # (named if it makes the softest mode soft; else each term with a remedy is listed)
            soft = self.soft_terms(u, 0.0) or "; ".join(
                f"possibly {t.remedy}" for t in self.eq.terms if getattr(t, "remedy", None))
            self.eq.close()
            raise PathStopped(f"the state at zero load is unstable ({inst} negative eigenvalue(s) on the supports' "
                              f"null space){': ' + soft if soft else ': a mechanism, or a term that is not convex at rest'}", sol)
        sol.path.append(self._record(u, 0.0, st0, its, inst, "start"))
        self.eq.commit(u)
        try:
            if opt.method == "load":
                self._load_control(sol, u, st0.load)
            else:
                self._arc_length(sol, u)
        except _Failed as exc:
            why = str(exc)
            if not getattr(exc, "diagnosed", False):
                soft = self.soft_terms(sol.path[-1].u.ravel(), sol.path[-1].load_factor)
                why += f"; {soft}" if soft else ""
            sol.stop_reason = why
        finally:
            self.eq.close()
        sol.timings["total"] = time.perf_counter() - self._t0
        sol.timings["factor"] = self.eq.kkt.seconds_factor
        sol.timings["solve"] = self.eq.kkt.seconds_solve
        sol.n_factorisations = self.eq.n_factorisations
        sol.n_hessians = self.eq.n_hessians
        sol.n_back_substitutions = self.eq.kkt.n_back
        sol.n_back_calls = self.eq.kkt.n_back_calls
        sol.n_single = self.eq.kkt.n_single
        sol.n_certificates = self.eq.kkt.certificates
        sol.n_krylov = self.eq.n_krylov
        sol.n_inexact = self.n_inexact
        sol.n_local = self.eq.n_local
        sol.n_parabola = self.n_parabola
        sol.completed = sol.stop_reason is None
        self._detect(sol)
        self._classify(sol)
        if self.jumps:                    # load control: the load factor rises along the path
            sol.critical_points = sorted(sol.critical_points + self.jumps, key=lambda cp: cp["bracket"][0])
        return sol

    def _stop_points(self):
        sgn = np.sign(self.opt.max_load)
        pts = sorted(set([float(t) for t in self.opt.targets] + [float(self.opt.max_load)]), key=lambda v: sgn * v)
        return pts

    def _load_control(self, sol, u, q):
        opt = self.opt
        lam_end = opt.max_load
        dlam = lam_end / opt.steps
        cap = abs(lam_end) if opt.max_step is None else opt.max_step
        dlam = np.sign(dlam) * min(abs(dlam), cap)
        dmin = abs(lam_end) * opt.min_step
        stops = self._stop_points()
        dlam0 = dlam
        lam = 0.0
        factored = True                 # the factorisation is at the current converged point
        back = None                     # the previous converged point (u, lam)
        jumped = None                   # the equilibrium of the smallest rejected jumping step
        softening = False               # increments limited since the last plain step (a limit point ahead?)
        plain = True                    # no failure and no limited increment since the last point
        t_new = None                    # the tangent du/dlam at the current point, when solved
        t_back = None                   # the tangent at the previous converged point (the cubic predictor)
        t_last = None                   # (load factor, |du/dlam|) at the previous converged point
        near = abs(dlam0) * 2.0 ** -opt.refine_critical   # a limit point's bracket is narrow enough
        sgn = float(np.sign(lam_end))
        while len(sol.path) <= opt.max_steps:
            t_here = None                                     # |du/dlam| at the current point
            t_cur = None                                      # the tangent at the current point, when solved
            lc = None                                         # the load of a limit point ahead, estimated
            nxt = next(s for s in stops if (s - lam) * sgn > 1e-12 * abs(lam_end))
            step = dlam if abs(dlam) < abs(nxt - lam) * (1 + 1e-9) else nxt - lam
            if abs(nxt - lam - step) < 1e-9 * abs(lam_end):
                step = nxt - lam
            lam_new = lam + step
            curved = False                                    # the predictor has the curvature term
            capped = False
            try:                                              # tangent predictor du/dlam
                t = t_new if factored and t_new is not None else (
                    self.eq.solve(q, self.eq.g) if factored else self._tangent(u, lam))
                factored = True
                t_cur = t
                t_here = float(np.linalg.norm(t))
                u0 = u + step * t
                if back is not None:                          # + the curvature of the last step(s)
                    h = lam - back[1]
                    # (the cubic only on a plain stretch of the path: not towards a limit point nor
                    # past a jumped one, where the quadratic is the safer extrapolation)
                    kind = opt.predictor if opt.predictor != "cubic" or (
                        t_back is not None and not softening and jumped is None) else "quadratic"
                    u0 = extrapolate(u, t, step, back[0], h, t_back, kind)
                    curved = True
                    # the response softens fast (towards a limit point): the predicted increment
                    # may grow by max_growth at most over the last one, as arc lengths do
                    last, pred = float(np.linalg.norm(u - back[0])), float(np.linalg.norm(u0 - u))
                    if pred > opt.max_growth * last > 0 and abs(step) * opt.max_growth * last / pred >= dmin:
                        step *= opt.max_growth * last / pred
                        lam_new, dlam, softening, capped = lam + step, step, True, True
                        u0 = extrapolate(u, t, step, back[0], h, t_back, kind)
                    # a limit point ahead: aim the step short of the load where the tangents say
                    # it is (FOLD_SHORT of the way there), not at the halving's guess
                    lc = fold_estimate(*t_last, lam, t_here) if (softening or jumped is not None) and t_last else None
                    if lc is not None and 0 < (lc - lam) * sgn < abs(step):
                        aim = sgn * max(FOLD_SHORT * abs(lc - lam), 2 * near)
                        if abs(aim) < abs(step):
                            step, lam_new, dlam = aim, lam + aim, aim
                            u0 = extrapolate(u, t, step, back[0], h, t_back, kind)
            except SolverError:
                u0, factored = u.copy(), False
            snapped = None
            made = self.eq.n_factorisations                   # (a failed attempt that makes none keeps it)
            try:
                # bracketing a limit point that a step jumped over, or an attempt beyond its
                # estimated load: an attempt beyond it has no equilibrium to converge to, and one
                # short of it converges in a few iterations (the predictor is close):
                # desired_iterations of them decide
                beyond = jumped is not None or (lc is not None and (lam_new - lc) * sgn > 0)
                budget = min(opt.desired_iterations, opt.max_iterations) if beyond else None
                u_new, st, its, inst = self.newton(u0, lam_new, factored=factored, budget=budget)
                # the tangent du/dlam at the new point (its factorisation is at hand: the next
                # step's predictor), and the step's consistency with the two tangents
                try:
                    t_new = self._load_tangent(st)
                except SolverError:
                    t_new = None
                ratio = None
                if curved and t_new is not None:
                    du = u_new - u
                    mismatch = du - 0.5 * step * (t + t_new)          # trapezoid rule of the end tangents
                    ratio = float(np.linalg.norm(mismatch)) / max(float(np.linalg.norm(du)), 1e-300)
                if ratio is not None and opt.jump_ratio and ratio > opt.jump_ratio:
                    jumped = (u_new, lam_new, st, its, inst, ratio)
                    raise _Failed(f"the step jumped: its increment differs from the trapezoid rule of the tangents at "
                                  f"its ends by {ratio:.3g} of itself (jump_ratio {opt.jump_ratio:g}): a limit point "
                                  "or another branch crossed")
            except (_Failed, SolverError) as exc:
                # an attempt that made no factorisation (its predicted state was not finite, or it
                # failed on the reused tangent) leaves the current point's, and its tangent du/dlam,
                # as they were: the next attempt reuses both (on the 10k ball's pinch one
                # factorisation fewer, 11 -> 10)
                kept = factored and t_cur is not None and self.eq.n_factorisations == made
                factored, plain, t_new = kept, False, t_cur if kept else None
                limit = softening or jumped is not None       # a limit point ahead: bracket it to ``near``
                if abs(step) / 2 >= (max(dmin, near) if limit else dmin):
                    log.info("step to %.6g failed (%s); halving", lam_new, exc)
                    sol.events.append({"from_load_factor": float(lam), "to_load_factor": float(lam_new),
                                       "action": "load step halved", "reason": str(exc)})
                    dlam = step / 2
                    continue
                why = " (a limit point of the load: the response softened towards it)" if limit else ""
                floor = max(dmin, near) if limit else dmin
                stalled = f"load step cut below {floor:.3g} at load factor {lam:.6g}{why}: {exc}"
                soft = self.soft_terms(u, lam) if limit else ""
                if soft:
                    # a limit point made by a term that is not convex by itself (a Nitsche edge
                    # term whose penalty no longer dominates): not the shell's, so no jump
                    err = _Failed(f"{stalled}; the limit point is spurious: {soft}; the path stops at the "
                                  "last stable point")
                    err.diagnosed = True
                    raise err from None
                if opt.limit_points != "jump" or back is None or not limit:
                    err = _Failed(stalled)
                    err.diagnosed = limit             # soft_terms already ran at this point: nothing soft
                    raise err from None
                first = min(abs(dlam0), abs(nxt - lam)) * sgn
                snapped = self._past(jumped, u, lam, nxt) or self._snap(u, lam, first)
                if snapped is None:
                    raise _Failed(f"{stalled}; no equilibrium found past it either") from None
                u_new, lam_new, st, its, inst, ratio = snapped
                self._record_jump(sol, u, lam, snapped, stalled)
                step = lam_new - lam
            if jumped is not None and (jumped[1] - lam_new) * sgn <= 0:
                jumped = None                                 # keep a jumped equilibrium still ahead
            if snapped is not None or (plain and not capped):
                softening = False                             # a plain step: nothing ahead
            plain = True
            is_target = abs(lam_new - nxt) <= 1e-12 * abs(lam_end)
            last = sol.path[-1].instability
            self._check_spurious(last, inst, lam, u_new, lam_new)
            pt = self._record(u_new, lam_new, st, its, inst, "target" if is_target and nxt != lam_end else "step")
            if opt.bifurcation != "report" and last is not None and inst is not None and inst != last:
                refined, crit = self._locate(sol, u, lam, u_new, lam_new, last)
                sol.path += refined
                if opt.bifurcation == "switch" and crit is not None and not self.switched:
                    self.switched = True
                    self._arc_length(sol, crit[0], crit[1], mode=self._critical_mode(*crit))
                    return
                factored = False
            sol.path.append(pt)
            self.eq.commit(u_new)
            self._emit(sol, pt)
            back = (u, lam) if snapped is None else None      # no curvature across a jump
            t_back = t_cur if snapped is None else None
            t_last = (lam, t_here) if snapped is None and t_here is not None else None
            u, lam, q, factored = u_new, lam_new, st.load, snapped is None
            if snapped is not None:
                t_new = None                                  # its factorisation may be elsewhere
            if abs(lam - lam_end) <= 1e-12 * abs(lam_end) or self._far(pt):
                return
            if snapped is not None:                           # past the jump: the initial step again
                dlam = dlam0
                continue
            # shrink only on failure (above); grow after easy steps
            growth = np.clip(np.sqrt(opt.desired_iterations / max(its, 1)), 1.0, opt.max_growth)
            dlam = step * growth if abs(step) >= abs(dlam) * 0.999 else dlam
            dlam = np.sign(dlam) * min(abs(dlam), cap)
        raise _Failed(f"the path needed more than max_steps={opt.max_steps} steps (reached load factor {lam:.6g})")

    def _past(self, jumped, u, lam, nxt):
        """Past the limit point at the converged (u, lam): the equilibrium of a rejected jumping
        step, brought back to the limit point's own load (the snap happens at constant load; Newton from it),
        else landed on the next stop point ``nxt`` if it lies beyond it, else as it is; None if
        there is none.  A landing that went back to u's branch does not count."""
        if jumped is None:
            return None
        sgn = np.sign(self.opt.max_load)
        tries = [lam] + ([nxt] if (jumped[1] - nxt) * sgn > 1e-12 * abs(self.opt.max_load) else [])
        for at in tries:
            try:
                u_new, st, its, inst = self.newton(jumped[0].copy(), at)
            except (_Failed, SolverError):
                continue
            if inst in (0, None) and float(np.linalg.norm(u_new - jumped[0])) < float(np.linalg.norm(u_new - u)):
                return u_new, at, st, its, inst, jumped[5]
        return jumped if len(tries) == 1 else None

    def _snap(self, u, lam, step):
        """An equilibrium past a limit point at the converged (u, lam) when no jumping step was
        found: Newton from u itself (the tangent is singular there) at lam + step, step / 2,
        step / 4, patiently (the energy descends to the next stable state), then brought back to
        lam by :meth:`_past` where that does not fall back; (u, lam, state, iterations,
        instability, None) or None."""
        for h in (step, step / 2, step / 4):
            try:
                u_new, st, its, inst = self.newton(u.copy(), lam + h, patient=True)
            except (_Failed, SolverError) as exc:
                log.info("no equilibrium at load factor %.6g past the limit point (%s)", lam + h, exc)
                continue
            if inst in (0, None):           # brought back to the limit point's load if it can
                return self._past((u_new, lam + h, st, its, inst, None), u, lam, lam + h)
        return None

    def _record_jump(self, sol, u, lam, snapped, why):
        """A limit point passed by a jump from the converged (u, lam) to ``snapped``."""
        u_new, lam_new, _, _, inst, ratio = snapped
        move = float(np.linalg.norm((u_new - u).reshape(-1, 3), axis=1).max())
        last = sol.path[-1]
        self.jumps.append({"kind": "limit point (jumped)", "load_factor": float(lam),
                           "bracket": [float(lam), float(lam_new)],
                           "instability_before": last.instability, "instability_after": inst,
                           "probes": {k: np.asarray(v).tolist() for k, v in last.probes.items()},
                           "jump": {"from_load_factor": float(lam), "to_load_factor": float(lam_new),
                                    "largest_control_point_move": move,
                                    "trapezoid_mismatch": ratio},
                           "branch_switched": False})
        msg = (f"limit point at load factor {lam:.6g}: the load-controlled path jumped to load factor "
               f"{lam_new:.6g} (largest control-point move {move:.4g})")
        log.warning("%s", msg)
        sol.events.append({"from_load_factor": float(lam), "to_load_factor": float(lam_new),
                           "action": "jumped past a limit point", "reason": why})

    def _arc_length(self, sol, u, lam=0.0, mode=None):
        """Arc-length continuation from the converged (u, lam); with ``mode`` (a branch switch at
        a bifurcation point) the first predictor is that eigenvector instead of the tangent."""
        opt = self.opt
        eq = self.eq
        lam_end = opt.max_load
        sgn_end = np.sign(lam_end)
        t = self._tangent(u, lam)                      # du/dlam here
        dl0 = abs(lam_end / opt.steps) * float(np.linalg.norm(t))
        if dl0 == 0:
            raise _Failed("zero tangent at the start: the loads do not deform the shell")
        dl = dl0
        dl_min = dl0 * opt.min_step
        dl_max = dl0 * 8
        du_prev = t * np.sign(lam_end)
        dlam_prev = float(sgn_end)
        if mode is not None:
            # leave along the mode: the first step moves the mode's largest control point by
            # 1 % of the body's size, and the corrector keeps that distance from the critical
            # point (off the fundamental path, whose steps may be tiny: a strip's axial shortening)
            size = float(np.ptp(eq.X, axis=0).max())
            phi = mode.reshape(-1, 3)
            dl = 1e-2 * size * float(np.linalg.norm(mode)) / float(np.linalg.norm(phi, axis=1).max())
            dl_min, dl_max = dl * opt.min_step, max(dl_max, 64 * dl)
            du_prev, dlam_prev = mode / float(np.linalg.norm(mode)), 0.0
        targets = [s for s in self._stop_points()]
        while len(sol.path) <= opt.max_steps:
            try:
                u_new, lam_new, its, st, inst = self._arc_step(u, lam, dl, du_prev, dlam_prev)
            except (_Failed, SolverError) as exc:
                if dl / 2 < dl_min:
                    raise _Failed(f"arc length cut below {dl_min:.3g} at load factor {lam:.6g}: {exc}") from None
                log.info("arc step %.3g from lam %.6g failed (%s); halving", dl, lam, exc)
                sol.events.append({"from_load_factor": float(lam), "arc_length": float(dl),
                                   "action": "arc length halved", "reason": str(exc)})
                dl /= 2
                continue
            # requested load levels crossed by this step: land on them exactly.  A change of
            # stability between the path's last point and a landed level (or the step's end) is
            # checked and narrowed down between those two points, by arc length from the first
            prev = None                                   # (u, lam) of the last level landed on
            crossed = [s for s in targets if (s - lam) * (s - lam_new) <= 0 and s != lam]
            for s in sorted(crossed, key=lambda v: abs(v - lam)):
                w = (s - lam) / (lam_new - lam)
                try:
                    u_t, st_t, its_t, inst_t = self.newton(u + w * (u_new - u), s)
                except (_Failed, SolverError) as exc:
                    log.info("could not land on load factor %.6g (%s)", s, exc)
                    continue
                pt = self._record(u_t, s, st_t, its_t, inst_t, "target")
                last = sol.path[-1].instability
                u_a, lam_a = prev if prev is not None else (u, lam)
                self._check_spurious(last, inst_t, lam_a, u_t, s)
                if opt.refine_critical and last is not None and inst_t is not None and inst_t != last \
                        and mode is None:
                    sol.path += self._bracket_between(sol, u_a, lam_a, u_t, s, last)
                sol.path.append(pt)
                self._emit(sol, pt, dl)
                if abs(s - lam_end) <= 1e-12 * abs(lam_end):
                    pt.kind = "step"
                    self.eq.commit(u_t)
                    return
                prev = (u_t, s)
            last = sol.path[-1].instability
            self._check_spurious(last, inst, lam if prev is None else prev[1], u_new, lam_new)
            if opt.refine_critical and last is not None and inst is not None and inst != last and mode is None:
                sol.path += (self._bracket(sol, u, lam, dl, du_prev, dlam_prev, last) if prev is None
                             else self._bracket_between(sol, *prev, u_new, lam_new, last))
            pt = self._record(u_new, lam_new, st, its, inst, "step" if mode is None else "branch")
            mode = None
            sol.path.append(pt)
            eq.commit(u_new)
            self._emit(sol, pt, dl)
            du_prev, dlam_prev = u_new - u, lam_new - lam
            u, lam = u_new, lam_new
            if (lam - lam_end) * sgn_end > 0 or self._far(pt):   # beyond the end without a landing
                return
            dl = float(np.clip(dl * np.sqrt(opt.desired_iterations / max(its, 1)), dl / 2,
                               min(dl * opt.max_growth, dl_max)))
        raise _Failed(f"the path needed more than max_steps={opt.max_steps} steps (reached load factor {lam:.6g})")

    def _locate(self, sol, u_a, lam_a, u_b, lam_b, inst_a):
        """Bisect the load step from the converged (u_a, lam_a) (instability inst_a) to (u_b, lam_b)
        (another instability) ``refine_critical`` times; returns the new path points in load order
        and (u, lam) of the point past the change closest to it ((u_b, lam_b) if no bisection
        converged).  A bracket that could not be narrowed further is an event of ``sol``."""
        a_side, b_side = [], []
        crit = (u_b, lam_b)
        for _ in range(self.opt.refine_critical):
            frac, got = _first_split(lambda f: self.newton((1 - f) * u_a + f * u_b, (1 - f) * lam_a + f * lam_b))
            if frac is None:
                sol.events.append({"from_load_factor": float(lam_a), "to_load_factor": float(lam_b),
                                   "action": BRACKET_NOT_NARROWED, "reason": f"no equilibrium found inside it ({got})"})
                break
            lam_m = (1 - frac) * lam_a + frac * lam_b
            u_m, st, its, inst = got
            pt = self._record(u_m, lam_m, st, its, inst, "refine")
            if inst == inst_a:
                a_side.append(pt)
                u_a, lam_a = u_m, lam_m
            else:
                b_side.append(pt)
                u_b, lam_b = u_m, lam_m
                crit = (u_m, lam_m)
        return a_side + b_side[::-1], crit

    #: a term with a ``remedy`` is named (see :meth:`soft_terms`) when it takes away at least
    #: SOFT_SHARE of the other terms' curvature along the tangent's softest mode, and at least
    #: SOFT_REST of the internal terms' curvature at rest along it
    SOFT_SHARE = 0.5
    SOFT_REST = 0.1

    def soft_terms(self, u, lam) -> str:
        """Why the tangent at (u, lam) is soft, when an energy term that is not convex by itself
        (one with a ``remedy``, :mod:`graspdef.problem.terms`, e.g. a Nitsche edge term) makes it
        so: along the softest mode v of the tangent (the eigenvalue closest to zero on the
        supports' null space, by inverse iteration) its curvature v^T H_i v is negative and cancels
        at least ``SOFT_SHARE`` of the other terms' positive curvature and at least ``SOFT_REST``
        of the internal terms' curvature at rest (the small-strain stiffness of that mode) -- a
        spurious mode of the discretisation, not the shell's.  At a physical limit or bifurcation
        point the shell's own curvature vanishes and such a term's is a small part of the rest
        stiffness (measured on Euler's clamped strip at P_cr: 6e-8 of 1e-2; on the neo-Hookean
        pinched cylinder's stall: 1.51 of 1.81).  Returns "" otherwise, or when no term has a
        remedy (nothing is computed then)."""
        terms = self.eq.terms
        if not any(getattr(t, "remedy", None) for t in terms) or all(getattr(t, "remedy", None) for t in terms):
            return ""
        try:
            st = self.eq.evaluate(u, lam, 2, keep_terms=True)       # the sum, and each term's part
            v = self._critical_mode(u, lam, st)

            def curvature(tv):
                c = float(v @ (tv.hessian @ v)) if tv.hessian is not None else 0.0
                return c + sum(ci * float(vi @ v) ** 2 for ci, vi in tv.rank_one)

            curv = [curvature(tv) for tv in st.terms]
            zero = np.zeros_like(u)
            rest = sum(curvature(t.evaluate(self.eq.X, 0.0, 2, zero)) for t in terms
                       if t.internal and not getattr(t, "remedy", None))
        except (SolverError, FloatingPointError, ValueError, np.linalg.LinAlgError) as exc:
            log.info("no softest-mode diagnosis at load factor %.6g (%s)", lam, exc)
            return ""
        notes = []
        for t, c in zip(terms, curv):
            others = sum(ci for tj, ci in zip(terms, curv) if tj is not t and ci > 0)
            if (getattr(t, "remedy", None) and c < 0 and -c >= self.SOFT_SHARE * others
                    and -c >= self.SOFT_REST * rest):
                notes.append(f"the tangent's softest mode at load factor {lam:.6g} is made soft by {t.remedy} "
                             f"(curvature along it: {-c:.3g} taken from the other terms' {others:.3g}; "
                             f"{rest:.3g} at rest)")
        return "; ".join(notes)

    def _check_spurious(self, last, inst, lam, u_new, lam_new) -> None:
        """Stop the path (at its last point, lam) when the tangent lost stability between it and the
        converged (u_new, lam_new) on a mode that a term with a remedy makes soft (:meth:`soft_terms`):
        what follows would be the artefact's branch."""
        if last is None or inst is None or inst <= last:
            return
        soft = self.soft_terms(u_new, lam_new)
        if soft:
            err = _Failed(f"the tangent lost stability between load factors {lam:.6g} and {lam_new:.6g} "
                          f"(negative eigenvalues {last} -> {inst}) on a spurious mode: {soft}; the path "
                          "stops at the last stable point")
            err.diagnosed = True
            raise err

    def _critical_mode(self, u, lam, state=None, iterations: int = 30, rtol: float = 1e-8) -> np.ndarray:
        """The eigenvector of the tangent (on the supports' null space) whose eigenvalue is closest
        to zero at (u, lam) -- the critical mode just past a bifurcation point -- by inverse
        iteration on the KKT factorisation (each iteration one back-substitution); ``state``: the
        order-2 state at (u, lam) if the caller has it."""
        st = self.eq.evaluate(u, lam, 2) if state is None else state
        self.eq.factor(st)
        rng = np.random.default_rng(0)                    # a fixed start: reproducible
        v = rng.standard_normal(self.eq.n)
        zero = np.zeros(self.eq.m)
        # the tangent is nearly singular here (that is the point): only the direction of each
        # solve matters, so its residual check is loose
        v = self.eq.solve(v, zero, rtol=1e-3)
        v /= np.linalg.norm(v)
        for _ in range(iterations):
            w = self.eq.solve(v, zero, rtol=1e-3)
            w /= np.linalg.norm(w)
            if float(w @ v) < 0:
                w = -w
            done = float(np.linalg.norm(w - v)) <= rtol ** 0.5
            v = w
            if done:
                break
        return v

    def _bracket(self, sol, u, lam, dl, du_prev, dlam_prev, inst_a):
        """Bisect the arc length from the stable side (u, lam) towards a change of stability;
        returns the new path points in path order (stable side first).  Where the corrector fails
        at the middle of the bracket, a quarter of the way in from either end is tried
        (``LOCATE_SPLITS``, as in :meth:`_locate`); a bracket that cannot be narrowed further is an
        event of ``sol``."""
        a_side, b_side = [], []
        w = dl                                       # the bracket's arc length from (u, lam)
        for _ in range(self.opt.refine_critical):
            frac, got = _first_split(lambda f: self._arc_step(u, lam, f * w, du_prev, dlam_prev))
            if frac is None:
                sol.events.append({"from_load_factor": float(lam), "arc_length": float(w),
                                   "action": BRACKET_NOT_NARROWED, "reason": f"no equilibrium found inside it ({got})"})
                break
            uh, lh, ih, sth, insth = got
            pt = self._record(uh, lh, sth, ih, insth, "refine")
            if insth == inst_a:
                a_side.append(pt)
                self.eq.commit(uh)
                du_prev, dlam_prev, u, lam = uh - u, lh - lam, uh, lh
                w *= 1 - frac
            else:
                b_side.append(pt)
                w *= frac
        return a_side + b_side[::-1]

    def _bracket_between(self, sol, u_a, lam_a, u_b, lam_b, inst_a):
        """:meth:`_bracket` from the converged (u_a, lam_a) towards the converged (u_b, lam_b) of
        another stability: the arc length between them, their difference as the direction."""
        return self._bracket(sol, u_a, lam_a, float(np.linalg.norm(u_b - u_a)), u_b - u_a, lam_b - lam_a, inst_a)

    def _arc_step(self, u, lam, dl, du_prev, dlam_prev):
        """One Crisfield step of arc length dl; returns (u, lam, iterations, state, instability)."""
        eq, opt = self.eq, self.opt
        st = eq.evaluate(u, lam, 2)
        eq.factor(st, inertia=False)
        t = eq.solve(st.load, eq.g)
        tn = float(np.linalg.norm(t))
        if tn == 0:
            raise _Failed("zero tangent")
        if dlam_prev == 0.0:                      # branch switch: predictor along the mode
            Du = dl * du_prev / float(np.linalg.norm(du_prev))
            Dlam = 0.0
        else:
            sgn = 1.0 if float(t @ du_prev) >= 0 else -1.0
            dlam = sgn * dl / tn
            Du = dlam * t
            Dlam = dlam
        self.last_step = np.inf
        for it in range(1, opt.max_iterations + 1):
            un, ln = u + Du, lam + Dlam
            st = eq.evaluate(un, ln, 2)
            if not np.isfinite(st.energy) or not np.all(np.isfinite(st.gradient)):
                raise _Failed(f"non-finite state near load factor {ln:.6g}")
            ok, rel = self._converged(st, un, ln)
            if ok and it > 1:
                self.inertia_residual = inst_rel
                return un, ln, it - 1, st, inst
            inst, inst_rel = eq.factor(st), rel
            cres = eq.constraint_residual(un, ln)
            sols = eq.solve(np.stack([-st.gradient, st.load], 1), np.stack([cres, eq.g], 1))
            dR, dF = sols[:, 0], sols[:, 1]
            a = float(dF @ dF)
            b = 2.0 * float(dF @ (Du + dR))
            c = float((Du + dR) @ (Du + dR)) - dl * dl
            disc = b * b - 4 * a * c
            if disc < 0:
                raise _Failed(f"no real root of the arc-length constraint near load factor {ln:.6g}")
            roots = [(-b + s * np.sqrt(disc)) / (2 * a) for s in (1.0, -1.0)]
            best = max(roots, key=lambda r: float((Du + dR + r * dF) @ Du))
            corr = dR + best * dF
            Du = Du + corr
            self.last_step = float(np.linalg.norm(corr)) / max(float(np.linalg.norm(u + Du)), 1e-300)
            Dlam = Dlam + best
        raise _Failed(f"arc-length corrector did not converge in {opt.max_iterations} iterations near load "
                      f"factor {lam + Dlam:.6g} (relative residual {rel:.2e})")


def solve_nonlinear(problem: Problem, options: PathOptions | None = None, backend: str = "auto",
                    progress: Callable[[dict], None] | None = None, allow_partial: bool = False,
                    precision: str = "auto") -> NonlinearSolution:
    """Follow the equilibrium path of ``problem`` (see the module docstring).

    Raises PathStopped (with ``.solution``, the converged part) when the path cannot reach
    ``options.max_load``, unless ``allow_partial``.  ``precision``: "auto" | "mixed" | "double",
    the tangents' factors (see :class:`PathSolver`)."""
    opt = options or PathOptions()
    sol = PathSolver(problem, opt, backend, progress, precision=precision).run()
    if not sol.completed and not allow_partial:
        raise PathStopped(f"the load path stopped at load factor {sol.load_factor:.6g} after "
                          f"{len(sol.path) - 1} steps: {sol.stop_reason}", sol)
    return sol
