"""BVP.1 and BVP.2 for shell segments: forward integration (classical Runge-Kutta, the thesis's "1/6 rule") of the
governing equations together with their rate (variational) equations, Newton on the unknown end forces, and the
segment tangent stiffness [KL] (thesis 3.1-3.19).

All segments of a model are integrated at once (numpy-vectorised over segments); every segment takes the same
number of RK4 steps.  A segment k is described by the arrays of a ``batch`` dict (index k):
    rho_a, eps_a, phi_a, kappa   reference geometry of the piece at its start (see meridian.py)
    s0, h                        start of integration (0, or delta > 0 for a pole piece) and step
    pole                         True if the piece starts on the axis (rho0 = 0)
    qH, qV, QH, QV, p            distributed reference loads (equations.py)

Unknowns at end 1 ("u", 3 per segment): for an ordinary segment the end forces r1 = (U, V, M)(sigma1) (the thesis's
f^H, f^V, f^M up to sign); for a pole piece the pole stretch and curvature (lambda_p, c_p) (the third entry unused),
from which the regular series solution starts the integration at sigma = delta.  Columns of the 6 x 7 sensitivity
matrix Y = dy/d(...) are (rho1, eps1, phi1, u1, u2, u3, Lam), its initial values the thesis's (3.9)-(3.10).
"""
import numpy as np

from graspdef.errors import SolverError

from .equations import geometry_at, rhs


class ShootingError(SolverError):
    """Shooting failed; ``segment`` is the batch index of the failing segment (or None)."""

    def __init__(self, msg, segment=None):
        super().__init__(msg)
        self.segment = segment


def start_states(material, batch, X1, u, lam):
    """Initial y (6, K) and Y (6, 7, K) at sigma1 (ordinary) or sigma = delta (pole pieces)."""
    K = X1.shape[1]
    y = np.empty((6, K))
    Y = np.zeros((6, 7, K))
    y[0:3] = X1
    y[3:6] = u
    for i in range(6):
        Y[i, i] = 1.0
    pole = batch["pole"]
    if np.any(pole):
        k = np.flatnonzero(pole)
        d = batch["s0"][k]
        lp, cp = u[0, k], u[1, k]
        kap = batch["kappa"][k]
        rho0, _, _, _ = geometry_at({key: batch[key][k] for key in ("rho_a", "eps_a", "phi_a", "kappa")}, d)
        _, g, H = material.shell_energy(lp, lp, cp, cp, kap, kap)
        phi_a = batch["phi_a"][k]
        sgn = np.cos(phi_a)  # pole with phi0 = 0 (+1) or pi (-1)
        qV, QV, p = batch["qV"][k], batch["QV"][k], batch["p"][k]
        fv = lp * lp * (qV + p * sgn) + QV
        y[0, k] = lp * rho0
        y[1, k] = X1[1, k] + sgn * lp * cp * d * d / 2
        y[2, k] = phi_a + cp * d
        y[3, k] = g[1] * d
        y[4, k] = -lam * fv * d * d / 2
        y[5, k] = g[3] * d * sgn
        Y[:, :, k] = 0.0
        Y[1, 1, k] = 1.0
        Y[0, 3, k] = rho0
        Y[1, 3, k] = sgn * cp * d * d / 2
        Y[1, 4, k] = sgn * lp * d * d / 2
        Y[2, 4, k] = d
        Y[3, 3, k] = (H[1, 0] + H[1, 1]) * d
        Y[3, 4, k] = (H[1, 2] + H[1, 3]) * d
        Y[4, 3, k] = -lam * 2 * lp * (qV + p * sgn) * d * d / 2
        Y[4, 6, k] = -fv * d * d / 2
        Y[5, 3, k] = (H[3, 0] + H[3, 1]) * d * sgn
        Y[5, 4, k] = (H[3, 2] + H[3, 3]) * d * sgn
    return y, Y


