"""The ``graspdef`` command line: one module per subcommand, each with ``DESCRIPTION``,
``add_arguments(parser)`` and ``run(args) -> int``; its one-line help is in :data:`COMMANDS`.
argparse stops here: a subcommand turns its arguments into typed inputs and calls a library function.

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
    graspdef fit OBJECT --data TABLE.csv --params E,pressure [--out DIR]   material parameters from measurements

Every error a user can cause prints one line ``graspdef: error: ...`` and exits with status 2.
Building the parser imports no numerical package, and :func:`main` imports the module of the one
subcommand it runs, none for ``graspdef --help`` (start-up stays fast; tests/test_startup.py).
"""
from __future__ import annotations

import argparse
import importlib
import logging
import re
import sys
from collections.abc import Iterable, Sequence

from ..errors import GraspdefError

#: subcommand -> (its module in graspdef.cli, its one-line help), in the order of ``graspdef --help``.
#: The help lines live here, not in the modules, so that listing the subcommands imports none of them.
COMMANDS = {
    "solve": ("solve", "solve a problem file (TOML) and write a run folder"),
    "bench": ("bench", "run a benchmark set and print/write the comparison table"),
    "score": ("score", "register a scan to a predicted surface and score it (score.json)"),
    "grasp": ("grasp", "MuJoCo grasp -> contacts -> shell deformation (a run folder)"),
    "view": ("view", "serve run folders or a ranking folder in the browser (viser on 127.0.0.1:8080)"),
    "report": ("report", "write a self-contained HTML report of run folders or of a ranking folder (report.html)"),
    "sweep": ("sweep", "run a grid of grasps (objects x forces x materials x contacts x meshes)"),
    "object": ("obj", ("add an object of your own from a mesh file (object add), or show an object's data "
                       "(object show)")),
    "rank": ("rank", "rank antipodal grasp candidates of an object by the work its shell takes (linear screen)"),
    "fit": ("fit", "fit E, air pressure or thickness of an object to a measured force-displacement table (fit.json)"),
}

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
  graspdef fit tennis_ball --data scenes/tennis_ball/table1_tian_jia_2010.csv --params E,pressure --out out/fit_tb
"""


def command_module(name: str):
    """The module of subcommand ``name`` (``graspdef.cli.solve`` for ``solve``), imported now."""
    return importlib.import_module(f"{__name__}.{COMMANDS[name][0]}")


def requested_command(argv: Sequence[str]) -> str | None:
    """The subcommand an argument list asks for: its first word that is not an option (the options
    before a subcommand, ``-q`` and ``-h``, take no value); None when there is none or it is not a
    subcommand (argparse then prints the help or the error, as for any other parser)."""
    word = next((a for a in argv if not a.startswith("-")), None)
    return word if word in COMMANDS else None


def build_parser(commands: Iterable[str] | None = None) -> argparse.ArgumentParser:
    """The ``graspdef`` parser with the arguments of ``commands`` (default: every subcommand).

    Only their modules are imported, with ``run`` as ``func``; every other subcommand gets its
    one-line help alone, so ``--help`` still lists them all."""
    ap = argparse.ArgumentParser(prog="graspdef", description="Robot-grasp deformation simulator: "
                                 "Loop-subdivision Kirchhoff-Love thin shells.", epilog=EPILOG,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-q", "--quiet", action="store_true", help="no progress messages")
    sub = ap.add_subparsers(dest="command", required=True)
    full = set(COMMANDS if commands is None else commands)
    for name, (_, help_line) in COMMANDS.items():
        if name not in full:
            sub.add_parser(name, help=help_line)
            continue
        mod = command_module(name)
        p = sub.add_parser(name, help=help_line, description=mod.DESCRIPTION)
        mod.add_arguments(p)
        p.set_defaults(func=mod.run)
    return ap


#: a value that starts with a minus sign and a digit but is not a plain number ("-2MPa", "-10mm"):
#: argparse takes it for an option and says "expected one argument" (plain numbers it accepts)
_NEGATIVE_VALUE = re.compile(r"-\.?\d")
_PLAIN_NUMBER = re.compile(r"-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def join_negative_values(argv: list[str]) -> list[str]:
    """``--opt -2MPa`` as ``--opt=-2MPa``: the value reaches the option (and its own check, e.g.
    "E must be positive") instead of argparse's "expected one argument"."""
    out: list[str] = []
    i = 0
    while i < len(argv):
        a = argv[i]
        if (a.startswith("--") and "=" not in a and i + 1 < len(argv) and _NEGATIVE_VALUE.match(argv[i + 1])
                and not _PLAIN_NUMBER.fullmatch(argv[i + 1])):
            out.append(f"{a}={argv[i + 1]}")
            i += 2
            continue
        out.append(a)
        i += 1
    return out


def main(argv: list[str] | None = None) -> int:
    """``graspdef ...``: parse, run the subcommand; a GraspdefError or OSError is one line and
    exit status 2."""
    return _main(argv)[0]


def _main(argv: list[str] | None) -> tuple[int, argparse.Namespace | None]:
    argv = join_negative_values(sys.argv[1:] if argv is None else list(argv))
    command = requested_command(argv)
    args = build_parser([command] if command else []).parse_args(argv)
    from .. import runtime

    runtime.configure()             # before any numerical runtime starts (graspdef.runtime)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    try:
        return args.func(args), args
    except (GraspdefError, OSError) as exc:
        print(f"graspdef: error: {exc}", file=sys.stderr)
        return 2, args


def console() -> None:
    """The ``graspdef`` console script: :func:`main`, then the process ends with its status.
    (MKL's out-of-core mode, which crashed processes at exit, runs in a worker process of its own:
    graspdef.solve.pardiso_ooc.)"""
    rc, _ = _main(None)
    sys.exit(rc)


if __name__ == "__main__":
    console()
