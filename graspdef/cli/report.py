"""``graspdef report RUN_DIR [RUN_DIR ...] [--out FILE] [--scan ID_or_FILE] [--table FILE]``, or
``graspdef report RANK_DIR [--out FILE]`` for a ranking folder (graspdef rank --out)."""
from __future__ import annotations

import argparse

from ._common import progress, warn

DESCRIPTION = ("One HTML page (pictures inlined, no external URL): the deformed surface coloured by displacement and "
               "by scan error, load-deflection and convergence plots, and a table in the layout of Tian & Jia's "
               "Table I for several grasp runs. A ranking folder (graspdef rank --out) gets its own page: summary, top ten, "
               "compliance map, Pareto front, rigid baseline, nonlinear re-check; figures also as PNG files beside it.")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The ``report`` sub-command's arguments (call on the sub-parser)."""
    p.add_argument("run_dirs", nargs="*", metavar="RUN_DIR",
                   help="run folders (graspdef solve/grasp --out); several grasp runs make the Table I comparison; "
                        "or one ranking folder (graspdef rank --out)")
    p.add_argument("--out", help="HTML file to write (default: RUN_DIR/report.html of the first run; a ranking's "
                                  "figures go to <stem>_figures/ beside it)")
    p.add_argument("--scan", metavar="ID_or_FILE",
                   help="score every run against this scan first (a scan file or a scans/manifest.toml id); "
                        "written to RUN_DIR/score")
    p.add_argument("--scan-units", help="length unit of the scan file (default: its 'comment units' line)")
    p.add_argument("--surface-offset-mm", type=float, default=None,
                   help="mid-surface to scanned-surface offset for --scan [mm] (default: half the grasp run's "
                        "shell thickness, else 0)")
    p.add_argument("--table", metavar="FILE",
                   help="CSV with columns run[,force_N][,measured_mm]: more run folders for the Table I "
                        "comparison (paths relative to the CSV)")
    p.add_argument("--title", help="page title")


def run(args: argparse.Namespace) -> int:
    """Write the report; 0, or 1 if a score is flagged (the page is written and says so).  Errors
    are GraspdefError subclasses (one line, exit status 2 in graspdef's main)."""
    from ..report.build import build_report

    def say(msg: str) -> None:
        progress(args, msg)

    flagged: list = []
    out = build_report(args.run_dirs, args.out, scan=args.scan, table=args.table, title=args.title,
                       surface_offset_mm=args.surface_offset_mm, scan_units=args.scan_units, progress=say,
                       flagged=flagged)
    say(f"wrote {out}")
    for run_dir, flags in flagged:       # like 'graspdef score': a flagged score is exit status 1
        warn(f"the score of {run_dir} is flagged ({', '.join(flags) or 'ok = false'}); the report shows it")
    return 1 if flagged else 0

