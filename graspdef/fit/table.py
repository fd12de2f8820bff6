"""The measured force-displacement table: a CSV file whose header states the unit of every column,
read into SI at I/O.

    # tennis ball, Tian & Jia 2010, Table II (indentation per finger)
    force_N,displacement_mm,point
    10.63,2.56,finger
    16.50,6.05,finger

Columns (any order; ``#`` starts a comment line):

* ``force_<unit>`` (required): the squeezing force per finger, > 0; unit N, kN or mN;
* ``displacement_<unit>`` (required): the measured displacement; unit m, mm, cm, um or in;
* ``point`` (optional, default ``finger``): which displacement of the forward model the row
  measures (an object: ``finger``, ``max``, ``approach``, or a finger ``left``/``right``; a shell
  model: the names of its measures);
* ``sigma_<unit>`` (optional): the row's measurement standard deviation, a length > 0 (the fit's
  weights; without it every row is weighted alike).

A header without a unit (``force,displacement``), an unknown column or unit, a value that is no
number, a non-positive force or sigma: one line (:class:`~graspdef.errors.ConfigError`) naming
the file, the line and the column.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ConfigError
from ..units import DIMENSIONS, unit_factor

#: the columns a table may have: base name -> dimension of its unit (None: a text column, no unit)
COLUMNS = {"force": "force", "displacement": "length", "sigma": "length", "point": None}
REQUIRED = ("force", "displacement")
DEFAULT_POINT = "finger"


@dataclass(frozen=True)
class MeasuredTable:
    """A force-displacement table in SI.

    Attributes
    ----------
    force : (m,) float array, squeezing force per finger [N]
    displacement : (m,) float array, measured displacement [m]
    point : tuple of m str, what each row measures (see the module docstring)
    sigma : (m,) float array [m] or None, each row's standard deviation
    file : Path or None, where it was read from
    units : the units the file's header stated (column -> unit), for the record
    """

    force: np.ndarray
    displacement: np.ndarray
    point: tuple[str, ...]
    sigma: np.ndarray | None = None
    file: Path | None = None
    units: dict | None = None

    def __post_init__(self) -> None:
        m = len(self.force)
        if m == 0:
            raise ConfigError(f"{self.file or 'table'}: no data rows")
        if len(self.displacement) != m or len(self.point) != m or (self.sigma is not None and len(self.sigma) != m):
            raise ConfigError(f"{self.file or 'table'}: columns of different lengths")
        if not np.all(np.isfinite(self.force)) or np.any(np.asarray(self.force) <= 0):
            raise ConfigError(f"{self.file or 'table'}: every force must be a positive number of newtons")

    def __len__(self) -> int:
        return len(self.force)


def _column(name: str, path: Path) -> tuple[str, str | None, float]:
    """A header cell -> (base name, unit, factor to SI)."""
    cell = name.strip()
    if cell == "point":
        return "point", None, 1.0
    base, _, unit = cell.partition("_")
    if base not in COLUMNS or base == "point":
        raise ConfigError(f"{path}: unknown column {cell!r}; accepted: force_<unit>, displacement_<unit>, "
                          "point, sigma_<unit> (e.g. force_N,displacement_mm,point)")
    dim = COLUMNS[base]
    if not unit:
        raise ConfigError(f"{path}: column {cell!r} states no unit; write {base}_<unit>, e.g. "
                          f"{base}_{next(iter(DIMENSIONS[dim]))} ({dim} units: {', '.join(DIMENSIONS[dim])})")
    return base, unit, unit_factor(unit, dim, f"{path}: column {cell!r}")


def read_table(path) -> MeasuredTable:
    """Read a force-displacement table (see the module docstring) into SI."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"data table not found: {path}")
    lines = [(i + 1, line) for i, line in enumerate(path.read_text().splitlines())
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise ConfigError(f"{path}: empty (expected a header such as force_N,displacement_mm,point and data rows)")
    rows = list(csv.reader([line for _, line in lines]))
    header = [_column(c, path) for c in rows[0]]
    bases = [b for b, _, _ in header]
    for b in set(bases):
        if bases.count(b) > 1:
            raise ConfigError(f"{path}: column {b!r} appears {bases.count(b)} times")
    for b in REQUIRED:
        if b not in bases:
            raise ConfigError(f"{path}: no {b} column (the header needs force_<unit> and displacement_<unit>, "
                              "e.g. force_N,displacement_mm,point)")
    if len(rows) < 2:
        raise ConfigError(f"{path}: no data rows below the header")
    cols: dict[str, list] = {b: [] for b in bases}
    for (lineno, _), row in zip(lines[1:], rows[1:]):
        if len(row) != len(header):
            raise ConfigError(f"{path}:{lineno}: {len(row)} values for {len(header)} columns")
        for (base, unit, factor), cell, name in zip(header, row, rows[0]):
            if base == "point":
                if not cell.strip():
                    raise ConfigError(f"{path}:{lineno}: empty point")
                cols[base].append(cell.strip())
                continue
            try:
                x = float(cell)
            except ValueError:
                raise ConfigError(f"{path}:{lineno}: {name.strip()} {cell.strip()!r} is not a number") from None
            if not math.isfinite(x):
                raise ConfigError(f"{path}:{lineno}: {name.strip()} must be finite, got {cell.strip()!r}")
            if base in ("force", "sigma") and x <= 0:
                what = "force" if base == "force" else "sigma (a standard deviation)"
                raise ConfigError(f"{path}:{lineno}: the {what} must be positive, got {cell.strip()}")
            cols[base].append(x * factor)
    m = len(cols["force"])
    return MeasuredTable(np.array(cols["force"]), np.array(cols["displacement"]),
                         tuple(cols.get("point", [DEFAULT_POINT] * m)),
                         np.array(cols["sigma"]) if "sigma" in cols else None, path,
                         {b: u for b, u, _ in header if u is not None})
