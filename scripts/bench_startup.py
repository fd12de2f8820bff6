"""Start-up times, old code against new, in one run (issue 17): whole processes of

* ``graspdef --help`` (what the console script runs: ``graspdef.cli.console``, ``main`` in trees before it),
* ``python -c "import graspdef"``,
* ``graspdef -q solve benchmarks/plate_ss_uniform.toml`` (the Tian & Jia plate, 40 x 40 faces:
  1,681 control vertices; reading, set-up, assembly, PARDISO solve, run folder),

for the OLD code (a git ref, default ``main``, checked out with ``git worktree add`` into a temporary
folder) and the NEW code (this working tree), with the same Python, each tree on ``PYTHONPATH`` and
as the working directory.  Each case runs once untimed first (numba's on-disk cache is compiled
there: ~20 s for a fresh checkout), then ``--repeats`` times, OLD and NEW alternating so that the
load of a shared machine falls on both; medians are reported, with the least wall time and the median CPU time (user + system of all
the process's threads: less sensitive to other work than the wall clock).  Both trees are byte-compiled first
(``compileall``), as an installed package is, unless ``--no-compile``: with PYTHONDONTWRITEBYTECODE
set, graspdef's own modules would otherwise be compiled from source in every process (~0.1 s).

Then ``python -X importtime`` runs of each case and tree (``--importtime-repeats``, the one of least
total kept: the load of other work only adds): the total import time (less noisy than the wall clock) and the biggest imports left.
The plate's centre deflection and largest displacement must agree in OLD and NEW (to 1e-10 of them:
the run-to-run rounding of the threaded solve; the lazy imports change no number).

Prints a table and writes ``bench_startup.json`` to ``--out``.  Times are of a shared machine:
indicative only.

    python scripts/bench_startup.py [--ref main] [--repeats 5] [--top 12] [--out out/bench_startup]
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PLATE = "benchmarks/plate_ss_uniform.toml"
#: OLD and NEW plate results must agree to this fraction: the threaded solve (numba, PARDISO) may sum
#: in another order from run to run, ~1e-13 of the deflection (single-threaded, both are equal to the
#: bit: tests/test_startup.py)
SAME_RTOL = 1e-10
#: what the ``graspdef`` console script runs
CLI = ("import sys\nsys.argv[0] = 'graspdef'\ntry:\n    from graspdef.cli import console\nexcept ImportError:\n"
       "    from graspdef.cli import main\n    sys.exit(main())\nconsole()")


def cases(out: Path) -> dict[str, list[str]]:
    """Case name -> the interpreter arguments (after ``python``)."""
    return {"graspdef --help": ["-c", CLI, "--help"],
            "import graspdef": ["-c", "import graspdef"],
            "plate solve (1,681 control vertices)": ["-c", CLI, "-q", "solve", PLATE, "--out", str(out / "plate")]}


def run(python: str, tree: Path, args: list[str],
        extra: tuple[str, ...] = ()) -> tuple[float, float, subprocess.CompletedProcess]:
    """Wall time and CPU time (user + system, all its threads) [s] of one whole process
    ``python *extra *args`` run in ``tree``."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    r = subprocess.run([python, *extra, *args], cwd=tree, env=env, capture_output=True, text=True, check=False)
    dt = time.perf_counter() - t0
    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (c1.ru_utime - c0.ru_utime) + (c1.ru_stime - c0.ru_stime)
    if r.returncode != 0:
        raise SystemExit(f"bench_startup: {' '.join(args[:1] + args[2:])} failed in {tree}:\n{r.stderr[-2000:]}")
    return dt, cpu, r


def import_times(stderr: str) -> list[tuple[int, int, int, str]]:
    """``-X importtime`` lines as (self us, cumulative us, depth, module)."""
    rows = []
    for line in stderr.splitlines():
        if not line.startswith("import time:") or "imported package" in line:
            continue
        self_us, cum_us, name = line[len("import time:"):].split("|")
        depth = (len(name) - len(name.lstrip(" ")) - 1) // 2
        rows.append((int(self_us), int(cum_us), depth, name.strip()))
    return rows


