"""``graspdef bench linear|nonlinear|axisym|kernels [--json FILE] [--out DIR]``: run a benchmark set."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from ._common import progress

DESCRIPTION = "run a benchmark set and print/write the comparison table"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("set", choices=["linear", "nonlinear", "axisym", "kernels"],
                   help="which benchmark set (kernels: the compiled kernels' ahead-of-time build against "
                        "numba's JIT build on small solves, which also warms numba's on-disk cache)")
    p.add_argument("--json", help="write the records to this JSON file")
    p.add_argument("--dir", help="folder with the benchmark problem files (default: the repository's "
                                 "benchmarks/, benchmarks/nonlinear/)")
    p.add_argument("--only", default="*", help="glob of benchmark names to run")
    p.add_argument("--out", help="also write a run folder: bench.json, table.md, provenance.json")


def run(args: argparse.Namespace) -> int:
    from ..bench import format_table, run_linear_benchmarks, run_nonlinear_benchmarks

    def say(m: str) -> None:
        progress(args, m)

    if args.set == "kernels":
        return _kernels(args, say)
    root = Path(args.dir) if args.dir else Path(__file__).resolve().parents[2] / "benchmarks"
    if args.set == "linear":
        records = run_linear_benchmarks(root, pattern=args.only, progress=say)
    elif args.set == "nonlinear":
        records = run_nonlinear_benchmarks(root / "nonlinear" if not args.dir else root, pattern=args.only,
                                           progress=say)
    else:
        from ..axisym.bench import run_axisym_bench

        records = run_axisym_bench(progress=say)
    print(format_table(records))
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(records, indent=2, default=float) + "\n")
        say(f"wrote {args.json}")
    if args.out:
        from ..runs.folder import atomic_folder
        from ..runs.provenance import write_provenance

        with atomic_folder(args.out) as tmp:
            (tmp / "bench.json").write_text(json.dumps(records, indent=2, default=float) + "\n")
            (tmp / "table.md").write_text(format_table(records) + "\n")
            write_provenance(tmp, {"set": args.set, "dir": str(root), "only": args.only})
        say(f"wrote {args.out}/ (bench.json, table.md, provenance.json)")
    failed = [r["name"] for r in records if not r.get("passed", True)]
    if failed:
        say(f"outside tolerance: {', '.join(failed)}")
    return 0


def _kernels(args: argparse.Namespace, say) -> int:
    """``graspdef bench kernels``: one line per ahead-of-time export (equal to the JIT build to the
    bit or not, both builds' time on the recorded arguments); exit status 1 if any differs or no
    small solve reached one, 2 (one line) if the ahead-of-time module is not usable."""
    from ..bench import check_kernels
    from ..errors import ProblemError

    for flag, value in (("--dir", args.dir), ("--only", None if args.only == "*" else args.only)):
        if value is not None:
            raise ProblemError(f"bench kernels: {flag} does not apply (it runs its own small solves)")
    out = check_kernels(progress=say)
    if not out["records"] and out["missing"]:
        raise ProblemError(out["status"])
    print(out["status"])
    for r in out["records"]:
        print(f"{'equal' if r['equal'] else 'DIFFERENT':9s}  {r['export']:45s} ahead of time {r['aot_s'] * 1e3:8.2f} ms"
              f"   JIT {r['jit_s'] * 1e3:8.2f} ms")
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(out, indent=2) + "\n")
    if args.out:
        from ..runs.folder import atomic_folder
        from ..runs.provenance import write_provenance

        with atomic_folder(args.out) as tmp:
            (tmp / "kernels.json").write_text(json.dumps(out, indent=2) + "\n")
            write_provenance(tmp, {"set": "kernels"})
        say(f"wrote {args.out}/ (kernels.json, provenance.json)")
    bad = [r["export"] for r in out["records"] if not r["equal"]]
    if bad or out["missing"]:
        say(f"differ from the JIT build: {', '.join(bad) or 'none'}; not reached: {', '.join(out['missing']) or 'none'}")
        return 1
    say(f"all {len(out['records'])} ahead-of-time exports equal the JIT build to the bit")
    return 0
