"""Hyperelastic Kirchhoff-Love shell materials with numerical integration through the thickness.

Follows Kiendl, Hsu, Wu & Reali (2015), "Isogeometric Kirchhoff-Love shell formulations for
general hyperelastic materials", Comput. Methods Appl. Mech. Engrg. 291:280, as specified for graspdef:

* Through the rest thickness ``t0`` the coordinate is ``zeta in [-t0/2, t0/2]``.  The in-plane
  Green-Lagrange strain at ``zeta`` is ``E_ab(zeta) = e_ab - zeta k_ab`` (from
  ``g_ab ~ a_ab - 2 zeta b_ab``), with the membrane strain ``e`` and curvature change ``k`` of
  :mod:`graspdef.shell.kinematics`.  The reference metric of every layer is approximated by the
  mid-surface metric ``A_ab`` (thin shell), so ``C_ab = A_ab + 2 E_ab``.
* Isotropy reduces the in-plane state to two scalars, ``c = A^ab C_ab`` (trace) and
  ``d = det(C_ab) / det(A_ab)`` (squared in-plane area stretch).  The through-thickness stretch
  ``C33 = lambda3^2`` follows from plane stress: ``C33 = 1/d`` for incompressible materials, and
  ``dpsi/dC33 = 0`` solved by Newton for compressible ones (static condensation; the reduced
  energy's Hessian is ``psi_ij - psi_i3 psi_j3 / psi_33``).
* The energy per unit rest mid-surface area is ``W = sum_g w_g t0/2 psi(E(zeta_g))`` with
  Gauss-Legendre points ``zeta_g``; with ``E(zeta) = [I, -zeta I] s`` its first and second
  derivatives with respect to the strain vector ``s`` follow by the chain rule.

At zero strain every material's Hessian equals :class:`~graspdef.shell.materials.LinearElastic`'s
tangent with the small-strain moduli (``E = 3 mu, nu = 1/2`` for the incompressible laws): the
Gauss rule integrates ``zeta^0`` and ``zeta^2`` exactly for ``n_thickness >= 2``.

A strain state that inverts the material somewhere in the thickness (``d <= 0`` at a Gauss
point) has energy ``+inf`` and NaN derivatives, so that a line search backtracks from it.

The module ends with a small registry (:data:`MATERIALS`, :func:`make_material`) that builds a
material from a name and a parameter table, for problem files.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import MISSING, dataclass, fields

import numpy as np

from ..config import check_names, unknown_name
from ..errors import ConfigError, ProblemError, SolverError
from ._kernels import (
    COMPRESSIBLE_NEO_HOOKEAN,
    EXPONENTIAL,
    MOONEY_RIVLIN,
    NEO_HOOKEAN,
    density_points,
)
from .materials import LinearElastic

__all__ = ["NeoHookean", "MooneyRivlin", "Exponential", "CompressibleNeoHookean", "CompressibleMooneyRivlin",
           "in_plane_invariants", "MATERIALS", "PARAMETERS", "make_material"]

#: d^2 d / dv^2 for v = (E11, E22, 2 E12), divided by det(A^ab): d = c - 1 + det(A^-1)(4 v1 v2 - v3^2)
_D2D = np.array([[0.0, 4.0, 0.0], [4.0, 0.0, 0.0], [0.0, 0.0, -2.0]])

#: the 6 entries (upper triangle) of a symmetric 3 x 3 matrix
_I = np.array([0, 1, 2, 0, 0, 1])
_J = np.array([0, 1, 2, 1, 2, 2])

#: entry of [M0 | M1 | M2] (each as its 6 entries) for every entry of the 6 x 6 matrix [[M0, M1], [M1, M2]]
_SYM = np.array([[0, 3, 4], [3, 1, 5], [4, 5, 2]])
_BLOCKS = np.block([[_SYM, _SYM + 6], [_SYM + 6, _SYM + 12]]).ravel()

_EPS = np.finfo(float).eps
_NEWTON_MAX = 60


@functools.lru_cache(maxsize=None)
def _gauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre points and weights on [-1, 1] (read-only)."""
    xg, wg = np.polynomial.legendre.leggauss(n)
    xg.flags.writeable = False
    wg.flags.writeable = False
    return xg, wg


