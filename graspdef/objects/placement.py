"""Where the gripper takes an object: a grasp line (an axis through a point of the object, or the
best antipodal pair of surface points found automatically) and the object's pose that puts that
line on the gripper's closing axis with its chord's midpoint where the fingers meet.

The parallel gripper (:mod:`graspdef.sim.gripper`) closes along the world x axis and its fingertips
meet at the origin; gravity is -z.  The object frame is the mesh's own; the pose keeps the
object's own z axis as close to upright as the grasp axis allows.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import trimesh

from ..errors import ProblemError
from ..geometry import TriMesh
from ..scans import vertex_normals
from ..sim.gripper import OPEN, TRAVEL

#: clearance [m] kept between the object and the open fingertips, and beyond the closed ones
CLEARANCE = 0.003


@dataclass(frozen=True)
class Grasp:
    """A grasp line in the object frame [m]: the two contact points (entry, exit), the unit axis
    from the first to the second, and the antipodal quality: the larger of the angles [deg]
    between the chord and the inward surface normals at its ends (0: perfectly antipodal; the
    grasp holds without slip while it is below atan(friction))."""

    first: np.ndarray
    second: np.ndarray
    axis: np.ndarray
    angle_deg: float
    how: str

    @property
    def centre(self) -> np.ndarray:
        return 0.5 * (self.first + self.second)

    @property
    def width(self) -> float:
        return float(np.linalg.norm(self.second - self.first))

    def record(self) -> dict:
        return {"how": self.how, "first_contact_m": self.first.tolist(), "second_contact_m": self.second.tolist(),
                "axis": self.axis.tolist(), "width_m": self.width, "antipodal_angle_deg": self.angle_deg}


def _chord_angles(tm: trimesh.Trimesh, p, q, tri_p, tri_q) -> float:
    d = (q - p) / np.linalg.norm(q - p)
    n_p, n_q = tm.face_normals[tri_p], tm.face_normals[tri_q]
    # at p the finger pushes along +d, against the outward normal n_p: antipodal when n_p = -d
    a_p = math.degrees(math.acos(float(np.clip(-n_p @ d, -1, 1))))
    a_q = math.degrees(math.acos(float(np.clip(n_q @ d, -1, 1))))
    return max(a_p, a_q)


def grasp_along(mesh: TriMesh, point, axis, where: str = "grasp") -> Grasp:
    """The grasp on the line through ``point`` [m, object frame] along ``axis``: the contacts are
    the line's first and last crossings of the surface."""
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    a = np.asarray(axis, float)
    if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) == 0:
        raise ProblemError(f"{where}: the grasp axis must be a non-zero 3-vector, got {axis!r}")
    a = a / np.linalg.norm(a)
    p = np.asarray(point, float)
    far = 2.0 * float(np.ptp(mesh.vertices, axis=0).max()) + float(np.linalg.norm(p - mesh.vertices.mean(axis=0)))
    locs, _, tris = tm.ray.intersects_location([p - far * a], [a], multiple_hits=True)
    if len(locs) < 2:
        raise ProblemError(f"{where}: the line through ({', '.join(f'{1e3 * c:.4g}' for c in p)}) mm along "
                           f"({', '.join(f'{c:.3g}' for c in a)}) misses the object (it crosses the surface "
                           f"{len(locs)} times); give a point inside it")
    t = (locs - (p - far * a)) @ a
    i, j = int(np.argmin(t)), int(np.argmax(t))
    return Grasp(locs[i], locs[j], a, _chord_angles(tm, locs[i], locs[j], tris[i], tris[j]), "given axis and point")


