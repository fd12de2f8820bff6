"""Where the contact barrier looks: the faces near a fingertip (:func:`select_faces`) and samples of
the shell's limit surface on them (:func:`sample_faces`: sub-triangle centroids of each face's
parameter domain, weighted by their rest area)."""
from __future__ import annotations

import numpy as np

from ..errors import ProblemError


def select_faces(shell, obstacle, e: np.ndarray, reach: float | None, depth: float | None,
                 spacing: float | None, name: str) -> tuple[np.ndarray, int]:
    """The real faces within the fingertip's reach and the sub-division L of each into L x L
    sample triangles.

    ``reach`` [m]: lateral radius about the axis ``e`` (faces whose control centroid is within it;
    default: the obstacle's lateral extent plus one control-mesh edge); ``depth`` [m]: at most this
    far in front of / behind the obstacle's front (default: half the shell's extent along e);
    ``spacing`` [m]: largest sample spacing (default: a third of the obstacle's smallest radius of
    curvature)."""
    X = shell.rest_positions
    mesh = shell.mesh
    real = mesh.faces[: mesh.n_real_faces]
    edge = float(np.linalg.norm(X[real[:, [1, 2, 0]]] - X[real], axis=-1).mean())
    cen = X[real].mean(axis=1)
    # front of the obstacle at s = 0: its distance-minimising point towards the shell's centroid
    c = X.mean(axis=0)
    phi, n = obstacle.distance(c[None], False)
    probe = c - phi[0] * n[0]
    rel = cen - probe
    ax = rel @ e
    lat = np.linalg.norm(rel - ax[:, None] * e, axis=1)
    reach = reach if reach is not None else obstacle.reach() + edge
    ext = (X @ e).max() - (X @ e).min()
    depth = depth if depth is not None else 0.5 * ext
    faces = np.flatnonzero((lat <= reach) & (ax <= depth) & (ax >= -depth))
    if len(faces) == 0:
        raise ProblemError(f"finger contact '{name}': no shell face within reach ({reach:.3g} m) of the fingertip")
    spacing = spacing if spacing is not None else obstacle.feature_radius / 3
    return faces, int(np.clip(np.ceil(edge / spacing), 1, 12))


def sample_faces(shell, ev, faces: np.ndarray, L: int):
    """Sub-triangle centroids of ``faces`` (L x L per face): stencils (F, S), N (F, q, S) and
    rest weights (F, q) [m^2]; S padded with zero weights."""
    pts = []
    for i in range(L):
        for j in range(L - i):
            pts.append(((i + 1 / 3) / L, (j + 1 / 3) / L))
            if i + j <= L - 2:
                pts.append(((i + 2 / 3) / L, (j + 2 / 3) / L))
    pts = np.array(pts)
    X = shell.rest_positions
    st_l, N_l, w_l = [], [], []
    for f in faces:
        st, N, dN, _ = ev.basis(int(f), pts)
        a1 = np.einsum("qs,sd->qd", dN[:, :, 0], X[st])
        a2 = np.einsum("qs,sd->qd", dN[:, :, 1], X[st])
        st_l.append(st)
        N_l.append(N)
        w_l.append(np.linalg.norm(np.cross(a1, a2), axis=1) / (2 * L * L))
    S = max(len(s) for s in st_l)
    stn = np.zeros((len(faces), S), np.int64)
    Nn = np.zeros((len(faces), len(pts), S))
    for k, (s, N) in enumerate(zip(st_l, N_l)):
        stn[k, : len(s)] = s
        Nn[k, :, : len(s)] = N
    return stn, Nn, np.array(w_l)
