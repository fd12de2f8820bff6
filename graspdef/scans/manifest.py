"""The scan manifest (``scans/manifest.toml``) and loading scans in metres.

Real scans are third-party files read in place from the shared scans folder (``../shared/scans``
next to the repository, or the folder named by the environment variable
``GRASPDEF_SHARED_SCANS``); they are never copied.  Generated scans are made from a recipe in the
manifest by :func:`graspdef.scans.scanner.generate_scan` and written under ``out/scans``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path

import numpy as np

from graspdef.config import Table, read_toml
from graspdef.errors import MeshError, ProblemError
from graspdef.geometry import TriMesh
from graspdef.units import length_scale

#: Repository root (the folder holding ``scans/manifest.toml``).
REPO_ROOT = Path(__file__).resolve().parents[2]
#: The manifest file.
MANIFEST_PATH = REPO_ROOT / "scans" / "manifest.toml"
#: Environment variable that overrides the shared scans folder.
SHARED_SCANS_ENV = "GRASPDEF_SHARED_SCANS"

_REQUIRED_REAL = ("path", "units", "frame", "licence", "source")
#: the keys a real scan's entry (or a [defaults.<name>] table) may hold
_REAL_KEYS = _REQUIRED_REAL + ("origin", "blob", "citation", "kind", "bytes", "licence_file")


@dataclass(frozen=True)
class ScanEntry:
    """One real scan of the manifest.

    Attributes
    ----------
    id : str
        Key in the manifest (``ycb_056_tennis_ball``, ...).
    path : str
        File path relative to the shared scans folder.
    units : str
        Length unit of the coordinates in the file (a key of ``graspdef.units.LENGTH_UNITS``).
    frame, licence, source : str
        Coordinate-frame note, licence identifier and source URL.
    extra : dict
        Every other manifest field (origin, blob, citation, kind, bytes, ...).
    """

    id: str
    path: str
    units: str
    frame: str
    licence: str
    source: str
    extra: dict = field(default_factory=dict)

    def file(self, shared: str | PathLike | None = None) -> Path:
        """Absolute path of the scan file in the shared scans folder."""
        return shared_scans_dir(shared) / self.path


@dataclass(frozen=True)
class Manifest:
    """The parsed manifest: real scans by id and generated-scan recipes by id."""

    real: dict[str, ScanEntry]
    generated: dict[str, dict]
    generated_dir: Path


def shared_scans_dir(override: str | PathLike | None = None) -> Path:
    """The shared scans folder: ``override``, else ``$GRASPDEF_SHARED_SCANS``, else
    ``<repo>/../shared/scans``.

    Raises
    ------
    ProblemError
        If the folder does not exist.
    """
    chosen = override or os.environ.get(SHARED_SCANS_ENV) or REPO_ROOT.parent / "shared" / "scans"
    path = Path(chosen).expanduser().resolve()
    if not path.is_dir():
        raise ProblemError(f"shared scans folder not found: {path} (set {SHARED_SCANS_ENV} to "
                           "the folder holding the real scans)")
    return path


def load_manifest(path: str | PathLike = MANIFEST_PATH) -> Manifest:
    """Read and check the manifest (with :mod:`graspdef.config`).

    Raises
    ------
    ProblemError
        If the file is missing or not TOML, holds an unknown key, an entry lacks one of path,
        units, frame, licence, source, or names an unknown unit, defaults table or recipe key;
        the message names the file, the table and the key.
    """
    from graspdef.scans.scanner import RECIPE_KEYS

    doc = read_toml(path, "scan manifest")
    doc.check({"schema", "defaults", "real", "generated"})
    doc.integer("schema", 1, minimum=1)
    defaults = doc.table("defaults", required=False).children()
    for d in defaults.values():
        d.check(_REAL_KEYS)
    real = {}
    for sid, raw in doc.table("real", required=False).children().items():
        raw.check(_REAL_KEYS + ("defaults",))
        base = defaults[raw.string("defaults", choices=defaults)].data if "defaults" in raw else {}
        entry = Table({**base, **{k: v for k, v in raw.items() if k != "defaults"}}, raw.source, raw.name)
        entry.check(_REAL_KEYS, _REQUIRED_REAL)
        units = entry.unit("units", "length")[0]
        real[sid] = ScanEntry(sid, entry.string("path"), units, entry.string("frame"), entry.string("licence"),
                              entry.string("source"),
                              extra={k: v for k, v in entry.items() if k not in _REQUIRED_REAL})
    gen = doc.table("generated", required=False)
    recipes = {}
    for rid, recipe in Table({k: v for k, v in gen.items() if k != "directory"}, gen.source,
                             gen.name).children().items():
        recipe.check(RECIPE_KEYS, ("source",))
        recipes[rid] = dict(recipe)
    return Manifest(real, recipes, REPO_ROOT / gen.string("directory", "out/scans"))


def scan_entry(scan_id: str, manifest: Manifest | None = None) -> ScanEntry:
    """The manifest entry of a real scan.

    Raises
    ------
    ProblemError
        If ``scan_id`` is not a real scan of the manifest.
    """
    manifest = manifest or load_manifest()
    try:
        return manifest.real[scan_id]
    except KeyError:
        raise ProblemError(f"unknown scan id {scan_id!r}; known: "
                           + ", ".join(sorted(manifest.real))) from None


def read_surface(path: str | PathLike, units: str) -> tuple[np.ndarray, np.ndarray]:
    """Read a scan file (triangle mesh or point cloud) without control-mesh checks.

    Scans may hold degenerate faces or pinch points that a control mesh may not (see
    ``validate_mesh``), so only the basics are checked here: readable, non-empty, finite.

    Parameters
    ----------
    path : str or path-like
        Any file trimesh reads (PLY, OBJ, STL, OFF, XYZ point clouds as PLY, ...).
    units : str
        Length unit of the file's coordinates.

    Returns
    -------
    vertices : ndarray, shape (n, 3), float64
        Positions [m].
    faces : ndarray, shape (m, 3), int64
        Triangles; shape (0, 3) for a point cloud.

    Raises
    ------
    ProblemError
        If the file is missing or the unit unknown.
    MeshError
        If the file cannot be read, is empty or has non-finite coordinates.
    """
    scale = length_scale(units)
    path = Path(path)
    if not path.is_file():
        raise ProblemError(f"scan file not found: {path}")
    import trimesh  # here, not at import: ~0.5 s, and a run whose control mesh is cached reads no scan

    try:
        loaded = trimesh.load(path, process=False)
    except Exception as exc:  # trimesh raises many exception types for unreadable files
        raise MeshError(f"cannot read scan file {path}: {exc}") from exc
    if isinstance(loaded, trimesh.Scene):
        loaded = (loaded.to_geometry() if hasattr(loaded, "to_geometry")
                  else loaded.dump(concatenate=True))
    vertices = np.asarray(getattr(loaded, "vertices", np.empty((0, 3))), dtype=np.float64)
    faces = np.asarray(getattr(loaded, "faces", None) if isinstance(loaded, trimesh.Trimesh)
                       else np.empty((0, 3)), dtype=np.int64).reshape(-1, 3)
    if vertices.ndim != 2 or vertices.shape[0] == 0:
        raise MeshError(f"{path}: the scan is empty (no points)")
    if not np.all(np.isfinite(vertices)):
        raise MeshError(f"{path}: non-finite (NaN or inf) coordinates")
    return vertices * scale, faces


def ply_units(path: str | PathLike) -> str | None:
    """The unit of a PLY file's ``comment units <unit>`` header line (as ``save_ply`` writes),
    or None if the file is not a PLY or has no such line."""
    path = Path(path)
    if path.suffix.lower() != ".ply" or not path.is_file():
        return None
    with path.open("rb") as fh:
        head = fh.read(4096)
    end = head.find(b"end_header")
    for line in head[: end if end >= 0 else None].splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[0] == b"comment" and parts[1] == b"units":
            return parts[2].decode("ascii", "replace")
    return None


def load_scan(scan_id: str, manifest: Manifest | None = None,
              shared: str | PathLike | None = None) -> TriMesh:
    """Load a real scan of the manifest, in metres.

    Returns
    -------
    TriMesh
        Vertices [m] and faces as stored (not validated as a control mesh: some YCB scans hold
        degenerate faces; use :func:`graspdef.scans.control_mesh` for a simulation mesh).
    """
    entry = scan_entry(scan_id, manifest)
    vertices, faces = read_surface(entry.file(shared), entry.units)
    return TriMesh(vertices, faces)
