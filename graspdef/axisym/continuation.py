"""Nodal Newton iteration, incremental loading with a constant-arc-length method, stability (thesis 3.29-3.38).

Proportional loading: nodal loads Lam {P_R}, distributed loads Lam {q_R}.  At an equilibrium the residual
R(x, Lam) = F_int(x, Lam) - Lam P_R vanishes on the free nodal coordinates; F_int and its derivatives
[K] = dF/dx and {C} = dF/dLam come from the segments' BVP.1 / BVP.2 (shooting.py, assembly.py).

Arc-length: Newton on (R_free = 0, |x_f - x_n|^2 + w^2 (Lam - Lam_n)^2 = ds^2) with the bordered Jacobian
[[K_ff, C_f - P_R,f], [2 (x_f - x_n)^T, 2 w^2 (Lam - Lam_n)]], which stays regular at limit points; the predictor is
the path tangent.  The balance factor w makes the first tangent half load, half displacement.  The step length
adapts to the number of iterations; a failed step (no convergence, shooting failure) is halved, and only below
``ds_min`` is a SolverError raised naming the load step and the segment.

Stability (thesis "Stability of equilibrium"): the sign of det [K_ff] and its inertia (number of negative
eigenvalues of the symmetric part).  A limit point is where the tangent's load component changes sign; its load is
the maximum of the cubic Hermite interpolant of Lam(s) between the bracketing points (Lam and dLam/ds known there).
"""
import time
from dataclasses import dataclass, field

import numpy as np

from graspdef.errors import SolverError

from .shooting import ShootingError, end_forces, mismatch, solve_bvp1, stiffness


@dataclass
class AxisymEquilibrium:
    """A converged equilibrium (nondimensional).  x: dof vector (nodes' rho, eps, phi); nodes: (nnodes, 3) table
    with the pole nodes' eps filled in; lam: load factor; shape: (npts, 3) deformed meridian (rho, eps, phi) in
    meridian order; K_ff: free-free stiffness; n_negative / det_sign: stability data; reactions at fixed dofs."""

    lam: float
    x: np.ndarray
    nodes: np.ndarray
    shape: np.ndarray
    n_negative: int
    det_sign: float
    iterations: int
    reactions: np.ndarray
    K_ff: np.ndarray = field(repr=False, default=None)
    asym: float = 0.0


@dataclass
class PathResult:
    """Load path: equilibria in order, the limit points found, wall time."""

    points: list
    limits: list
    seconds: float
    model_name: str = ""
    stopped_by: str = ""

    @property
    def lam(self):
        return np.array([p.lam for p in self.points])

    def node(self, k):
        """(nsteps, 3) history of node k (rho, eps, phi)."""
        return np.array([p.nodes[k] for p in self.points])


