"""3-D incompressible strain energies and the shell energy phi of the thesis (2.73), (2.77), (2.78).

Nondimensional: energies are divided by C1 (3-D) or by t0*C1 (shell, per unit undeformed area); lengths by t0.

* Mooney-Rivlin  W = C1 (I1 - 3) + C2 (I2 - 3),           w = W/C1 = (I1 - 3) + gamma (I2 - 3),  gamma = C2/C1
* exponential    W = (C1/gamma) (exp(gamma (I1 - 3)) - 1), w = (exp(gamma (I1 - 3)) - 1)/gamma  (thesis A.46: dw/dI1 = exp(..))

The shell energy per unit undeformed reference area is phi = w(0) + (1/24) d^2 w/d tau0^2 (0) (thesis 2.73, tau0 =
zeta0/t0), a function of the reference-surface strains (l1, l2, c1, c2) = (lambda_xi, lambda_theta, c_xi, c_theta)
with c_xi = dphi/dsigma and c_theta = sin(phi)/rho0, and of the undeformed curvatures (k1, k2).  The closed forms
of phi, its gradient (the constitutive relations 2.76: n_xi0, n_theta0, m_xi0, m_theta0) and its Hessian are
generated symbolically by scripts/axisym_codegen.py into _energy_generated.py.

Small-strain check (asserted in the tests): at l = 1, c = k the Hessian is the linear, incompressible (nu = 1/2)
shell's: membrane 4 mu [[1, 1/2], [1/2, 1]], bending (mu/3) [[1, 1/2], [1/2, 1]], mu = 2 (C1 + C2) / C1.
"""
from dataclasses import dataclass

import numpy as np

from graspdef.errors import ProblemError, SolverError

from . import _energy_generated as _gen

KINDS = ("mooney_rivlin", "exponential")


@dataclass(frozen=True)
class AxisymMaterial:
    """Incompressible hyperelastic material.

    kind: "mooney_rivlin" or "exponential"; C1 in Pa (the stress unit of the nondimensionalisation);
    gamma: C2/C1 for Mooney-Rivlin, the exponent coefficient for the exponential law (dimensionless);
    volume_factor: keep the undeformed volume element (1 - zeta0 k1)(1 - zeta0 k2) in the thickness integral
    (False = the thesis's 2.73).
    """

    kind: str = "mooney_rivlin"
    C1: float = 1.0
    gamma: float = 0.1
    volume_factor: bool = False

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ProblemError(f"material kind {self.kind!r} is not one of {KINDS}")
        if not (np.isfinite(self.C1) and self.C1 > 0):
            raise ProblemError(f"material C1 must be positive, got {self.C1}")
        if not np.isfinite(self.gamma) or (self.kind == "exponential" and self.gamma <= 0):
            raise ProblemError(f"material gamma {self.gamma} is invalid for {self.kind}")
        if self.kind == "mooney_rivlin" and self.gamma < 0:
            raise ProblemError(f"Mooney-Rivlin gamma = C2/C1 must be >= 0, got {self.gamma}")

    @property
    def mu(self) -> float:
        """Small-strain shear modulus in Pa."""
        return 2.0 * self.C1 * (1.0 + self.gamma) if self.kind == "mooney_rivlin" else 2.0 * self.C1

    def shell_energy(self, l1, l2, c1, c2, k1, k2):
        """phi, grad (4, ...), hess (4, 4, ...) of the nondimensional shell energy (see module docstring)."""
        name = self.kind + ("_volume" if self.volume_factor else "")
        return getattr(_gen, name)(l1, l2, c1, c2, k1, k2, self.gamma)

    def w3d(self, I1, I2):
        """Nondimensional 3-D strain energy w = W/C1 of the invariants."""
        if self.kind == "mooney_rivlin":
            return (I1 - 3.0) + self.gamma * (I2 - 3.0)
        return np.expm1(self.gamma * (I1 - 3.0)) / self.gamma

    def invert(self, n1, m1, l2, c2, k1, k2, guess):
        """Solve the constitutive relations d phi/d l1 = n1, d phi/d c1 = m1 for (l1, c1) by Newton.

        guess: array (2, K) of starting values; returns (l1, c1, phi, grad, hess) at the solution.
        Raises SolverError (with the indices of the failing points in the message) if Newton does not converge.
        """
        l1, c1 = np.array(guess[0], float), np.array(guess[1], float)
        newton = getattr(_gen, self.kind + ("_volume" if self.volume_factor else "") + "_newton")
        for it in range(40):
            r0, r1, a, b, d = newton(l1, l2, c1, c2, k1, k2, self.gamma)
            r0, r1 = r0 - n1, r1 - m1
            det = a * d - b * b
            with np.errstate(divide="ignore", invalid="ignore"):
                dl = (d * r0 - b * r1) / det
                dc = (a * r1 - b * r0) / det
            if not (np.all(np.isfinite(dl)) and np.all(np.isfinite(dc))):
                break
            # keep the stretch positive: never step more than 50 % of l1
            s = np.minimum(1.0, 0.5 * l1 / np.maximum(np.abs(dl), 1e-300))
            l1 = l1 - s * dl
            c1 = c1 - s * dc
            err = np.max(np.abs(dl) + np.abs(dc)) if np.size(dl) else 0.0
            if err < 1e-9 and np.all(s == 1.0):  # quadratic convergence: the residual is now ~err^2
                phi, g, H = self.shell_energy(l1, l2, c1, c2, k1, k2)
                return l1, c1, phi, g, H
        bad = ~np.isfinite(dl) | ~np.isfinite(dc) | (np.abs(dl) + np.abs(dc) > 1e-9)
        idx = np.flatnonzero(np.atleast_1d(bad))
        err = SolverError(f"constitutive relations could not be inverted (Newton for stretch and curvature "
                          f"did not converge; the shell energy loses convexity in (stretch, curvature) under very "
                          f"large bending, thesis Ch. 5)")
        err.points = idx
        raise err
