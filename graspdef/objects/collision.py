"""An object's collision geometry for MuJoCo: its convex hull when the object is nearly convex,
else a convex decomposition (CoACD, Wei et al. 2022; MuJoCo collides convex meshes only)."""
from __future__ import annotations

import numpy as np
import trimesh

from ..errors import MeshError
from ..geometry import TriMesh

#: hull volume / object volume up to which the convex hull is the collision geometry
CONVEX_RATIO = 1.03
#: CoACD's concavity threshold (its default 0.05 of the object's size) and the most parts
COACD_THRESHOLD = 0.05
COACD_MAX_PARTS = 16


def collision_parts(mesh: TriMesh) -> tuple[list[trimesh.Trimesh], str]:
    """Convex parts [m] covering ``mesh`` (closed, outward) and a line saying how they were made."""
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    hull = tm.convex_hull
    ratio = float(hull.volume / tm.volume)
    if ratio <= CONVEX_RATIO:
        return [hull], f"convex hull (hull volume {ratio:.3f} x the object's: nearly convex)"
    try:
        import coacd
    except ImportError as exc:
        raise MeshError(f"the object is not convex (hull volume {ratio:.2f} x its own) and its convex "
                        f"decomposition needs coacd ({exc}): pip install 'graspdef[objects]'") from exc
    coacd.set_log_level("error")
    parts = coacd.run_coacd(coacd.Mesh(np.asarray(tm.vertices), np.asarray(tm.faces)), threshold=COACD_THRESHOLD,
                            max_convex_hull=COACD_MAX_PARTS, seed=0)
    hulls = [trimesh.Trimesh(v, f, process=True).convex_hull for v, f in parts]
    return hulls, (f"CoACD convex decomposition into {len(hulls)} parts (hull volume {ratio:.2f} x the object's; "
                   f"threshold {COACD_THRESHOLD}, seed 0)")