class AxisymState:
    """Current equilibrium iterate of a Discrete model: x, lam, shooting unknowns u and the last solution."""

    def __init__(self, disc):
        self.d = disc
        self.x = disc.x0()
        self.lam = 0.0
        self.u = disc.initial_u()
        self.store = {}
        self.sol = None
        self.R0 = np.zeros(disc.ndof)  # residual of the unloaded, undeformed discrete model (see reference())

    def copy(self):
        s = AxisymState.__new__(AxisymState)
        s.d, s.x, s.lam, s.u = self.d, self.x.copy(), self.lam, self.u.copy()
        s.store = {"strains": None if self.store.get("strains") is None else self.store["strains"].copy()}
        s.sol, s.R0, s.mis = self.sol, self.R0, getattr(self, "mis", 0.0)
        return s

    def reference(self):
        """Solve the unloaded state and keep its residual R0 (the RK4 truncation error of the undeformed
        geometry, ~3e-5 per radian for the default discretisation) so that the discrete undeformed shell is
        exactly stress-free; all later residuals are F_int - R0 - Lam P_R."""
        R, K, dR = self.evaluate(self.x, 0.0, step=0, full=True)
        self.R0 = R.copy()
        return R - self.R0, K, dR

    def evaluate(self, x, lam, step=None, full=False):
        """Nodal residual R = F_int - Lam P_R, stiffness [K] and dR/dLam at nodal positions x and load lam.

        The segments' end unknowns are predicted linearly from the last solution (thesis 3.15) and one shot is
        made; with full=True BVP.1 is iterated to convergence first (thesis), otherwise the remaining end mismatch
        e enters through the segment's linearisation (r1 -> r1 - [U12]^-1 e), i.e. the BVP.1 Newton correction is
        carried inside the nodal Newton iteration (the same fixed point, one shot per iteration).  self.mis holds
        max |e|; an iterate counts as converged only when both R and e are negligible."""
        d = self.d
        X1, X2 = d.ends(x)
        u = self.predict_u(x, lam)
        try:
            sol = solve_bvp1(d.material, d.batch, X1, X2, u, lam, d.nsteps, self.store,
                             maxit=25 if full else 1, trajectory=True, raise_unconverged=full)
        except ShootingError as exc:
            where = d.piece_name(exc.segment) if exc.segment is not None else "a segment"
            raise SolverError(f"load step {step}: {where}: {exc}") from None
        except SolverError as exc:
            raise SolverError(f"load step {step}: {exc}") from None
        y2, Y2 = sol["y2"], sol["Y2"]
        e, A = mismatch(d.batch, y2, Y2, X2)
        du = np.linalg.solve(A, -e.T[:, :, None])[:, :, 0].T
        KL, C = stiffness(d.batch, y2, Y2)
        P = end_forces(d.batch, sol["u"] + du, y2)
        Yk = np.moveaxis(Y2, -1, 0)
        pole = d.batch["pole"]
        dr2 = np.einsum("kij,jk->ki", Yk[:, 3:6, 3:6], du)
        if np.any(pole):
            k = np.flatnonzero(pole)
            dr2[k] = np.einsum("kij,jk->ki", Yk[k, 3:6, 3:5], du[0:2, k])
        P[:, 3:6] += dr2
        F, K, Cv = d.assemble(P, KL, C)
        sol.update(KL=KL, C=C, x=x.copy(), lam=lam, X1=X1, X2=y2[0:3].copy(), P=P)
        self.mis = float(np.max(np.abs(e))) if e.size else 0.0
        self.sol, self.u, self.x, self.lam = sol, sol["u"], x.copy(), lam
        return F - self.R0 - lam * d.Pref, K, Cv - d.Pref

    def predict_u(self, x, lam):
        """Linear prediction of the shooting unknowns from the last solution's sensitivities (thesis 3.15)."""
        if self.sol is None:
            return self.u
        d, sol = self.d, self.sol
        X1, X2 = d.ends(x)
        dX1, dX2, dl = X1 - sol["X1"], X2 - sol["X2"], lam - sol["lam"]
        Y = np.moveaxis(sol["Y2"], -1, 0)
        rhs = dX2.T - np.einsum("kij,jk->ki", Y[:, 0:3, 0:3], dX1) - Y[:, 0:3, 6] * dl
        A = Y[:, 0:3, 3:6].copy()
        pole = d.batch["pole"]
        if np.any(pole):
            k = np.flatnonzero(pole)
            rhs[k] = np.stack([dX2[0, k] - Y[k, 0, 6] * dl, dX2[2, k] - Y[k, 2, 6] * dl, np.zeros(k.size)], 1)
            A[k] = 0.0
            A[k, 0, 0:2] = Y[k, 0, 3:5]
            A[k, 1, 0:2] = Y[k, 2, 3:5]
            A[k, 2, 2] = 1.0
        du = np.linalg.solve(A, rhs[:, :, None])[:, :, 0].T
        u = sol["u"] + du
        if np.any(pole):
            lp = sol["u"][0, pole]
            u[0, pole] = np.where(u[0, pole] > 0.3 * lp, u[0, pole], 0.3 * lp)
        return u

    def equilibrium(self, K, iterations, keep_K=True):
        d, sol = self.d, self.sol
        X = d.positions(self.x)
        for pn, k in d.pole_piece.items():  # pole height from the pole piece's vertical travel
            X[pn, 1] = X[d.b_idx[k], 1] - (sol["y2"][1, k] - d.X0[pn, 1])
        traj = sol["traj"].copy()  # (n+1, 6, K)
        for pn, k in d.pole_piece.items():  # the pole piece was integrated from the undeformed pole height
            traj[:, 1, k] += X[pn, 1] - d.X0[pn, 1]
        shape = np.concatenate([traj[:, 0:3, k] for k in range(traj.shape[2])], 0)
        for pn, k in d.pole_piece.items():
            shape = np.vstack([[0.0, X[pn, 1], 0.0], shape]) if k == 0 else shape
        Kff = K[np.ix_(d.free, d.free)]
        sym = 0.5 * (Kff + Kff.T)
        ev = np.linalg.eigvalsh(sym)
        sign, _ = np.linalg.slogdet(Kff)
        F, _, _ = d.assemble(sol["P"])
        reactions = (F - self.R0 - self.lam * d.Pref)[d.fixed]
        asym = float(np.max(np.abs(Kff - Kff.T)) / max(np.max(np.abs(Kff)), 1e-300))
        return AxisymEquilibrium(lam=self.lam, x=self.x.copy(), nodes=X, shape=shape, n_negative=int(np.sum(ev < 0)),
                           det_sign=float(sign), iterations=iterations, reactions=reactions,
                           K_ff=Kff if keep_K else None, asym=asym)


