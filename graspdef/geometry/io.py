"""Reading meshes in any format trimesh understands and writing PLY files with a unit comment."""

from __future__ import annotations

import re
from collections.abc import Mapping
from os import PathLike
from pathlib import Path

import numpy as np

from graspdef.errors import MeshError, ProblemError
from graspdef.geometry.mesh import TriMesh
from graspdef.units import LENGTH_UNITS, length_scale  # noqa: F401  (re-exported: the tables live in graspdef.units)

_PROPERTY_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _declared_face_count(path: Path) -> int | None:
    """Number of faces (polygons) the file declares, for OBJ, OFF and PLY files; else None."""
    suffix = path.suffix.lower()
    if suffix == ".obj":
        return len(re.findall(rb"^[ \t]*f[ \t]", path.read_bytes(), flags=re.MULTILINE))
    with path.open("rb") as fh:
        head = fh.read(65536)
    if suffix == ".ply":
        match = re.search(rb"^element[ \t]+face[ \t]+(\d+)", head, flags=re.MULTILINE)
        return int(match.group(1)) if match else None
    if suffix == ".off":
        tokens = re.sub(rb"#[^\n]*", b"", head).split()
        return int(tokens[2]) if len(tokens) > 2 and tokens[0].endswith(b"OFF") else None
    return None


def load_mesh(path: str | PathLike, units: str) -> TriMesh:
    """Read a triangle mesh and convert it to metres.

    Parameters
    ----------
    path : str or path-like
        Any format ``trimesh.load`` reads (PLY, OBJ, STL, OFF, ...); loaded with
        ``process=False`` so vertex order and count are kept.
    units : str
        Length unit of the coordinates in the file, a key of :data:`LENGTH_UNITS`.

    Returns
    -------
    TriMesh
        Validated mesh with vertices in metres.

    Raises
    ------
    ProblemError
        If the file does not exist or ``units`` is unknown.
    MeshError
        If trimesh cannot read the file, the file contains polygons with more than three
        vertices (for OBJ, OFF and PLY, detected by comparing the declared face count with the
        triangles trimesh returns) or the mesh fails :func:`~graspdef.geometry.mesh.validate_mesh`.
    """
    scale = length_scale(units)
    path = Path(path)
    if not path.is_file():
        raise ProblemError(f"mesh file not found: {path}")
    import trimesh  # here, not at import: it costs ~0.2-0.7 s and most runs never read a mesh file

    try:
        loaded = trimesh.load(path, process=False, force="mesh")
        vertices, faces = np.asarray(loaded.vertices), np.asarray(loaded.faces)
    except Exception as exc:  # trimesh raises many exception types for unreadable files
        raise MeshError(f"cannot read mesh file {path}: {exc}") from exc
    declared = _declared_face_count(path)
    if declared is not None and declared != faces.shape[0]:
        raise MeshError(f"{path}: faces must be triangles; the file declares {declared} faces "
                        f"but they form {faces.shape[0]} triangles (some have more than 3 "
                        "vertices)")
    return TriMesh(vertices * scale, faces).validated(str(path))


def save_ply(path: str | PathLike, vertices: np.ndarray, faces: np.ndarray, *,
             units: str = "m", vertex_scalars: Mapping[str, np.ndarray] | None = None,
             binary: bool = True) -> None:
    """Write a triangle mesh as a PLY file with a ``comment units <units>`` header line.

    Parameters
    ----------
    path : str or path-like
        Output file; overwritten if it exists.
    vertices : ndarray, shape (n, 3), float
        Vertex positions [m]; written divided by the unit length so the file is in ``units``.
    faces : ndarray, shape (m, 3), int
        Triangles, written as ``property list uchar int vertex_indices``.
    units : str
        Length unit of the written coordinates, a key of :data:`LENGTH_UNITS`, or
        ``"consistent"`` for a self-consistent unit set (coordinates written as given).
    vertex_scalars : mapping of str to ndarray of shape (n,), optional
        Extra per-vertex ``double`` properties (e.g. ``{"displacement": |u|}``), written as
        given (no unit conversion).  Names must be identifiers other than x, y, z.
    binary : bool
        Binary little-endian if True, ASCII otherwise.

    Raises
    ------
    ProblemError
        For unknown units, wrongly shaped arrays or invalid scalar names.
    """
    scale = 1.0 if units == "consistent" else length_scale(units)
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces)
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        raise ProblemError(f"vertices must have shape (n, 3), got {vertices.shape}")
    if faces.ndim != 2 or faces.shape[1] != 3 or not np.issubdtype(faces.dtype, np.integer):
        raise ProblemError(f"faces must be integers of shape (m, 3), got {faces.dtype} "
                           f"{faces.shape}")
    columns = {"x": vertices[:, 0] / scale, "y": vertices[:, 1] / scale,
               "z": vertices[:, 2] / scale}
    for name, values in (vertex_scalars or {}).items():
        values = np.asarray(values, dtype=np.float64)
        if not _PROPERTY_NAME.fullmatch(name) or name in columns:
            raise ProblemError(f"invalid vertex scalar name {name!r}")
        if values.shape != (vertices.shape[0],):
            raise ProblemError(f"vertex scalar {name!r} must have shape ({vertices.shape[0]},), "
                               f"got {values.shape}")
        columns[name] = values

    header = "\n".join([
        "ply",
        f"format {'binary_little_endian' if binary else 'ascii'} 1.0",
        f"comment units {units}",
        f"element vertex {vertices.shape[0]}",
        *(f"property double {name}" for name in columns),
        f"element face {faces.shape[0]}",
        "property list uchar int vertex_indices",
        "end_header",
    ]) + "\n"
    with Path(path).open("wb") as fh:
        fh.write(header.encode("ascii"))
        if binary:
            table = np.empty(vertices.shape[0], dtype=[(name, "<f8") for name in columns])
            for name, values in columns.items():
                table[name] = values
            polygons = np.empty(faces.shape[0], dtype=[("n", "u1"), ("v", "<i4", (3,))])
            polygons["n"], polygons["v"] = 3, faces
            fh.write(table.tobytes())
            fh.write(polygons.tobytes())
        else:
            np.savetxt(fh, np.column_stack(list(columns.values())), fmt="%.17g")
            np.savetxt(fh, np.column_stack([np.full(faces.shape[0], 3), faces]), fmt="%d")
