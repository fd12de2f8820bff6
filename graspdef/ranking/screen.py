"""Where to grasp: a linear screen of many antipodal grasp pairs on a closed shell.

One factorisation of the free shell's stiffness at rest (rigid modes removed by orthogonality:
exact for a self-equilibrated load), then back-substitutions in blocks of many right-hand sides.
A pair is two samples of the limit surface (:mod:`graspdef.subdivision.samples`: exact limit
points with exact weights, spacing edge / 2^level); the finger at the first pushes +F d, the one
at the second -F d, with d the unit chord between the two samples -- equal, opposite and collinear,
so the pair is exactly self-equilibrated.  With b the load vector of the unit pair and
u = F K^-1 b, per pair:

* closing displacement delta = b.u (the contact points' approach) [m]; grasp stiffness F/delta;
* the work spent deforming the object to reach F: W = F delta / 2 [J] -- the minimal-work metric
  of Xu et al. for hollow deformable objects; the strain energy u.K u / 2 is computed separately
  (Clapeyron: equal in linear theory, a check);
* max displacement over the limit surface (control-vertex limit points and the two contacts);
* peak principal strain and von Mises stress on both faces of the wall
  (:mod:`graspdef.shell.strains`, at the quadrature points: under a point force they grow as the
  mesh is refined, a relative figure);
* the contacts' normals (the mean over the contact patch) and the grasp line after deformation,
  and the friction margin atan(mu) - (largest angle between a deformed inward normal and the
  deformed line) [deg]; the same at rest (the rigid baseline's margin, with the same normals);
* an estimate of the contact area of a flat pad: the rest surface's outer face within the pad's
  disk that the pad, pressed in by the indentation delta / 2, would overlap [m^2].

SI throughout.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ..errors import ProblemError
from ..problem.problem import Problem
from ..problem.supports import RigidModes
from ..shell.strains import linear_strain_operator
from ..solve.linear import rest_stiffness
from ..solve.sparse import KKTSystem
from ..subdivision.rules import limit_matrix
from ..subdivision.samples import level_for, limit_samples

#: right-hand sides per back-substitution block (memory: 3 n_control x BLOCK doubles, and the
#: strain operator's 6 n_points x BLOCK)
BLOCK = 64


@dataclass
class PairFigures:
    """Per-pair linear figures (arrays of one length, SI)."""

    closing_m: np.ndarray
    work_J: np.ndarray
    strain_energy_J: np.ndarray
    stiffness_N_per_m: np.ndarray
    max_displacement_m: np.ndarray
    peak_strain: np.ndarray
    peak_von_mises_Pa: np.ndarray
    deformed_angle_deg: np.ndarray
    rest_angle_deg: np.ndarray
    contact_area_m2: np.ndarray

    @classmethod
    def concat(cls, parts: list["PairFigures"]) -> "PairFigures":
        return cls(**{k: np.concatenate([getattr(p, k) for p in parts]) for k in cls.__dataclass_fields__})


class LinearScreen:
    """The free closed shell's rest stiffness, factorised once, and its limit-surface samples.

    ``shell``: a closed shell (an object's); ``E``, ``nu``: the small-strain moduli for the stress
    [Pa]; ``pad_radius`` [m]: the flat pad's disk for the contact-area estimate; ``level``:
    sample refinements (default: ~100k samples)."""

    def __init__(self, shell, E: float, nu: float, pad_radius: float = 0.012, level: int | None = None,
                 backend: str = "auto"):
        mesh = shell.mesh
        if mesh.n_control != mesh.n_real:
            raise ProblemError("ranking grasps needs a closed object (this shell has a free edge)")
        t0 = time.perf_counter()
        self.shell, self.E, self.nu, self.pad_radius = shell, float(E), float(nu), float(pad_radius)
        self.problem = Problem(shell, [], [RigidModes()])
        C, _, _ = self.problem.constraints(with_targets=True)
        self.K = rest_stiffness(self.problem)
        self.kkt = KKTSystem(C, backend)
        self.kkt.factor(self.K)
        neg = self.kkt.negative_pivots(self.kkt.m)
        if neg is not None and neg != self.kkt.m:
            raise ProblemError(f"the object's rest stiffness is singular beyond its rigid modes ({neg} "
                               f"negative pivots for {self.kkt.m} constraints): a mechanism is free")
        x = shell.rest_positions
        self.samples = limit_samples(mesh.faces, mesh.n_control, level_for(mesh.n_control) if level is None else level)
        self.P = self.samples.points(x)
        self.normal = self.samples.normals(self.P)
        # a closed, outward-oriented mesh: the sample normals point outward (checked: the mean of
        # (P - centroid).n is positive)
        if float(np.einsum("ij,ij->i", self.P - self.P.mean(0), self.normal).mean()) < 0:
            self.normal = -self.normal
        self.area = self.samples.areas(self.P)
        f = self.samples.faces
        self.spacing = float(np.linalg.norm(self.P[f[:, 1]] - self.P[f[:, 0]], axis=1).mean())
        self.half_t = 0.5 * float(np.mean(np.atleast_1d(shell.thickness)))
        self.outer = self.P + self.half_t * self.normal
        self.tree = cKDTree(self.P)
        self.outer_tree = cKDTree(self.outer)
        self.L = limit_matrix(mesh.faces, mesh.n_control, np.arange(mesh.n_real))
        self.strain = linear_strain_operator(shell)
        self.seconds_setup = time.perf_counter() - t0

    @property
    def n_control(self) -> int:
        return self.shell.mesh.n_control

    def locate(self, points) -> tuple[np.ndarray, np.ndarray]:
        """Nearest samples of the mid-surface to contact points on the outer face (k, 3) [m]:
        (sample indices, distances [m] from the outer face's sample)."""
        d, i = self.outer_tree.query(np.atleast_2d(np.asarray(points, float)))
        return i, d

    def unit_pairs(self, i1: np.ndarray, i2: np.ndarray) -> tuple[sp.csc_matrix, np.ndarray]:
        """(B (3 n_control, k): load vectors of unit pairs, d (k, 3): unit chords first -> second)."""
        d = self.P[i2] - self.P[i1]
        w = np.linalg.norm(d, axis=1)
        if np.any(w <= 0):
            raise ProblemError("a grasp pair has both contacts at the same point")
        d = d / w[:, None]
        W = self.samples.W
        cols, rows, vals = [], [], []
        for sign, idx in ((1.0, i1), (-1.0, i2)):
            sub = W[idx].tocoo()
            for k in range(3):
                rows.append(3 * sub.col + k)
                cols.append(sub.row)
                vals.append(sign * sub.data * d[sub.row, k])
        B = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(self.shell.n_dofs, len(i1)))
        return B, d

    def solve(self, i1, i2, force) -> tuple[np.ndarray, sp.csc_matrix, np.ndarray]:
        """Displacements U (3 n_control, k) [m] of the pairs at ``force`` [N] (one, or one per
        pair), with B and d."""
        B, d = self.unit_pairs(np.asarray(i1), np.asarray(i2))
        U, _, _ = self.kkt.solve(B.toarray() * np.broadcast_to(np.asarray(force, float), (len(d),))[None, :])
        return U, B, d

    def surface_displacements(self, U: np.ndarray) -> np.ndarray:
        """Displacements (k, n_control, 3) [m] of the control vertices' limit points."""
        k = U.shape[1]
        return np.stack([self.L @ U[:, j].reshape(-1, 3) for j in range(k)])

    def _moved(self, idx: np.ndarray, cand: np.ndarray, U3: np.ndarray) -> np.ndarray:
        """Deformed positions (r, 3) of samples ``idx`` (r,) under candidate ``cand`` (r,)'s field."""
        if U3 is None:
            return self.P[idx]
        sub = self.samples.W[idx].tocoo()
        u = np.zeros((len(idx), 3))
        np.add.at(u, sub.row, sub.data[:, None] * U3[sub.col, :, cand[sub.row]])
        return self.P[idx] + u

    def _patch_boundary(self, idx: np.ndarray, radius: np.ndarray):
        """Boundary of each contact's patch -- the sample faces with every corner within
        ``radius`` of sample ``idx[c]`` -- as directed edges (owner c, i, j) oriented with the faces.
        The patch's vector area is 1/2 sum x_i x x_j over them (Stokes): its mean normal."""
        f, vf, ns = self.samples.faces, self.samples.vertex_faces, self.samples.n
        near = self.tree.query_ball_point(self.P[idx], r=radius)
        sizes = np.fromiter((len(x) for x in near), dtype=np.int64, count=len(near))
        owner = np.repeat(np.arange(len(near)), sizes)
        inside = np.concatenate([np.asarray(x, dtype=np.int64) for x in near])
        # (owner, face) for every inside corner; a face is inside when all three corners are
        sub = vf[inside]                                    # rows in order: the corners' incident faces
        of = np.repeat(owner, np.diff(sub.indptr))
        ff = sub.indices.astype(np.int64)
        key = np.sort(of * len(f) + ff)                     # sort-based counting (numpy's hashed
        start = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])   # unique is slow on these keys)
        count = np.diff(np.r_[start, len(key)])
        full = key[start[count == 3]]
        fo, fi = full // len(f), full % len(f)
        fc = f[fi]
        e = np.concatenate([fc[:, [0, 1]], fc[:, [1, 2]], fc[:, [2, 0]]])
        eo = np.tile(fo, 3)
        fwd = (eo * ns + e[:, 0]) * ns + e[:, 1]
        rev = (eo * ns + e[:, 1]) * ns + e[:, 0]
        rev.sort()
        pos = np.minimum(np.searchsorted(rev, fwd), max(len(rev) - 1, 0))
        b = (rev[pos] != fwd) if len(rev) else np.ones(len(fwd), bool)
        return eo[b], e[b, 0], e[b, 1]

    def _deformed_angles(self, i1, i2, U, radius) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(largest angle [deg] between a deformed inward normal and the deformed line, the same
        at rest, displacement magnitudes at both contacts (k, 2) [m]).

        A contact's normal is the mean normal of the surface over the patch of ``radius`` (k,) [m]
        about it (at least two sample spacings): the patch's vector area, from its boundary moved
        by the candidate's displacement.  (The normal at the point of a point force is a
        discretisation artefact; the patch's mean is not, and it is invariant under the mesh's
        symmetries.)"""
        k = len(i1)
        cand = np.arange(k)
        U3 = U.reshape(self.n_control, 3, k)
        ends = [self._moved(idx, cand, U3) for idx in (i1, i2)]
        umag = np.stack([np.linalg.norm(e - self.P[idx], axis=1) for e, idx in zip(ends, (i1, i2))], 1)
        angles = []
        rims = {id(i1): self._patch_boundary(i1, radius), id(i2): self._patch_boundary(i2, radius)}
        for field, (p1, p2) in ((U3, ends), (None, (self.P[i1], self.P[i2]))):
            dd = p2 - p1
            dd /= np.linalg.norm(dd, axis=1, keepdims=True)
            ang = np.zeros(k)
            for idx, inward in ((i1, dd), (i2, -dd)):
                owner, bi, bj = rims[id(idx)]
                xi = self._moved(bi, owner, field)
                xj = self._moved(bj, owner, field)
                n = np.zeros((k, 3))
                np.add.at(n, owner, np.cross(xi, xj))
                n /= np.linalg.norm(n, axis=1, keepdims=True)
                n = np.where((np.einsum("ij,ij->i", n, self.normal[idx]) < 0)[:, None], -n, n)
                # atan2(|n x d|, n.d): accurate near 0, where arccos loses half the digits
                a = np.degrees(np.arctan2(np.linalg.norm(np.cross(-n, inward), axis=1),
                                          np.einsum("ij,ij->i", -n, inward)))
                ang = np.maximum(ang, a)
            angles.append(ang)
        return angles[0], angles[1], umag

    def contact_area(self, idx: np.ndarray, push: np.ndarray, depth: np.ndarray) -> np.ndarray:
        """Estimate per contact: area of the outer face's samples within the pad's disk (radius
        ``pad_radius`` about the line through the contact along ``push``) lying within ``depth``
        [m] of the pad's plane -- the rest surface a rigid flat pad pressed in by ``depth`` overlaps."""
        out = np.zeros(len(idx))
        near = self.outer_tree.query_ball_point(self.outer[idx], r=self.pad_radius * math.sqrt(2.0) + 1e-12)
        for j, (i, nb) in enumerate(zip(idx, near)):
            nb = np.asarray(nb, dtype=np.int64)
            rel = self.outer[nb] - self.outer[i]
            h = rel @ push[j]                                   # how far beyond the pad's rest plane
            lat = np.linalg.norm(rel - h[:, None] * push[j], axis=1)
            facing = self.normal[nb] @ push[j] < 0              # the face the pad approaches
            sel = (lat <= self.pad_radius) & (h <= depth[j]) & facing
            out[j] = float(self.area[nb[sel]].sum())
        return out

    def evaluate(self, i1, i2, force, progress=None) -> PairFigures:
        """Figures of the pairs (``i1[j]``, ``i2[j]``) (sample indices) at ``force`` [N] per finger
        (one force, or one per pair),
        in blocks of :data:`BLOCK` back-substitutions; ``progress(done, total)`` after each."""
        i1, i2 = np.asarray(i1, np.int64), np.asarray(i2, np.int64)
        forces = np.broadcast_to(np.asarray(force, float), (len(i1),))
        parts = []
        for s in range(0, len(i1), BLOCK):
            a, b = i1[s: s + BLOCK], i2[s: s + BLOCK]
            force = forces[s: s + BLOCK]
            U, B, d = self.solve(a, b, force)
            closing = np.asarray(B.multiply(U).sum(axis=0)).ravel()
            energy = 0.5 * np.einsum("ij,ij->j", U, self.K @ U)
            ul = self.surface_displacements(U)
            peak_e, peak_s = self.strain.peaks(U, self.E, self.nu)
            area = 0.5 * (self.contact_area(a, d, 0.5 * closing) + self.contact_area(b, -d, 0.5 * closing))
            radius = np.maximum(np.sqrt(area / np.pi), 2.0 * self.spacing)
            ang, ang0, ucontact = self._deformed_angles(a, b, U, radius)
            maxu = np.maximum(np.linalg.norm(ul, axis=2).max(axis=1), ucontact.max(axis=1))
            parts.append(PairFigures(closing, 0.5 * force * closing, energy,
                                     np.where(closing > 0, force / np.where(closing > 0, closing, 1.0), np.inf),
                                     maxu, peak_e, peak_s, ang, ang0, area))
            if progress is not None:
                progress(min(s + BLOCK, len(i1)), len(i1))
        return PairFigures.concat(parts)

    def close(self) -> None:
        self.kkt.close()
