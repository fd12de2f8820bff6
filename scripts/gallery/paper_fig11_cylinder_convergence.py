"""Tian & Jia (2010) Fig. 11: convergence of the displacement under the load of the pinched
cylinder (Fig. 10), normalised by the reference value, against the number of control vertices.

Cylinder with rigid end diaphragms (MacNeal & Harder 1985): R = 300, L = 600, t = 3, E = 3e6,
nu = 0.3, two opposite inward point loads F = 1 at mid-length; full model (no symmetry planes),
one point held axially.  Reference: 1.8248e-5 (../shared/BENCHMARKS.md 1.2).  The paper's curve
stops at 2,500 control points ("our linear equation solver stops at 2,500 control points"; its
normalised value was still approaching 1 there).

Full mode: 2 n x n cells, n = 16 ... 160 (544 ... 51,520 control vertices); fast mode: n = 16,
24, 32.  Key number: the normalised displacement on the finest mesh (full: 1.0008 at 51,520).

    python scripts/gallery/paper_fig11_cylinder_convergence.py [--out DIR] [--fast]
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import numpy as np  # noqa: E402

import _common as C  # noqa: E402
from graspdef.geometry import cylinder  # noqa: E402
from graspdef.problem.loads import PointLoad  # noqa: E402
from graspdef.problem.problem import Problem, locate  # noqa: E402
from graspdef.problem.supports import EdgeSupport, PointSupport  # noqa: E402
from graspdef.shell.materials import LinearElastic  # noqa: E402
from graspdef.shell.model import Shell  # noqa: E402
from graspdef.solve.linear import solve_linear  # noqa: E402

NAME = "paper_fig11_cylinder_convergence"
CYL_REF = 1.8248e-5
SIZES, FAST_SIZES = [16, 24, 32, 48, 64, 96, 128, 160], [16, 24, 32]


def pinched_cylinder_problem(n_z: int) -> Problem:
    """Full-model pinched cylinder with 2 n_z x n_z cells; probe "A" under the inward load at +x."""
    R, L = 300.0, 600.0
    m = cylinder(R, L, 2 * n_z, n_z)
    sh = Shell(m.vertices, m.faces, LinearElastic(3e6, 0.3), 3.0)
    ends = lambda p: (np.abs(p[:, 2]) < 1e-6) | (np.abs(p[:, 2] - L) < 1e-6)
    sup = [EdgeSupport("diaphragm", ends, normal=(0, 0, 1))]
    A, _ = locate(sh, None, [R, 0, L / 2], "A")
    B, _ = locate(sh, None, [-R, 0, L / 2], "B")
    Cp, _ = locate(sh, None, [0, R, L / 2], "C")
    return Problem(sh, [PointLoad(A.face, A.bary, (-1.0, 0, 0)), PointLoad(B.face, B.bary, (1.0, 0, 0))],
                   sup + [PointSupport(Cp.face, Cp.bary, ((0, 0, 1),))], {"A": A})


def pinched_cylinder(n_z: int) -> tuple[int, float]:
    """(control vertices, radial displacement under the load)."""
    pr = pinched_cylinder_problem(n_z)
    sol = solve_linear(pr)
    return pr.shell.mesh.n_real, float(-sol.probe("A")[0])


def main(argv: list[str] | None = None) -> dict:
    return C.convergence_main(
        NAME, __doc__, argv, "pinched_cylinder", pinched_cylinder, CYL_REF, SIZES, FAST_SIZES,
        dict(ref_label="reference 1.8248e-5", column="normalised", ylabel="normalised displacement under the load",
             title="Fig. 11: pinched cylinder"),
        "paper: normalised value approaching 1 at <= 2,500 control points (curve only)",
        "MacNeal & Harder 1985 via ../shared/BENCHMARKS.md 1.2", ratio=True)


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
