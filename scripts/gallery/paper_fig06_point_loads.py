"""Tian & Jia (2010) Fig. 6: a half ellipsoid and a monkey saddle, edges held in place (simply
supported), under a central point load; linear elasticity.

Paper's table (Fig. 6): ellipsoid E = 1000, nu = 0.3, t = 1.0, P = 20.0 N, max. displacement
34.3; monkey saddle x^3 - 3 x y^2 = 5000 z on [-50, 50]^2, E = 100, nu = 0, t = 1.0, P = 5.0 N,
max. displacement 28.6 (SI units, "the unit of Young's modulus is Pa while the unit of length is
meter").

* Monkey saddle: graspdef gives 3.73 (3.74 on 80 x 80 cells: converged), 8x stiffer than the
  paper's 28.6.  We could not find the cause in the paper's text.  The same model flattened
  (scale 5e8) is a simply supported square plate under a central point load, whose Kirchhoff value
  is 0.0116008 P a^2 / D = 69.60 (../shared/BENCHMARKS.md 2.1): graspdef gives 69.57 (-0.05 %), so
  the solver's plate limit is right.  Reported, not asserted against 28.6.
* Half ellipsoid: the semi-axes in the caption are illegible in the OCR ("x^2/? + y^2/? + z^2/? =
  1"); we ASSUME a = b = 50, c = 25 (the saddle's footprint), apex load 20 N downward.  The
  number is therefore not comparable with 34.3; printed beside it for completeness.
  A check that can be made: with a = b = c = R (a hemisphere, R/t = 50) the apex deflection must
  approach Reissner's point-load value sqrt(3 (1 - nu^2)) P R / (4 E t^2) = 0.4131 (the edge is
  > 15 bending lengths away).

seed_readings.py tries the other readings of the garbled table (saddle: clamped, shear-diaphragm,
roller and corner-held edges, height coefficient 500 / 50000, "286" read as 28.6 / 2.86 / 286;
ellipsoid: five choices of semi-axes and the flat-plate bound): none reproduces 28.6 or 34.3
(issue 16 item 5).

Full mode: saddle 40 x 40 and 80 x 80 cells, ellipsoid 32 rings; fast mode: saddle 16 x 16,
ellipsoid 16 rings.

    python scripts/gallery/paper_fig06_point_loads.py [--out DIR] [--fast]
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import numpy as np  # noqa: E402

import _common as C  # noqa: E402
from graspdef.geometry import TriMesh, hemisphere, monkey_saddle  # noqa: E402
from graspdef.problem.loads import PointLoad  # noqa: E402
from graspdef.problem.problem import Problem  # noqa: E402
from graspdef.problem.supports import EdgeSupport  # noqa: E402
from graspdef.shell.materials import LinearElastic  # noqa: E402
from graspdef.shell.model import Shell  # noqa: E402
from graspdef.solve.linear import solve_linear  # noqa: E402

NAME = "paper_fig06_point_loads"
PAPER = {"ellipsoid_max_displacement_m": 34.3, "saddle_max_displacement_m": 28.6}
#: simply supported square plate, central point load: 0.0116008 P a^2 / D (a = 100, P = 5, E = 100, nu = 0, t = 1)
PLATE_POINT = 0.0116008 * 5.0 * 100.0 ** 2 / (100.0 / 12.0)
ELLIPSOID_AXES = (50.0, 50.0, 25.0)      # assumed: illegible in the paper


def _solve(mesh: TriMesh, E: float, nu: float, P: float, at, edge) -> tuple:
    sh = Shell(mesh.vertices, mesh.faces, LinearElastic(E, nu), 1.0)
    sup = [EdgeSupport("simply_supported", edge)]
    pt = Problem(sh, [], sup).locate(at, "load point")
    sol = solve_linear(Problem(sh, [PointLoad(pt.face, pt.bary, (0.0, 0.0, -P))], sup, {"P": pt}))
    u = sol.vertex_displacements()
    v, f = sol.deformed_surface()
    return sol.max_displacement(), float(-sol.probe("P")[2]), sh.mesh.n_real, (v - u, f, np.linalg.norm(u, axis=1), u)


def saddle(n: int, scale: float = 5000.0):
    """Monkey saddle x^3 - 3xy^2 = scale z on [-50, 50]^2, n x n cells, 5 N at the centre:
    (max displacement, centre deflection, control vertices, surfaces)."""
    edge = lambda p: (np.abs(np.abs(p[:, 0]) - 50) < 1e-6) | (np.abs(np.abs(p[:, 1]) - 50) < 1e-6)
    return _solve(monkey_saddle(50.0, n, scale), 100.0, 0.0, 5.0, [0.0, 0.0, 0.0], edge)


def half_ellipsoid(n_rings: int, axes=ELLIPSOID_AXES):
    """Half ellipsoid z >= 0 with semi-axes ``axes``, edge (z = 0) held, 20 N down at the apex."""
    h = hemisphere(1.0, n_rings)
    mesh = TriMesh(h.vertices * np.asarray(axes, float), h.faces)
    edge = lambda p: np.abs(p[:, 2]) < 1e-9
    return _solve(mesh, 1000.0, 0.3, 20.0, [0.0, 0.0, axes[2]], edge)


def reissner(P: float, R: float, E: float, nu: float, t: float) -> float:
    return np.sqrt(3 * (1 - nu ** 2)) * P * R / (4 * E * t ** 2)


def main(argv: list[str] | None = None) -> dict:
    a = C.parse(NAME, __doc__, argv)
    clock = C.Timer()
    n_saddle = [16] if a.fast else [40, 80]
    n_ell = 16 if a.fast else 32
    rows = []
    for n in n_saddle:
        umax, uc, nc, surf = saddle(n)
        rows.append({"case": "monkey saddle", "cells": f"{n} x {n}", "n_control": nc, "max_displacement_m": umax,
                     "published_m": PAPER["saddle_max_displacement_m"]})
        print(rows[-1], flush=True)
    saddle_surf = surf
    umax_f, uc_f, nc_f, _ = saddle(n_saddle[0], scale=5e8)
    rows.append({"case": "flattened saddle (scale 5e8) = plate", "cells": f"{n_saddle[0]} x {n_saddle[0]}",
                 "n_control": nc_f, "max_displacement_m": umax_f, "published_m": None,
                 "kirchhoff_plate_m": PLATE_POINT})
    umax_e, ue, nce, ell_surf = half_ellipsoid(n_ell)
    rows.append({"case": f"half ellipsoid {ELLIPSOID_AXES} (assumed axes)", "cells": f"{n_ell} rings",
                 "n_control": nce, "max_displacement_m": umax_e, "published_m": PAPER["ellipsoid_max_displacement_m"]})
    R = ELLIPSOID_AXES[0]
    umax_h, uh, nch, _ = half_ellipsoid(n_ell, (R, R, R))
    rows.append({"case": f"hemisphere R = {R:g} (Reissner check)", "cells": f"{n_ell} rings", "n_control": nch,
                 "max_displacement_m": umax_h, "apex_deflection_m": uh, "published_m": None,
                 "reissner_m": reissner(20.0, R, 1000.0, 0.3, 1.0)})
    for r in rows:
        ref = r.get("published_m") or r.get("kirchhoff_plate_m") or r.get("reissner_m")
        value = r.get("apex_deflection_m", r["max_displacement_m"])
        r["ratio_to_reference"] = value / ref
    print(C.table(rows, ["case", "cells", "n_control", "max_displacement_m", "published_m", "kirchhoff_plate_m",
                         "reissner_m", "apex_deflection_m", "ratio_to_reference"]))

    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, (x, f, mag, u), lab, pub, val in (
            (axs[0], ell_surf, f"half ellipsoid, axes {ELLIPSOID_AXES} (assumed), P = 20 N",
             PAPER["ellipsoid_max_displacement_m"], umax_e),
            (axs[1], saddle_surf, "monkey saddle, P = 5 N", PAPER["saddle_max_displacement_m"], rows[len(n_saddle) - 1]["max_displacement_m"])):
        scale = 0.15 * np.ptp(x, axis=0).max() / mag.max()
        C.surface(ax, x + scale * u, f, mag, views=("iso",), label="|u| [m]", vmax=float(mag.max()),
                  title=f"{lab}\nmax |u| {val:.3g} m (paper {pub:g} m); shape ×{scale:.2g}")
    fig.tight_layout()
    fig.subplots_adjust(top=0.86)
    key = {"saddle_max_displacement_m": rows[len(n_saddle) - 1]["max_displacement_m"],
           "saddle_published_m": PAPER["saddle_max_displacement_m"],
           "flattened_saddle_m": umax_f, "kirchhoff_plate_m": PLATE_POINT,
           "ellipsoid_max_displacement_m": umax_e, "ellipsoid_published_m": PAPER["ellipsoid_max_displacement_m"],
           "ellipsoid_axes_assumed_m": ELLIPSOID_AXES,
           "hemisphere_apex_m": uh, "reissner_m": reissner(20.0, R, 1000.0, 0.3, 1.0)}
    rec = {"figure": "Tian & Jia 2010, Fig. 6", "fast": a.fast, "rows": rows, "key": key, "seconds": clock(),
           "note": "saddle 8x stiffer than the paper (cause not found); ellipsoid axes illegible (assumed)"}
    return C.finish(a.out, NAME, rec, fig, rows)


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
