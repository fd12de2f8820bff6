"""Half-edge look-ups on an oriented triangle mesh (vectorised).

For a face ``(i, j, k)`` listed counter-clockwise, walking counter-clockwise around vertex ``i``
from neighbour ``j`` reaches ``k``: ``next_ccw(i, j) = k``.  These look-ups give ordered one-rings,
which is all the Loop basis needs from the topology.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class HalfEdges:
    """Sorted directed-edge keys of a mesh and the third vertex of the face on their left.

    Parameters
    ----------
    keys : (3 n_faces,) int64
        ``i * n_vertices + j`` for every directed edge ``i -> j`` of every face, sorted.
    third : (3 n_faces,) int64
        The face's remaining vertex ``k`` for each key.
    face : (3 n_faces,) int64
        The face that owns each directed edge.
    n_vertices : int
    """

    keys: np.ndarray
    third: np.ndarray
    face: np.ndarray
    n_vertices: int

    @classmethod
    def build(cls, faces: np.ndarray, n_vertices: int) -> "HalfEdges":
        f = np.asarray(faces, dtype=np.int64)
        i = np.concatenate([f[:, 0], f[:, 1], f[:, 2]])
        j = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
        k = np.concatenate([f[:, 2], f[:, 0], f[:, 1]])
        owner = np.tile(np.arange(len(f), dtype=np.int64), 3)
        keys = i * n_vertices + j
        order = np.argsort(keys, kind="stable")
        return cls(keys[order], k[order], owner[order], n_vertices)

    def _find(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        q = np.asarray(i, dtype=np.int64) * self.n_vertices + np.asarray(j, dtype=np.int64)
        pos = np.searchsorted(self.keys, q)
        pos = np.minimum(pos, len(self.keys) - 1)
        return np.where(self.keys[pos] == q, pos, -1)

    def next_ccw(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Vertex after ``j`` counter-clockwise around ``i`` (-1 where ``i -> j`` has no face)."""
        pos = self._find(i, j)
        return np.where(pos >= 0, self.third[np.maximum(pos, 0)], -1)

    def face_of(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Face containing the directed edge ``i -> j`` (-1 if none)."""
        pos = self._find(i, j)
        return np.where(pos >= 0, self.face[np.maximum(pos, 0)], -1)

    def rings(self, centers: np.ndarray, firsts: np.ndarray, length: int) -> np.ndarray:
        """Ordered counter-clockwise rings of ``length`` vertices starting at ``firsts``.

        Returns (n, length) int64; entries past a missing face are -1.
        """
        out = np.empty((len(centers), length), dtype=np.int64)
        out[:, 0] = firsts
        for m in range(1, length):
            prev = out[:, m - 1]
            out[:, m] = np.where(prev >= 0, self.next_ccw(centers, np.maximum(prev, 0)), -1)
        return out


def face_counts(faces: np.ndarray, n_vertices: int) -> np.ndarray:
    """Number of faces incident to each vertex, (n_vertices,) int64."""
    return np.bincount(np.asarray(faces).ravel(), minlength=n_vertices)


def interior_mask(faces: np.ndarray, n_vertices: int) -> np.ndarray:
    """True where every edge at the vertex has a face on both sides (a closed one-ring)."""
    f = np.asarray(faces, dtype=np.int64)
    i = np.concatenate([f[:, 0], f[:, 1], f[:, 2]])
    j = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
    fwd = i * n_vertices + j
    rev = np.sort(j * n_vertices + i)
    pos = np.minimum(np.searchsorted(rev, fwd), len(rev) - 1)
    unmatched = rev[pos] != fwd          # directed edge i->j whose twin j->i is missing
    ok = np.ones(n_vertices, dtype=bool)
    ok[i[unmatched]] = False
    ok[j[unmatched]] = False
    ok[np.bincount(f.ravel(), minlength=n_vertices) == 0] = False
    return ok
