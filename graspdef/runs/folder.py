"""Writing a folder atomically: every run-folder writer (solve, grasp, score, sweep, bench --out)
goes through :func:`atomic_folder`, so a failed run leaves nothing partial and never clobbers a
good folder."""
from __future__ import annotations

import contextlib
import shutil
import tempfile
from os import PathLike
from pathlib import Path


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