def _converged(st, R, f, tolR, step_size):
    """Residual below tolerance (or, at the round-off floor, a negligible last Newton correction with a residual
    within 1e3 x tolerance), and the segments' end mismatch negligible."""
    r = np.max(np.abs(R[f])) if f.size else 0.0
    xs = 1.0 + np.max(np.abs(st.x))
    small_step = step_size is not None and step_size < 1e-10 * xs
    return (r < tolR or (small_step and r < 1e3 * tolR)) and st.mis < 1e-8 * xs


def _tolerances(d, lam, R):
    scale = 1.0 + np.max(np.abs(lam * d.Pref)) if d.Pref.size else 1.0
    return 1e-8 * max(scale, 1.0)


def solve_load(model, lam, increments=1, tol=None, maxit=25):
    """Load-controlled Newton (no limit points): equilibrium at load factor lam reached in equal increments."""
    d = model.build()
    st = AxisymState(d)
    R, K, dR = st.reference()
    f = d.free
    its = 0
    for inc in range(1, increments + 1):
        lam_i = lam * inc / increments
        x = st.x.copy()
        if inc > 0:  # tangent predictor
            x[f] += np.linalg.solve(K[np.ix_(f, f)], -dR[f] * (lam_i - st.lam))
        last = None
        for its in range(1, maxit + 1):
            R, K, dR = st.evaluate(x, lam_i, step=inc)
            tolR = tol or _tolerances(d, lam_i, R)
            if its > 1 and _converged(st, R, f, tolR, last):
                break
            try:
                dx = np.linalg.solve(K[np.ix_(f, f)], -R[f])
            except np.linalg.LinAlgError:
                raise SolverError(f"load step {inc}: singular stiffness [K] (limit point or unsupported motion)") \
                    from None
            x = st.x.copy()
            x[f] += dx
            last = float(np.max(np.abs(dx))) if dx.size else 0.0
        else:
            raise SolverError(f"load step {inc}: nodal Newton did not converge in {maxit} iterations "
                              f"(residual {np.max(np.abs(R[f])):.3g})")
    return st.equilibrium(K, its)