def integrate(material, batch, y, Y, lam, nsteps, store, trajectory=False):
    """Classical RK4 of the state and its sensitivities from s0 to the end of every piece.

    store: dict holding the strains of the previous integration (warm start of the constitutive Newton);
    returns (y2, Y2, traj) with traj (nsteps+1, 6, K) if requested."""
    loads = (batch["qH"], batch["qV"], batch["QH"], batch["QV"], batch["p"])
    h = batch["h"]
    K = y.shape[1]
    traj = [y.copy()] if trajectory else None
    strains = store.get("strains")
    if strains is None or strains.shape != (nsteps, 4, 2, K):
        strains = None
    new = np.empty((nsteps, 4, 2, K))

    def F(j, stage, s, yy, YY):
        geom = geometry_at(batch, s)
        guess = strains[j, stage] if strains is not None else np.array([yy[0] / geom[0], geom[2]])
        try:
            f, J, fl, st = rhs(material, yy, geom, loads, lam, guess)
        except SolverError:
            try:  # fall back to the undeformed guess
                f, J, fl, st = rhs(material, yy, geom, loads, lam, np.array([np.ones(K), geom[2]]))
            except SolverError as exc:
                bad = getattr(exc, "points", np.flatnonzero(~np.isfinite(yy).all(axis=0)))
                raise ShootingError(f"integration step {j + 1}/{nsteps}: {exc}",
                                    int(bad[0]) if len(bad) else None) from None
        new[j, stage] = st
        dY = np.einsum("ijk,jlk->ilk", J, YY)
        dY[:, 6] += fl
        return f, dY

    for j in range(nsteps):
        s = batch["s0"] + j * h
        k1, K1 = F(j, 0, s, y, Y)
        k2, K2 = F(j, 1, s + h / 2, y + h / 2 * k1, Y + h / 2 * K1)
        k3, K3 = F(j, 2, s + h / 2, y + h / 2 * k2, Y + h / 2 * K2)
        k4, K4 = F(j, 3, s + h, y + h * k3, Y + h * K3)
        y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        Y = Y + h / 6 * (K1 + 2 * K2 + 2 * K3 + K4)
        if not np.all(np.isfinite(y)):
            bad = np.flatnonzero(~np.isfinite(y).all(axis=0))
            raise ShootingError(f"integration diverged at step {j + 1}/{nsteps}", int(bad[0]))
        if trajectory:
            traj.append(y.copy())
    store["strains"] = new
    return y, Y, (np.array(traj) if trajectory else None)


def mismatch(batch, y2, Y2, X2):
    """End-2 mismatch e (3, K) and its Jacobian A = de/du (K, 3, 3)."""
    K = y2.shape[1]
    e = y2[0:3] - X2
    A = np.moveaxis(Y2[0:3, 3:6], -1, 0).copy()
    pole = batch["pole"]
    if np.any(pole):
        k = np.flatnonzero(pole)
        e[:, k] = np.array([y2[0, k] - X2[0, k], y2[2, k] - X2[2, k], np.zeros(k.size)])
        A[k] = 0.0
        A[k, 0, 0:2] = Y2[0, 3:5, k]
        A[k, 1, 0:2] = Y2[2, 3:5, k]
        A[k, 2, 2] = 1.0
    return e, A


