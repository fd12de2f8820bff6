"""Where the contact barrier looks: samples of the shell's limit surface on the faces near a
fingertip (sub-triangle centroids of each face's parameter domain, weighted by their rest area)."""
from __future__ import annotations

import numpy as np


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