# ------------------------------------------------------------------------------------------------
# parameter checks
# ------------------------------------------------------------------------------------------------
def _number(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ProblemError(f"{name} must be a number, got {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise ProblemError(f"{name} must be finite, got {value!r}")
    return v


def _positive(name: str, value) -> float:
    v = _number(name, value)
    if v <= 0.0:
        raise ProblemError(f"{name} must be positive, got {value!r}")
    return v


def _non_negative(name: str, value) -> float:
    v = _number(name, value)
    if v < 0.0:
        raise ProblemError(f"{name} must be >= 0, got {value!r}")
    return v


def _set_mooney_rivlin_constants(mat, name: str) -> None:
    """Check and set ``mat.C1``, ``mat.C2`` (frozen dataclass): both >= 0, C1 + C2 > 0."""
    c1 = _non_negative(f"{name} C1", mat.C1)
    c2 = _non_negative(f"{name} C2", mat.C2)
    if c1 + c2 <= 0.0:
        raise ProblemError(
            f"{name} needs C1 + C2 > 0 (shear modulus mu = 2 (C1 + C2)) with C1, C2 >= 0 "
            f"for stability, got C1={mat.C1!r}, C2={mat.C2!r}")
    object.__setattr__(mat, "C1", c1)
    object.__setattr__(mat, "C2", c2)


def _n_thickness(value) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 2:
        raise ProblemError(
            f"n_thickness (Gauss points through the thickness) must be an integer >= 2, got "
            f"{value!r}: one point has no bending stiffness")
    return int(value)


# ------------------------------------------------------------------------------------------------
# in-plane kinematics
# ------------------------------------------------------------------------------------------------
def in_plane_invariants(v: np.ndarray, rest_inv: np.ndarray):
    """Invariants of the in-plane right Cauchy-Green tensor ``C_ab = A_ab + 2 E_ab``.

    Parameters
    ----------
    v : (..., 3) array
        In-plane Green-Lagrange strain in Voigt form ``(E11, E22, 2 E12)`` (covariant, [-]).
    rest_inv : (..., 3) array
        Contravariant rest metric ``(A^11, A^22, A^12)`` [-].

    Returns
    -------
    p : (...) array
        ``c - 2`` where ``c = A^ab C_ab`` (``= 2 A^ab E_ab``, exactly linear in v).
    q : (...) array
        ``d - 1 - p = det(A^ab) (4 E11 E22 - 4 E12^2)`` (exactly quadratic in v); with ``p`` it
        gives ``d = det(C_ab)/det(A_ab) = 1 + p + q`` without cancellation at small strain.
    grad_c : (..., 3) array
        ``dc/dv = 2 (A^11, A^22, A^12)``.
    grad_d : (..., 3) array
        ``dd/dv = grad_c + det(A^ab) (4 v2, 4 v1, -2 v3)``.
    hess_d : (..., 3, 3) array
        ``d^2 d/dv^2 = det(A^ab) [[0, 4, 0], [4, 0, 0], [0, 0, -2]]`` (constant in v; the -2
        rather than -1/2 on the shear entry is because v3 = 2 E12; ``d^2 c/dv^2 = 0``).
    """
    v = np.asarray(v, dtype=float)
    rest_inv = np.asarray(rest_inv, dtype=float)
    A11, A22, A12 = rest_inv[..., 0], rest_inv[..., 1], rest_inv[..., 2]
    det_inv = A11 * A22 - A12 * A12
    grad_c = 2.0 * rest_inv
    p, q, grad_d = _pq_grad_d(v, A11, A22, A12, det_inv, grad_c)
    hess_d = det_inv[..., None, None] * _D2D
    return p, q, grad_c, grad_d, hess_d


def _pq_grad_d(v, A11, A22, A12, det_inv, grad_c):
    """p, q and grad d of :func:`in_plane_invariants` (rest quantities precomputed)."""
    v1, v2, v3 = v[..., 0], v[..., 1], v[..., 2]
    p = 2.0 * (A11 * v1 + A22 * v2 + A12 * v3)
    q = det_inv * (4.0 * v1 * v2 - v3 * v3)
    r = np.empty(np.broadcast_shapes(v.shape, det_inv.shape + (3,)))
    r[..., 0] = 4.0 * v2
    r[..., 1] = 4.0 * v1
    r[..., 2] = -2.0 * v3
    r *= det_inv[..., None]
    r += grad_c
    return p, q, r


def _rows(a: np.ndarray, shape: tuple, n: int) -> np.ndarray:
    """(..., k) broadcast to shape + (k,), as a contiguous (k, n) array of component rows."""
    k = a.shape[-1]
    return np.ascontiguousarray(np.broadcast_to(a, shape + (k,)).reshape(n, k).T)


# ------------------------------------------------------------------------------------------------
# common thickness integration
# ------------------------------------------------------------------------------------------------
class _ThicknessIntegrated:
    """Shared code: Gauss-Legendre integration of psi(c, d) over the thickness and the chain rule
    to the strain vector.  Subclasses implement ``_psi(p, q, aux)`` returning psi per unit rest
    volume [Pa] and its derivatives psi_c, psi_d, psi_cc, psi_cd, psi_dd, and ``_c33(p, q)``."""

    n_thickness: int

    def _prepare(self, p: np.ndarray, q: np.ndarray):
        """Per-point data needed by _psi (the solved C33 for compressible laws)."""
        return None

    def _kind(self):
        """(kind, parameters) of the compiled density kernel, or None (a subclass not known to
        ``_kernels.density_points``: the numpy path is used)."""
        return None

    def serial_at(self, n_points: int) -> bool:
        """Whether :meth:`density` at ``n_points`` points runs serially -- numpy, or the compiled
        kernel's ahead-of-time build, which releases the GIL -- and never numba's parallel build
        (graspdef.shell.energy.ShellEnergy.concurrent)."""
        return self._kind() is None or density_points.ahead_of_time(n_points)

    def density(self, s: np.ndarray, rest_inv: np.ndarray, thickness: np.ndarray):
        """Energy per unit rest mid-surface area and its derivatives with respect to ``s``.

        Parameters
        ----------
        s : (..., 6) array
            Strain vector ``(e11, e22, 2 e12, k11, k22, 2 k12)``: membrane Green-Lagrange strain
            [-] and curvature change [1/m], covariant components.
        rest_inv : (..., 3) array
            Contravariant rest metric ``(A^11, A^22, A^12)`` [-].
        thickness : array broadcastable against ``s[..., 0]``
            Rest thickness t0 [m], e.g. (n_faces, 1) against s of shape (n_faces, n_quad, 6).

        Returns
        -------
        W : (...) array
            Energy per unit rest area [J/m^2]; ``+inf`` where the material is inverted.
        dW : (..., 6) array
            dW/ds: membrane forces and bending moments (2nd Piola-Kirchhoff resultants) [N/m, N].
        ddW : (..., 6, 6) array
            d^2W/ds^2, symmetric.
        """
        return self._evaluate(s, rest_inv, thickness, 2)

    def _evaluate(self, s: np.ndarray, rest_inv: np.ndarray, thickness: np.ndarray, order: int):
        """(W, dW, ddW) of :meth:`density`; dW (order < 1) and ddW (order < 2) may be None.
        Compiled per point (``_kernels.density_points``) for the materials of this module,
        otherwise (subclasses) :meth:`_density_numpy`."""
        kind = self._kind()
        if kind is None:
            W, dW, ddW = self._density_numpy(s, rest_inv, thickness)
            return W, (dW if order >= 1 else None), (ddW if order >= 2 else None)
        s = np.asarray(s, dtype=float)
        rest_inv = np.asarray(rest_inv, dtype=float)
        t = np.asarray(thickness, dtype=float)
        shape = np.broadcast_shapes(s.shape[:-1], rest_inv.shape[:-1], t.shape)
        n = math.prod(shape)
        # (an array already of the points' shape is reshaped, not broadcast: numba types a
        # broadcast's read-only view apart, graspdef.compiled._Loader)
        sf = np.ascontiguousarray(s.reshape(n, 6) if s.shape[:-1] == shape else np.broadcast_to(s, shape + (6,)).reshape(n, 6))
        rf = np.ascontiguousarray(rest_inv.reshape(n, 3) if rest_inv.shape[:-1] == shape
                                  else np.broadcast_to(rest_inv, shape + (3,)).reshape(n, 3))
        half = 0.5 * np.broadcast_to(t, shape).reshape(n)
        xg, wg = (a.copy() for a in _gauss(self.n_thickness))       # writable, as reshaped above
        W, dW, ddW, conv = density_points(kind[0], np.asarray(kind[1], dtype=float), sf, rf, half,
                                          xg, wg, order, 8.0 * _EPS, _NEWTON_MAX)
        if not conv.all():
            raise SolverError(
                f"compressible neo-Hookean: plane-stress condition dpsi/dC33 = 0 not converged in "
                f"{_NEWTON_MAX} Newton steps at {int((~conv).sum())} point(s)")
        return (W.reshape(shape), dW.reshape(shape + (6,)) if order >= 1 else None,
                ddW.reshape(shape + (6, 6)) if order >= 2 else None)

    def _density_numpy(self, s: np.ndarray, rest_inv: np.ndarray, thickness: np.ndarray):
        """:meth:`density` in numpy, for any subclass implementing ``_psi`` (the reference of the
        compiled path; the tests compare the two)."""
        s = np.asarray(s, dtype=float)
        rest_inv = np.asarray(rest_inv, dtype=float)
        t = np.asarray(thickness, dtype=float)
        shape = np.broadcast_shapes(s.shape[:-1], rest_inv.shape[:-1], t.shape)
        n = math.prod(shape)
        # component-major layout: every per-point quantity is a contiguous (n,) row, so that the
        # arithmetic below runs on whole rows (no fancy indexing along a short last axis)
        sc = _rows(s, shape, n)                                   # (6, n)
        ri = _rows(rest_inv, shape, n)                            # (3, n)
        half = 0.5 * np.broadcast_to(t, shape).reshape(n)
        xg, wg = np.polynomial.legendre.leggauss(self.n_thickness)
        A11, A22, A12 = ri[0], ri[1], ri[2]
        det_inv = A11 * A22 - A12 * A12
        # symmetric 3 x 3 matrices are handled as their 6 entries (_I[j], _J[j])
        gc = 2.0 * ri                                             # (3, n)
        gcc = [gc[i] * gc[j] for i, j in zip(_I, _J)]
        Hd = [det_inv * _D2D[i, j] for i, j in zip(_I, _J)]
        ng = len(xg)
        psi_g = np.empty((ng, n))
        grad_g = np.empty((ng, 3, n))
        hess_g = np.empty((ng, 6, n))
        bad = np.zeros(n, dtype=bool)
        gd = np.empty((3, n))
        for ig, x in enumerate(xg):
            hx = half * x
            v1, v2, v3 = sc[0] - hx * sc[3], sc[1] - hx * sc[4], sc[2] - hx * sc[5]
            p = 2.0 * (A11 * v1 + A22 * v2 + A12 * v3)
            q = det_inv * (4.0 * v1 * v2 - v3 * v3)
            np.multiply(4.0 * v2, det_inv, out=gd[0])
            np.multiply(4.0 * v1, det_inv, out=gd[1])
            np.multiply(-2.0 * v3, det_inv, out=gd[2])
            gd += gc
            inverted = 1.0 + p + q <= 0.0
            if inverted.any():
                bad |= inverted
                p, q = np.where(inverted, 0.0, p), np.where(inverted, 0.0, q)
            psi, pc, pd, pcc, pcd, pdd = self._psi(p, q, self._prepare(p, q))
            psi_g[ig] = psi
            np.multiply(pc, gc, out=grad_g[ig])
            grad_g[ig] += pd * gd
            for jj, (i, j) in enumerate(zip(_I, _J)):
                gci, gcj, gdi, gdj = gc[i], gc[j], gd[i], gd[j]
                hess_g[ig, jj] = (pcc * gcc[jj] + pcd * (gci * gdj + gdi * gcj)
                                  + pdd * (gdi * gdj) + pd * Hd[jj])
        # moments sum_g w_g x_g^m (.)_g, m = 0, 1, 2 (one small matrix product each), then the
        # powers of t0/2 from zeta_g = x_g t0/2 and the weight t0/2 of the rule on [-t0/2, t0/2]
        mom = np.stack([wg, wg * xg, wg * xg * xg])
        W = half * np.tensordot(wg, psi_g, axes=(0, 0))
        G = np.tensordot(mom[:2], grad_g, axes=(1, 0))           # (2, 3, n)
        Hm = np.tensordot(mom, hess_g, axes=(1, 0))              # (3, 6, n)
        h2 = half * half
        dW = np.empty((n, 6))
        dW[:, :3] = (half * G[0]).T
        dW[:, 3:] = (-(h2 * G[1])).T
        K = np.concatenate([half * Hm[0], -(h2 * Hm[1]), (h2 * half) * Hm[2]])   # (18, n): M0, M1, M2
        ddW = np.ascontiguousarray(np.take(K, _BLOCKS, axis=0).T)     # [[M0, M1], [M1, M2]]
        if bad.any():
            W = np.where(bad, np.inf, W)
            dW[bad] = np.nan
            ddW[bad] = np.nan
        return W.reshape(shape), dW.reshape(shape + (6,)), ddW.reshape(shape + (6, 6))

    def tangent(self, rest_inv: np.ndarray, thickness: np.ndarray) -> np.ndarray:
        """Hessian at zero strain, (..., 6, 6): ``blockdiag(t0 H, t0^3/12 H)`` with the plane-stress
        matrix H of the small-strain moduli ``E``, ``nu`` (same as LinearElastic.tangent)."""
        rest_inv = np.asarray(rest_inv, dtype=float)
        s = np.zeros(rest_inv.shape[:-1] + (6,))
        return self.density(s, rest_inv, thickness)[2]

    def thickness_stretch(self, s: np.ndarray, rest_inv: np.ndarray) -> np.ndarray:
        """Through-thickness stretch lambda3 = sqrt(C33) at the mid-surface [-], (...).

        The deformed thickness is ``lambda3 * t0`` (to the thin-shell accuracy of the model).
        """
        s = np.asarray(s, dtype=float)
        p, q, *_ = in_plane_invariants(s[..., :3], np.asarray(rest_inv, dtype=float))
        out = np.full(np.broadcast_shapes(p.shape, q.shape), np.nan)
        ok = 1.0 + p + q > 0.0
        p, q = np.where(ok, p, 0.0), np.where(ok, q, 0.0)
        lam3 = np.sqrt(self._c33(p, q))
        out[ok] = np.broadcast_to(lam3, out.shape)[ok]
        return out if out.ndim else out[()]


# ------------------------------------------------------------------------------------------------
# incompressible materials: C33 = 1/d, W3D(I1, I2)
# ------------------------------------------------------------------------------------------------
class _Incompressible(_ThicknessIntegrated):
    """psi(c, d) = W3D(I1, I2) with I1 = c + 1/d, I2 = d + c/d (lambda3^2 = C33 = 1/d).

    Subclasses implement ``_w(i1, i2)`` of ``i1 = I1 - 3``, ``i2 = I2 - 3`` returning
    W, W_1, W_2, W_11, W_12, W_22 (derivatives with respect to I1, I2)."""

    @property
    def E(self) -> float:
        """Small-strain Young's modulus 3 mu [Pa] (incompressible; subclasses define mu)."""
        return 3.0 * self.mu

    @property
    def nu(self) -> float:
        """Small-strain Poisson's ratio, 1/2 (incompressible)."""
        return 0.5

    def _c33(self, p, q):
        return 1.0 / (1.0 + p + q)

    def _psi(self, p, q, aux):
        d = 1.0 + p + q
        c = 2.0 + p
        inv_d = 1.0 / d
        # I1 - 3 and I2 - 3 free of cancellation at small strain (both are O(|E|^2)):
        i1 = (p * p + p * q - q) * inv_d
        i2 = ((p + q) ** 2 - q) * inv_d
        W, W1, W2, W11, W12, W22 = self._w(i1, i2)
        inv_d2 = inv_d * inv_d
        I2d = 1.0 - c * inv_d2                       # dI2/dd; dI1/dc = 1, dI1/dd = -1/d^2, dI2/dc = 1/d
        pc = W1 + W2 * inv_d
        pd = -W1 * inv_d2 + W2 * I2d
        pcc = W11 + 2.0 * W12 * inv_d + W22 * inv_d2
        pcd = -W11 * inv_d2 + W12 * (I2d - inv_d2 * inv_d) + W22 * inv_d * I2d - W2 * inv_d2
        pdd = (W11 * inv_d2 * inv_d2 - 2.0 * W12 * inv_d2 * I2d + W22 * I2d * I2d
               + 2.0 * inv_d2 * inv_d * (W1 + W2 * c))
        return W, pc, pd, pcc, pcd, pdd


def _const(x, like):
    return np.broadcast_to(np.asarray(x, dtype=float), np.shape(like))


@dataclass(frozen=True)
class NeoHookean(_Incompressible):
    """Incompressible neo-Hookean shell material, ``W = mu/2 (I1 - 3)`` per unit volume.

    Parameters
    ----------
    mu : float
        Shear modulus [Pa] (small-strain Young's modulus ``E = 3 mu``).
    n_thickness : int, optional
        Gauss-Legendre points through the thickness (default 3, at least 2).
    """

    mu: float
    n_thickness: int = 3

    def __post_init__(self) -> None:
        object.__setattr__(self, "mu", _positive("neo-Hookean shear modulus mu", self.mu))
        object.__setattr__(self, "n_thickness", _n_thickness(self.n_thickness))

    def _w(self, i1, i2):
        z = _const(0.0, i1)
        return 0.5 * self.mu * i1, _const(0.5 * self.mu, i1), z, z, z, z

    def _kind(self):
        return (NEO_HOOKEAN, (self.mu,)) if type(self) is NeoHookean else None


@dataclass(frozen=True)
class MooneyRivlin(_Incompressible):
    """Incompressible Mooney-Rivlin shell material, ``W = C1 (I1 - 3) + C2 (I2 - 3)``.

    Parameters
    ----------
    C1, C2 : float
        Material constants [Pa]; both >= 0 with ``C1 + C2 > 0`` (stability).  The small-strain
        shear modulus is ``mu = 2 (C1 + C2)``.
    n_thickness : int, optional
        Gauss-Legendre points through the thickness (default 3, at least 2).
    """

    C1: float
    C2: float
    n_thickness: int = 3

    def __post_init__(self) -> None:
        _set_mooney_rivlin_constants(self, "Mooney-Rivlin")
        object.__setattr__(self, "n_thickness", _n_thickness(self.n_thickness))

    @property
    def mu(self) -> float:
        """Small-strain shear modulus 2 (C1 + C2) [Pa]."""
        return 2.0 * (self.C1 + self.C2)

    def _w(self, i1, i2):
        z = _const(0.0, i1)
        return (self.C1 * i1 + self.C2 * i2, _const(self.C1, i1), _const(self.C2, i1), z, z, z)

    def _kind(self):
        return (MOONEY_RIVLIN, (self.C1, self.C2)) if type(self) is MooneyRivlin else None


@dataclass(frozen=True)
class Exponential(_Incompressible):
    """Incompressible exponential law ``W = C0 (exp[C1 (I1 - 3)] - 1)``.

    The law ``exp[C1 (I1 - 3)] - 1`` used by Kiendl et al. (2015) made dimensional by the stress
    scale C0.  Small-strain shear modulus ``mu = 2 C0 C1``.

    Parameters
    ----------
    C0 : float
        Stress scale [Pa], > 0.
    C1 : float
        Stiffening exponent [-], > 0.
    n_thickness : int, optional
        Gauss-Legendre points through the thickness (default 3, at least 2).
    """

    C0: float
    C1: float
    n_thickness: int = 3

    def __post_init__(self) -> None:
        object.__setattr__(self, "C0", _positive("exponential stress scale C0", self.C0))
        object.__setattr__(self, "C1", _positive("exponential exponent C1", self.C1))
        object.__setattr__(self, "n_thickness", _n_thickness(self.n_thickness))

    @property
    def mu(self) -> float:
        """Small-strain shear modulus 2 C0 C1 [Pa]."""
        return 2.0 * self.C0 * self.C1

    def _w(self, i1, i2):
        a = self.C1 * i1
        ex = np.exp(a)
        z = _const(0.0, i1)
        W1 = self.C0 * self.C1 * ex
        return self.C0 * np.expm1(a), W1, z, self.C1 * W1, z, z

    def _kind(self):
        return (EXPONENTIAL, (self.C0, self.C1)) if type(self) is Exponential else None


# ------------------------------------------------------------------------------------------------
# compressible neo-Hookean: C33 from plane stress
# ------------------------------------------------------------------------------------------------
def _lame(E: float, nu: float, law: str, incompressible: str) -> tuple[float, float]:
    """Lame parameters (mu, lam) [Pa] of a compressible law from E [Pa] > 0 and 0 <= nu < 1/2."""
    E = _positive(f"{law} Young's modulus E", E)
    nu = _number(f"{law} Poisson's ratio nu", nu)
    if not 0.0 <= nu < 0.5:
        raise ProblemError(f"{law} Poisson's ratio nu must lie in [0, 0.5), got {nu!r} "
                           f"(nu = 0.5 is incompressible: use {incompressible})")
    return E / (2.0 * (1.0 + nu)), E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))


