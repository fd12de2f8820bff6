"""Writing a folder atomically: every run-folder writer (solve, grasp, score, sweep, bench --out)
goes through :func:`atomic_folder`, so a failed run leaves nothing partial and never clobbers a
good folder."""
from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from os import PathLike
from pathlib import Path

from ..errors import GraspdefError


class OutputFolderError(GraspdefError):
    """An output folder cannot be written (checked before any work)."""


def check_output_folder(out: str | PathLike, marker: str = "result.json") -> Path:
    """Refuse, before any heavy work, an output folder that cannot be written or that holds
    something other than a graspdef run (a run folder -- one holding ``marker`` -- is replaced
    atomically at the end; a folder of other files is never clobbered)."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise OutputFolderError(f"--out {out} is a file, not a folder")
    if out.is_dir() and any(out.iterdir()) and not (out / marker).is_file():
        raise OutputFolderError(f"--out {out} holds files that are not a graspdef run folder; give a new or empty "
                                "folder (a run folder is replaced)")
    parent = out.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputFolderError(f"--out {out}: cannot create it ({parent} is not writable)")
    return out


@contextlib.contextmanager
def atomic_folder(out: str | PathLike):
    """Write a folder atomically: yields a temporary folder beside ``out`` that replaces ``out``
    only if the block finishes; on any error it is removed and ``out`` is left as it was."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    try:
        yield tmp
        if out.exists():
            shutil.rmtree(out)
        tmp.rename(out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
