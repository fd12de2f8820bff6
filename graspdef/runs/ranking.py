"""The ranking folder (``graspdef rank``): its files, their one writer (atomic) and one reader.

A ranking folder holds (SI units; docs/ranking-folder.md)::

    ranking.json    the record: object, force, friction, material, timings, the criterion, the
                    rank correlations, the nonlinear re-evaluation, the column list with units
    ranking.csv     every candidate, one row each, in rank order (columns: :data:`COLUMNS`)
    compliance.ply  the shell's limit surface (metres) with per-vertex ``compliance_m_per_N``,
                    ``stiffness_N_per_m`` and ``pinch_width_m`` (NaN where no pinch fits)
    shapes.npz      ``rest`` (n, 3) [m] limit points of the control vertices, ``faces`` (m, 3),
                    ``candidates`` (k,), ``displacement`` (k, n, 3) [m, float32]: the linear
                    displacement of the k best candidates at the ranking's force

The viewer and the report read it with :func:`read_ranking`; they use the table's columns (its
``pareto`` and ``held`` flags, ranks and correlations) as written, never recompute them.
"""
from __future__ import annotations

import csv
import json
import math
import zipfile
from dataclasses import dataclass
from os import PathLike
from pathlib import Path

import numpy as np

from ..geometry.io import save_ply
from .folder import atomic_folder
from .read import _ply
from .record import RunFolderError

SCHEMA = "graspdef.ranking"
VERSION = 1
FILES = ("ranking.json", "ranking.csv", "compliance.ply", "shapes.npz")

#: ranking.csv columns: (name, unit, meaning)
COLUMNS = [
    ("rank", "", "rank by the criterion of ranking.json (1 = best)"),
    ("candidate", "", "candidate number (sampling order)"),
    ("first_x_m", "m", "first contact, object frame"), ("first_y_m", "m", ""), ("first_z_m", "m", ""),
    ("second_x_m", "m", "second contact"), ("second_y_m", "m", ""), ("second_z_m", "m", ""),
    ("width_m", "m", "distance between the contacts (the gripper's opening at contact)"),
    ("antipodal_angle_deg", "deg", "larger angle between a contact's inward normal (the outer mesh's face) and "
                                   "the grasp line, as sampled"),
    ("friction_margin_deg", "deg", "rigid baseline: atan(friction) - the larger angle between a contact patch's "
                                   "mean inward normal and the line, at rest (> 0: inside the cone)"),
    ("rigid_rank", "", "rank of the rigid-object baseline (friction margin, then weight torque ratio)"),
    ("force_N", "N", "squeezing force per finger the figures below are at: the ranking's force, or with a force "
                     "range the least force in it that holds the candidate against its weight (the range's top "
                     "if none does)"),
    ("closing_m", "m", "linear: approach of the two contact points along the grasp line at the force"),
    ("indentation_per_finger_m", "m", "closing / 2"),
    ("work_J", "J", "work of the fingers to reach the force: F closing / 2"),
    ("strain_energy_J", "J", "u.K u / 2 (equals the work in linear theory: Clapeyron)"),
    ("grasp_stiffness_N_per_m", "N/m", "force / closing"),
    ("max_displacement_m", "m", "largest displacement of the limit surface (rigid motion removed)"),
    ("peak_strain", "", "largest principal strain magnitude on either face of the wall (quadrature points)"),
    ("peak_von_mises_Pa", "Pa", "largest plane-stress von Mises stress on either face (linear elastic)"),
    ("strain_limit_ratio", "", "peak strain / the given strain limit (NaN: no limit given)"),
    ("contact_area_m2", "m^2", "estimate per finger: the flat pad pressed by the indentation into the rest "
                               "surface (geometric overlap), mean of the two fingers"),
    ("deformed_friction_margin_deg", "deg", "the same after the linear deformation: the patches' mean normals "
                                            "and the line through the moved contacts"),
    ("weight_torque_ratio", "", "weight's torque about the grasp line (gravity across it) / torsional friction "
                                "of the two contacts"),
    ("weight_slip_ratio", "", "weight / tangential friction of the two contacts: m g / (2 friction F)"),
    ("held", "", "1: deformed friction margin > 0, both weight ratios at most 1 and the strain limit (if any) kept"),
    ("pareto", "", "1: on the Pareto front of (least work, largest deformed friction margin)"),
]
COLUMN_NAMES = [c[0] for c in COLUMNS]
INT_COLUMNS = {"rank", "candidate", "rigid_rank", "held", "pareto"}