@dataclass(frozen=True)
class CompressibleNeoHookean(_ThicknessIntegrated):
    """Compressible neo-Hookean shell material with a plane-stress through-thickness stretch.

    ``psi = mu/2 (I1 - 3) - mu ln J + lam/2 (ln J)^2`` per unit rest volume, with
    ``I1 = c + C33`` and ``J^2 = d C33``.  ``C33`` solves ``dpsi/dC33 = 0`` at every point
    (Newton in ``u = ln C33``, converged to round-off); the reduced energy's derivatives follow
    from the envelope theorem (first) and static condensation (second).  At small strain it is
    LinearElastic(E, nu) with ``E = mu (3 lam + 2 mu)/(lam + mu)``, ``nu = lam / (2 (lam + mu))``.

    Parameters
    ----------
    mu : float
        Shear modulus [Pa], > 0.
    lam : float
        First Lame parameter [Pa], >= 0 (i.e. 0 <= nu < 1/2, the range LinearElastic accepts
        short of incompressibility; use NeoHookean for nu = 1/2).
    n_thickness : int, optional
        Gauss-Legendre points through the thickness (default 3, at least 2).
    """

    mu: float
    lam: float
    n_thickness: int = 3

    def __post_init__(self) -> None:
        object.__setattr__(self, "mu", _positive("compressible neo-Hookean shear modulus mu", self.mu))
        object.__setattr__(self, "lam", _non_negative(
            "compressible neo-Hookean Lame parameter lam (0 <= nu < 1/2)", self.lam))
        object.__setattr__(self, "n_thickness", _n_thickness(self.n_thickness))

    @classmethod
    def from_E_nu(cls, E: float, nu: float, n_thickness: int = 3) -> "CompressibleNeoHookean":
        """From Young's modulus E [Pa] > 0 and Poisson's ratio 0 <= nu < 1/2 [-]."""
        mu, lam = _lame(E, nu, "compressible neo-Hookean", "neo_hookean")
        return cls(mu=mu, lam=lam, n_thickness=n_thickness)

    @property
    def E(self) -> float:
        """Small-strain Young's modulus mu (3 lam + 2 mu)/(lam + mu) [Pa]."""
        return self.mu * (3.0 * self.lam + 2.0 * self.mu) / (self.lam + self.mu)

    @property
    def nu(self) -> float:
        """Small-strain Poisson's ratio lam / (2 (lam + mu)) [-]."""
        return self.lam / (2.0 * (self.lam + self.mu))

    def _log_c33(self, log_d: np.ndarray) -> np.ndarray:
        """u = ln C33 solving f(u) = 2 mu (e^u - 1) + lam (ln d + u) = 0 (= 4 C33 dpsi/dC33).

        f is increasing and convex in u, so Newton started above the root decreases
        monotonically to it.  Both starts used are upper bounds: the root of the linearisation
        (expm1(u) >= u) and, for ln d < 0, log(1 - lam ln d / (2 mu)) (f(u) >= 2 mu expm1(u) +
        lam ln d for u >= 0)."""
        mu, lam = self.mu, self.lam
        u = -lam * log_d / (2.0 * mu + lam)
        neg = log_d < 0.0
        if neg.any():
            u = np.where(neg, np.minimum(u, np.log1p(-lam * np.where(neg, log_d, 0.0) / (2.0 * mu))), u)
        finite = np.isfinite(log_d)
        tol = 8.0 * _EPS * (1.0 + np.abs(log_d))
        for _ in range(_NEWTON_MAX):
            f = 2.0 * mu * np.expm1(u) + lam * (log_d + u)
            du = -f / (2.0 * mu * np.exp(u) + lam)
            u = u + du
            if not np.any(finite & ~(np.abs(du) <= tol * (1.0 + np.abs(u)))):
                return u
        worst = np.abs(du)[finite].max()
        raise SolverError(
            f"compressible neo-Hookean: plane-stress condition dpsi/dC33 = 0 not converged in "
            f"{_NEWTON_MAX} Newton steps (last step {worst:.3e} in ln C33)")

    def _c33(self, p, q):
        return np.exp(self._log_c33(np.log1p(p + q)))

    def _kind(self):
        return ((COMPRESSIBLE_NEO_HOOKEAN, (self.mu, self.lam))
                if type(self) is CompressibleNeoHookean else None)

    def _prepare(self, p, q):
        log_d = np.log1p(p + q)
        return log_d, self._log_c33(log_d)

    def _psi(self, p, q, aux):
        log_d, u = aux
        mu, lam = self.mu, self.lam
        d = 1.0 + p + q
        L = log_d + u                                          # 2 ln J
        psi = 0.5 * mu * (p + np.expm1(u) - L) + 0.125 * lam * L * L
        pc = _const(0.5 * mu, d)
        pd = (0.5 * lam * L - mu) / (2.0 * d)
        m = 2.0 * mu + lam - lam * L                            # = 2 mu C33 + lam > 0 at the root
        pdd = (m * m - lam * lam) / (4.0 * d * d * m)          # psi_dd - psi_d3^2 / psi_33
        z = _const(0.0, d)
        return psi, pc, pd, z, z, pdd


