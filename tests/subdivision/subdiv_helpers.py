"""Meshes and checks shared by the subdivision tests (imported by name: pytest puts this folder on
sys.path).  Nothing here calls graspdef except ``loop_refine``, which only chains ``rules.refine``."""
from __future__ import annotations

import numpy as np

from graspdef.subdivision.rules import refine

from graspdef.testing import FD_FLOOR, assert_fd_rate  # noqa: F401  (re-exported for the tests)


def bipyramid(n: int, rng=None, jitter: float = 0.0):
    """Closed double cone: ``n`` equator vertices (valence 4) and two poles of valence ``n``.

    Vertices 0..n-1 on the unit circle, ``n`` = north pole (z = 1), ``n+1`` = south pole.  Each
    face lists its pole first, so in the chart of face ``f`` the pole is at (0, 0).  Faces
    0..n-1 hold the north pole (face i = (N, e_i, e_i+1)), faces n..2n-1 the south pole.
    """
    t = 2.0 * np.pi * np.arange(n) / n
    eq = np.stack([np.cos(t), np.sin(t), np.zeros(n)], axis=1)
    x = np.vstack([eq, [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]])
    i = np.arange(n)
    j = (i + 1) % n
    north = np.stack([np.full(n, n), i, j], axis=1)
    south = np.stack([np.full(n, n + 1), j, i], axis=1)
    if rng is not None and jitter > 0:
        x = x + jitter * rng.standard_normal(x.shape)
    return x, np.vstack([north, south]).astype(np.int64)


def torus(nu: int, nv: int, R: float = 2.0, r: float = 0.7):
    """Closed torus triangulated as a doubly periodic grid: every vertex has valence 6."""
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="xy")
    u = 2 * np.pi * i.ravel() / nu
    v = 2 * np.pi * j.ravel() / nv
    x = np.stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)], 1)
    v00 = (i + j * nu).ravel()
    v10 = ((i + 1) % nu + j * nu).ravel()
    v01 = (i + ((j + 1) % nv) * nu).ravel()
    v11 = ((i + 1) % nu + ((j + 1) % nv) * nu).ravel()
    f = np.concatenate([np.stack([v00, v10, v11], 1), np.stack([v00, v11, v01], 1)])
    return x, f.astype(np.int64)


def random_flips(x, faces, rng, n_flips: int, min_valence: int = 3):
    """Topologically valid random edge flips of a closed oriented mesh (valences spread out).

    A flip of edge a-b between faces (a, b, c) and (b, a, d) gives (a, d, c) and (d, b, c); it is
    skipped if c-d already is an edge or a or b would drop below ``min_valence``."""
    f = np.array(faces, dtype=np.int64)
    owner = {}                                   # directed edge -> face
    for fi, (a, b, c) in enumerate(f.tolist()):
        owner[a, b] = owner[b, c] = owner[c, a] = fi
    val = np.bincount(_edges(f).ravel(), minlength=len(x))
    for _ in range(n_flips):
        fi = int(rng.integers(len(f)))
        k = int(rng.integers(3))
        a, b, c = (int(f[fi, (k + s) % 3]) for s in range(3))
        gi = owner[b, a]
        d = next(int(v) for v in f[gi] if v != a and v != b)
        if c == d or (c, d) in owner or (d, c) in owner:
            continue
        if val[a] - 1 < min_valence or val[b] - 1 < min_valence:
            continue
        for e in ((a, b), (b, c), (c, a), (b, a), (a, d), (d, b)):
            del owner[e]
        f[fi] = (a, d, c)
        f[gi] = (d, b, c)
        for g in (fi, gi):
            p, q, r = (int(v) for v in f[g])
            owner[p, q] = owner[q, r] = owner[r, p] = g
        val[a] -= 1
        val[b] -= 1
        val[c] += 1
        val[d] += 1
    return f


def _edges(f):
    pairs = np.sort(np.stack([f.ravel(), np.roll(f, -1, axis=1).ravel()], 1), axis=1)
    return np.unique(pairs, axis=0)


def valences(faces, nv):
    return np.bincount(_edges(np.asarray(faces)).ravel(), minlength=nv)


def loop_refine(x, faces, levels: int):
    """Control points and faces after ``levels`` Loop steps (``rules.refine`` chained)."""
    x = np.asarray(x, float)
    f = np.asarray(faces, np.int64)
    for _ in range(levels):
        S, f = refine(f, len(x))
        x = S @ x
    return x, f


# chart corners (v, w) of the four children of a face, in the child numbering of ``rules.refine``
# (child k = 4 f + k): corners at parent vertex 0, 1, 2 and the centre triangle.
_CHILD_CORNERS = np.array([
    [[0.0, 0.0], [0.5, 0.0], [0.0, 0.5]],
    [[0.5, 0.0], [1.0, 0.0], [0.5, 0.5]],
    [[0.0, 0.5], [0.5, 0.5], [0.0, 1.0]],
    [[0.5, 0.5], [0.0, 0.5], [0.5, 0.0]],
])
_CORNERS = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


def refinement_chain(x, faces, levels: int):
    """Lists [x_0 .. x_levels], [faces_0 .. faces_levels] of successive Loop refinements."""
    xs = [np.asarray(x, float)]
    fs = [np.asarray(faces, np.int64)]
    for _ in range(levels):
        S, f = refine(fs[-1], len(xs[-1]))
        xs.append(S @ xs[-1])
        fs.append(f)
    return xs, fs


def dyadic_vertex(fs, face: int, point):
    """Level and index of the control vertex that sits at chart point ``point`` of ``face`` of
    ``fs[0]``, where ``fs`` are the face arrays of successive refinements (``refinement_chain``).
    Child k of face f is face 4 f + k of the next level (``rules.refine``).  Independent of
    ``basis._child_coords``: the child holding the point is found by barycentric coordinates from
    the corner table above."""
    p = np.asarray(point, float)
    cur = int(face)
    for level in range(len(fs)):
        hit = np.flatnonzero(np.abs(_CORNERS - p).sum(1) < 1e-12)
        if len(hit):
            return level, int(fs[level][cur, hit[0]])
        for k in range(4):
            P = _CHILD_CORNERS[k]
            T = np.column_stack([P[1] - P[0], P[2] - P[0]])
            loc = np.linalg.solve(T, p - P[0])
            if loc.min() >= -1e-14 and loc.sum() <= 1 + 1e-14:
                cur, p = 4 * cur + k, loc
                break
        else:
            raise AssertionError("point outside the reference triangle")
    raise AssertionError(f"chart point is not a vertex after {len(fs) - 1} refinements")


def edge_chart(face_vertices, a: int, b: int, t):
    """Chart points (v, w) in a face of the points (1-t) a + t b along its edge a-b."""
    fv = list(np.asarray(face_vertices))
    t = np.atleast_1d(np.asarray(t, float))
    bary = np.zeros((len(t), 3))
    bary[:, fv.index(a)] = 1.0 - t
    bary[:, fv.index(b)] = t
    return bary[:, 1:3]
