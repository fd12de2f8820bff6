"""Tian & Jia (2010) Fig. 8: convergence of the centre deflection of the simply supported square
plate of Fig. 7 under a uniform load, against the number of control vertices.

Plate: L = 100, h = 1, nu = 0.3, q/E = 1e-7 (E = 1e6, q = 0.1; the paper's E, nu and load are not
legible: ../shared/BENCHMARKS.md section 2.2 reconstructs them), simply supported edges.
Reference: the Kirchhoff plate's Navier series 0.0040623527 q L^4 / D = 0.44361 (the paper: "0.443
according to the analytical solution"; its own solver stopped at ~2,500 control points and
"converges to a value approximately 1?% less than the analytical value" -- digit illegible).

Full mode: 4 x 4 ... 224 x 224 cells (25 ... 50,625 control vertices); fast mode: 4, 8, 16.
Key number: the error on the finest mesh (full: +7.1e-6 % at 50,625 control vertices; -0.0026 % before
the nearly dependent support rows of the boundary loop were dropped instead of re-based).

    python scripts/gallery/paper_fig08_plate_convergence.py [--out DIR] [--fast]
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import numpy as np  # noqa: E402

import _common as C  # noqa: E402
from graspdef.geometry import rectangle  # noqa: E402
from graspdef.problem.loads import Pressure  # noqa: E402
from graspdef.problem.problem import Problem, locate  # noqa: E402
from graspdef.problem.supports import EdgeSupport  # noqa: E402
from graspdef.shell.materials import LinearElastic  # noqa: E402
from graspdef.shell.model import Shell  # noqa: E402
from graspdef.solve.linear import solve_linear  # noqa: E402

NAME = "paper_fig08_plate_convergence"
PLATE_REF = 0.0040623527 * 0.1 * 100.0 ** 4 / (1e6 / (12 * (1 - 0.09)))
SIZES, FAST_SIZES = [4, 8, 16, 32, 64, 128, 224], [4, 8, 16]


def plate(n: int) -> tuple[int, float]:
    """Centre deflection of the Tian & Jia plate on n x n cells: (control vertices, deflection)."""
    m = rectangle(100.0, 100.0, n, n)
    sh = Shell(m.vertices, m.faces, LinearElastic(1e6, 0.3), 1.0)
    edges = lambda p: (np.abs(np.abs(p[:, 0]) - 50) < 1e-6) | (np.abs(np.abs(p[:, 1]) - 50) < 1e-6)
    sup = [EdgeSupport("simply_supported", edges)]
    c, _ = locate(sh, Problem(sh, [], sup).evaluator, [0.0, 0.0, 0.0], "centre")
    sol = solve_linear(Problem(sh, [Pressure(0.1)], sup, {"c": c}))
    return m.n_vertices, float(sol.probe("c")[2])


def main(argv: list[str] | None = None) -> dict:
    return C.convergence_main(
        NAME, __doc__, argv, "plate_ss_uniform", plate, PLATE_REF, SIZES, FAST_SIZES,
        dict(ref_label=f"Navier series {PLATE_REF:.5f}", column="value", ylabel="centre deflection",
             title="Fig. 8: simply supported plate, uniform load"),
        "0.443 (analytical); paper's solver ~1?% below (digit illegible)", "Navier series, ../shared/BENCHMARKS.md 2.1-2.2")


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
