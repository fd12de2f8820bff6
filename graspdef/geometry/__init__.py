"""Control-mesh geometry: the mesh container and its validation, analytic primitives, mesh file
input/output and region predicates."""

from graspdef.geometry.io import LENGTH_UNITS, length_scale, load_mesh, save_ply
from graspdef.geometry.mesh import (
    TriMesh,
    boundary_edges,
    boundary_loops,
    edge_face_counts,
    is_closed,
    unique_edges,
    validate_mesh,
    vertex_valence,
)
from graspdef.geometry.primitives import (
    annulus,
    cylinder,
    disk,
    ellipsoid,
    height_field,
    hemisphere,
    icosphere,
    monkey_saddle,
    polygon,
    rectangle,
    sphere,
    spherical_cap,
    square_plate,
)
from graspdef.geometry.regions import compile_predicate

__all__ = [
    "LENGTH_UNITS", "TriMesh", "annulus", "boundary_edges", "boundary_loops", "compile_predicate",
    "cylinder", "edge_face_counts", "ellipsoid", "height_field", "hemisphere", "icosphere",
    "disk", "is_closed", "length_scale", "load_mesh", "monkey_saddle", "polygon", "rectangle", "save_ply", "sphere",
    "spherical_cap", "square_plate", "unique_edges", "validate_mesh", "vertex_valence",
]
