"""Live re-solves behind the viewer's force and modulus sliders, and the load path's states.

Linear runs: u = s_F (E0/E) u_f + u_g exactly (u_f: the response to the run's loads, u_g: to
its prescribed displacements), both solved once with one kept KKT factorisation; a slider move
costs one sparse product with the limit map.

Nonlinear runs: the target load factor is lam = lam_end s_F (E0/E) -- scaling every modulus by
E/E0 scales the elastic energy (and the Nitsche terms) by the same factor, so the equilibrium at
modulus E under load lam_end s_F is the one at E0 under lam_end s_F E0/E.  That holds for loads
that scale with the load factor; with prescribed displacements or an enclosed gas the modulus
slider is off.  A few Newton steps run from the current converged state (halving the increment
up to ``max_cuts`` times); a state is shown only when it converged.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, replace

import numpy as np

from ..problem.config import load_problem
from ..problem.loads import PointLoad
from ..problem.potentials import EnclosedGas
from ..solve.nonlinear import PathOptions, PathSolver, path_options, solve_nonlinear
from ..solve.linear import LinearResponse
from ..subdivision.rules import limit_matrix
from ..runs.read import RunData

log = logging.getLogger(__name__)


class Aborted(Exception):
    """A background path solve was stopped (the viewer is closing)."""


@dataclass
class LiveResult:
    """Outcome of one live request: limit displacements (n, 3) [m] if converged."""

    converged: bool
    displacements: np.ndarray | None
    force_scale: float
    modulus_scale: float
    load_factor: float | None
    seconds: float
    message: str


class LiveModel:
    """Re-solves of one run (see the module docstring).  Not thread-safe: one worker uses it."""

    def __init__(self, run: RunData, backend: str = "auto", max_iterations: int = 20, max_cuts: int = 4):
        t0 = time.perf_counter()
        if run.problem_file is None:
            raise FileNotFoundError(f"{run.path}: no problem.toml")
        self.run = run
        self.spec = load_problem(run.problem_file)
        self.problem = self.spec.problem
        shell = self.problem.shell
        mesh = shell.mesh
        self.L = limit_matrix(mesh.faces, mesh.n_control, np.arange(mesh.n_real))
        if self.L.shape[0] != len(run.rest_vertices):
            raise ValueError(f"{run.path}: problem.toml builds {self.L.shape[0]} surface vertices, the run has "
                             f"{len(run.rest_vertices)}")
        mat = shell.material
        self.modulus_name = "E" if hasattr(mat, "E") else "modulus"
        self.modulus0 = float(getattr(mat, "E", 1.0))
        forces = [np.linalg.norm(ld.force) for ld in self.problem.loads if isinstance(ld, PointLoad)]
        self.force0 = float(max(forces)) if forces else None          # largest point force [N]
        self.nonlinear = run.analysis == "nonlinear"
        self.max_cuts = max_cuts
        self.backend = backend
        self.linear: LinearResponse | None = None
        self.solver: PathSolver | None = None
        if self.nonlinear:
            opts = path_options(self.spec.solver)
            self.options = opts
            self.solver = PathSolver(self.problem, PathOptions(method="load", max_iterations=max_iterations,
                                                               tol=opts.tol, line_search=True), backend,
                                     precision=self.spec.precision)
            eq = self.solver.eq
            self.modulus_ok = not (eq.m and np.any(eq.g)) and not any(isinstance(t, EnclosedGas) for t in eq.terms)
            self.lam_end = float((run.record.get("convergence") or {}).get("load_factor", opts.max_load))
            self.u = None                                  # (3 n_control,) current converged state
            self.lam = None
        else:
            self.linear = LinearResponse(self.problem, backend, self.spec.precision)
            self.modulus_ok = True
            self.lam_end = 1.0
        self.seconds_setup = time.perf_counter() - t0

    def close(self) -> None:
        if self.linear is not None:
            self.linear.close()
        if self.solver is not None:
            self.solver.eq.close()

    # ---- nonlinear path ----------------------------------------------------------------------
    def start_from(self, u: np.ndarray, lam: float) -> None:
        """Use the converged state (n_control, 3) [m] at load factor ``lam`` as the current one."""
        self.u = np.asarray(u, float).ravel().copy()
        self.lam = float(lam)
        self.solver.eq.commit(self.u)

    def solve_path(self, should_stop=lambda: False, load_factors=None):
        """Re-solve the run's load path (when ``path_u.npz`` is absent); returns the solution
        (converged points only); raises :class:`Aborted` when ``should_stop()`` turns true.

        ``load_factors`` (those of path.csv) become targets of a load-controlled path, so that
        the re-solve lands on every point of the stored path even if the adaptive steps differ."""
        opts = self.options
        if load_factors is not None and opts.method == "load":
            lf = np.asarray(load_factors, float)
            ok = lf[(lf * np.sign(opts.max_load) > 0) & (np.abs(lf) <= abs(opts.max_load))]
            opts = replace(opts, targets=tuple(sorted(set(map(float, opts.targets)) | set(map(float, ok)),
                                                      key=lambda v: abs(v))),
                           max_steps=max(opts.max_steps, 2 * len(lf) + 10))

        def progress(info):
            if should_stop():
                raise Aborted("viewer closing")
        return solve_nonlinear(self.problem, opts, self.backend, progress=progress, allow_partial=True,
                               precision=self.spec.precision)

    # ---- requests --------------------------------------------------------------------------------
    def request(self, force_scale: float, modulus_scale: float) -> LiveResult:
        """The state at ``force_scale`` x the run's loads and ``modulus_scale`` x its moduli."""
        t0 = time.perf_counter()
        if not modulus_scale > 0:
            return LiveResult(False, None, force_scale, modulus_scale, None, 0.0, "the modulus must be positive")
        if not self.modulus_ok and modulus_scale != 1.0:
            return LiveResult(False, None, force_scale, modulus_scale, None, 0.0,
                              "modulus changes are off for this run (prescribed displacements or enclosed gas)")
        if not self.nonlinear:
            u = self.linear.displacements(force_scale, modulus_scale)
            return LiveResult(True, self.L @ u, force_scale, modulus_scale, force_scale, time.perf_counter() - t0,
                              "linear: exact")
        if self.u is None:
            return LiveResult(False, None, force_scale, modulus_scale, None, 0.0, "the load path is not ready yet")
        target = self.lam_end * force_scale / modulus_scale
        u, lam = self.u, self.lam
        steps, its, cuts = 0, 0, 0
        inc = target - lam
        while abs(target - lam) > 1e-14 * max(1.0, abs(target)):
            nxt = target if abs(target - lam) <= abs(inc) else lam + inc
            try:
                u_new, _, it, _ = self.solver.newton(u, nxt)
            except Exception as exc:            # noqa: BLE001 (non-convergence in any form)
                cuts += 1
                if cuts > self.max_cuts:
                    return LiveResult(False, None, force_scale, modulus_scale, target, time.perf_counter() - t0,
                                      f"Newton did not converge at load factor {nxt:.4g} ({exc}); showing the "
                                      f"last converged state (load factor {self.lam:.4g})")
                inc *= 0.5
                continue
            u, lam = u_new, nxt
            self.solver.eq.commit(u)
            steps, its = steps + 1, its + it
        self.u, self.lam = u, lam
        return LiveResult(True, self.L @ u.reshape(-1, 3), force_scale, modulus_scale, lam, time.perf_counter() - t0,
                          f"nonlinear: converged at load factor {lam:.4g} ({steps} step(s), {its} Newton iterations)")