class RankingFolderError(RunFolderError):
    """A ranking folder is missing or unreadable."""


@dataclass(frozen=True)
class Ranking:
    """A ranking folder as read: the record, the table (column -> array, rank order), the limit
    surface with its compliance map, and the stored shapes."""

    folder: Path
    record: dict
    table: dict
    vertices: np.ndarray            # (n, 3) [m] limit points of the control vertices
    faces: np.ndarray               # (m, 3)
    compliance: np.ndarray          # (n,) [m/N], NaN where no pinch fits
    stiffness: np.ndarray           # (n,) [N/m]
    pinch_width: np.ndarray         # (n,) [m]
    shape_candidates: np.ndarray    # (k,)
    displacements: np.ndarray       # (k, n, 3) [m]

    @property
    def n(self) -> int:
        return len(self.table["rank"])

    def row(self, i: int) -> dict:
        """Row ``i`` (rank order) as a dict of Python numbers."""
        return {k: (int(v[i]) if k in INT_COLUMNS else float(v[i])) for k, v in self.table.items()}

    def contacts(self) -> tuple[np.ndarray, np.ndarray]:
        """(first, second) contact points (n, 3) [m], rank order."""
        t = self.table
        return (np.stack([t["first_x_m"], t["first_y_m"], t["first_z_m"]], 1),
                np.stack([t["second_x_m"], t["second_y_m"], t["second_z_m"]], 1))

    def displacement_of(self, candidate: int) -> np.ndarray | None:
        """Stored displacement (n, 3) [m] of ``candidate`` (its number), or None if not stored."""
        hit = np.flatnonzero(self.shape_candidates == int(candidate))
        return None if not len(hit) else self.displacements[hit[0]].astype(float)


def is_ranking(folder: str | PathLike) -> bool:
    return (Path(folder) / "ranking.json").is_file()


def _fmt(v) -> str:
    if isinstance(v, (bool, np.bool_)):
        return str(int(v))
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    v = float(v)
    return "nan" if math.isnan(v) else ("inf" if math.isinf(v) else f"{v:.9g}")


