"""The one run-folder reader: every consumer (report, viewer, score, sweep, gallery scripts) reads
a run with :func:`read_run` (the format: docs/run-folder.md).

Required: ``result.json`` (a :class:`~graspdef.runs.record.RunRecord` of this schema),
``deformed.ply`` (with the per-vertex displacement field ``ux, uy, uz``) and ``undeformed.ply``
(same vertex count and faces); for a nonlinear run also ``path.csv``.  Optional, used when
present and skipped when absent:

* ``problem.toml`` -- rebuilds the Problem for live re-solves and for the surface along the path;
* ``path_u.npz`` -- control-point displacements of every path point (:mod:`graspdef.runs.pathfile`);
* ``contacts.json`` -- grasp contacts (see :func:`read_contacts` for the accepted layout);
* ``score.json`` with ``scan_errors.ply`` -- a scan score (``graspdef score``), in the run folder
  or in one of its sub-folders, or given explicitly.

Every problem with a folder -- missing, truncated or corrupt files included -- raises
:class:`RunFolderError` naming the folder and the file (one line, never a traceback).
"""
from __future__ import annotations

import csv
import json
import logging
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..units import LENGTH_UNITS
from .derived import displacement_field_label
from .pathfile import FILENAME as PATH_U_FILE
from .pathfile import read_path_u
from .record import RunFolderError, RunRecord

log = logging.getLogger(__name__)

MM = 1e3
REQUIRED = ("result.json", "deformed.ply", "undeformed.ply")


def unit_scale(unit: str | None) -> float:
    """Metres per ``unit`` ("consistent" and unknown-but-stated consistent sets: 1)."""
    if unit in (None, "consistent"):
        return 1.0
    if unit not in LENGTH_UNITS:
        raise RunFolderError(f"unknown length unit {unit!r} (valid: {', '.join(LENGTH_UNITS)}, consistent)")
    return LENGTH_UNITS[unit]


def _ply(path: Path, where: str) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, str | None]:
    """Vertices (file units), faces (or (0, 3)), the raw vertex record array and the units comment."""
    import trimesh  # here, not at import (start-up)

    try:
        m = trimesh.load(path, process=False)
    except Exception as exc:  # trimesh raises many types for unreadable files
        raise RunFolderError(f"{where}: cannot read {path.name}: {exc}") from None
    verts = np.asarray(getattr(m, "vertices", np.zeros((0, 3))), dtype=np.float64)
    faces = np.asarray(getattr(m, "faces", np.zeros((0, 3), int)), dtype=np.int64).reshape(-1, 3)
    raw = (m.metadata.get("_ply_raw") or {}).get("vertex", {}).get("data") if hasattr(m, "metadata") else None
    units = None
    with path.open("rb") as fh:
        head = fh.read(4096)
    for line in head[: max(head.find(b"end_header"), 0)].splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[:2] == [b"comment", b"units"]:
            units = parts[2].decode("ascii", "replace")
    if verts.size == 0 or not np.all(np.isfinite(verts)):
        raise RunFolderError(f"{where}: {path.name} has no vertices or non-finite ones")
    if faces.size and (faces.min() < 0 or faces.max() >= len(verts)):
        raise RunFolderError(f"{where}: {path.name} has faces naming vertices that do not exist")
    return verts, faces, raw, units


@dataclass
class PathTable:
    """``path.csv``: one row per converged point (probe displacements in SI)."""

    load_factors: np.ndarray                     # (k,)
    probes: dict[str, np.ndarray]                # name -> (k, 3) [m]
    stable: list                                 # (k,) True/False/None
    columns: dict[str, np.ndarray]               # every numeric column by header name


@dataclass
class Contacts:
    """Grasp contacts in SI: fingers (dicts with name, position [m], wxyz, size [m] or None) and
    contact points (c, 3) [m] with their forces (c, 3) [N] on the object."""

    fingers: list[dict]
    points: np.ndarray
    forces: np.ndarray
    force_unit: str = "N"


@dataclass
class ScanOverlay:
    """A scan in the prediction's frame [m] with its signed per-point error [mm]."""

    points: np.ndarray          # (s, 3) [m]
    errors_mm: np.ndarray       # (s,)
    stats_mm: dict
    baseline_stats_mm: dict
    summary: str
    source: Path