# ------------------------------------------------------------------------------------------------
# compressible Mooney-Rivlin: C33 from plane stress
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CompressibleMooneyRivlin(_ThicknessIntegrated):
    """Compressible Mooney-Rivlin shell material with a plane-stress through-thickness stretch.

    ``psi = C1 (I1 - 3 - 2 ln J) + C2 (I2/J^2 - 3 + 2 ln J) + lam/2 (ln J)^2`` per unit rest
    volume (``I2/J^2 = tr C^-1``).  At J = 1 it is the incompressible Mooney-Rivlin law
    ``C1 (I1 - 3) + C2 (I2 - 3)``; the C2 term adds no volumetric stiffness, so at small strain it is
    LinearElastic(E, nu) with the Lame parameters (lam, mu = 2 (C1 + C2)), exactly as
    :class:`CompressibleNeoHookean` (which it is for C2 = 0, mu = 2 C1).  With the in-plane
    invariants c, d and ``z = C33``: ``I1 = c + z``, ``tr C^-1 = c/d + 1/z``, ``J^2 = d z``.
    ``z`` solves ``dpsi/dz = 0``, i.e. ``f(u) = 4 C1 (e^u - 1) + 4 C2 (1 - e^-u) + lam (ln d + u) = 0``
    in ``u = ln z`` (f increasing, its root between 0 and -ln d: Newton safeguarded by bisection,
    converged to round-off); the reduced energy's derivatives follow from the envelope theorem
    (first) and static condensation (second).

    Parameters
    ----------
    C1, C2 : float
        Material constants [Pa], both >= 0 with ``C1 + C2 > 0``; small-strain shear modulus
        ``mu = 2 (C1 + C2)``.
    lam : float
        First Lame parameter [Pa], >= 0 (0 <= nu < 1/2; use MooneyRivlin for nu = 1/2).
    n_thickness : int, optional
        Gauss-Legendre points through the thickness (default 3, at least 2).
    """

    C1: float
    C2: float
    lam: float
    n_thickness: int = 3

    def __post_init__(self) -> None:
        _set_mooney_rivlin_constants(self, "compressible Mooney-Rivlin")
        object.__setattr__(self, "lam", _non_negative(
            "compressible Mooney-Rivlin Lame parameter lam (0 <= nu < 1/2)", self.lam))
        object.__setattr__(self, "n_thickness", _n_thickness(self.n_thickness))

    @classmethod
    def from_E_nu(cls, E: float, nu: float, c2_over_c1: float, n_thickness: int = 3) -> "CompressibleMooneyRivlin":
        """From the small-strain Young's modulus E [Pa] > 0, Poisson's ratio 0 <= nu < 1/2 and the
        ratio C2/C1 >= 0: mu = E / (2 (1 + nu)) = 2 (C1 + C2), lam = E nu / ((1 + nu)(1 - 2 nu))."""
        mu, lam = _lame(E, nu, "compressible Mooney-Rivlin", "mooney_rivlin")
        r = _non_negative("compressible Mooney-Rivlin ratio C2/C1", c2_over_c1)
        c1 = mu / (2.0 * (1.0 + r))
        return cls(C1=c1, C2=r * c1, lam=lam, n_thickness=n_thickness)

    @property
    def mu(self) -> float:
        """Small-strain shear modulus 2 (C1 + C2) [Pa]."""
        return 2.0 * (self.C1 + self.C2)

    @property
    def E(self) -> float:
        """Small-strain Young's modulus mu (3 lam + 2 mu)/(lam + mu) [Pa]."""
        mu = self.mu
        return mu * (3.0 * self.lam + 2.0 * mu) / (self.lam + mu)

    @property
    def nu(self) -> float:
        """Small-strain Poisson's ratio lam / (2 (lam + mu)) [-]."""
        return self.lam / (2.0 * (self.lam + self.mu))

    def _log_c33(self, log_d: np.ndarray) -> np.ndarray:
        """u = ln C33 solving f(u) = 4 C1 expm1(u) - 4 C2 expm1(-u) + lam (ln d + u) = 0.

        f' = 4 C1 e^u + 4 C2 e^-u + lam > 0; f(0) = lam ln d and f(-ln d) = 4 C1 (1/d - 1) -
        4 C2 (d - 1) have opposite signs (or one is zero), so the root lies between 0 and -ln d.
        Newton from the root of the linearisation; a step leaving the bracket is replaced by
        bisection."""
        c1, c2, lam = 4.0 * self.C1, 4.0 * self.C2, self.lam
        log_d = np.asarray(log_d, dtype=float)
        finite = np.isfinite(log_d)
        ld = np.where(finite, log_d, 0.0)
        lo, hi = np.minimum(0.0, -ld), np.maximum(0.0, -ld)
        u = -lam * ld / (c1 + c2 + lam)
        tol = 8.0 * _EPS * (1.0 + np.abs(ld))
        for _ in range(_NEWTON_MAX):
            f = c1 * np.expm1(u) - c2 * np.expm1(-u) + lam * (ld + u)
            lo = np.where(f < 0.0, u, lo)
            hi = np.where(f > 0.0, u, hi)
            new = u - f / (c1 * np.exp(u) + c2 * np.exp(-u) + lam)
            new = np.where((new < lo) | (new > hi), 0.5 * (lo + hi), new)
            du = new - u
            u = new
            if np.all(np.abs(du) <= tol * (1.0 + np.abs(u))):
                return np.where(finite, u, np.nan)
        worst = np.abs(du).max()
        raise SolverError(
            f"compressible Mooney-Rivlin: plane-stress condition dpsi/dC33 = 0 not converged in "
            f"{_NEWTON_MAX} Newton steps (last step {worst:.3e} in ln C33)")

    def _c33(self, p, q):
        return np.exp(self._log_c33(np.log1p(p + q)))

    def _prepare(self, p, q):
        log_d = np.log1p(p + q)
        return log_d, self._log_c33(log_d)

    def _psi(self, p, q, aux):
        log_d, u = aux
        C1, C2, lam = self.C1, self.C2, self.lam
        d = 1.0 + p + q
        z = np.exp(u)
        L = log_d + u                                          # 2 ln J
        # c + z - 3 - L and c/d + 1/z - 3 + L without their O(1) parts (c = 2 + p)
        psi = (C1 * (p + np.expm1(u) - L) + C2 * (-(p + 2.0 * q) / d + np.expm1(-u) + L)
               + 0.125 * lam * L * L)
        inv_d = 1.0 / d
        pc = C1 + C2 * inv_d
        pd = (-C1 + C2 * (q - 1.0) * inv_d + 0.25 * lam * L) * inv_d
        m = 4.0 * (C1 * z + C2 / z) + lam                     # 4 C33^2 psi_33 > 0 at the root
        pcd = -C2 * inv_d * inv_d
        pdd = (C1 * z + C2 * (2.0 * (2.0 + p) * inv_d - 1.0 / z) + 0.25 * lam - 0.25 * lam * lam / m) * inv_d * inv_d
        return psi, pc, pd, _const(0.0, d), pcd, pdd