def stiffness(batch, y2, Y2):
    """Segment stiffness [KL] (K, 6, 6) and load vector {C} (K, 6) at a converged shot (thesis 3.11-3.19).

    Rows/columns: (rho1, eps1, phi1, rho2, eps2, phi2); nodal forces P1 = -r1, P2 = r2 (per radian, thesis 2.88-2.89).
    For a pole piece the end-1 rows/columns are zero and the eps2 column is zero (free vertical translation)."""
    Yk = np.moveaxis(Y2, -1, 0)  # (K, 6, 7)
    U11, U12, U13 = Yk[:, 0:3, 0:3], Yk[:, 0:3, 3:6], Yk[:, 0:3, 6]
    U21, U22, U23 = Yk[:, 3:6, 0:3], Yk[:, 3:6, 3:6], Yk[:, 3:6, 6]
    pole = batch["pole"]
    Kn = y2.shape[1]
    KL = np.zeros((Kn, 6, 6))
    C = np.zeros((Kn, 6))
    ordk = np.flatnonzero(~pole)
    if ordk.size:
        W = np.linalg.inv(U12[ordk])
        WU11 = W @ U11[ordk]
        WU13 = np.einsum("kij,kj->ki", W, U13[ordk])
        KL[ordk, 0:3, 0:3] = WU11
        KL[ordk, 0:3, 3:6] = -W
        KL[ordk, 3:6, 0:3] = U21[ordk] - U22[ordk] @ WU11
        KL[ordk, 3:6, 3:6] = U22[ordk] @ W
        C[ordk, 0:3] = WU13
        C[ordk, 3:6] = U23[ordk] - np.einsum("kij,kj->ki", U22[ordk], WU13)
    pk = np.flatnonzero(pole)
    if pk.size:
        A2 = Yk[pk][:, [0, 2]][:, :, 3:5]
        B = Yk[pk, 3:6, 3:5]
        Ai = np.linalg.inv(A2)
        BA = B @ Ai
        KL[pk, 3, 3] = BA[:, 0, 0]
        KL[pk, 4, 3] = BA[:, 1, 0]
        KL[pk, 5, 3] = BA[:, 2, 0]
        KL[pk, 3, 5] = BA[:, 0, 1]
        KL[pk, 4, 5] = BA[:, 1, 1]
        KL[pk, 5, 5] = BA[:, 2, 1]
        C[pk, 3:6] = Yk[pk, 3:6, 6] - np.einsum("kij,kj->ki", BA, Yk[pk][:, [0, 2], 6])
    return KL, C


def end_forces(batch, u, y2):
    """Nodal forces (K, 6): P1 = -r1 (zero for pole pieces), P2 = r2."""
    P = np.zeros((y2.shape[1], 6))
    P[:, 0:3] = -u.T
    P[batch["pole"], 0:3] = 0.0
    P[:, 3:6] = y2[3:6].T
    return P


def solve_bvp1(material, batch, X1, X2, u, lam, nsteps, store, tol=1e-10, maxit=25, trajectory=False,
               raise_unconverged=True):
    """BVP.1: Newton on the unknown end-1 quantities u until the integrated end-2 position matches X2.

    Returns dict(u, y2, Y2, traj, iterations, converged); with raise_unconverged=False the last shot is returned
    after maxit shots (used inside the nodal Newton iteration, which carries the remaining correction).  Raises ShootingError naming the worst segment on failure."""
    u = np.array(u, float)
    scale = 1.0 + np.max(np.abs(X2))
    u_prev, du = None, None
    for it in range(maxit):
        for cut in range(8):  # backtrack the Newton step if the shot cannot be integrated
            try:
                y1, Y1 = start_states(material, batch, X1, u, lam)
                y2, Y2, traj = integrate(material, batch, y1, Y1, lam, nsteps, store, trajectory)
                break
            except ShootingError:
                if u_prev is None or cut == 7:
                    raise
                du = 0.5 * du
                u = u_prev + du
        e, A = mismatch(batch, y2, Y2, X2)
        err = np.max(np.abs(e), axis=0)
        if np.all(err < tol * scale) or (it == maxit - 1 and not raise_unconverged):
            return dict(u=u, y2=y2, Y2=Y2, traj=traj, iterations=it + 1, converged=bool(np.all(err < tol * scale)))
        try:
            du = np.linalg.solve(A, -e.T[:, :, None])[:, :, 0].T
        except np.linalg.LinAlgError:
            raise ShootingError("singular shooting matrix dX2/du", int(np.argmax(err))) from None
        pole = batch["pole"]
        if np.any(pole):  # keep the pole stretch positive
            lp = u[0, pole]
            f = np.minimum(1.0, 0.5 * lp / np.maximum(np.abs(du[0, pole]), 1e-300))
            du[:, pole] *= f
        u_prev = u
        u = u + du
    raise ShootingError(f"shooting (BVP.1) did not converge in {maxit} Newton iterations "
                        f"(end mismatch {np.max(err):.3g})", int(np.argmax(err)))
