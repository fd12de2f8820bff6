"""What every subcommand shares: progress lines on stderr (``-q`` silences them)."""
from __future__ import annotations

import argparse
import sys


def progress(args: argparse.Namespace, msg: str) -> None:
    """One progress line ``[graspdef] msg`` on stderr, unless ``--quiet``."""
    if not getattr(args, "quiet", False):
        print(f"[graspdef] {msg}", file=sys.stderr, flush=True)


def warn(msg: str) -> None:
    """One warning line on stderr (always shown)."""
    print(f"graspdef: warning: {msg}", file=sys.stderr, flush=True)