@dataclass
class RunData:
    """One run folder, read (see the module docstring); SI arrays (or the run's consistent units)."""

    path: Path
    record: RunRecord
    faces: np.ndarray                              # (m, 3)
    rest_vertices: np.ndarray                      # (n, 3) limit surface at rest
    deformed_vertices: np.ndarray                  # (n, 3) final state
    displacements: np.ndarray                      # (n, 3) the field of derived.max_displacement
    problem_file: Path | None = None
    path_table: PathTable | None = None
    path_u: tuple[np.ndarray, np.ndarray, sp.csr_matrix] | None = None
    contacts: Contacts | None = None
    scan: ScanOverlay | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def name(self) -> str:
        return self.record.name

    @property
    def analysis(self) -> str:
        return self.record.analysis

    @property
    def length_unit(self) -> str:
        return self.record.units["length"]

    @property
    def display_unit(self) -> str:
        """The length unit consumers display: mm for SI runs, else the consistent unit."""
        return "consistent" if self.length_unit == "consistent" else "mm"

    @property
    def display_scale(self) -> float:
        """Metres (run units) per display unit."""
        return 1.0 if self.length_unit == "consistent" else 1e-3

    @property
    def force_unit(self) -> str:
        return self.record.units.get("force", "N")

    @property
    def label(self) -> str:
        return f"{self.name} ({self.analysis})"

    @property
    def derived(self) -> dict:
        return dict(self.record.derived)

    @property
    def displacement_label(self) -> str:
        """What the stored displacement field is (the colour-bar label)."""
        return displacement_field_label(self.record.derived)

    @property
    def outer_offset(self) -> float:
        """Mid-surface to outer-surface distance (half the shell thickness, ``thickness_m`` of the
        record; 0 when the record has none): what a scan of the object sees is offset by this."""
        t = self.record.get("thickness_m")
        return 0.5 * float(t) if isinstance(t, (int, float)) and t > 0 else 0.0

    def max_displacement(self) -> float | None:
        """``derived.max_displacement`` (SI or consistent), the one number every consumer shows."""
        return self.record.value("max_displacement")

    def path_displacements(self, i: int) -> np.ndarray | None:
        """Limit displacements (n, 3) of path point ``i`` from the rest shape (None without path_u)."""
        if self.path_u is None:
            return None
        u, _, L = self.path_u
        return L @ u[i]


TEXT_COLUMNS = ("kind",)


def read_path_csv(path: Path, where: str) -> PathTable:
    """``path.csv``: every row as long as the header, every column but ``kind`` numeric (empty =
    not applicable), finite load factors; anything else is one :class:`RunFolderError`."""
    try:
        with path.open(newline="", encoding="utf-8") as fh:
            rows = list(csv.reader(fh))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise RunFolderError(f"{where}: cannot read path.csv: {exc}") from None
    if len(rows) < 2 or "load_factor" not in rows[0]:
        raise RunFolderError(f"{where}: path.csv has no 'load_factor' column or no rows (incomplete run?)")
    header, body = rows[0], rows[1:]
    for i, r in enumerate(body, start=2):
        if len(r) != len(header):
            raise RunFolderError(f"{where}: path.csv line {i} has {len(r)} fields, the header {len(header)} "
                                 "(truncated or corrupt file)")
    cols: dict[str, np.ndarray] = {}
    for j, name in enumerate(header):
        if name in TEXT_COLUMNS:
            continue
        try:
            cols[name] = np.array([float(r[j]) if r[j] != "" else np.nan for r in body])
        except ValueError:
            bad = next(i for i, r in enumerate(body, start=2) if not _is_number(r[j]))
            raise RunFolderError(f"{where}: path.csv line {bad}, column {name!r}: {body[bad - 2][j]!r} is not a "
                                 "number") from None
    if not np.all(np.isfinite(cols["load_factor"])):
        raise RunFolderError(f"{where}: path.csv: load_factor must be finite on every line")
    probes: dict[str, np.ndarray] = {}
    for name in header:
        if "_ux[" in name:
            base, unit = name.split("_ux[")
            comps = [cols.get(f"{base}_u{c}[{unit}") for c in "xyz"]
            if all(c is not None for c in comps):
                probes[base] = np.stack(comps, axis=1)
    stable = [None if not np.isfinite(v) else bool(v) for v in cols.get("stable", np.full(len(body), np.nan))]
    return PathTable(cols["load_factor"], probes, stable, cols)