def solve_path(model, ds=0.5, max_steps=200, stop=None, ds_max=None, ds_min=1e-6, maxit=10, lam_max=None,
               target_iterations=4, weight=None, progress=None, on_failure="raise", unload_fraction=None):
    """Trace the equilibrium path from the unloaded state with the constant-arc-length method.

    ds: first arc-length step (weighted norm, nondimensional); stop(eq) -> True ends the path; lam_max: stop when
    |Lam| exceeds it; unload_fraction: stop once past a limit point when Lam < unload_fraction * Lam_limit.
    on_failure="stop" ends the path at the last converged point when a step cannot be
    completed even with the smallest step (PathResult.stopped_by holds the error); "raise" raises it.
    Returns a PathResult.  Never returns an unconverged point."""
    t_start = time.perf_counter()
    d = model.build()
    st = AxisymState(d)
    R, K, dR = st.reference()
    f = d.free
    Kff = K[np.ix_(f, f)]
    if np.linalg.cond(Kff) > 1e13:
        raise SolverError("stiffness [K] of the unloaded shell is singular: unsupported rigid-body motion "
                          "(restrain enough nodal coordinates)")
    tx = np.linalg.solve(Kff, -dR[f])
    w = weight if weight is not None else max(np.linalg.norm(tx), 1e-12)
    t = np.concatenate([tx, [1.0]])
    t /= np.sqrt(tx @ tx + w * w)
    ds_max = ds_max or 20 * ds
    points = [st.equilibrium(K, 0)]
    tangents = [t]
    svals = [0.0]
    limits = []
    step = 0
    h = ds
    stopped_by = ""
    while step < max_steps:
        step += 1
        base = st.copy()
        failed = None
        while True:
            try:
                its, K, dR = _arc_step(st, base, t, h, w, maxit, step)
                break
            except SolverError as exc:
                st = base.copy()
                h *= 0.5
                if h < ds_min:
                    failed = SolverError(f"load step {step}: arc-length step fell below {ds_min:g} "
                                         f"(last failure: {exc})")
                    break
        if failed is not None:
            if on_failure == "raise" or step == 1:
                raise failed
            stopped_by = str(failed)
            break
        Kff = K[np.ix_(f, f)]
        A = np.zeros((f.size + 1, f.size + 1))
        A[:-1, :-1] = Kff
        A[:-1, -1] = dR[f]
        A[-1, :-1] = t[:-1]
        A[-1, -1] = w * w * t[-1]
        rhs = np.zeros(f.size + 1)
        rhs[-1] = 1.0
        tn = np.linalg.solve(A, rhs)
        tn /= np.sqrt(tn[:-1] @ tn[:-1] + w * w * tn[-1] ** 2)
        if tn[:-1] @ t[:-1] + w * w * tn[-1] * t[-1] < 0:
            tn = -tn
        eq = st.equilibrium(K, its)
        points.append(eq)
        svals.append(svals[-1] + h)
        tangents.append(tn)
        if len(points) >= 2 and t[-1] > 0 >= tn[-1]:
            limits.append(_limit(points[-2], points[-1], t, tn, h, w, svals[-2], step))
        t = tn
        if progress:
            progress(step, eq)
        if stop is not None and stop(eq):
            break
        if lam_max is not None and abs(eq.lam) > lam_max:
            break
        if unload_fraction is not None and limits and eq.lam < unload_fraction * limits[0]["lam"]:
            break
        if its <= target_iterations - 1:
            h = min(h * 1.5, ds_max)
        elif its > target_iterations + 2:
            h *= 0.6
    return PathResult(points=points, limits=limits, seconds=time.perf_counter() - t_start,
                      model_name=model.name, stopped_by=stopped_by)


def _limit(p0, p1, t0, t1, h, w, s0, step):
    """Limit point between two converged points: maximum of the cubic Hermite interpolant of Lam(s)."""
    l0, l1, d0, d1 = p0.lam, p1.lam, t0[-1], t1[-1]
    ss = np.linspace(0, 1, 2001)
    h00, h10 = 2 * ss**3 - 3 * ss**2 + 1, ss**3 - 2 * ss**2 + ss
    h01, h11 = -2 * ss**3 + 3 * ss**2, ss**3 - ss**2
    lam = h00 * l0 + h10 * h * d0 + h01 * l1 + h11 * h * d1
    i = int(np.argmax(lam))
    return dict(lam=float(lam[i]), s=float(s0 + ss[i] * h), step=int(step), bracket=(float(p0.lam), float(p1.lam)),
                frac=float(ss[i]))


def _arc_step(st, base, t, h, w, maxit, step):
    """One constant-arc-length step from the converged state base along tangent t."""
    d = st.d
    f = d.free
    x = base.x.copy()
    x[f] += h * t[:-1]
    lam = base.lam + h * t[-1]
    xn, ln = base.x[f], base.lam
    for it in range(1, maxit + 1):
        R, K, dR = st.evaluate(x, lam, step=step)
        g = (x[f] - xn) @ (x[f] - xn) + w * w * (lam - ln) ** 2 - h * h
        tolR = _tolerances(d, lam, R)
        if it > 1 and abs(g) < 1e-8 * h * h and np.max(np.abs(dz)) < 1e-7 \
                and _converged(st, R, f, tolR, float(np.max(np.abs(dz)))):
            return it, K, dR
        A = np.zeros((f.size + 1, f.size + 1))
        A[:-1, :-1] = K[np.ix_(f, f)]
        A[:-1, -1] = dR[f]
        A[-1, :-1] = 2 * (x[f] - xn)
        A[-1, -1] = 2 * w * w * (lam - ln)
        try:
            dz = np.linalg.solve(A, -np.concatenate([R[f], [g]]))
        except np.linalg.LinAlgError:
            raise SolverError(f"load step {step}: singular bordered stiffness") from None
        if not np.all(np.isfinite(dz)):
            raise SolverError(f"load step {step}: non-finite Newton correction")
        x = x.copy()
        x[f] += dz[:-1]
        lam += dz[-1]
    raise SolverError(f"load step {step}: nodal Newton did not converge in {maxit} iterations "
                      f"(residual {np.max(np.abs(R[f])):.3g})")
