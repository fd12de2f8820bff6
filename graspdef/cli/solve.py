"""``graspdef solve PROBLEM.toml --out DIR``: solve one problem file (linear or a nonlinear path)."""
from __future__ import annotations

import argparse
import time
from pathlib import Path

from ._common import progress, warn

DESCRIPTION = "Solve a problem file and write result.json, deformed.ply and a copy of the problem into --out."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("problem", help="problem file (.toml)")
    p.add_argument("--out", required=True, help="output folder (replaced if it exists)")
    p.add_argument("--backend", choices=["auto", "pardiso", "pardiso-ooc", "superlu"],
                   help="sparse solver (pardiso-ooc: PARDISO with its factor on disk, for problems larger than memory)")


def _path_progress(args: argparse.Namespace, info: dict) -> None:
    st = {True: "stable", False: "UNSTABLE", None: "stability n/a"}[info["stable"]]
    arc = f", arc length {info['arc_length']:.3g}" if "arc_length" in info else ""
    progress(args, f"  point {info['step']:4d} ({info['kind']}): load factor {info['load_factor']:.6g}, "
                   f"{info['iterations']} Newton iterations, {st}{arc}, {info['seconds']:.1f} s")


def run(args: argparse.Namespace) -> int:
    from ..problem.config import load_problem
    from ..solve.output import result_record, write_run

    from ..runs.folder import check_output_folder

    check_output_folder(args.out)                 # before any work, not after the solve
    t0 = time.perf_counter()
    progress(args, f"reading {args.problem}")
    spec = load_problem(args.problem, backend=args.backend)
    spec.problem.check_self_equilibrated(where=str(args.problem))
    shell = spec.problem.shell
    progress(args, f"shell: {shell.mesh.n_real} control vertices (+{shell.n_control - shell.mesh.n_real} ghosts), "
                   f"{shell.mesh.n_real_faces} faces; set-up {time.perf_counter() - t0:.2f} s")
    backend = args.backend or spec.backend
    unit = spec.length_unit
    stopped = None
    if spec.solver.get("type", "linear") == "nonlinear":
        from ..solve.nonlinear import BRACKET_NOT_NARROWED, PathStopped, path_options, solve_nonlinear

        try:
            sol = solve_nonlinear(spec.problem, path_options(spec.solver), backend=backend,
                                  progress=lambda info: _path_progress(args, info), precision=spec.precision)
        except PathStopped as exc:
            if not exc.solution.path:                # nothing converged (refused at zero load): nothing to write
                raise
            sol, stopped = exc.solution, exc
        single = (f" ({sol.n_single} in single precision, refined in double; {sol.n_certificates} of their "
                  "inertias certified before use, a failed one refactorised in double)" if sol.n_single else "")
        progress(args, f"path: {len(sol.path) - 1} points, {sol.n_factorisations} factorisations{single}, "
                       f"{sol.timings.get('total', 0.0):.1f} s")
        for cp in sol.critical_points:
            jump = cp.get("jump")
            progress(args, f"{cp['kind']} at load factor {cp['load_factor']:.6g} "
                           f"(negative eigenvalues {cp['instability_before']} -> {cp['instability_after']})"
                           + ("" if jump is None else f"; the path jumped to the equilibrium at load factor "
                              f"{jump['to_load_factor']:.6g}, the largest control point moving "
                              f"{jump['largest_control_point_move'] / spec.length_scale:.4g} {unit}"))
        for ev in sol.events:
            if ev.get("action") == BRACKET_NOT_NARROWED:
                progress(args, f"a critical point's bracket from load factor {ev['from_load_factor']:.6g} was not "
                               f"narrowed further: {ev['reason']}")
    else:
        from ..solve.linear import solve_linear

        sol = solve_linear(spec.problem, backend=backend, precision=spec.precision)
        progress(args, "solved: " + ", ".join(f"{k} {v:.2f} s" for k, v in sol.timings.items())
                 + ("; a single-precision factor, refined in double" if sol.kkt.precision == "mixed" else ""))
    out = write_run(args.out, spec, sol, Path(args.problem).read_text())
    rec = result_record(spec, sol)
    ls = spec.length_scale                 # the record is SI; the lines speak the problem file's unit
    for name, p in rec["probes"].items():
        progress(args, f"probe {name}: u = [{', '.join(f'{c / ls:.6g}' for c in p['displacement'])}] {unit}")
    files = "result.json, deformed.ply, undeformed.ply" + (", path.csv" if rec["analysis"] == "nonlinear" else "")
    for w in rec.get("warnings", []):
        warn(w)
    md = rec.derived["max_displacement"]
    progress(args, f"{md['label']} {md['value'] / ls:.6g} {unit}; wrote {out}/ ({files}, SI units)")
    if stopped is not None:
        raise stopped.__class__(f"{stopped} (the converged part of the path is in {out})", stopped.solution)
    return 0
