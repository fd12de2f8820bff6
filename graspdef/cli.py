"""The ``graspdef`` command line.

    graspdef solve PROBLEM.toml --out DIR      solve one problem file (linear or nonlinear path)
    graspdef bench linear|nonlinear|axisym [--json FILE]   run a benchmark set, print the table
    graspdef grasp SCENE --force F --out DIR   MuJoCo grasp, contacts mapped onto the shell, solved
    graspdef score PREDICTION SCAN --out DIR   register a scan to a predicted surface, score it
    graspdef view RUN_DIR [RUN_DIR ...] [--host H] [--port P]   browse run folders (viser)
    graspdef report RUN_DIR [RUN_DIR ...] [--scan SCAN] [--out FILE]   self-contained HTML report
    graspdef sweep SPEC.toml --out DIR [--workers N | --scheduler tcp://HOST:PORT]   a grid of grasps

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
  graspdef solve benchmarks/nonlinear/cantilever_moment.toml --out out/rollup
  graspdef bench nonlinear --json out/bench_nonlinear.json
  graspdef score out/ball/deformed.ply ycb_056_tennis_ball --out out/ball_score
  graspdef grasp tennis_ball --force 21.48 --out out/grasp_tennis_ball
  graspdef view out/plate out/rollup --port 8080
  graspdef report out/grasp_tennis_ball                            # -> out/grasp_tennis_ball/report.html
  graspdef sweep sweeps/smoke.toml --out out/sweep_smoke            # local, 2 worker processes
  graspdef sweep sweeps/smoke.toml --out /shared/sweep --scheduler tcp://10.0.0.5:8786
"""


def _solve(args: argparse.Namespace) -> int:
    from .problem.config import load_problem
    from .solve.output import result_record, write_run

    t0 = time.perf_counter()
    _progress(args, f"reading {args.problem}")
    spec = load_problem(args.problem)
    shell = spec.problem.shell
    _progress(args, f"shell: {shell.mesh.n_real} control vertices (+{shell.n_control - shell.mesh.n_real} ghosts), "
                    f"{shell.mesh.n_real_faces} faces; set-up {time.perf_counter() - t0:.2f} s")
    backend = args.backend or spec.backend
    unit = spec.length_unit
    stopped = None
    if spec.solver.get("type", "linear") == "nonlinear":
        from .solve.nonlinear import PathStopped, path_options, solve_nonlinear

        sol, stopped = None, None
        try:
            sol = solve_nonlinear(spec.problem, path_options(spec.solver), backend=backend,
                                  progress=lambda info: _path_progress(args, info))
        except PathStopped as exc:
            sol, stopped = exc.solution, exc
        _progress(args, f"path: {len(sol.path) - 1} points, {sol.n_factorisations} factorisations, "
                        f"{sol.timings.get('total', 0.0):.1f} s")
        for cp in sol.critical_points:
            _progress(args, f"{cp['kind']} at load factor {cp['load_factor']:.6g} "
                            f"(negative eigenvalues {cp['instability_before']} -> {cp['instability_after']})")
    else:
        from .solve.linear import solve_linear

        sol = solve_linear(spec.problem, backend=backend)
        _progress(args, "solved: " + ", ".join(f"{k} {v:.2f} s" for k, v in sol.timings.items()))
    out = write_run(args.out, spec, sol, Path(args.problem).read_text())
    rec = result_record(spec, sol)
    for name, p in rec["probes"].items():
        _progress(args, f"probe {name}: u = [{', '.join(f'{c:.6g}' for c in p['displacement'])}] {unit}")
    files = "result.json, deformed.ply, undeformed.ply" + (", path.csv" if rec["analysis"] == "nonlinear" else "")
    _progress(args, f"max displacement {rec['max_displacement']:.6g} {unit}; wrote {out}/ ({files})")
    if stopped is not None:
        raise stopped.__class__(f"{stopped} (the converged part of the path is in {out})", stopped.solution)
    return 0


def _path_progress(args: argparse.Namespace, info: dict) -> None:
    st = {True: "stable", False: "UNSTABLE", None: "stability n/a"}[info["stable"]]
    arc = f", arc length {info['arc_length']:.3g}" if "arc_length" in info else ""
    _progress(args, f"  point {info['step']:4d} ({info['kind']}): load factor {info['load_factor']:.6g}, "
                    f"{info['iterations']} Newton iterations, {st}{arc}, {info['seconds']:.1f} s")


def _bench(args: argparse.Namespace) -> int:
    from .bench import format_table, run_linear_benchmarks, run_nonlinear_benchmarks

    say = lambda m: _progress(args, m)  # noqa: E731
    root = Path(args.dir) if args.dir else Path(__file__).resolve().parent.parent / "benchmarks"
    if args.set == "linear":
        records = run_linear_benchmarks(root, pattern=args.only, progress=say)
    elif args.set == "nonlinear":
        records = run_nonlinear_benchmarks(root / "nonlinear" if not args.dir else root, pattern=args.only, progress=say)
    else:
        from .axisym.bench import run_axisym_bench

        records = run_axisym_bench(progress=say)
    print(format_table(records))
    if args.json:
        import json
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(records, indent=2, default=float) + "\n")
        _progress(args, f"wrote {args.json}")
    if args.out:
        import json

        from .geometry.io import atomic_folder
        from .geometry.provenance import write_provenance

        with atomic_folder(args.out) as tmp:
            (tmp / "bench.json").write_text(json.dumps(records, indent=2, default=float) + "\n")
            (tmp / "table.md").write_text(format_table(records) + "\n")
            write_provenance(tmp, {"set": args.set, "dir": str(root), "only": args.only})
        _progress(args, f"wrote {args.out}/ (bench.json, table.md, provenance.json)")
    failed = [r["name"] for r in records if not r.get("passed", True)]
    if failed:
        _progress(args, f"outside tolerance: {', '.join(failed)}")
    return 0


