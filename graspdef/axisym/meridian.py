"""Reference (undeformed) meridian geometry: pieces of constant meridional curvature (arcs and straight lines).

Nondimensional (lengths / t0).  A piece starts at (rho0, eps0) with tangent angle phi0 (thesis Fig. 1:
e_xi = cos(phi) e_r + sin(phi) k, e_n = -sin(phi) e_r + cos(phi) k) and has curvature kappa = dphi0/dsigma
(0 for a line).  At local arc length s:

    phi0(s) = phi0 + kappa s,   rho0(s) = rho0 + s cos(phi0 + kappa s/2) sinc(kappa s/2),
    eps0(s) = eps0 + s sin(phi0 + kappa s/2) sinc(kappa s/2),
    kappa_xi0 = kappa,          kappa_theta0 = sin(phi0(s)) / rho0(s)   (-> kappa at a pole).

Spheres, cylinders, plates, cones and toroidal pieces are all of this form.
"""
import numpy as np


def _sinc(x):
    return np.sinc(x / np.pi)


def evaluate(rho_a, eps_a, phi_a, kappa, s):
    """rho0, eps0, phi0, k1, k2 at local arc length s (all broadcast)."""
    half = 0.5 * kappa * s
    sc = s * _sinc(half)
    mid = phi_a + half
    rho0 = rho_a + sc * np.cos(mid)
    eps0 = eps_a + sc * np.sin(mid)
    phi0 = phi_a + kappa * s
    k1 = kappa + 0.0 * s
    with np.errstate(divide="ignore", invalid="ignore"):
        k2 = np.where(np.abs(rho0) > 1e-300, np.sin(phi0) / rho0, kappa)
    return rho0, eps0, phi0, k1, k2


def arc_through(start, end, kappa):
    """Length of the constant-curvature piece from start=(rho, eps, phi) to end=(rho, eps, phi), or None.

    The end angle fixes the length (phi_end - phi_start)/kappa for an arc; a line needs phi_end == phi_start and
    the length is the distance.  Returns (length, position mismatch)."""
    r1, z1, p1 = start
    r2, z2, p2 = end
    if abs(kappa) < 1e-14:
        L = (r2 - r1) * np.cos(p1) + (z2 - z1) * np.sin(p1)
    else:
        L = (p2 - p1) / kappa
    rr, zz, pp, _, _ = evaluate(r1, z1, p1, kappa, L)
    mismatch = float(np.hypot(rr - r2, zz - z2) + abs(np.angle(np.exp(1j * (pp - p2)))))
    return float(L), mismatch
