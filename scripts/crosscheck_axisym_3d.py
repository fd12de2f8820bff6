"""Cross-check of the axisymmetric shell solver (graspdef.axisym, the thesis method) against the 3-D
Loop-subdivision Kirchhoff-Love nonlinear shell solver (graspdef.solve.nonlinear) on the same
axisymmetric problems with the same incompressible Mooney-Rivlin material (C2/C1 = gamma = 0.1).

    python scripts/crosscheck_axisym_3d.py [--fast] [--jobs 2] [--out out/crosscheck] [--subdivisions 3 4 5]
                                           [--r-over-t 10 20 40] [--replot]

Cases (R = 1, C1 = 1; loads nondimensional as in docs/axisym.md):

1. "pinched": a closed sphere squeezed at its poles by two opposite total forces F, each spread
   uniformly over a ring of radius a = 0.2 R around its pole (vertical dead load).  Axisymmetric:
   ``pinched_sphere(R, t, mat, F, contact_radius=a)`` (upper half by symmetry), load control
   (``solve_load``).  3-D: an icosphere (subdivisions 3/4/5: 642/2,562/10,242 control vertices;
   a regular vertex of the mesh lies at each pole) with ``n_ring`` PointLoads of F/n_ring on
   each ring, located on the limit surface, held by RigidModes; load control to the same loads.
   Compared: the pole (apex) displacement, half the change of the pole-to-pole distance in 3-D,
   at F/(C1 t^2) levels below the axisymmetric limit load (which lies at an apex displacement of
   ~20 % R for R/t = 10, ~9 % R for R/t = 20 and ~3 % R for R/t = 40).
2. "inflation": the same sphere (R/t = 10) under a follower pressure p.  Compared: the stretch
   of the mid-surface (axisym: pole radius / R; 3-D: (V / V0)^(1/3) of the enclosed volume) at
   p R/(C1 t) levels below the pressure maximum, with the membrane closed form
   p R/(C1 t) = 4 (1/l - 1/l^7)(1 + gamma l^2) and with the closed-form uniform-inflation solutions
   of the two shell energies (thesis phi = w + (1/24) d2w/dzeta0^2 with exact layer kinematics;
   3-D: Gauss points through the thickness with E(zeta) = e - zeta k and the mid-surface metric
   for every layer, Kiendl et al. 2015), which isolates the O((t/R)^2) difference between the
   two thickness models from discretisation errors.

Both cases are also solved by the axisymmetric solver with the 3-D solver's thickness model
(``axisym_material("3d")``, a diagnostic subclass of graspdef.axisym.AxisymMaterial defined here): with
the same shell energy the comparison checks the two solvers; against the thesis's energy it
includes the O(t/R) difference between the two first-approximation shell theories (about 2 % at
R/t = 10 for the pinched sphere).  Results and discussion: docs/crosscheck.md.

Writes ``crosscheck.json`` and ``crosscheck.png`` to --out and prints the tables.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

GAMMA = 0.1
R = 1.0
RING_RADIUS = 0.2          # a / R
#: load levels F / (C1 t^2) per R/t, all below the axisymmetric limit load (2.046 at R/t = 10, 1.276 at 20,
#: 1.105 at 40, reached at apex displacements of 19.5 %, 8.5 % and 3.4 % of R)
PINCH_LOADS = {10.0: (0.01, 0.25, 0.5, 1.0, 1.5, 1.8), 20.0: (0.01, 0.2, 0.4, 0.8, 1.1), 40.0: (0.01, 0.25, 0.5, 0.8)}
FAST_LOADS = (0.01, 0.5, 1.0, 1.5)
INFLATION_LOADS = (1.0, 2.0, 2.5)   # p R / (C1 t), below the maximum 2.98 (membrane)


# ------------------------------------------------------------------------------------------------
# axisymmetric side
# ------------------------------------------------------------------------------------------------
def shell3d_thickness_energy(l1, l2, c1, c2, k1, k2, g, n_gauss=3):
    """The 3-D solver's thickness model written in the axisymmetric variables (diagnostic).

    Nondimensional (t0 = C1 = 1) energy per unit undeformed area, gradient and Hessian in
    (l1, l2, c1, c2) = (lambda_xi, lambda_theta, c_xi, c_theta) as AxisymMaterial.shell_energy.  The 3-D
    solver (graspdef.shell.hyperelastic, Kiendl et al. 2015) uses E_ab(zeta) = e_ab - zeta k_ab with
    k = b - B (covariant) and the mid-surface metric for every layer; in principal axes of an
    axisymmetric state the layer's squared stretches are a = l1^2 - 2 zeta (l1 c1 - k1) and
    b = l2^2 - 2 zeta (l2 c2 - k2) (b_xixi per undeformed length^2 = l1^2 kappa_xi = l1 c1), the
    normal stretch^2 is 1/(a b) and W = (I1 - 3) + g (I2 - 3) is summed over n_gauss Gauss-Legendre
    points.  The thesis instead uses the exact layer stretches l (1 - zeta kappa)/(1 - zeta0 kappa0)
    (deformed thickness coordinate zeta(zeta0) from incompressibility) and phi = w + w''/24."""
    l1, l2, c1, c2, k1, k2 = np.broadcast_arrays(*(np.asarray(x, float) for x in (l1, l2, c1, c2, k1, k2)))
    xg, wg = np.polynomial.legendre.leggauss(n_gauss)
    phi = np.zeros(l1.shape)
    G = np.zeros((4,) + l1.shape)
    H = np.zeros((4, 4) + l1.shape)
    dd = np.array([[2.0, 0.0], [0.0, 0.0]])
    for x, w in zip(xg, wg):
        z, w = x / 2, w / 2
        a = l1 ** 2 - 2 * z * (l1 * c1 - k1)
        b = l2 ** 2 - 2 * z * (l2 * c2 - k2)
        phi += w * ((a + b + 1 / (a * b) - 3) + g * (a * b + 1 / a + 1 / b - 3))
        pa, pb = 1 - 1 / (a * a * b) + g * (b - 1 / a ** 2), 1 - 1 / (a * b * b) + g * (a - 1 / b ** 2)
        paa, pbb, pab = 2 / (a ** 3 * b) + 2 * g / a ** 3, 2 / (a * b ** 3) + 2 * g / b ** 3, 1 / (a * a * b * b) + g
        da = (2 * l1 - 2 * z * c1, -2 * z * l1)          # d a / d(l1, c1)
        db = (2 * l2 - 2 * z * c2, -2 * z * l2)          # d b / d(l2, c2)
        dd[0, 1] = dd[1, 0] = -2 * z
        ia, ib = (0, 2), (1, 3)
        for p in range(2):
            G[ia[p]] += w * pa * da[p]
            G[ib[p]] += w * pb * db[p]
            for q in range(2):
                H[ia[p], ia[q]] += w * (paa * da[p] * da[q] + pa * dd[p, q])
                H[ib[p], ib[q]] += w * (pbb * db[p] * db[q] + pb * dd[p, q])
                H[ia[p], ib[q]] += w * pab * da[p] * db[q]
                H[ib[q], ia[p]] += w * pab * da[p] * db[q]
    return phi, G, H


def _shell3d_material_class():
    from graspdef.axisym import AxisymMaterial

    class Shell3DThicknessMaterial(AxisymMaterial):
        """AxisymMaterial with the 3-D solver's thickness model instead of the thesis's phi (diagnostic:
        the same shell energy in both solvers isolates the discretisation/solver difference)."""

        def shell_energy(self, l1, l2, c1, c2, k1, k2):
            return shell3d_thickness_energy(l1, l2, c1, c2, k1, k2, self.gamma)

        def invert(self, n1, m1, l2, c2, k1, k2, guess):
            l1, c1 = np.array(guess[0], float), np.array(guess[1], float)
            for _ in range(40):
                _, g, H = self.shell_energy(l1, l2, c1, c2, k1, k2)
                r0, r1 = g[0] - n1, g[2] - m1
                a, b, d = H[0, 0], H[0, 2], H[2, 2]
                det = a * d - b * b
                dl, dc = (d * r0 - b * r1) / det, (a * r1 - b * r0) / det
                s = np.minimum(1.0, 0.5 * l1 / np.maximum(np.abs(dl), 1e-300))
                l1, c1 = l1 - s * dl, c1 - s * dc
                if (np.max(np.abs(dl) + np.abs(dc)) if np.size(dl) else 0.0) < 1e-9 and np.all(s == 1.0):
                    phi, g, H = self.shell_energy(l1, l2, c1, c2, k1, k2)
                    return l1, c1, phi, g, H
            from graspdef.errors import SolverError
            err = SolverError("constitutive relations (3-D thickness model) could not be inverted")
            err.points = np.arange(np.size(l1))
            raise err

    return Shell3DThicknessMaterial


def axisym_material(energy: str = "thesis"):
    """The axisymmetric solver's material: energy "thesis" (the thesis's phi, graspdef.axisym as is) or
    "3d" (the 3-D solver's thickness model, diagnostic)."""
    from graspdef.axisym import AxisymMaterial
    cls = AxisymMaterial if energy == "thesis" else _shell3d_material_class()
    return cls("mooney_rivlin", C1=1.0, gamma=GAMMA)


def axisym_pinched(R_over_t: float, loads, a: float = RING_RADIUS, rk_steps: int = 2, max_piece: float = 1.0,
                   energy: str = "thesis"):
    """Apex displacement / R of the axisymmetric pinched sphere at each F/(C1 t^2) in ``loads``."""
    from graspdef.axisym import pinched_sphere, solve_load
    t = R / R_over_t
    m = pinched_sphere(R, t, axisym_material(energy), F=t ** 2, contact_radius=a * R, rk_steps=rk_steps,
                       max_piece=max_piece)
    out = []
    for L in loads:
        eq = solve_load(m, L, increments=max(2, int(np.ceil(4 * L))))
        out.append((eq.nodes[0, 1] * t - R) / R)
    return np.array(out)


def axisym_inflated(R_over_t: float, loads, energy: str = "thesis"):
    """Mid-surface stretch of the axisymmetric inflated sphere at each p R/(C1 t) in ``loads``."""
    from graspdef.axisym import inflated_sphere, solve_load
    t = R / R_over_t
    m = inflated_sphere(R, t, axisym_material(energy), p=t / R, max_piece=0.4)
    out = []
    for L in loads:
        eq = solve_load(m, L, increments=max(2, int(np.ceil(4 * L))))
        out.append(eq.nodes[0, 1] * t / R)
    return np.array(out)


# ------------------------------------------------------------------------------------------------
# 3-D side
# ------------------------------------------------------------------------------------------------
def shell_material():
    from graspdef.shell.hyperelastic import MooneyRivlin
    return MooneyRivlin(1.0, GAMMA)


def shell3d_pinched(subdivisions: int, R_over_t: float, loads, a: float = RING_RADIUS, n_ring: int = 64):
    """Apex displacement / R (half the change of the pole-to-pole distance) of the 3-D sphere at
    each F/(C1 t^2) in ``loads``; returns (values, info)."""
    from graspdef.bench import ring_pinched_sphere
    from graspdef.geometry import sphere
    from graspdef.shell.model import Shell
    from graspdef.solve.nonlinear import PathOptions, solve_nonlinear
    t0 = time.perf_counter()
    t = R / R_over_t
    m = sphere(R, subdivisions)
    sh = Shell(m.vertices, m.faces, shell_material(), t)
    Fmax = max(loads) * t ** 2
    pr = ring_pinched_sphere(sh, R, a, n_ring, Fmax)
    factors = tuple(L * t ** 2 / Fmax for L in loads)
    sol = solve_nonlinear(pr, PathOptions(steps=4, targets=factors))
    out = []
    for f in factors:
        pt = sol.at(f)
        out.append(0.5 * (pt.probes["top"][2] - pt.probes["bottom"][2]) / R)
    info = {"n_control": int(sh.mesh.n_real), "seconds": time.perf_counter() - t0, "steps": len(sol.path) - 1,
            "newton_iterations": int(sum(sol.iterations())), "n_ring": n_ring}
    return np.array(out), info


def shell3d_inflated(subdivisions: int, R_over_t: float, loads):
    """Mid-surface stretch (V/V0)^(1/3) of the 3-D sphere at each p R/(C1 t) in ``loads``."""
    from graspdef.geometry import sphere
    from graspdef.problem.potentials import FollowerPressure
    from graspdef.problem.problem import Problem
    from graspdef.problem.supports import RigidModes
    from graspdef.shell.model import Shell
    from graspdef.shell.volume import EnclosedVolume
    from graspdef.solve.nonlinear import PathOptions, solve_nonlinear
    t0 = time.perf_counter()
    t = R / R_over_t
    m = sphere(R, subdivisions)
    sh = Shell(m.vertices, m.faces, shell_material(), t)
    pmax = max(loads) * t / R
    pr = Problem(sh, [FollowerPressure(pmax)], [RigidModes()])
    factors = tuple(L * t / R / pmax for L in loads)
    sol = solve_nonlinear(pr, PathOptions(steps=4, targets=factors))
    vol = EnclosedVolume(sh)
    V0 = vol.value(sh.rest_positions)
    out = [(vol.value(sh.rest_positions + sol.at(f).u) / V0) ** (1 / 3) for f in factors]
    info = {"n_control": int(sh.mesh.n_real), "seconds": time.perf_counter() - t0, "steps": len(sol.path) - 1}
    return np.array(out), info


# ------------------------------------------------------------------------------------------------
# closed forms for uniform inflation
# ------------------------------------------------------------------------------------------------
def membrane_pressure(lam):
    """p R/(C1 t) of the thin membrane (pressure on the mid-surface)."""
    return 4 * (1 / lam - lam ** -7) * (1 + GAMMA * lam ** 2)


def thesis_pressure(lam, R_over_t):
    """p R/(C1 t) of the thesis's shell energy phi under uniform inflation (lam_xi = lam_theta =
    lam, curvatures unchanged per unit undeformed length: c = k = -t/R): p = phi'(lam) / lam^2."""
    mat = axisym_material()
    k = -1.0 / R_over_t
    _, g, _ = mat.shell_energy(np.atleast_1d(lam), np.atleast_1d(lam), np.full(1, k), np.full(1, k),
                               np.full(1, k), np.full(1, k))
    return float((g[0] + g[1])[0] / lam ** 2)


def kiendl_pressure(lam, R_over_t, n_gauss: int = 3):  # the 3-D solver's thickness model
    """p R/(C1 t) of the 3-D solver's thickness model under uniform inflation: in-plane stretch^2 of
    the layer zeta is lam^2 + 2 zeta (lam - 1)/R (E = e - zeta k with the mid-surface metric for
    every layer), lambda_3 from incompressibility, Gauss-Legendre through the thickness."""
    xg, wg = np.polynomial.legendre.leggauss(n_gauss)
    t = 1.0 / R_over_t                      # R = 1

    def energy(l):
        m2 = l ** 2 + 2 * (0.5 * t * xg) * (l - 1)
        I1 = 2 * m2 + m2 ** -2
        I2 = m2 ** 2 + 2 / m2
        return float(np.sum(0.5 * wg * ((I1 - 3) + GAMMA * (I2 - 3))))   # per unit area / (t C1)
    h = 1e-6
    return (energy(lam + h) - energy(lam - h)) / (2 * h) / lam ** 2


def stretch_of(pfun, p, *args):
    return brentq(lambda l: pfun(l, *args) - p, 1.0 + 1e-9, 1.47)


# ------------------------------------------------------------------------------------------------
def _job(args):
    kind, s, Rt, loads, n_ring = args
    if kind == "pinched":
        v, info = shell3d_pinched(s, Rt, loads, n_ring=n_ring)
    else:
        v, info = shell3d_inflated(s, Rt, loads)
    return (kind, Rt, s), v.tolist(), info


def _pct(v, ref):
    return 100 * (np.asarray(v) / np.asarray(ref) - 1)


def run(subdivisions, ratios, inflation_subdivisions, n_ring, fast, jobs=1):
    res = {"gamma": GAMMA, "R": R, "ring_radius_over_R": RING_RADIUS, "n_ring": n_ring, "fast": fast,
           "pinched": [], "inflation": []}
    loads_of = {Rt: (FAST_LOADS if fast else PINCH_LOADS[Rt]) for Rt in ratios}
    tasks = [("pinched", s, Rt, loads_of[Rt], n_ring) for Rt in ratios for s in subdivisions]
    tasks += [("inflation", s, 10.0, INFLATION_LOADS, 0) for s in inflation_subdivisions]
    tasks.sort(key=lambda a: -a[1])          # largest meshes first
    if jobs > 1:
        from concurrent.futures import ProcessPoolExecutor
        pool = ProcessPoolExecutor(jobs)
        futures = [pool.submit(_job, a) for a in tasks]
    else:
        pool, futures = None, None
    # the axisymmetric side meanwhile (in this process)
    ax = {}
    for Rt in ratios:
        for energy in ("thesis", "3d"):
            t0 = time.perf_counter()
            v = axisym_pinched(Rt, loads_of[Rt], energy=energy)
            ax[("pinched", Rt, energy)] = (v, time.perf_counter() - t0)
            print(f"axisym pinched R/t = {Rt:g} ({energy} energy): {time.perf_counter() - t0:.1f} s", flush=True)
    for energy in ("thesis", "3d"):
        t0 = time.perf_counter()
        ax[("inflation", 10.0, energy)] = (axisym_inflated(10.0, INFLATION_LOADS, energy=energy), time.perf_counter() - t0)
    done = {}
    for n, a in enumerate(tasks):
        key, v, info = futures[n].result() if futures else _job(a)
        done[key] = (np.array(v), info)
        print(f"3-D {key[0]} R/t = {key[1]:g}, subdivisions {key[2]}: {info['n_control']} control vertices, "
              f"{info['seconds']:.1f} s", flush=True)
    if pool:
        pool.shutdown()

    for Rt in ratios:
        loads = loads_of[Rt]
        a_th, s_th = ax[("pinched", Rt, "thesis")]
        a_3d, s_3d = ax[("pinched", Rt, "3d")]
        rec = {"R_over_t": Rt, "loads": list(loads), "axisym": a_th.tolist(), "axisym_seconds": s_th,
               "axisym_3d_energy": a_3d.tolist(), "axisym_3d_energy_seconds": s_3d,
               "thickness_model_diff_pct": _pct(a_3d, a_th).tolist(), "shell3d": {}}
        for s in subdivisions:
            v, info = done[("pinched", Rt, s)]
            rec["shell3d"][str(s)] = {"values": v.tolist(), "diff_vs_axisym_pct": _pct(v, a_th).tolist(),
                                      "diff_vs_axisym_3d_energy_pct": _pct(v, a_3d).tolist(), **info}
        res["pinched"].append(rec)
        print(f"\n== pinched sphere, R/t = {Rt:g}, ring radius a = {RING_RADIUS:g} R: apex displacement / R; "
              f"diff = 3-D / axisym - 1 (thesis energy) [same energy]")
        print(f"{'F/(C1t^2)':>9} {'axisym':>9} {'ax(3-D en)':>10} "
              + " ".join(f"{'3-D s' + str(s):>9} {'diff [same en.]':>16}" for s in subdivisions))
        for i, L in enumerate(loads):
            row = f"{L:9.3f} {a_th[i]:9.6f} {a_3d[i]:10.6f} "
            for s in subdivisions:
                r = rec["shell3d"][str(s)]
                row += f"{r['values'][i]:9.6f} {r['diff_vs_axisym_pct'][i]:+6.2f}% [{r['diff_vs_axisym_3d_energy_pct'][i]:+6.2f}%] "
            print(row)

    Rt, loads = 10.0, INFLATION_LOADS
    a_th, s_th = ax[("inflation", Rt, "thesis")]
    a_3d, s_3d = ax[("inflation", Rt, "3d")]
    rec = {"R_over_t": Rt, "loads": list(loads), "axisym": a_th.tolist(), "axisym_seconds": s_th,
           "axisym_3d_energy": a_3d.tolist(), "axisym_3d_energy_seconds": s_3d,
           "membrane": [stretch_of(membrane_pressure, p) for p in loads],
           "thesis_closed_form": [stretch_of(thesis_pressure, p, Rt) for p in loads],
           "shell3d_closed_form": [stretch_of(kiendl_pressure, p, Rt) for p in loads], "shell3d": {}}
    for s in inflation_subdivisions:
        v, info = done[("inflation", Rt, s)]
        rec["shell3d"][str(s)] = {"values": v.tolist(), "diff_vs_axisym_pct": _pct(v - 1, a_th - 1).tolist(),
                                  "diff_vs_axisym_3d_energy_pct": _pct(v - 1, a_3d - 1).tolist(), **info}
    res["inflation"].append(rec)
    print(f"\n== inflated sphere, R/t = {Rt:g}: mid-surface stretch - 1 (cf = closed form for uniform inflation); "
          f"diff = relative difference of stretch - 1, 3-D vs axisym (thesis energy) [same energy]")
    print(f"{'pR/(C1t)':>8} {'membrane':>9} {'thesis cf':>9} {'axisym':>9} {'3-D en cf':>9} {'ax(3-D en)':>10} "
          + " ".join(f"{'3-D s' + str(s):>9} {'diff [same en.]':>16}" for s in inflation_subdivisions))
    for i, p in enumerate(loads):
        row = (f"{p:8.2f} {rec['membrane'][i] - 1:9.6f} {rec['thesis_closed_form'][i] - 1:9.6f} {a_th[i] - 1:9.6f} "
               f"{rec['shell3d_closed_form'][i] - 1:9.6f} {a_3d[i] - 1:10.6f} ")
        for s in inflation_subdivisions:
            r = rec["shell3d"][str(s)]
            row += f"{r['values'][i] - 1:9.6f} {r['diff_vs_axisym_pct'][i]:+6.2f}% [{r['diff_vs_axisym_3d_energy_pct'][i]:+6.2f}%] "
        print(row)
    return res


def plot(res, path):
    """Top row: load vs apex displacement / stretch; bottom row: relative difference of the 3-D
    solution from the axisymmetric one (solid: thesis energy; dashed: same energy)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    n = len(res["pinched"]) + 1
    fig, axes = plt.subplots(2, n, figsize=(5.0 * n, 8.0), squeeze=False)
    colors = ["tab:blue", "tab:orange", "tab:green", "tab:red"]
    for col, rec in enumerate(res["pinched"]):
        axp, axd = axes[0, col], axes[1, col]
        axp.plot(-np.array(rec["axisym"]), rec["loads"], "k-o", label="axisym (thesis energy)")
        axp.plot(-np.array(rec["axisym_3d_energy"]), rec["loads"], "k:^", mfc="none",
                 label="axisym with the 3-D thickness model")
        axd.plot(rec["loads"], rec["thickness_model_diff_pct"], "k:^", mfc="none",
                 label="axisym: 3-D thickness model vs thesis")
        for c, (s, r) in zip(colors, rec["shell3d"].items()):
            axp.plot(-np.array(r["values"]), rec["loads"], "--s", color=c, ms=4, mfc="none",
                     label=f"3-D, {r['n_control']} vertices")
            axd.plot(rec["loads"], r["diff_vs_axisym_pct"], "-s", color=c, ms=4, label=f"3-D {r['n_control']} vs thesis")
            axd.plot(rec["loads"], r["diff_vs_axisym_3d_energy_pct"], "--o", color=c, ms=4, mfc="none",
                     label=f"3-D {r['n_control']} vs same energy")
        axp.set_xlabel("apex displacement / R")
        axp.set_ylabel("F / (C1 t^2)")
        axp.set_title(f"pinched MR sphere, R/t = {rec['R_over_t']:g}, ring a = {res['ring_radius_over_R']:g} R",
                      fontsize=10)
        axp.legend(fontsize=7)
        axd.axhspan(-1, 1, color="0.9")
        axd.axhline(0, color="k", lw=0.5)
        axd.set_xlabel("F / (C1 t^2)")
        axd.set_ylabel("apex displacement: 3-D / axisym - 1 [%]")
        axd.legend(fontsize=6)
    rec = res["inflation"][0]
    axi, axd = axes[0, -1], axes[1, -1]
    lam = np.linspace(1.0, 1.47, 100)
    axi.plot(lam, membrane_pressure(lam), "k:", label="membrane closed form")
    axi.plot(rec["axisym"], rec["loads"], "ko", label="axisym (thesis energy)")
    axi.plot(rec["axisym_3d_energy"], rec["loads"], "k^", mfc="none", label="axisym, 3-D thickness model")
    for c, (s, r) in zip(colors, rec["shell3d"].items()):
        axi.plot(r["values"], rec["loads"], "s", color=c, mfc="none", label=f"3-D, {r['n_control']} vertices")
        axd.plot(rec["loads"], r["diff_vs_axisym_pct"], "-s", color=c, label=f"3-D {r['n_control']} vs thesis")
        axd.plot(rec["loads"], r["diff_vs_axisym_3d_energy_pct"], "--o", color=c, mfc="none",
                 label=f"3-D {r['n_control']} vs same energy")
    axi.set_xlabel("mid-surface stretch")
    axi.set_ylabel("p R / (C1 t)")
    axi.set_title(f"inflated MR sphere, R/t = {rec['R_over_t']:g}", fontsize=10)
    axi.legend(fontsize=7)
    axd.axhspan(-1, 1, color="0.9")
    axd.axhline(0, color="k", lw=0.5)
    axd.set_xlabel("p R / (C1 t)")
    axd.set_ylabel("stretch - 1: 3-D / axisym - 1 [%]")
    axd.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> None:
    from _study import write_results      # scripts/_study.py (run as a script: scripts/ is on the path)

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/crosscheck")
    ap.add_argument("--fast", action="store_true",
                    help="subdivisions 2 and 3, R/t = 10 only, loads 0.01-1.5, inflation on 2 and 3 (~2 min)")
    ap.add_argument("--subdivisions", type=int, nargs="+", default=None)
    ap.add_argument("--r-over-t", type=float, nargs="+", default=None, choices=sorted(PINCH_LOADS))
    ap.add_argument("--n-ring", type=int, default=64, help="point loads per ring (64 and 128 agree to 1e-6)")
    ap.add_argument("--jobs", type=int, default=1, help="3-D runs in parallel processes")
    ap.add_argument("--replot", action="store_true", help="only redraw the PNG from --out/crosscheck.json")
    a = ap.parse_args()
    if a.replot:
        out = Path(a.out)
        plot(json.loads((out / "crosscheck.json").read_text()), out / "crosscheck.png")
        return
    subs = a.subdivisions or ([2, 3] if a.fast else [3, 4, 5])
    ratios = a.r_over_t or ([10.0] if a.fast else sorted(PINCH_LOADS))
    infl = [2, 3] if a.fast else [3, 4]
    t0 = time.perf_counter()
    res = run(subs, ratios, infl, a.n_ring, a.fast, a.jobs)
    res["total_seconds"] = time.perf_counter() - t0
    out = Path(a.out)
    write_results(out, "crosscheck", res, plot)


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