def antipodal_candidates(mesh: TriMesh, centre_of_mass, friction: float, max_width: float, min_width: float,
                         n: int | None = None, seed: int = 0, limit: int | None = None,
                         max_reach: float | None = None) -> list[Grasp]:
    """Antipodal grasps of the surface, least cost first: from each start point (every vertex,
    and with ``n`` above the vertex count, ``n`` - vertices seeded random surface points) a ray
    along the inward normal to the surface's far side; a pair qualifies if its chord fits the
    gripper (``min_width`` to ``max_width`` [m]), both ends lie inside the friction cone (angle <
    atan(friction)) and the line crosses the surface only there (the fingers come from outside).
    Cost: the antipodal angle over the cone's, plus the line's distance from the centre of mass
    (the weight's torque) over half the object's size.  ``limit``: stop after that many.
    ``max_reach`` [m]: also refuse a line along which the object reaches farther than this from
    the chord's midpoint (the open fingers would cut it; :func:`pose_for`'s check)."""
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    starts, normals = mesh.vertices, vertex_normals(mesh)
    if n is not None and n > len(starts):
        pts, fi = trimesh.sample.sample_surface(tm, int(n) - len(starts), seed=seed)
        starts, normals = np.vstack([starts, pts]), np.vstack([normals, tm.face_normals[fi]])
    size = float(np.ptp(mesh.vertices, axis=0).max())
    locs, ray_idx, tris = tm.ray.intersects_location(starts, -normals, multiple_hits=True)
    # the first crossing beyond the start (a ray from a vertex may report the start's own faces)
    dist = np.einsum("ij,ij->i", locs - starts[ray_idx], -normals[ray_idx])
    ok = dist > 1e-3 * size
    locs, ray_idx, tris, dist = locs[ok], ray_idx[ok], tris[ok], dist[ok]
    order = np.lexsort((dist, ray_idx))
    first = order[np.r_[True, ray_idx[order][1:] != ray_idx[order][:-1]]] if len(order) else order
    locs, ray_idx, tris = locs[first], ray_idx[first], tris[first]
    cone = math.degrees(math.atan(friction))
    com = np.asarray(centre_of_mass, float)
    p = starts[ray_idx]
    w = np.linalg.norm(locs - p, axis=1)
    keep = (w >= min_width) & (w <= max_width)
    p, q, w, i, tq = p[keep], locs[keep], w[keep], ray_idx[keep], tris[keep]
    d = (q - p) / w[:, None]
    a_p = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", normals[i], -d), -1, 1)))
    a_q = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", tm.face_normals[tq], d), -1, 1)))
    angle = np.maximum(a_p, a_q)
    keep = angle < cone
    p, q, w, i, d, angle = p[keep], q[keep], w[keep], i[keep], d[keep], angle[keep]
    # cost: the antipodal angle as a fraction of the friction cone, plus the line's distance from the
    # centre of mass (the weight's torque) as a fraction of half the object's size
    off = np.linalg.norm(np.cross(com - p, d), axis=1)
    cost = np.round(angle / cone + off / (0.5 * size), 6)
    order = np.lexsort((i, cost))
    out = []
    far = 2.0 * size
    for s0 in range(0, len(order), 512):
        blk = order[s0: s0 + 512]
        # the fingers come from outside along the line: p and q must be its first and last crossings
        origin = p[blk] - far * d[blk]
        hits, ridx, _ = tm.ray.intersects_location(origin, d[blk], multiple_hits=True)
        t = np.einsum("ij,ij->i", hits - origin[ridx], d[blk][ridx])
        lo = np.full(len(blk), np.inf)
        hi = np.full(len(blk), -np.inf)
        np.minimum.at(lo, ridx, t)
        np.maximum.at(hi, ridx, t)
        ok = np.isfinite(lo) & (lo >= far - 1e-4 * size) & (hi <= far + w[blk] + 1e-4 * size)
        if max_reach is not None:
            centre = 0.5 * (p[blk] + q[blk])
            reach = np.abs(np.einsum("vk,bk->bv", mesh.vertices, d[blk]) - np.einsum("bk,bk->b", centre, d[blk])[:, None])
            ok &= reach.max(axis=1) <= max_reach
        for k in np.flatnonzero(ok):
            j = blk[k]
            out.append(Grasp(p[j].copy(), q[j].copy(), d[j].copy(), float(angle[j]), "best antipodal pair (automatic)"))
            if limit is not None and len(out) >= limit:
                return out
    return out


def best_antipodal(mesh: TriMesh, centre_of_mass, friction: float, max_width: float, min_width: float) -> Grasp:
    """The least-cost antipodal grasp of :func:`antipodal_candidates` (its vertices only)."""
    found = antipodal_candidates(mesh, centre_of_mass, friction, max_width, min_width, limit=1,
                                 max_reach=OPEN - CLEARANCE)
    if not found:
        cone = math.degrees(math.atan(friction))
        raise ProblemError(f"no antipodal grasp found: no pair of surface points {min_width * 1e3:.0f} to "
                           f"{max_width * 1e3:.0f} mm apart (the gripper's opening) with both normals within the "
                           f"friction cone ({cone:.0f} deg for friction {friction:g}); give --grasp-axis and "
                           "--grasp-point")
    return found[0]


def pose_for(mesh: TriMesh, grasp: Grasp, where: str = "grasp") -> tuple[np.ndarray, np.ndarray]:
    """(position [m], rotation matrix object -> world) that puts ``grasp``'s axis on the world x
    axis and its chord's midpoint at the origin, the object's z axis as upright as possible.
    Refuses a grasp the gripper cannot make: a chord outside its opening, or an object that the
    open fingers would cut."""
    x = grasp.axis
    up = np.array([0.0, 0.0, 1.0])
    if abs(x @ up) > 0.99:
        up = np.array([0.0, 1.0, 0.0])
    z = up - (up @ x) * x
    z /= np.linalg.norm(z)
    y = np.cross(z, x)
    R = np.vstack([x, y, z])                      # rows: world axes in the object frame
    pos = -R @ grasp.centre
    lo, hi = 2 * (OPEN - TRAVEL) + 2 * CLEARANCE, 2 * (OPEN - CLEARANCE)
    if not lo <= grasp.width <= hi:
        raise ProblemError(f"{where}: the grasp is {grasp.width * 1e3:.1f} mm wide; the gripper takes "
                           f"{lo * 1e3:.0f} to {hi * 1e3:.0f} mm: choose another grasp (--grasp-axis, --grasp-point)")
    xw = (mesh.vertices @ R.T + pos)[:, 0]
    reach = float(np.abs(xw).max())
    if reach > OPEN - CLEARANCE:
        raise ProblemError(f"{where}: placed for this grasp the object reaches {reach * 1e3:.1f} mm from the grasp "
                           f"centre along the closing axis, beyond the open fingertips at {OPEN * 1e3:.0f} mm: "
                           "choose a grasp across a narrower part")
    return pos, R
