"""A disk cache of the control meshes made from scan files: what :func:`graspdef.scans.control_mesh`
returns for a scan file, a face count, a method and a relaxation, kept as an ``.npz`` so that the
next run (a grasp, a ranking's recheck, a sweep's case) reads it instead of remeshing.

Remeshing the tennis ball's 16k-face scan into its 1,280-face control mesh takes ~1 s (the rays'
intersections, the closest points of the deviation check and reading the ASCII PLY), on every
run; reading the cached mesh takes a few milliseconds.

**The key** is a SHA-256 of everything the mesh depends on: the scan file's bytes, its unit, the
face count, the method and the relaxation, the source of graspdef's scan and geometry packages (the
remeshing, the reader, the icospheres and the checks) and the versions of numpy, trimesh, open3d
and pymeshlab.  A changed file, option or code gives another key; an entry is never updated,
only written whole (a temporary file renamed into place, so concurrent runs never read half a
file).  A cached mesh equals the computed one to the bit (``tests/scans/test_scan_cache.py``).

**Where:** ``$GRASPDEF_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/graspdef`` (``~/.cache/graspdef``),
in a ``control_mesh`` folder.  ``GRASPDEF_CACHE_DIR=off`` (or empty) turns the cache off.  A cache
that cannot be read or written is reported by a warning and the mesh is computed as without it.

File format (``<key>.npz``): ``vertices`` [m] float64 (n, 3), ``faces`` int64 (m, 3), ``units``
("m"), ``report`` (the :class:`ControlMeshReport` as JSON, lengths in metres) and ``key``.
"""
from __future__ import annotations

import hashlib
import json
import logging
import os
import tempfile
from dataclasses import asdict
from pathlib import Path

import numpy as np

from ..geometry import TriMesh
from .manifest import read_surface
from .remesh import ControlMeshReport, control_mesh

log = logging.getLogger(__name__)

#: environment variable naming the cache folder ("off" or empty: no cache)
CACHE_ENV = "GRASPDEF_CACHE_DIR"
_OFF = ("", "0", "off", "none", "no", "false")
_PACKAGES = ("numpy", "trimesh", "open3d-cpu", "open3d", "pymeshlab")


def cache_dir() -> Path | None:
    """The cache's root folder, or None when ``GRASPDEF_CACHE_DIR`` turns it off."""
    value = os.environ.get(CACHE_ENV)
    if value is not None:
        return None if value.strip().lower() in _OFF else Path(value).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "graspdef"


def _code_fingerprint() -> bytes:
    """The sources of graspdef.scans and graspdef.geometry and the versions of the packages the
    remeshing calls."""
    from importlib import metadata

    h = hashlib.sha256()
    root = Path(__file__).resolve().parents[1]
    for package in ("scans", "geometry"):
        for src in sorted((root / package).glob("*.py")):
            h.update(src.name.encode())
            h.update(src.read_bytes())
    for name in _PACKAGES:
        try:
            h.update(f"{name}={metadata.version(name)}".encode())
        except metadata.PackageNotFoundError:
            h.update(f"{name}=absent".encode())
    return h.digest()


def control_mesh_key(path: str | os.PathLike, units: str, n_faces: int, method: str, relax: int) -> str:
    """The cache key (hex SHA-256) of the control mesh of the scan file ``path``."""
    h = hashlib.sha256()
    h.update(Path(path).read_bytes())
    h.update(json.dumps({"units": units, "n_faces": int(n_faces), "method": method,
                         "relax": int(relax)}, sort_keys=True).encode())
    h.update(_code_fingerprint())
    return h.hexdigest()


def _read(file: Path, key: str) -> tuple[TriMesh, ControlMeshReport] | None:
    try:
        with np.load(file, allow_pickle=False) as z:
            if str(z["key"]) != key or str(z["units"]) != "m":
                raise ValueError("key or units do not match")
            mesh = TriMesh(np.array(z["vertices"], np.float64), np.array(z["faces"], np.int64))
            report = ControlMeshReport(**json.loads(str(z["report"])))
    except (FileNotFoundError, NotADirectoryError):     # not cached (or no cache folder: _write says so)
        return None
    except Exception as exc:   # a damaged or foreign file: recompute and replace it
        log.warning("control-mesh cache: %s unreadable (%s); remeshing", file, exc)
        return None
    return mesh, report


def _write(file: Path, key: str, mesh: TriMesh, report: ControlMeshReport) -> None:
    try:
        file.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=file.stem, suffix=".tmp", dir=file.parent)
        try:
            with os.fdopen(fd, "wb") as fh:
                np.savez(fh, vertices=mesh.vertices, faces=mesh.faces, units="m", key=key,
                         report=json.dumps(asdict(report)))
            os.replace(tmp, file)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    except OSError as exc:
        log.warning("control-mesh cache: cannot write %s (%s); the mesh is not cached", file, exc)


def cached_control_mesh(path: str | os.PathLike, units: str, n_faces: int, method: str = "auto",
                        relax: int = 0) -> tuple[TriMesh, ControlMeshReport]:
    """:func:`graspdef.scans.control_mesh` of the scan file ``path`` (coordinates in ``units``),
    read from the cache when it holds it, else computed and stored.  Errors are control_mesh's
    and read_surface's (nothing is cached for a scan that fails)."""
    root = cache_dir()
    if root is None or not Path(path).is_file():
        return control_mesh(TriMesh(*read_surface(path, units)), n_faces, method, relax=relax)
    key = control_mesh_key(path, units, n_faces, method, relax)
    file = root / "control_mesh" / f"{key}.npz"
    hit = _read(file, key)
    if hit is not None:
        return hit
    mesh, report = control_mesh(TriMesh(*read_surface(path, units)), n_faces, method, relax=relax)
    _write(file, key, mesh, report)
    return mesh, report
