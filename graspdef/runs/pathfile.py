"""``path_u.npz``: the control-point displacements of every converged point of a load path.

A run folder's ``path.csv`` holds one row per converged point, but only probe displacements; this
optional file adds the full state so that a viewer can show the surface at every step without
re-solving.  It depends on numpy and scipy only.

Keys (SI, metres):

* ``u`` (n_points, n_control, 3) float64: control-point displacements, ghosts included;
* ``load_factors`` (n_points,) float64: the rows of ``path.csv`` in the same order;
* ``limit_data``, ``limit_indices``, ``limit_indptr``, ``limit_shape``: the CSR limit map L
  (n_vertices, n_control) with ``L @ (X + u)`` the limit surface at the real control vertices
  (the vertex order of ``deformed.ply``);
* ``format`` = "graspdef.path_u/1".
"""
from __future__ import annotations

from os import PathLike
from pathlib import Path

import numpy as np
import scipy.sparse as sp

FILENAME = "path_u.npz"
FORMAT = "graspdef.path_u/1"


def write_path_u(run_dir: str | PathLike, u: np.ndarray, load_factors: np.ndarray, limit_map: sp.spmatrix) -> Path:
    """Write ``path_u.npz`` into ``run_dir``.

    Parameters
    ----------
    u : (n_points, n_control, 3) control-point displacements [m]
    load_factors : (n_points,)
    limit_map : (n_vertices, n_control) sparse limit map

    Returns the written path.
    """
    u = np.asarray(u, dtype=np.float64)
    lf = np.asarray(load_factors, dtype=np.float64)
    L = sp.csr_matrix(limit_map)
    if u.ndim != 3 or u.shape[2] != 3 or u.shape[0] != lf.shape[0] or L.shape[1] != u.shape[1]:
        raise ValueError(f"path_u: inconsistent shapes u {u.shape}, load_factors {lf.shape}, limit map {L.shape}")
    path = Path(run_dir) / FILENAME
    np.savez_compressed(path, u=u, load_factors=lf, limit_data=L.data, limit_indices=L.indices,
                        limit_indptr=L.indptr, limit_shape=np.array(L.shape), format=np.array(FORMAT))
    return path


def read_path_u(path: str | PathLike) -> tuple[np.ndarray, np.ndarray, sp.csr_matrix]:
    """Read ``path_u.npz``: (u (k, n_control, 3) [m], load factors (k,), limit map).

    Raises ValueError for a file that is not a path_u file or is inconsistent."""
    with np.load(path, allow_pickle=False) as z:
        if "format" not in z or str(z["format"]) != FORMAT:
            raise ValueError(f"{path}: not a {FORMAT} file")
        u, lf = z["u"], z["load_factors"]
        L = sp.csr_matrix((z["limit_data"], z["limit_indices"], z["limit_indptr"]), shape=tuple(z["limit_shape"]))
    if u.ndim != 3 or u.shape[0] != lf.shape[0] or L.shape[1] != u.shape[1]:
        raise ValueError(f"{path}: inconsistent shapes u {u.shape}, load factors {lf.shape}, limit map {L.shape}")
    return u, lf, L
