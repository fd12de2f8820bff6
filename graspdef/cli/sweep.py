"""``graspdef sweep SPEC.toml --out DIR [--workers N | --scheduler tcp://HOST:PORT]``
(kept free of heavy imports: the parser is built at start-up)."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import ProblemError
from ._common import progress

DESCRIPTION = ("Run every case of a sweep spec (TOML) in parallel -- an embedded local cluster, or a dask.distributed "
               "cluster with --scheduler -- into a resumable sweep folder: one run folder per case, results.csv and "
               "summary.md.")


EPILOG = """examples:
  graspdef sweep sweeps/smoke.toml --out out/sweep_smoke        # embedded local cluster, 2 worker processes
  graspdef sweep out/sweep_smoke                                # resume: finished and failed cases are kept
  graspdef sweep sweeps/table1.toml --out /shared/t1 --scheduler tcp://head:8786

a spec (docs/sweep.md):
  [grid]
  scenes = ["tennis_ball"]
  forces_N = [10.63, 21.48]
  materials = ["linear", "rubber_air"]      # built-in: linear, nonlinear
  control_faces = [320, 1280]               # optional mesh levels
  [materials.rubber_air]
  analysis = "nonlinear"
  gas = "on"
"""


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.epilog = EPILOG
    ap.formatter_class = argparse.RawDescriptionHelpFormatter
    ap.add_argument("spec", help="sweep spec (.toml), or an existing sweep folder to resume (its spec.toml)")
    ap.add_argument("--out", help="sweep folder (created, or resumed: finished cases are not recomputed); "
                                  "default: the folder given as SPEC")
    where = ap.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=2,
                       help="worker processes of the embedded local cluster (default 2; 1 thread each)")
    where.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                       help="run on this dask.distributed cluster instead (workers need graspdef and the "
                            "sweep folder on a shared filesystem)")
    ap.add_argument("--retry-failed", action="store_true", help="rerun cases recorded as failed")
    ap.add_argument("--parquet", action="store_true", help="also write results.parquet (needs pyarrow)")
    ap.add_argument("--connect-timeout", type=float, default=5.0, metavar="S",
                    help="seconds to wait for the scheduler and its first worker (default 5)")


def run(args: argparse.Namespace) -> int:
    """Run the sweep for parsed arguments; prints one line (the summary); 0 when every case is
    done, 1 when some failed (their errors are in summary.md and results.csv)."""
    from ..sweep.run import run_sweep
    from ..sweep.spec import load_spec

    src = Path(args.spec)
    if src.is_dir():
        if not (src / "spec.toml").is_file():
            raise ProblemError(f"{src} is a folder without spec.toml: give a sweep spec file or a sweep folder")
        spec_file, out = src / "spec.toml", Path(args.out or src)
    else:
        if not args.out:
            raise ProblemError("give --out DIR (the sweep folder) for a new sweep")
        spec_file, out = src, Path(args.out)
    spec = load_spec(spec_file)
    res = run_sweep(spec, out, scheduler=args.scheduler, workers=args.workers, retry_failed=args.retry_failed,
                    parquet=args.parquet, connect_timeout=args.connect_timeout,
                    progress=lambda m: progress(args, m))
    print(f"{spec.name}: {res.n_done} done, {res.n_failed} failed of {res.n_cases} cases "
          f"({res.n_run} run now, {res.n_skipped} reused); {res.out / 'results.csv'}, {res.out / 'summary.md'}")
    return 0 if res.n_failed == 0 and res.n_done == res.n_cases else 1