def write_ranking(out: str | PathLike, record: dict, rows: list[dict], vertices: np.ndarray, faces: np.ndarray,
                  maps: dict, shape_candidates: np.ndarray, displacements: np.ndarray) -> Path:
    """Write the ranking folder ``out`` atomically.  ``rows``: dicts with every name of
    :data:`COLUMN_NAMES`, in rank order; ``maps``: ``compliance_m_per_N``, ``stiffness_N_per_m``,
    ``pinch_width_m`` per vertex; ``displacements`` (k, n, 3) [m]."""
    missing = [c for c in COLUMN_NAMES if rows and c not in rows[0]]
    if missing:
        raise RankingFolderError(f"ranking rows lack the columns {missing}")
    rec = {"schema": SCHEMA, "version": VERSION, **record,
           "columns": [{"name": n, "unit": u, "meaning": m} for n, u, m in COLUMNS],
           "files": {"ranking.csv": "every candidate in rank order", "compliance.ply":
                     "limit surface [m] with compliance_m_per_N, stiffness_N_per_m, pinch_width_m per vertex",
                     "shapes.npz": "rest [m], faces, candidates, displacement [m] of the best candidates"}}
    with atomic_folder(out) as tmp:
        with open(tmp / "ranking.csv", "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(COLUMN_NAMES)
            for r in rows:
                w.writerow([_fmt(r[c]) for c in COLUMN_NAMES])
        save_ply(tmp / "compliance.ply", vertices, faces, units="m",
                 vertex_scalars={k: np.asarray(maps[k], float) for k in
                                 ("compliance_m_per_N", "stiffness_N_per_m", "pinch_width_m")})
        np.savez_compressed(tmp / "shapes.npz", rest=np.asarray(vertices, float), faces=np.asarray(faces, np.int64),
                            candidates=np.asarray(shape_candidates, np.int64),
                            displacement=np.asarray(displacements, np.float32))
        (tmp / "ranking.json").write_text(json.dumps(rec, indent=1, default=float) + "\n")
    return Path(out)


def read_ranking(folder: str | PathLike) -> Ranking:
    """Read a ranking folder; one-line :class:`RankingFolderError` for a missing or damaged file."""
    folder = Path(folder)
    for f in FILES:
        if not (folder / f).is_file():
            raise RankingFolderError(f"{folder}: not a ranking folder ({f} is missing; graspdef rank writes one)")
    try:
        record = json.loads((folder / "ranking.json").read_text())
    except (OSError, ValueError) as exc:
        raise RankingFolderError(f"{folder / 'ranking.json'}: unreadable ({exc})") from exc
    if not isinstance(record, dict):
        raise RankingFolderError(f"{folder / 'ranking.json'}: not a ranking record (a JSON object)")
    if record.get("schema") != SCHEMA or record.get("version") != VERSION:
        raise RankingFolderError(f"{folder / 'ranking.json'}: schema {record.get('schema')!r} version "
                                 f"{record.get('version')!r}; this graspdef reads {SCHEMA} version {VERSION}")
    try:
        with open(folder / "ranking.csv", newline="") as fh:
            header, *lines = list(csv.reader(fh)) or [None]
    except (UnicodeDecodeError, csv.Error) as exc:
        raise RankingFolderError(f"{folder / 'ranking.csv'}: unreadable ({exc})") from None
    if header != COLUMN_NAMES:
        raise RankingFolderError(f"{folder / 'ranking.csv'}: columns {header} are not those of this graspdef")
    short = [k for k, r in enumerate(lines, start=2) if len(r) != len(COLUMN_NAMES)]
    if short:
        raise RankingFolderError(f"{folder / 'ranking.csv'}: line {short[0]} has {len(lines[short[0] - 2])} "
                                 f"values, not {len(COLUMN_NAMES)}")
    try:
        data = np.array([[float(x) for x in r] for r in lines], dtype=float).reshape(-1, len(COLUMN_NAMES))
    except ValueError as exc:
        raise RankingFolderError(f"{folder / 'ranking.csv'}: a value is not a number ({exc})") from exc
    table = {c: (data[:, i].astype(np.int64) if c in INT_COLUMNS else data[:, i]) for i, c in enumerate(COLUMN_NAMES)}
    verts, faces, attrs, units = _ply(folder / "compliance.ply", str(folder))
    maps = ("compliance_m_per_N", "stiffness_N_per_m", "pinch_width_m")
    if units != "m" or attrs is None or not set(maps) <= set(attrs.dtype.names or ()):
        raise RankingFolderError(f"{folder / 'compliance.ply'}: not a compliance map in metres (units {units!r}, "
                                 f"needs {', '.join(maps)} per vertex)")
    try:
        with np.load(folder / "shapes.npz") as z:
            cands, disp = z["candidates"], z["displacement"]
    except (OSError, ValueError, KeyError, zipfile.BadZipFile) as exc:
        raise RankingFolderError(f"{folder / 'shapes.npz'}: unreadable ({exc})") from None
    if disp.ndim != 3 or disp.shape[1:] != verts.shape or len(cands) != len(disp):
        raise RankingFolderError(f"{folder / 'shapes.npz'}: displacement {disp.shape} does not match the surface's "
                                 f"{verts.shape} and {len(cands)} candidates")
    absent = sorted(set(np.asarray(cands).tolist()) - set(table["candidate"].tolist()))
    if absent:
        raise RankingFolderError(f"{folder / 'shapes.npz'}: candidates {absent} are not in ranking.csv")
    return Ranking(folder, record, table, verts, faces,
                   np.asarray(attrs["compliance_m_per_N"], float), np.asarray(attrs["stiffness_N_per_m"], float),
                   np.asarray(attrs["pinch_width_m"], float), np.asarray(cands), disp)
