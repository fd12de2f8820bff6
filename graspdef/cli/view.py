"""``graspdef view RUN_DIR [RUN_DIR ...] [--host HOST] [--port PORT] [--score DIR] [--no-live]``."""
from __future__ import annotations

import argparse

from ._common import progress

HELP = "serve run folders in the browser (viser on 127.0.0.1:8080)"
DESCRIPTION = "Serve run folders as a viser page (127.0.0.1 unless --host); Ctrl-C stops it."


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The ``view`` sub-command's arguments (call on the sub-parser)."""
    p.add_argument("run_dirs", nargs="+", metavar="RUN_DIR", help="run folders (graspdef solve --out), side by side")
    p.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1: this machine only)")
    p.add_argument("--port", type=int, default=8080, help="port (default 8080; 0: any free port)")
    p.add_argument("--score", action="append", default=None, metavar="DIR",
                   help="a 'graspdef score' folder for the scan overlay, one per run in order (default: "
                        "score.json in the run folder or a sub-folder)")
    p.add_argument("--no-live", dest="live", action="store_false", help="no live re-solve sliders")


def run(args: argparse.Namespace) -> int:
    """Run the viewer until Ctrl-C.  Errors (missing or incomplete run folder, port in use) are
    raised as GraspdefError subclasses, which ``graspdef``'s main turns into one line and exit 2."""
    from ..viewer.server import Viewer

    v = Viewer(args.run_dirs, args.host, args.port, score_dirs=getattr(args, "score", None),
               live=getattr(args, "live", True))
    try:
        progress(args, f"viewer at {v.url} ({len(v.runs)} run(s)); Ctrl-C stops it")
        v.wait()
    finally:
        v.stop()
    return 0

