"""The ``graspdef`` command line: one module per subcommand, each with ``HELP``, ``DESCRIPTION``,
``add_arguments(parser)`` and ``run(args) -> int``.  argparse stops here: a subcommand turns its
arguments into typed inputs and calls a library function.

    graspdef solve PROBLEM.toml --out DIR      solve one problem file (linear or nonlinear path)
    graspdef bench linear|nonlinear|axisym [--json FILE]   run a benchmark set, print the table
    graspdef grasp SCENE --force F --out DIR   MuJoCo grasp, contacts mapped onto the shell, solved
    graspdef score PREDICTION SCAN --out DIR   register a scan to a predicted surface, score it
    graspdef view RUN_DIR [RUN_DIR ...] [--host H] [--port P]   browse run folders (viser)
    graspdef report RUN_DIR [RUN_DIR ...] [--scan SCAN] [--out FILE]   self-contained HTML report
    graspdef sweep SPEC.toml --out DIR [--workers N | --scheduler tcp://HOST:PORT]   a grid of grasps
    graspdef object show SCENE                 what a grasp of this object will use (law, E, nu, gas)
    graspdef object add NAME --mesh FILE ...   a mesh of your own -> an object folder to grasp
    graspdef rank OBJECT --force F --out DIR   where to grasp: antipodal candidates ranked (linear screen)

Every error a user can cause prints one line ``graspdef: error: ...`` and exits with status 2.
Building the parser imports no numerical package (``graspdef --help`` stays fast).
"""
from __future__ import annotations

import argparse
import logging
import sys

from ..errors import GraspdefError
from . import bench, grasp, obj, rank, report, score, solve, sweep, view

#: subcommands in the order of ``graspdef --help``
COMMANDS = {"solve": solve, "bench": bench, "score": score, "grasp": grasp, "view": view, "report": report,
            "sweep": sweep, "object": obj, "rank": rank}

EPILOG = """examples:
  graspdef solve benchmarks/plate_ss_uniform.toml --out out/plate
  graspdef bench linear --json out/bench_linear.json
  graspdef solve benchmarks/nonlinear/cantilever_moment.toml --out out/rollup
  graspdef bench nonlinear --json out/bench_nonlinear.json
  graspdef score out/ball/deformed.ply ycb_056_tennis_ball --out out/ball_score
  graspdef object show tennis_ball
  graspdef grasp tennis_ball --force 21.48 --out out/grasp_tennis_ball
  graspdef view out/plate out/rollup --port 8080
  graspdef report out/grasp_tennis_ball                            # -> out/grasp_tennis_ball/report.html
  graspdef sweep sweeps/smoke.toml --out out/sweep_smoke            # local, 2 worker processes
  graspdef sweep sweeps/smoke.toml --out /shared/sweep --scheduler tcp://10.0.0.5:8786
"""


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="graspdef", description="Robot-grasp deformation simulator: "
                                 "Loop-subdivision Kirchhoff-Love thin shells.", epilog=EPILOG,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-q", "--quiet", action="store_true", help="no progress messages")
    sub = ap.add_subparsers(dest="command", required=True)
    for name, mod in COMMANDS.items():
        p = sub.add_parser(name, help=mod.HELP, description=mod.DESCRIPTION)
        mod.add_arguments(p)
        p.set_defaults(func=mod.run)
    return ap


def main(argv: list[str] | None = None) -> int:
    """``graspdef ...``: parse, run the subcommand; a GraspdefError or OSError is one line and
    exit status 2."""
    args = build_parser().parse_args(argv)
    from .. import runtime

    runtime.configure()             # before any numerical runtime starts (graspdef.runtime)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    try:
        return args.func(args)
    except (GraspdefError, OSError) as exc:
        print(f"graspdef: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
