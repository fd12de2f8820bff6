"""``provenance.json``: what a run folder was made with, so it can be reproduced from the folder.

Every run-folder writer (``graspdef solve``, ``score``, ``grasp``, ``sweep`` and ``bench --out``)
calls :func:`write_provenance` inside its :func:`graspdef.runs.folder.atomic_folder` block.  The
record holds the exact configuration the writer was given (a JSON-ready dict: the problem file's
text, the grasp options, the sweep spec, ...), the command line, the UTC time, the host, the
graspdef version and git commit (with a ``dirty`` flag when the working tree differs from it),
and the versions of Python and of the numerical packages the run used.

It lives in the run package (the lowest layer above geometry), next to ``atomic_folder``, because
every writer above may import it; it imports nothing of graspdef's and never imports a package itself (optional packages are
reported only when the process has already imported them).
"""
from __future__ import annotations

import datetime
import functools
import json
import platform
import socket
import subprocess
import sys
from importlib import metadata
from os import PathLike
from pathlib import Path

#: packages whose versions are recorded; optional ones only when already imported by the process
REQUIRED = ("numpy", "scipy", "trimesh", "numba")
OPTIONAL = ("pypardiso", "mujoco", "open3d", "viser", "dask", "distributed", "matplotlib")

_REPO = Path(__file__).resolve().parents[2]


def _version(dist: str) -> str | None:
    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return None


@functools.lru_cache(maxsize=1)
def _git() -> dict:
    """Commit of the graspdef checkout (None when graspdef is not run from a git checkout)."""
    if not (_REPO / ".git").exists():
        return {"commit": None, "dirty": None}
    try:
        commit = subprocess.run(["git", "-C", str(_REPO), "rev-parse", "HEAD"], capture_output=True,
                                text=True, timeout=10, check=True).stdout.strip()
        status = subprocess.run(["git", "-C", str(_REPO), "status", "--porcelain", "--untracked-files=no",
                                 "--", "graspdef"], capture_output=True, text=True, timeout=10, check=True).stdout
        return {"commit": commit, "dirty": bool(status.strip())}
    except (OSError, subprocess.SubprocessError):
        return {"commit": None, "dirty": None}


def provenance_record(config: dict | None = None, command: list[str] | None = None) -> dict:
    """The provenance of a run made now by this process.

    Parameters
    ----------
    config : dict, optional
        The exact configuration of the run, JSON-ready (e.g. ``{"problem_file": "...", "text": ...}``).
    command : list of str, optional
        The command line; default ``sys.argv`` (the program name reduced to ``graspdef`` when
        it is the console script).
    """
    argv = list(sys.argv if command is None else command)
    if argv and Path(argv[0]).name in ("graspdef", "__main__.py", "cli.py"):
        argv[0] = "graspdef"
    packages = {p: _version(p) for p in REQUIRED}
    packages.update({p: _version(p) for p in OPTIONAL if p in sys.modules})
    return {
        "graspdef": {"version": _version("graspdef"), **_git(), "path": str(_REPO)},
        "command": argv,
        "config": config if config is not None else {},
        "time_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "host": socket.gethostname(),
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "packages": packages,
        # the compiled kernels' builds (graspdef.compiled; read only if the process loaded it)
        "kernels": sys.modules["graspdef.compiled"].builds_used() if "graspdef.compiled" in sys.modules else None,
    }


def write_provenance(folder: str | PathLike, config: dict | None = None, command: list[str] | None = None,
                     **extra) -> Path:
    """Write ``provenance.json`` into ``folder`` (see :func:`provenance_record`); ``extra``
    entries are added at the top level.  Returns the file's path."""
    rec = provenance_record(config, command)
    rec.update(extra)
    path = Path(folder) / "provenance.json"
    path.write_text(json.dumps(rec, indent=2, default=str) + "\n")
    return path


def read_provenance(folder: str | PathLike) -> dict:
    """The ``provenance.json`` of a run folder."""
    return json.loads((Path(folder) / "provenance.json").read_text())
