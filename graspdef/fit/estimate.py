"""Least-squares identification of positive parameters from a measured table.

Unknowns are the logarithms of the parameters (positivity without constraints, and steps relative
to each parameter's size), residuals ``(predicted - measured) / sigma`` per table row, solved by
``scipy.optimize.least_squares`` (trust-region reflective, within a factor ``bound`` of the start).
The Jacobian is by forward differences in the log-parameters with step ``h`` (default 1e-3: each
parameter changed by ``e^h - 1`` = 0.1 %), one forward evaluation per parameter beyond the point
itself; no adjoint.

Reported (:class:`FitResult`): the values, the residual of each row and their RMS, standard errors
from the Jacobian at the solution (``cov = s^2 (J^T J)^-1`` in log-parameters, ``s^2 = chi^2 / (m - n)``,
a parameter's standard error ``theta * sqrt(cov_ii)`` by the delta method), the correlation
matrix, the condition number of ``J^T J``, and warnings: parameters that trade off (``|corr| >
0.95`` or ``cond(J^T J) > 1e8``: "E and pressure are not separately identifiable from these data"),
a parameter at its bound, no residual degrees of freedom.  A fit whose optimiser does not converge,
or whose forward model fails (a path that stops, a singular solve), is reported as not converged,
with the reason; never as converged.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import GraspdefError, ProblemError
from .table import MeasuredTable

#: |correlation| above which two parameters are reported as trading off
CORRELATION_LIMIT = 0.95
#: condition number of J^T J (log-parameters, weighted residuals) above which the fit is reported
#: as not identifying its parameters separately (|J| condition 1e4)
CONDITION_LIMIT = 1e8
#: forward-difference step in the log-parameters (0.1 % of each parameter)
FD_STEP = 1e-3
#: the optimiser stops when a step changes the log-parameters by less than this (relative 1e-6: far
#: below any standard error a measured table gives; scipy's default 1e-8 spends its last evaluations
#: on steps of 1e-8 near the minimum)
XTOL = 1e-6
#: each parameter is searched within [start / BOUND, start * BOUND]
BOUND = 100.0
#: weight of the rows of a table without a sigma column [m] (any constant gives the same estimate
#: and, through s^2, the same standard errors)
UNIT_SIGMA = 1e-3


@dataclass(frozen=True)
class Parameter:
    """A parameter that can be fitted: its SI unit, a display unit and what it is."""

    name: str
    unit: str
    dimension: str
    display: str
    meaning: str


#: the parameters an object's forward model accepts (graspdef.fit.models.ObjectModel)
PARAMETERS = {
    "E": Parameter("E", "Pa", "pressure", "MPa", "small-strain Young's modulus of the material law"),
    "pressure": Parameter("pressure", "Pa", "pressure", "kPa", "gauge pressure of the enclosed air, unloaded"),
    "thickness": Parameter("thickness", "m", "length", "mm", "wall thickness"),
}


def parse_names(text: str, accepted=PARAMETERS) -> list[str]:
    """``"E,pressure"`` -> ["E", "pressure"]; an unknown or repeated name is one line."""
    names = [t.strip() for t in str(text).split(",") if t.strip()]
    if not names:
        raise ProblemError(f"--params: no parameter named; accepted: {', '.join(accepted)}")
    for n in names:
        if n not in accepted:
            raise ProblemError(f"--params: unknown parameter {n!r}; accepted: {', '.join(accepted)} "
                               "(friction mu is not fitted: the point-load chain takes MuJoCo's contact forces)")
        if names.count(n) > 1:
            raise ProblemError(f"--params: {n!r} given twice")
    return names


class ForwardFailed(GraspdefError):
    """The forward model failed at some parameters (its reason and where)."""


@dataclass
class FitResult:
    """What a fit found and how much to trust it (see the module docstring); SI throughout."""

    names: list
    values: np.ndarray
    start: np.ndarray
    std: np.ndarray                     # standard errors [the parameters' units]; NaN when unavailable
    correlation: np.ndarray
    condition: float                    # of J^T J (log-parameters, weighted residuals)
    table: MeasuredTable
    predicted: np.ndarray               # [m] at the fitted values
    sigma: np.ndarray                   # [m] the weights used
    converged: bool
    message: str
    s2: float
    dof: int
    n_evaluations: int                  # forward-model evaluations (each row of the table at one theta)
    n_solves: int | None                # forward solves, when the model counts them
    seconds: float
    fd_step: float = FD_STEP
    warnings: list = field(default_factory=list)
    model: dict = field(default_factory=dict)

    @property
    def residual(self) -> np.ndarray:
        """predicted - measured [m] per row."""
        return self.predicted - self.table.displacement

    @property
    def rms(self) -> float:
        """RMS of the residuals [m]."""
        return float(np.sqrt(np.mean(self.residual ** 2)))

    def value(self, name: str) -> float:
        return float(self.values[self.names.index(name)])

    def to_json(self) -> dict:
        """fit.json: values in SI with their units stated."""
        def num(x):
            x = float(x)
            return x if math.isfinite(x) else None

        t = self.table
        return {
            "kind": "fit", "converged": self.converged, "message": self.message,
            "units": {"force": "N", "displacement": "m", **{n: PARAMETERS[n].unit if n in PARAMETERS else "" for n in self.names}},
            "parameters": {n: {"value": num(v), "std": num(s), "start": num(s0),
                               "unit": PARAMETERS[n].unit if n in PARAMETERS else "",
                               "meaning": PARAMETERS[n].meaning if n in PARAMETERS else ""}
                           for n, v, s, s0 in zip(self.names, self.values, self.std, self.start)},
            "rows": [{"force_N": num(f), "point": p, "measured_m": num(d), "predicted_m": num(y),
                      "residual_m": num(y - d), "sigma_m": num(s), "normalised_residual": num((y - d) / s)}
                     for f, p, d, y, s in zip(t.force, t.point, t.displacement, self.predicted, self.sigma)],
            "rms_residual_m": num(self.rms), "chi2": num(np.sum((self.residual / self.sigma) ** 2)),
            "dof": self.dof, "s2": num(self.s2),
            "correlation": {"names": list(self.names), "matrix": [[num(c) for c in row] for row in self.correlation]},
            "condition_number_JTJ": num(self.condition),
            "warnings": list(self.warnings),
            "method": {"optimiser": "scipy.optimize.least_squares (trf) on log-parameters, residuals "
                                    "(predicted - measured) / sigma",
                       "jacobian": f"forward differences in log-parameters, step h = {self.fd_step:g} "
                                   f"(each parameter x e^h, +{(math.exp(self.fd_step) - 1) * 100:.3g} %)",
                       "covariance": "s^2 (J^T J)^-1 in log-parameters, s^2 = chi2 / dof; std = value * sqrt(cov_ii)",
                       "bounds": f"[start / {BOUND:g}, start * {BOUND:g}]",
                       "xtol": XTOL,
                       "sigma": "the table's sigma column" if t.sigma is not None else
                                f"none in the table: every row weighted alike (sigma = {UNIT_SIGMA:g} m)"},
            "cost": {"forward_evaluations": self.n_evaluations, "forward_solves": self.n_solves,
                     "seconds": num(self.seconds)},
            "data": {"file": None if t.file is None else str(t.file), "header_units": t.units},
            "model": self.model,
        }


def identifiability(J: np.ndarray, names: list, s2: float) -> tuple[np.ndarray, np.ndarray, float, list]:
    """(cov in log-parameters, correlation, cond(J^T J), warnings) of a weighted Jacobian ``J``
    (rows: residuals, columns: log-parameters)."""
    n = J.shape[1]
    JTJ = J.T @ J
    eig, vec = np.linalg.eigh(JTJ)
    cond = float(eig[-1] / eig[0]) if eig[0] > 0 else math.inf
    warnings = []
    # (J^T J)^-1 by its eigen-decomposition, eigenvalues floored at round-off (1e-16 of the largest):
    # a direction the data do not see gets a huge variance (not the pseudo-inverse's zero)
    lam = np.maximum(eig, max(float(eig[-1]), 1e-300) * 1e-16)
    P = (vec / lam) @ vec.T
    dp = np.sqrt(np.diag(P))
    corr = P / np.outer(dp, dp)
    cov = s2 * P
    pairs = []
    for i in range(n):
        for j in range(i + 1, n):
            if np.isfinite(corr[i, j]) and abs(corr[i, j]) > CORRELATION_LIMIT:
                pairs.append((i, j))
                warnings.append(f"{names[i]} and {names[j]} are not separately identifiable from these data "
                                f"(correlation {corr[i, j]:+.4f}): the data fix a combination of them, not each")
    if n > 1 and cond > CONDITION_LIMIT:
        weak = vec[:, 0]
        involved = [names[k] for k in np.flatnonzero(np.abs(weak) > 0.2 * np.abs(weak).max())]
        if not any(set(involved) >= {names[i], names[j]} for i, j in pairs) or len(involved) > 2:
            warnings.append(f"{' and '.join(involved)} are not separately identifiable from these data "
                            f"(condition number of J^T J {cond:.3g} > {CONDITION_LIMIT:g})")
    elif n == 1 and eig[0] <= 0:
        warnings.append(f"the data do not depend on {names[0]} (zero sensitivity)")
    return cov, corr, cond, warnings


def fit(model: Callable[[dict], np.ndarray], table: MeasuredTable, start: dict, *, fd_step: float = FD_STEP,
        bound: float = BOUND, max_nfev: int = 30, progress: Callable[[dict], None] | None = None) -> FitResult:
    """Fit ``start``'s parameters (name -> start value, SI, > 0) so that ``model(theta)`` -- the
    predicted displacements [m] at the table's rows, ``theta`` a dict like ``start`` -- matches
    ``table.displacement``.  ``max_nfev``: iterations of the optimiser (each costs one model
    evaluation, and len(start) more for its Jacobian).  ``progress``: called with each new
    evaluation's theta and RMS residual.  See the module docstring for what is reported."""
    from scipy.optimize import least_squares   # here: scipy.optimize is heavy (start-up)

    names = list(start)
    x0 = np.array([start[k] for k in names], float)
    if not np.all(np.isfinite(x0)) or np.any(x0 <= 0):
        raise ProblemError(f"start values must be positive numbers, got {dict(start)}")
    m, n = len(table), len(names)
    if m < n:
        raise ProblemError(f"{table.file or 'table'}: {m} rows for {n} parameters ({', '.join(names)}): a fit needs "
                           "at least as many rows as parameters")
    if not (0 < fd_step < 0.1):
        raise ProblemError(f"fd_step must lie in (0, 0.1), got {fd_step!r}")
    sigma = table.sigma if table.sigma is not None else np.full(m, UNIT_SIGMA)
    d = table.displacement
    z0 = np.log(x0)
    cache: dict[tuple, np.ndarray] = {}
    best = {"z": z0, "cost": math.inf}
    t0 = time.perf_counter()

    def predict(z):
        key = tuple(np.round(z, 14))
        if key not in cache:
            theta = dict(zip(names, np.exp(z).tolist()))
            try:
                y = np.asarray(model(theta), float)
            except GraspdefError as exc:
                raise ForwardFailed(f"the forward model failed at {_fmt(theta)}: {exc}") from None
            if y.shape != (m,) or not np.all(np.isfinite(y)):
                raise ForwardFailed(f"the forward model returned no finite prediction per row at {_fmt(theta)}")
            cache[key] = y
            cost = float(np.sum(((y - d) / sigma) ** 2))
            if cost < best["cost"]:
                best.update(z=np.array(z), cost=cost)
            if progress is not None:
                progress({"theta": theta, "rms_m": float(np.sqrt(np.mean((y - d) ** 2))), "evaluations": len(cache)})
        return cache[key]

    failed: list[str] = []

    def fun(z):
        # a trial step whose forward solve fails (a path that stops) is answered with a non-finite
        # residual: least_squares (trf) then shrinks its trust region and tries a shorter step; the
        # start point and the Jacobian's evaluations must succeed (else the fit stops, not converged)
        if len(cache) and not np.array_equal(z, z0):
            try:
                return (predict(z) - d) / sigma
            except ForwardFailed as exc:
                failed.append(str(exc))
                return np.full(m, np.nan)
        return (predict(z) - d) / sigma

    def jac(z):
        r0 = fun(z)
        J = np.empty((m, n))
        for j in range(n):
            zj = np.array(z, float)
            zj[j] += fd_step
            J[:, j] = ((predict(zj) - d) / sigma - r0) / fd_step
        return J

    lo, hi = z0 - math.log(bound), z0 + math.log(bound)
    try:
        res = least_squares(fun, z0, jac=jac, bounds=(lo, hi), method="trf", max_nfev=max_nfev, x_scale=1.0,
                            xtol=XTOL)
        z, converged, message = res.x, bool(res.status > 0), str(res.message)
        J = jac(z)
    except ForwardFailed as exc:
        z, converged, message, J = best["z"], False, str(exc), None
        if not cache:       # not even the start ran: say what to change
            message += ("; the forward model fails at the start values, so there is nothing to fit from: give "
                        "other start values (--start; a nonlinear load path that stops at the start is usually a "
                        "shell too soft for the force: a larger E)")
    if failed:
        warnings_failed = [f"{len(failed)} trial step(s) of the optimiser failed in the forward model and were "
                           f"stepped back from (the first: {failed[0]})"]
    else:
        warnings_failed = []
    n_solves = getattr(model, "n_solves", None)
    seconds = time.perf_counter() - t0
    theta = np.exp(z)
    warnings = list(warnings_failed)
    if not converged:
        warnings.append(f"the fit did NOT converge: {message}; the values are the best evaluated, not an estimate")
    predicted = cache.get(tuple(np.round(z, 14)), np.full(m, np.nan))
    dof = m - n
    r = (predicted - d) / sigma
    s2 = float(r @ r) / dof if dof > 0 else math.nan
    if dof == 0:
        warnings.append("as many rows as parameters: no residual degrees of freedom, so no standard errors "
                        "(add measurements)")
    if J is not None:
        cov, corr, cond, w = identifiability(J, names, s2)
        warnings += w
        std = theta * np.sqrt(np.abs(np.diag(cov)))
    else:
        corr, cond, std = np.full((n, n), np.nan), math.nan, np.full(n, np.nan)
    for k, name in enumerate(names):
        if converged and (z[k] <= lo[k] + 1e-6 or z[k] >= hi[k] - 1e-6):
            warnings.append(f"{name} ended at its bound (a factor {bound:g} from its start): not an estimate")
    return FitResult(names, theta, x0, std, corr, cond, table, predicted, sigma, converged, message, s2, dof,
                     len(cache), n_solves, seconds, fd_step, warnings, dict(getattr(model, "description", {}) or {}))


def _fmt(theta: dict) -> str:
    return ", ".join(f"{k} = {v:.6g} {PARAMETERS[k].unit if k in PARAMETERS else ''}".rstrip() for k, v in theta.items())