# ------------------------------------------------------------------------------------------------
# registry
# ------------------------------------------------------------------------------------------------
#: material name -> class (``make_material`` builds them)
MATERIALS: dict[str, type] = {
    "linear_elastic": LinearElastic,
    "saint_venant_kirchhoff": LinearElastic,
    "neo_hookean": NeoHookean,
    "mooney_rivlin": MooneyRivlin,
    "exponential": Exponential,
    "compressible_neo_hookean": CompressibleNeoHookean,
    "compressible_mooney_rivlin": CompressibleMooneyRivlin,
}

#: material name -> {parameter: unit}; "Pa" entries are stresses (scale them when converting
#: units), "1" dimensionless, "count" an integer.  compressible_neo_hookean takes either
#: (mu, lam) or (E, nu).
PARAMETERS: dict[str, dict[str, str]] = {
    "linear_elastic": {"E": "Pa", "nu": "1"},
    "saint_venant_kirchhoff": {"E": "Pa", "nu": "1"},
    "neo_hookean": {"mu": "Pa", "n_thickness": "count"},
    "mooney_rivlin": {"C1": "Pa", "C2": "Pa", "n_thickness": "count"},
    "exponential": {"C0": "Pa", "C1": "1", "n_thickness": "count"},
    "compressible_neo_hookean": {"mu": "Pa", "lam": "Pa", "E": "Pa", "nu": "1", "n_thickness": "count"},
    "compressible_mooney_rivlin": {"C1": "Pa", "C2": "Pa", "lam": "Pa", "n_thickness": "count"},
}


