"""Contact records: what a rigid-body simulation hands to the shell solver.

All arrays are in the world frame, SI units (m, N).  ``forces`` is the force each contact
exerts ON THE OBJECT; ``normals`` are unit vectors pointing into the object (the direction in
which the finger pushes)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ProblemError


@dataclass(frozen=True)
class Pose:
    """Rigid pose x_world = R @ x_object + p; ``quat`` is (w, x, y, z)."""

    position: np.ndarray
    rotation: np.ndarray

    def to_object(self, x: np.ndarray) -> np.ndarray:
        """World points (n, 3) -> object frame."""
        return (np.asarray(x, float) - self.position) @ self.rotation

    def vector_to_object(self, v: np.ndarray) -> np.ndarray:
        return np.asarray(v, float) @ self.rotation

    def to_world(self, x: np.ndarray) -> np.ndarray:
        return np.asarray(x, float) @ self.rotation.T + self.position

    @property
    def quat(self) -> np.ndarray:
        R = self.rotation
        w = np.sqrt(max(0.0, 1 + np.trace(R))) / 2
        if w > 1e-6:
            return np.array([w, (R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w), (R[1, 0] - R[0, 1]) / (4 * w)])
        i = int(np.argmax(np.diag(R)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = np.sqrt(max(0.0, 1 + R[i, i] - R[j, j] - R[k, k])) * 2
        q = np.empty(4)
        q[0] = (R[k, j] - R[j, k]) / s
        q[1 + i] = s / 4
        q[1 + j] = (R[j, i] + R[i, j]) / s
        q[1 + k] = (R[k, i] + R[i, k]) / s
        return q

    def record(self) -> dict:
        return {"position_m": self.position.tolist(), "quat_wxyz": self.quat.tolist(),
                "rotation": self.rotation.tolist()}


@dataclass(frozen=True)
class ContactSet:
    """Contacts on one object.

    Shapes: positions, normals, forces (n_contacts, 3); normal_force, friction_force
    (n_contacts,); finger (n_contacts,) labels (e.g. "left", "right")."""

    positions: np.ndarray
    normals: np.ndarray
    forces: np.ndarray
    normal_force: np.ndarray
    friction_force: np.ndarray
    finger: tuple[str, ...]
    geoms: tuple[tuple[str, str], ...] = field(default=())
    #: (n_contacts, 3) contact torques ON THE OBJECT [N m] (torsional friction about the normal,
    #: condim >= 4), or None
    torques: np.ndarray | None = None
    #: (n_contacts,) sliding friction coefficient of each contact (MuJoCo's: the larger of the two
    #: geoms' when their priorities are equal), or None
    mu: np.ndarray | None = None

    def __post_init__(self) -> None:
        n = len(self.finger)
        if self.torques is not None and (np.shape(self.torques) != (n, 3) or not np.all(np.isfinite(self.torques))):
            raise ProblemError(f"contact set: torques must be finite with shape ({n}, 3)")
        for name in ("positions", "normals", "forces"):
            a = getattr(self, name)
            if np.shape(a) != (n, 3) or not np.all(np.isfinite(a)):
                raise ProblemError(f"contact set: {name} must be finite with shape ({n}, 3)")

    def __len__(self) -> int:
        return len(self.finger)

    @property
    def fingers(self) -> list[str]:
        return sorted(set(self.finger))

    def select(self, finger: str) -> np.ndarray:
        return np.array([f == finger for f in self.finger], bool)

    def per_finger(self) -> dict[str, dict]:
        """Sums per finger: total force vector on the object [N], normal-force sum, friction sum,
        force-weighted mean contact point, the unit mean normal and the friction coefficient (the
        largest of the finger's contacts'; None if not known)."""
        out = {}
        for f in self.fingers:
            m = self.select(f)
            fn = self.normal_force[m]
            w = fn / fn.sum() if fn.sum() > 0 else np.full(m.sum(), 1 / m.sum())
            nrm = (self.normals[m] * fn[:, None]).sum(axis=0)
            out[f] = {"n_contacts": int(m.sum()), "force": self.forces[m].sum(axis=0),
                      "friction_coefficient": None if self.mu is None or not m.any() else float(self.mu[m].max()),
                      "normal_force": float(fn.sum()), "friction_force": float(self.friction_force[m].sum()),
                      "point": w @ self.positions[m], "normal": nrm / max(np.linalg.norm(nrm), 1e-300)}
        return out

    def net_force(self) -> np.ndarray:
        return self.forces.sum(axis=0)

    def net_moment(self, about=(0.0, 0.0, 0.0)) -> np.ndarray:
        """Moment of the forces about ``about`` plus the contact torques [N m]."""
        m = np.cross(self.positions - np.asarray(about, float), self.forces).sum(axis=0)
        return m if self.torques is None else m + self.torques.sum(axis=0)

    def transformed(self, pose: Pose) -> "ContactSet":
        """The same contacts expressed in the object frame of ``pose``."""
        return ContactSet(pose.to_object(self.positions), pose.vector_to_object(self.normals),
                          pose.vector_to_object(self.forces), self.normal_force, self.friction_force,
                          self.finger, self.geoms,
                          None if self.torques is None else pose.vector_to_object(self.torques), self.mu)

    def records(self) -> list[dict]:
        return [{"finger": self.finger[i], "position_m": self.positions[i].tolist(),
                 "normal": self.normals[i].tolist(), "force_N": self.forces[i].tolist(),
                 "normal_force_N": float(self.normal_force[i]), "friction_force_N": float(self.friction_force[i]),
                 **({"torque_Nm": self.torques[i].tolist()} if self.torques is not None else {}),
                 **({"friction_coefficient": float(self.mu[i])} if self.mu is not None else {}),
                 **({"geoms": list(self.geoms[i])} if self.geoms else {})} for i in range(len(self))]
