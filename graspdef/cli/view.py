"""``graspdef view RUN_DIR [RUN_DIR ...] [--host HOST] [--port PORT] [--score DIR] [--no-live]``, or
``graspdef view RANK_DIR [--top N]`` for a ranking folder (graspdef rank --out)."""
from __future__ import annotations

import argparse

from ..errors import GraspdefError
from ._common import progress

DESCRIPTION = ("Serve run folders as a viser page (127.0.0.1 unless --host); Ctrl-C stops it. A ranking folder "
               "(graspdef rank --out) shows the compliance map, the ranked candidates and the stored deformed shapes.")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The ``view`` sub-command's arguments (call on the sub-parser)."""
    p.add_argument("run_dirs", nargs="+", metavar="RUN_DIR",
                   help="run folders (graspdef solve --out), side by side; or one ranking folder (graspdef rank --out)")
    p.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1: this machine only)")
    p.add_argument("--port", type=int, default=8080, help="port (default 8080; 0: any free port)")
    p.add_argument("--score", action="append", default=None, metavar="DIR",
                   help="a 'graspdef score' folder for the scan overlay, one per run in order (default: "
                        "score.json in the run folder or a sub-folder)")
    p.add_argument("--no-live", dest="live", action="store_false", help="no live re-solve sliders")
    p.add_argument("--top", type=int, default=None, metavar="N",
                   help="ranking folder: draw the best N candidates as segments (default 200)")


def run(args: argparse.Namespace) -> int:
    """Run the viewer until Ctrl-C.  Errors (missing or incomplete run folder, port in use) are
    raised as GraspdefError subclasses, which ``graspdef``'s main turns into one line and exit 2."""
    from ..runs.ranking import is_ranking

    rankings = [d for d in args.run_dirs if is_ranking(d)]
    if rankings:
        from ..viewer.ranking import DEFAULT_TOP, RankingViewer

        if len(args.run_dirs) > 1:
            raise GraspdefError(f"{rankings[0]} is a ranking folder: view it on its own (graspdef view RANK_DIR)")
        if getattr(args, "score", None):
            raise GraspdefError("--score is for run folders, not for a ranking folder")
        top = args.top if getattr(args, "top", None) is not None else DEFAULT_TOP
        v = RankingViewer(rankings[0], args.host, args.port, top=top)
        what = f"ranking {rankings[0]} ({v.ranking.n} candidates, {v.n_drawn} drawn)"
    else:
        from ..viewer.server import Viewer

        if getattr(args, "top", None) is not None:
            raise GraspdefError("--top is for a ranking folder (graspdef rank --out), not for run folders")
        v = Viewer(args.run_dirs, args.host, args.port, score_dirs=getattr(args, "score", None),
                   live=getattr(args, "live", True))
        what = f"{len(v.runs)} run(s)"
    try:
        progress(args, f"viewer at {v.url} ({what}); Ctrl-C stops it")
        v.wait()
    finally:
        v.stop()
    return 0