def make_material(name: str, params: Mapping):
    """Build a shell material from its registry name and a parameter table (SI units).

    Parameters
    ----------
    name : str
        One of :data:`MATERIALS` (``linear_elastic`` = ``saint_venant_kirchhoff``,
        ``neo_hookean``, ``mooney_rivlin``, ``exponential``, ``compressible_neo_hookean``,
        ``compressible_mooney_rivlin``).
    params : mapping
        Constructor parameters, see :data:`PARAMETERS` (``n_thickness`` is optional).

    Raises
    ------
    ProblemError
        Unknown name or parameter key (with a did-you-mean), missing parameter, invalid value.
    """
    if not isinstance(name, str) or name not in MATERIALS:
        raise ConfigError(unknown_name(name, MATERIALS, noun="material"))
    if not isinstance(params, Mapping):
        raise ProblemError(f"material {name!r}: parameters must be a table, got {type(params).__name__}")
    valid = PARAMETERS[name]
    check_names(params, valid, noun="parameter", prefix=f"material {name!r}: ")
    kw = dict(params)
    if name == "compressible_neo_hookean":
        has_lame, has_en = {"mu", "lam"} & kw.keys(), {"E", "nu"} & kw.keys()
        if has_lame and has_en:
            raise ProblemError(f"material {name!r}: give either (mu, lam) or (E, nu), not both "
                               f"(got {', '.join(sorted(kw))})")
        if has_en:
            required = ("E", "nu")
        else:
            required = ("mu", "lam")
        missing = [k for k in required if k not in kw]
        if missing:
            raise ProblemError(f"material {name!r}: missing parameter(s) {', '.join(missing)} "
                               f"(give mu, lam or E, nu; optional n_thickness)")
        if has_en:
            return CompressibleNeoHookean.from_E_nu(**kw)
        return CompressibleNeoHookean(**kw)
    cls = MATERIALS[name]
    required = [f.name for f in fields(cls) if f.default is MISSING and f.default_factory is MISSING]
    missing = [k for k in required if k not in kw]
    if missing:
        optional = [k for k in valid if k not in required]
        raise ProblemError(f"material {name!r}: missing parameter(s) {', '.join(missing)} "
                           f"(required: {', '.join(required)}"
                           + (f"; optional: {', '.join(optional)})" if optional else ")"))
    return cls(**kw)