def _is_number(t: str) -> bool:
    try:
        float(t or "nan")
        return True
    except ValueError:
        return False


def _vec(v, n: int, what: str, where: str) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise RunFolderError(f"{where}: contacts.json: {what} must be {n} finite numbers, got {v!r}")
    return a


def read_contacts(path: Path, default_length_unit: str, where: str) -> Contacts:
    """Read ``contacts.json`` (see :func:`_read_contacts`); a malformed file is one RunFolderError."""
    try:
        return _read_contacts(path, default_length_unit, where)
    except (TypeError, ValueError, AttributeError, KeyError, IndexError) as exc:
        raise RunFolderError(f"{where}: contacts.json is malformed: {type(exc).__name__}: {exc}") from None


def _read_contacts(path: Path, default_length_unit: str, where: str) -> Contacts:
    """Read ``contacts.json``.

    Accepted layout (lengths in ``units.length``, default the run's; forces in ``units.force``,
    default N; forces act on the object)::

        {"units": {"length": "mm", "force": "N"},
         "fingers": [{"name": "left_pad", "position": [x, y, z],
                      "wxyz": [1, 0, 0, 0], "size": [sx, sy, sz]}, ...],
         "contacts": [{"position": [x, y, z], "force": [fx, fy, fz], "finger": "left_pad"}, ...]}

    ``point``/``at`` are accepted for ``position``, ``quaternion`` for ``wxyz``.  The grasp
    pipeline's layout is read too: ``"frame": "world"`` with ``object_pose`` (``position_m``,
    ``rotation`` or ``quat_wxyz``), contacts with ``position_m``/``force_N`` (moved into the object
    frame of the surfaces) and ``per_finger`` centres (``point_m``) drawn as finger markers."""
    try:
        doc = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise RunFolderError(f"{where}: contacts.json is not valid JSON: {exc}") from None
    if not isinstance(doc, dict):
        raise RunFolderError(f"{where}: contacts.json must hold an object")
    units = doc.get("units", {}) if isinstance(doc.get("units", {}), dict) else {}
    ls = unit_scale(units.get("length", default_length_unit))
    fu = units.get("force", "N")
    fs = {"N": 1.0, "kN": 1e3, "mN": 1e-3, "consistent": 1.0}.get(fu)
    if fs is None:
        raise RunFolderError(f"{where}: contacts.json: unknown force unit {fu!r}")
    R, t = np.eye(3), np.zeros(3)                      # world -> object frame (grasp runs)
    pose = doc.get("object_pose")
    if doc.get("frame") == "world" and isinstance(pose, dict):
        if "rotation" in pose:
            R = np.asarray(pose["rotation"], float).reshape(3, 3)
        elif "quat_wxyz" in pose:
            w, x, y, z = _vec(pose["quat_wxyz"], 4, "object_pose.quat_wxyz", where) / np.linalg.norm(pose["quat_wxyz"])
            R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                          [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                          [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        t = _vec(pose.get("position_m", [0, 0, 0]), 3, "object_pose.position_m", where)

    def to_obj(p):                                     # world point [m] -> object frame
        return (p - t) @ R

    fingers = []
    for i, f in enumerate(doc.get("fingers", []) or []):
        if not isinstance(f, dict):
            raise RunFolderError(f"{where}: contacts.json: fingers[{i}] must be an object")
        pos = f.get("position", f.get("pos"))
        q = f.get("wxyz", f.get("quaternion", [1.0, 0.0, 0.0, 0.0]))
        size = f.get("size")
        fingers.append({"name": str(f.get("name", f"finger_{i}")),
                        "position": _vec(pos, 3, f"fingers[{i}].position", where) * ls,
                        "wxyz": _vec(q, 4, f"fingers[{i}].wxyz", where),
                        "size": None if size is None else np.abs(_vec(size, 3, f"fingers[{i}].size", where)) * ls})
    for name, pf in (doc.get("per_finger") or {}).items():     # grasp runs: one marker per finger
        if isinstance(pf, dict) and "point_m" in pf:
            fingers.append({"name": str(name), "position": to_obj(_vec(pf["point_m"], 3, f"per_finger.{name}", where)),
                            "wxyz": np.array([1.0, 0, 0, 0]), "size": None})
    pts, frc = [], []
    for i, c in enumerate(doc.get("contacts", []) or []):
        if not isinstance(c, dict):
            raise RunFolderError(f"{where}: contacts.json: contacts[{i}] must be an object")
        if "position_m" in c:                                   # grasp-run records (SI)
            pts.append(to_obj(_vec(c["position_m"], 3, f"contacts[{i}].position_m", where)))
            frc.append(_vec(c.get("force_N"), 3, f"contacts[{i}].force_N", where) @ R)
            continue
        p = c.get("position", c.get("point", c.get("at")))
        pts.append(_vec(p, 3, f"contacts[{i}].position", where) * ls)
        frc.append(_vec(c.get("force"), 3, f"contacts[{i}].force", where) * fs)
    return Contacts(fingers, np.array(pts).reshape(-1, 3), np.array(frc).reshape(-1, 3), "N")


def find_score(run_dir: Path) -> Path | None:
    """The folder holding a ``score.json`` for this run: the run folder or one sub-folder."""
    if (run_dir / "score.json").is_file():
        return run_dir
    subs = sorted(p.parent for p in run_dir.glob("*/score.json"))
    return subs[0] if subs else None


def read_scan_overlay(score_dir: Path, where: str) -> ScanOverlay:
    """See :func:`_read_scan_overlay`; a malformed score is one RunFolderError."""
    try:
        return _read_scan_overlay(score_dir, where)
    except (TypeError, ValueError, AttributeError, KeyError, IndexError) as exc:
        raise RunFolderError(f"{where}: score folder {score_dir} is malformed: {type(exc).__name__}: {exc}") from None


def _read_scan_overlay(score_dir: Path, where: str) -> ScanOverlay:
    """A ``graspdef score`` folder: the scan (``scan_errors.ply``) moved into the prediction's
    frame with the stored registration, and its signed errors [mm]."""
    try:
        rec = json.loads((score_dir / "score.json").read_text())
    except (OSError, ValueError) as exc:
        raise RunFolderError(f"{where}: cannot read {score_dir / 'score.json'}: {exc}") from None
    name = (rec.get("files") or {}).get("scan_errors", "scan_errors.ply")
    f = score_dir / name
    if not f.is_file():
        raise RunFolderError(f"{where}: score.json names {name}, which is missing in {score_dir}")
    verts, _, raw, units = _ply(f, where)
    if raw is None or "error_mm" not in raw.dtype.names:
        raise RunFolderError(f"{where}: {name} has no per-point 'error_mm'")
    s_units = units or (rec.get("inputs") or {}).get("scan_units")
    pts = verts * unit_scale(s_units)
    try:
        T = np.asarray(rec["prediction"]["registration"]["transform_scan_to_surface"], float)
    except (KeyError, TypeError):
        T = np.eye(4)
    if T.shape != (4, 4):
        raise RunFolderError(f"{where}: score.json: transform_scan_to_surface must be 4x4")
    pts = pts @ T[:3, :3].T + T[:3, 3] / MM                   # "t in mm"
    pred = (rec.get("prediction") or {}).get("errors", {})
    base = (rec.get("baseline") or {}).get("errors", {})
    return ScanOverlay(pts, np.asarray(raw["error_mm"], float), pred, base, str(rec.get("summary", "")), score_dir)


def read_run(run_dir: str | PathLike, score_dir: str | PathLike | None = None) -> RunData:
    """Read a run folder (see the module docstring); raise :class:`RunFolderError` if it is
    missing, incomplete, corrupt, inconsistent or of another schema."""
    d = Path(run_dir)
    where = f"run folder {d}"
    if not d.exists():
        raise RunFolderError(f"{where} does not exist")
    if not d.is_dir():
        raise RunFolderError(f"{where} is not a folder")
    missing = [f for f in REQUIRED if not (d / f).is_file()]
    if missing:
        raise RunFolderError(f"{where} is incomplete: missing {', '.join(missing)} (write one with "
                             "'graspdef solve PROBLEM.toml --out DIR' or 'graspdef grasp SCENE --force F --out DIR')")
    try:
        doc = json.loads((d / "result.json").read_text(encoding="utf-8"))
    except (ValueError, OSError) as exc:
        raise RunFolderError(f"{where}: result.json is not valid JSON: {exc}") from None
    rec = RunRecord.from_json(doc, where)
    lu = rec.units["length"]
    if lu != "consistent" and lu != "m":
        raise RunFolderError(f"{where}: result.json: length unit {lu!r} (run folders are SI: 'm', or 'consistent')")
    dv, df, raw, du = _ply(d / "deformed.ply", where)
    rv, rf, _, ru = _ply(d / "undeformed.ply", where)
    for fname, u in (("deformed.ply", du), ("undeformed.ply", ru)):
        if u is not None and u != lu:
            raise RunFolderError(f"{where}: {fname} states units {u!r} but result.json says {lu!r}")
    if dv.shape != rv.shape or df.shape != rf.shape or not np.array_equal(df, rf):
        raise RunFolderError(f"{where}: deformed.ply ({len(dv)} vertices, {len(df)} faces) and undeformed.ply "
                             f"({len(rv)} vertices, {len(rf)} faces) do not match")
    if len(df) == 0:
        raise RunFolderError(f"{where}: deformed.ply has no faces")
    if raw is None or not {"ux", "uy", "uz"} <= set(raw.dtype.names or ()):
        raise RunFolderError(f"{where}: deformed.ply has no per-vertex displacement (ux, uy, uz)")
    u = np.column_stack([np.asarray(raw[c], dtype=float) for c in ("ux", "uy", "uz")])
    if u.shape != dv.shape or not np.all(np.isfinite(u)):
        raise RunFolderError(f"{where}: deformed.ply: the displacement field is not finite on every vertex")
    run = RunData(d, rec, df, rv, dv, u)
    run.notes += [f"warning: {w}" for w in (rec.get("warnings") or []) if isinstance(w, str)]
    if (d / "problem.toml").is_file():
        run.problem_file = d / "problem.toml"
    else:
        run.notes.append("no problem.toml: live re-solves are off")
    if rec.analysis == "nonlinear":
        if not (d / "path.csv").is_file():
            raise RunFolderError(f"{where} is incomplete: a nonlinear run needs path.csv")
        run.path_table = read_path_csv(d / "path.csv", where)
        conv = rec.get("convergence") or {}
        if conv.get("completed") is False:
            run.notes.append(f"the load path stopped at load factor {conv.get('load_factor', float('nan')):.4g}: "
                             f"{conv.get('stop_reason') or 'see result.json'}")
        if (d / PATH_U_FILE).is_file():
            try:
                pu, lf, L = read_path_u(d / PATH_U_FILE)
            except Exception as exc:  # numpy/zipfile raise many types for a corrupt archive
                raise RunFolderError(f"{where}: {PATH_U_FILE} is unreadable: {type(exc).__name__}: {exc}") from None
            if L.shape[0] != len(rv) or len(lf) != len(run.path_table.load_factors) or \
                    not np.allclose(lf, run.path_table.load_factors, rtol=1e-9, atol=1e-12):
                raise RunFolderError(f"{where}: {PATH_U_FILE} does not match path.csv / the surface")
            run.path_u = (pu, lf, L)
    if (d / "contacts.json").is_file():
        run.contacts = read_contacts(d / "contacts.json", lu, where)
    sd = Path(score_dir) if score_dir is not None else find_score(d)
    if score_dir is not None and not (sd / "score.json").is_file():
        raise RunFolderError(f"score folder {sd}: no score.json")
    if sd is not None:
        run.scan = read_scan_overlay(sd, where)
    return run