def package(module: str) -> str:
    """The package an import is charged to: the top-level name (scipy by subpackage)."""
    parts = module.split(".")
    return ".".join(parts[:2]) if parts[0] in ("scipy", "graspdef") and len(parts) > 1 else parts[0]


def import_summary(rows: list[tuple[int, int, int, str]], top: int) -> dict:
    """Total import time, the biggest top-level imports (cumulative) and packages (summed self time)."""
    by_pkg: dict[str, int] = {}
    for s, _, _, name in rows:
        by_pkg[package(name)] = by_pkg.get(package(name), 0) + s
    roots = sorted(((c, name) for _, c, d, name in rows if d == 0), reverse=True)
    return {"total_ms": sum(s for s, *_ in rows) / 1e3, "modules": len(rows),
            "top_level_ms": {name: c / 1e3 for c, name in roots[:top]},
            "packages_ms": {k: v / 1e3 for k, v in sorted(by_pkg.items(), key=lambda kv: -kv[1])[:top]}}


def git(*args: str) -> str:
    return subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True, text=True, check=True).stdout.strip()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ref", default="main", help="git ref of the OLD code (default main)")
    ap.add_argument("--repeats", type=int, default=5, help="timed runs per case and tree (default 5)")
    ap.add_argument("--importtime-repeats", type=int, default=5,
                    help="-X importtime runs per case and tree; the one of least total is kept (default 5)")
    ap.add_argument("--top", type=int, default=12, help="imports listed per case (default 12)")
    ap.add_argument("--no-compile", action="store_true", help="do not byte-compile the two trees first")
    ap.add_argument("--out", default="out/bench_startup", help="folder for bench_startup.json")
    a = ap.parse_args()
    python = sys.executable
    old_commit = git("rev-parse", a.ref)
    tmp = Path(tempfile.mkdtemp(prefix="bench_startup_"))
    old_tree = tmp / "old"
    git("worktree", "add", "--detach", str(old_tree), old_commit)
    try:
        trees = {"old": old_tree, "new": ROOT}
        outs = {k: tmp / f"out_{k}" for k in trees}
        for k, tree in trees.items():
            if not a.no_compile:
                subprocess.run([python, "-m", "compileall", "-q", str(tree / "graspdef")], check=True,
                               capture_output=True)
            *_, r = run(python, tree, ["-c", "import graspdef; print(graspdef.__file__)"])
            assert Path(r.stdout.strip()).is_relative_to(tree), (k, r.stdout)       # the tree, not an install
        results = {}
        for case in cases(tmp):
            print(f"{case}: warm-up, then {a.repeats} runs of each tree ...", file=sys.stderr, flush=True)
            times: dict[str, list[float]] = {"old": [], "new": []}
            cpu: dict[str, list[float]] = {"old": [], "new": []}
            imports = {}
            for k, tree in trees.items():
                run(python, tree, cases(outs[k])[case])                         # warm-up (numba cache, OS cache)
            for _ in range(a.repeats):
                for k, tree in trees.items():
                    dt, c, _ = run(python, tree, cases(outs[k])[case])
                    times[k].append(dt)
                    cpu[k].append(c)
            for k, tree in trees.items():          # the run of least total import time (noise only adds)
                runs = [import_summary(import_times(run(python, tree, cases(outs[k])[case],
                                                        extra=("-X", "importtime"))[2].stderr), a.top)
                        for _ in range(a.importtime_repeats)]
                imports[k] = min(runs, key=lambda x: x["total_ms"])
                imports[k]["totals_ms"] = [x["total_ms"] for x in runs]
            results[case] = {k: {"runs_s": times[k], "median_s": statistics.median(times[k]), "min_s": min(times[k]),
                                 "cpu_runs_s": cpu[k], "cpu_median_s": statistics.median(cpu[k]),
                                 "import_time": imports[k]} for k in trees}
        plate = {}
        for k in trees:
            rec = json.loads((outs[k] / "plate" / "result.json").read_text())
            plate[k] = {"n_control": rec["n_control"], "u_centre": rec["probes"]["centre"]["displacement"],
                        "max_displacement": rec["derived"]["max_displacement"]["value"]}
        ref = abs(plate["new"]["max_displacement"])
        diff = max(abs(a - b) for a, b in zip([plate["old"]["max_displacement"], *plate["old"]["u_centre"]],
                                               [plate["new"]["max_displacement"], *plate["new"]["u_centre"]]))
        plate["max_rel_difference"] = diff / ref
        same = plate["old"]["n_control"] == plate["new"]["n_control"] and diff <= SAME_RTOL * ref
    finally:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(old_tree)], capture_output=True,
                       check=False)
        shutil.rmtree(tmp, ignore_errors=True)

    print(f"\nOLD = {a.ref} ({old_commit[:10]}), NEW = working tree ({git('rev-parse', 'HEAD')[:10]}"
          f"{', with changes' if git('status', '--porcelain', '--untracked-files=no', '--', 'graspdef') else ''}); "
          f"median (least) of {a.repeats} whole processes; imports: the sum of all -X importtime lines (least of {a.importtime_repeats} runs) and the number of modules\n")
    print("| case | OLD [s] | NEW [s] | OLD / NEW | CPU OLD / NEW [s] | OLD imports [ms] (modules) | "
          "NEW imports [ms] (modules) |")
    print("|---|---|---|---|---|---|---|")
    for case, r in results.items():
        o, n = r["old"], r["new"]
        print(f"| {case} | {o['median_s']:.3f} ({o['min_s']:.3f}) | {n['median_s']:.3f} ({n['min_s']:.3f}) | "
              f"{o['median_s'] / n['median_s']:.2f} | {o['cpu_median_s']:.3f} / {n['cpu_median_s']:.3f} | "
              f"{o['import_time']['total_ms']:.0f} ({o['import_time']['modules']}) | "
              f"{n['import_time']['total_ms']:.0f} ({n['import_time']['modules']}) |")
    print(f"\nplate ({plate['new']['n_control']} control vertices): OLD and NEW centre deflection and largest "
          f"displacement {'equal' if same else 'DIFFER'} to {plate['max_rel_difference']:.1e} of it "
          f"(u_centre = {plate['new']['u_centre'][2]:.10g}; limit {SAME_RTOL:g})")
    for case, r in results.items():
        imp = r["new"]["import_time"]
        print(f"\nNEW, {case}: biggest imports by package (self time summed) [ms]: "
              + ", ".join(f"{k} {v:.0f}" for k, v in imp["packages_ms"].items()))
        print("  imported by the program (cumulative) [ms]: "
              + ", ".join(f"{k} {v:.0f}" for k, v in imp["top_level_ms"].items()))
    record = {"date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
              "old": {"ref": a.ref, "commit": old_commit}, "new": {"commit": git("rev-parse", "HEAD")},
              "python": python, "python_version": sys.version.split()[0], "cpus": os.cpu_count(),
              "repeats": a.repeats, "importtime_repeats": a.importtime_repeats, "byte_compiled": not a.no_compile, "plate": PLATE,
              "plate_result_equal": same, "plate_result": plate,
              "cases": results}
    o = Path(a.out)
    o.mkdir(parents=True, exist_ok=True)
    (o / "bench_startup.json").write_text(json.dumps(record, indent=2) + "\n")
    print(f"\nwrote {o / 'bench_startup.json'}")
    if not same:
        raise SystemExit("bench_startup: the plate's result differs between OLD and NEW")


if __name__ == "__main__":
    main()
