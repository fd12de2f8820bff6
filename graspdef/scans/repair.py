"""A user's mesh file -> a closed, consistently oriented triangle surface in metres, or one clear
error naming what is wrong and where.

Repairs that cannot change the object's shape are made and listed (duplicate faces, unreferenced
vertices, unwelded triangle soup as STL files hold it, small holes of up to a few edges, the
faces' orientation, loose debris far smaller than the object, coincident vertices of two surface
sheets pulled apart); anything else -- a point cloud, an open surface, edges shared by three or
more faces, several objects in one file -- is refused with the offending elements named (indices
and positions in mm), because fixing it means guessing the shape.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import trimesh

from ..errors import MeshError
from ..geometry import TriMesh
from ..geometry.mesh import boundary_loops, edge_face_counts, is_closed

#: a loose component below this fraction of the largest's area is debris, dropped with a note
DEBRIS_AREA = 0.01
#: holes of at most this many boundary edges are closed (trimesh.repair.fill_holes)
SMALL_HOLE_EDGES = 8


@dataclass
class RepairedSurface:
    """A closed, outward-oriented surface [m] and the repairs made to get it (one line each)."""

    mesh: TriMesh
    repairs: list[str] = field(default_factory=list)


def _n(count: int, word: str) -> str:
    """``3 holes``, ``1 hole``."""
    return f"{count} {word}" if count == 1 else f"{count} {word}s"


def _mm(p) -> str:
    return "(" + ", ".join(f"{1e3 * c:.2f}" for c in np.asarray(p, float)) + ") mm"


def _listing(items, positions, limit: int = 3) -> str:
    shown = [f"{tuple(int(i) for i in np.ravel(it))} at {_mm(p)}" for it, p in zip(items[:limit], positions[:limit])]
    more = f" and {len(items) - limit} more" if len(items) > limit else ""
    return "; ".join(shown) + more


def _pull_apart(v: np.ndarray, f: np.ndarray) -> int:
    """Coincident vertices that belong to different sheets of the surface (a pinch the scan's
    reconstruction left, e.g. at a bottle's nozzle) moved 30 % towards the centre of their own
    neighbours, so that remeshing does not fuse them into a non-manifold edge.  In place; returns
    how many were moved."""
    _, inv, cnt = np.unique(np.round(v, 12), axis=0, return_inverse=True, return_counts=True)
    inv = np.ravel(inv)
    moved = 0
    for g in np.flatnonzero(cnt > 1):
        for i in np.flatnonzero(inv == g):
            nb = np.unique(f[np.any(f == i, axis=1)])
            nb = nb[nb != i]
            if nb.size:
                v[i] += 0.3 * (v[nb].mean(axis=0) - v[i])
                moved += 1
    return moved


def _split_sheets(v: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """Two sheets of surface touching along an edge (an edge of 4 faces; a closed scan pinched at
    a thin tip, welded): each vertex of such an edge gets one copy per fan of faces connected
    around it through ordinary two-face edges, so that every sheet has its own edge.  The shape is
    unchanged (the copies coincide; :func:`_pull_apart` separates them).  Returns (v, f, copies)."""
    edges, counts = edge_face_counts(f)
    count = {(int(a), int(b)): int(c) for (a, b), c in zip(edges, counts)}
    f = f.copy()
    extra = []
    for vert in np.unique(edges[counts > 2]):
        around = np.flatnonzero(np.any(f == vert, axis=1))
        parent = {int(i): int(i) for i in around}

        def root(i):
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        by_edge: dict = {}
        for i in around:
            for w in f[i]:
                if w != vert:
                    by_edge.setdefault((min(vert, w), max(vert, w)), []).append(int(i))
        for e, fs in by_edge.items():
            if count.get((int(e[0]), int(e[1]))) == 2 and len(fs) == 2:
                parent[root(fs[0])] = root(fs[1])
        groups: dict = {}
        for i in around:
            groups.setdefault(root(int(i)), []).append(int(i))
        for fs in list(groups.values())[1:]:
            new = len(v) + len(extra)
            extra.append(v[vert])
            for i in fs:
                f[i][f[i] == vert] = new
    if extra:
        v = np.vstack([v, np.array(extra)])
    return v, f, len(extra)


def _components(tm: trimesh.Trimesh) -> list[trimesh.Trimesh]:
    """The edge-connected pieces of a surface (scipy; no networkx)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    adj = np.asarray(tm.face_adjacency)
    n = len(tm.faces)
    g = coo_matrix((np.ones(len(adj)), (adj[:, 0], adj[:, 1])), shape=(n, n)) if len(adj) else coo_matrix((n, n))
    k, label = connected_components(g, directed=False)
    if k == 1:
        return [tm]
    out = []
    for c in range(k):
        sub = tm.submesh([np.flatnonzero(label == c)], append=True, repair=False)
        out.append(sub)
    return out


def repair_surface(vertices: np.ndarray, faces: np.ndarray, where: str) -> RepairedSurface:
    """Make ``(vertices [m], faces)`` a closed, outward-oriented manifold surface of one object,
    or raise MeshError naming the offending elements (``where``: the file, for messages)."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    repairs: list[str] = []
    if f.shape[0] == 0:
        raise MeshError(f"{where}: a point cloud ({len(v)} points, no faces): reconstruct a closed surface "
                        "first (e.g. open3d's Poisson reconstruction) and give that")
    tm = trimesh.Trimesh(v, f, process=False)
    n0 = len(tm.faces)
    tm.update_faces(tm.unique_faces())
    tm.remove_unreferenced_vertices()
    if len(tm.faces) < n0:
        repairs.append(f"removed {_n(n0 - len(tm.faces), 'duplicate face')}")
    if not is_closed(tm.faces):
        # triangle soup (STL) or split seams: weld coincident vertices, if that closes the surface
        welded = tm.copy()
        welded.merge_vertices(merge_tex=True, merge_norm=True)
        nf = len(welded.faces)
        welded.update_faces(welded.nondegenerate_faces())
        welded.remove_unreferenced_vertices()
        def open_edges(faces):
            return int(np.sum(edge_face_counts(np.asarray(faces))[1] == 1))

        if open_edges(welded.faces) < open_edges(tm.faces):
            repairs.append(f"welded coincident vertices ({len(tm.vertices)} -> {len(welded.vertices)})"
                           + (f", dropped {_n(nf - len(welded.faces), 'collapsed face')}" if nf > len(welded.faces) else ""))
            tm = welded
    edges, counts = edge_face_counts(np.asarray(tm.faces))
    if np.any(counts > 2) and np.all(counts[counts > 2] % 2 == 0):
        v2, f2, copies = _split_sheets(np.asarray(tm.vertices, float), np.asarray(tm.faces))
        e2, c2 = edge_face_counts(f2)
        if not np.any(c2 > 2):
            repairs.append(f"split {_n(int(np.sum(counts > 2)), 'edge')} where two sheets of the surface "
                           f"touch ({copies} vertex {'copy' if copies == 1 else 'copies'})")
            tm = trimesh.Trimesh(v2, f2, process=False)
            edges, counts = e2, c2
    bad = np.flatnonzero(counts > 2)
    if bad.size:
        e = edges[bad]
        raise MeshError(f"{where}: {_n(bad.size, 'non-manifold edge')} (shared by 3 or more faces), e.g. vertex pairs "
                        f"{_listing(e, tm.vertices[e].mean(axis=1))}: separate the touching parts in a mesh editor")
    parts = _components(tm)
    if len(parts) > 1:
        areas = np.array([p.area for p in parts])
        keep = areas >= DEBRIS_AREA * areas.max()
        if keep.sum() > 1:
            big = np.argsort(-areas)[:3]
            raise MeshError(f"{where}: {int(keep.sum())} separate objects in one file (areas "
                            + ", ".join(f"{areas[i] * 1e6:.0f} mm^2 around {_mm(parts[i].centroid)}" for i in big)
                            + "): give one object per file")
        repairs.append(f"dropped {int((~keep).sum())} loose {'piece' if (~keep).sum() == 1 else 'pieces'} of debris ({areas[~keep].sum() * 1e6:.2g} mm^2, "
                       f"< {DEBRIS_AREA:.0%} of the object)")
        tm = parts[int(np.argmax(areas))]
    if not is_closed(tm.faces):
        loops = boundary_loops(np.asarray(tm.faces))
        small = [lp for lp in loops if len(lp) <= SMALL_HOLE_EDGES]
        if len(small) == len(loops):
            # a fan from each loop's first vertex, oriented like the loop's faces (the boundary edges
            # run with their face on the left, so the patch runs against them)
            patch = [[lp[0], lp[k + 1], lp[k]] for lp in loops for k in range(1, len(lp) - 1)]
            closed = trimesh.Trimesh(tm.vertices, np.vstack([tm.faces, np.array(patch, dtype=np.int64)
                                                              .reshape(-1, 3)]), process=False)
            if is_closed(closed.faces):
                repairs.append(f"closed {_n(len(loops), 'small hole')} ({_n(len(patch), 'face')} added)")
                tm = closed
        if not is_closed(tm.faces):
            loops = boundary_loops(np.asarray(tm.faces))
            loops.sort(key=len, reverse=True)
            desc = "; ".join(f"{len(lp)} edges around {_mm(tm.vertices[lp].mean(axis=0))}" for lp in loops[:3])
            raise MeshError(f"{where}: the surface is open: {_n(len(loops), 'hole')} ({desc}"
                            + (" ..." if len(loops) > 3 else "") + "); a closed object needs a watertight "
                            "surface (close the holes, e.g. by Poisson reconstruction)")
    if not tm.is_winding_consistent:
        trimesh.repair.fix_winding(tm)
        if not tm.is_winding_consistent:
            raise MeshError(f"{where}: the faces cannot be oriented consistently (a Moebius-like surface)")
        repairs.append("made the faces' orientation consistent")
    if tm.volume < 0:
        tm.invert()
        repairs.append("turned the faces' orientation outward")
    v, f = np.array(tm.vertices, dtype=np.float64), np.array(tm.faces, dtype=np.int64)
    moved = _pull_apart(v, f)
    if moved:
        repairs.append(f"pulled apart {moved} coincident vertices of separate surface sheets (a pinch)")
    return RepairedSurface(TriMesh(v, f), repairs)
