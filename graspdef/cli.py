"""The ``graspdef`` command line.

    graspdef solve PROBLEM.toml --out DIR      solve one problem file, write a run folder
    graspdef bench linear [--json FILE]        run the linear benchmark set, print the table

Every error a user can cause prints one line ``graspdef: error: ...`` and exits with status 2.
"""
from __future__ import annotations

import argparse
import logging
import sys
import time
from pathlib import Path

from .errors import GraspdefError

EPILOG = """examples:
  graspdef solve benchmarks/plate_ss_uniform.toml --out out/plate
  graspdef bench linear --json out/bench_linear.json
"""


def _solve(args: argparse.Namespace) -> int:
    from .problem.config import load_problem
    from .solve.linear import solve_linear
    from .solve.output import result_record, write_run

    t0 = time.perf_counter()
    _progress(args, f"reading {args.problem}")
    spec = load_problem(args.problem)
    shell = spec.problem.shell
    _progress(args, f"shell: {shell.mesh.n_real} control vertices (+{shell.n_control - shell.mesh.n_real} ghosts), "
                    f"{shell.mesh.n_real_faces} faces; set-up {time.perf_counter() - t0:.2f} s")
    sol = solve_linear(spec.problem, backend=args.backend or spec.backend)
    _progress(args, "solved: " + ", ".join(f"{k} {v:.2f} s" for k, v in sol.timings.items()))
    out = write_run(args.out, spec, sol, Path(args.problem).read_text())
    rec = result_record(spec, sol)
    unit = spec.length_unit
    for name, p in rec["probes"].items():
        _progress(args, f"probe {name}: u = [{', '.join(f'{c:.6g}' for c in p['displacement'])}] {unit}")
    _progress(args, f"max displacement {rec['max_displacement']:.6g} {unit}; wrote {out}/result.json, deformed.ply")
    return 0


def _bench(args: argparse.Namespace) -> int:
    from .bench import format_table, run_linear_benchmarks

    records = run_linear_benchmarks(Path(args.dir), pattern=args.only, progress=lambda m: _progress(args, m))
    print(format_table(records))
    if args.json:
        import json
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(records, indent=2) + "\n")
        _progress(args, f"wrote {args.json}")
    failed = [r["name"] for r in records if not r["passed"]]
    if failed:
        _progress(args, f"outside tolerance: {', '.join(failed)}")
    return 0


def _progress(args: argparse.Namespace, msg: str) -> None:
    if not getattr(args, "quiet", False):
        print(f"[graspdef] {msg}", file=sys.stderr, flush=True)


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="graspdef", description="Robot-grasp deformation simulator: "
                                 "Loop-subdivision Kirchhoff-Love thin shells.", epilog=EPILOG,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-q", "--quiet", action="store_true", help="no progress messages")
    sub = ap.add_subparsers(dest="command", required=True)
    s = sub.add_parser("solve", help="solve a problem file (TOML) and write a run folder",
                       description="Solve a problem file and write result.json, deformed.ply and a copy "
                                   "of the problem into --out.")
    s.add_argument("problem", help="problem file (.toml)")
    s.add_argument("--out", required=True, help="output folder (replaced if it exists)")
    s.add_argument("--backend", choices=["auto", "pardiso", "superlu"], help="sparse solver")
    s.set_defaults(func=_solve)
    b = sub.add_parser("bench", help="run a benchmark set and print/write the comparison table")
    b.add_argument("set", choices=["linear"], help="which benchmark set")
    b.add_argument("--json", help="write the records to this JSON file")
    b.add_argument("--dir", default=str(Path(__file__).resolve().parent.parent / "benchmarks"),
                   help="folder with the benchmark problem files")
    b.add_argument("--only", default="*", help="glob of benchmark names to run")
    b.set_defaults(func=_bench)
    return ap


def main(argv: list[str] | None = None) -> int:
    ap = build_parser()
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    try:
        return args.func(args)
    except GraspdefError as exc:
        print(f"graspdef: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"graspdef: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