def _score(args: argparse.Namespace) -> int:
    from .registration import score_cli

    rec = score_cli(args.prediction, args.scan, args.out, undeformed_path=args.undeformed,
                    prediction_units=args.prediction_units, scan_units=args.scan_units,
                    init=args.init, region=args.region, surface_offset_mm=args.surface_offset_mm)
    print(rec["summary"])
    if not rec["ok"]:
        _progress(args, f"the score is flagged ({', '.join(rec.get('flags', [])) or 'see score.json'}); "
                        f"wrote {args.out}/score.json")
        return 1
    return 0


def _grasp(args: argparse.Namespace) -> int:
    from .pipeline.grasp import run_from_args

    return run_from_args(args)


def _view(args: argparse.Namespace) -> int:
    from .viewer import viewer_cli

    return viewer_cli(args)


def _report(args: argparse.Namespace) -> int:
    from .report.cli import run as report_run

    return report_run(args)


def _sweep(args: argparse.Namespace) -> int:
    from .sweep.cli import run_from_args

    return run_from_args(args, progress=lambda m: _progress(args, m))


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
    b.add_argument("set", choices=["linear", "nonlinear", "axisym"], help="which benchmark set")
    b.add_argument("--json", help="write the records to this JSON file")
    b.add_argument("--dir", help="folder with the benchmark problem files (default: the repository's "
                                  "benchmarks/, benchmarks/nonlinear/)")
    b.add_argument("--only", default="*", help="glob of benchmark names to run")
    b.add_argument("--out", help="also write a run folder: bench.json, table.md, provenance.json")
    b.set_defaults(func=_bench)
    c = sub.add_parser("score", help="register a scan to a predicted surface and score it (score.json)",
                       description="Rigid registration (open3d ICP) of a scan to a predicted surface; writes "
                                   "score.json and per-vertex errors, with the undeformed shape as the baseline.")
    c.add_argument("prediction", help="predicted surface (a run folder's deformed.ply)")
    c.add_argument("scan", help="scan file or a scans/manifest.toml id (e.g. ycb_056_tennis_ball)")
    c.add_argument("--out", required=True, help="output folder")
    c.add_argument("--undeformed", help="undeformed surface (default: undeformed.ply beside the prediction)")
    c.add_argument("--prediction-units", help="length unit of the prediction file (default: its 'comment units')")
    c.add_argument("--scan-units", help="length unit of the scan file")
    c.add_argument("--init", default="pca", choices=["pca", "centroid", "identity"], help="coarse alignment")
    c.add_argument("--region", help="undeformed region to align on, e.g. 'z < -10' (prediction units)")
    c.add_argument("--surface-offset-mm", type=float, default=0.0, help="mid-surface to outer-surface offset [mm]")
    c.set_defaults(func=_score)
    from .pipeline.cli_args import add_grasp_arguments
    gr = sub.add_parser("grasp", help="MuJoCo grasp -> contacts -> shell deformation (a run folder)",
                        description="Close the scene's gripper to the force per finger, settle, map the contacts "
                                    "onto the object's shell and solve; writes a run folder.")
    add_grasp_arguments(gr)
    gr.set_defaults(func=_grasp)
    from .viewer.cli import add_arguments as add_view_arguments
    w = sub.add_parser("view", help="serve run folders in the browser (viser on 127.0.0.1:8080)",
                       description="Serve run folders as a viser page (127.0.0.1 unless --host); Ctrl-C stops it.")
    add_view_arguments(w)
    w.set_defaults(func=_view)
    from .report.cli import add_arguments as add_report_arguments
    rp = sub.add_parser("report", help="write a self-contained HTML report of run folders (report.html)",
                        description="One HTML page (pictures inlined, no external URL): the deformed surface coloured "
                                    "by displacement and by scan error, load-deflection and convergence plots, and "
                                    "a table in the layout of Tian & Jia's Table I for several grasp runs.")
    add_report_arguments(rp)
    rp.set_defaults(func=_report)
    from .sweep.cli import add_arguments as add_sweep_arguments
    sw = sub.add_parser("sweep", help="run a grid of grasps (objects x forces x materials x contacts x meshes)",
                        description="Run every case of a sweep spec (TOML) in parallel -- an embedded local cluster, "
                                    "or a dask.distributed cluster with --scheduler -- into a resumable sweep folder: "
                                    "one run folder per case, results.csv and summary.md.")
    add_sweep_arguments(sw)
    sw.set_defaults(func=_sweep)
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
