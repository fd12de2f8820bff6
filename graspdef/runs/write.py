"""The one run-folder writer (the format: docs/run-folder.md).

:func:`write_run` writes, atomically (:func:`graspdef.runs.folder.atomic_folder`):

* ``result.json`` -- the :class:`~graspdef.runs.record.RunRecord`;
* ``deformed.ply`` -- the deformed limit surface with per-vertex ``ux, uy, uz`` (the displacement
  field that defines ``derived.max_displacement``), ``displacement`` (its magnitude) and, for
  nonlinear runs, ``strain_energy_density`` [J/m^2];
* ``undeformed.ply`` -- the limit surface at rest (the baseline of scan scores);
* ``deformed.vtu`` -- the same surface and fields for ParaView (VTK XML, ASCII);
* ``path.csv`` (a load path: one row per converged point; every column name carries its unit) and
  ``path_u.npz`` (the control-point displacements of every point, :mod:`graspdef.runs.pathfile`);
* any extra JSON or text files the kind has (``contacts.json``, ``problem.toml``);
* ``provenance.json`` (:mod:`graspdef.runs.provenance`).

Lengths are metres (or the run's consistent unit), forces newtons: the writer takes SI arrays.
"""
from __future__ import annotations

import csv
import json
from os import PathLike
from pathlib import Path

import numpy as np

from ..geometry.io import save_ply
from .folder import atomic_folder
from .pathfile import write_path_u
from .provenance import write_provenance
from .record import RunRecord


def _vtu(path: Path, verts: np.ndarray, faces: np.ndarray, point_data: dict[str, np.ndarray], units: str) -> None:
    """A triangle surface with point data as an ASCII VTK XML unstructured grid."""
    def arr(a, name=None, n=1, typ="Float64"):
        head = f'<DataArray type="{typ}"' + (f' Name="{name}"' if name else "") + \
               f' NumberOfComponents="{n}" format="ascii">'
        body = " ".join(repr(float(v)) if typ.startswith("Float") else str(int(v)) for v in np.ravel(a))
        return f"{head}\n{body}\n</DataArray>\n"

    pd = "".join(arr(v, k, 1 if v.ndim == 1 else v.shape[1]) for k, v in point_data.items())
    text = (f'<?xml version="1.0"?>\n<!-- graspdef run: lengths in {units} -->\n'
            '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">\n<UnstructuredGrid>\n'
            f'<Piece NumberOfPoints="{len(verts)}" NumberOfCells="{len(faces)}">\n'
            f"<PointData>\n{pd}</PointData>\n<Points>\n{arr(verts, n=3)}</Points>\n<Cells>\n"
            + arr(faces, "connectivity", typ="Int64") + arr(3 * np.arange(1, len(faces) + 1), "offsets", typ="Int64")
            + arr(np.full(len(faces), 5), "types", typ="UInt8")
            + "</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")
    path.write_text(text)


def write_run(out: str | PathLike, record: RunRecord, *, rest: np.ndarray, deformed: np.ndarray,
              faces: np.ndarray, displacement: np.ndarray, path: tuple[list[str], list[list]] | None = None,
              path_u: tuple[np.ndarray, np.ndarray, object] | None = None, json_files: dict | None = None,
              text_files: dict | None = None, provenance: dict | None = None,
              vertex_fields: dict | None = None) -> Path:
    """Write a run folder (see the module docstring); return its path.

    ``rest``, ``deformed`` (n, 3): limit surface at rest and deformed; ``displacement`` (n, 3):
    the field of ``record.derived['max_displacement']``; ``path``: (header, rows) of path.csv;
    ``path_u``: (u (k, n_control, 3), load factors (k,), limit map); ``vertex_fields``: further
    per-vertex scalars (n,), SI (e.g. ``strain_energy_density`` [J/m^2]), into both surfaces files."""
    unit = record.units["length"]
    rest, deformed, displacement = (np.asarray(a, dtype=float) for a in (rest, deformed, displacement))
    files = {"result": "result.json", "deformed": "deformed.ply", "undeformed": "undeformed.ply",
             "deformed_vtu": "deformed.vtu", "provenance": "provenance.json"}
    if path is not None:
        files["path"] = "path.csv"
    if path_u is not None:
        files["path_u"] = "path_u.npz"
    for name in list(json_files or {}) + list(text_files or {}):
        files[Path(name).stem] = name
    rec = RunRecord(record.kind, record.name, record.analysis, record.units, record.derived, files, record.data)
    mag = np.linalg.norm(displacement, axis=1)
    with atomic_folder(out) as tmp:
        (tmp / "result.json").write_text(json.dumps(rec.to_json(), indent=2, default=float) + "\n")
        save_ply(tmp / "deformed.ply", deformed, faces, units=unit,
                 vertex_scalars={"ux": displacement[:, 0], "uy": displacement[:, 1], "uz": displacement[:, 2],
                                 "displacement": mag, **(vertex_fields or {})})
        save_ply(tmp / "undeformed.ply", rest, faces, units=unit)
        _vtu(tmp / "deformed.vtu", deformed, faces, {"displacement": displacement, "displacement_magnitude": mag,
                                                     **{k: np.asarray(v, float) for k, v in (vertex_fields or {}).items()}},
             unit)
        if path is not None:
            header, rows = path
            with open(tmp / "path.csv", "w", newline="") as fh:
                w = csv.writer(fh)
                w.writerow(header)
                w.writerows(rows)
        if path_u is not None:
            write_path_u(tmp, *path_u)
        for name, obj in (json_files or {}).items():
            (tmp / name).write_text(json.dumps(obj, indent=2, default=float) + "\n")
        for name, text in (text_files or {}).items():
            (tmp / name).write_text(text)
        write_provenance(tmp, provenance)
    return Path(out)
