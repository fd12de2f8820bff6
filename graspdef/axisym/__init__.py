"""Finite axisymmetric deformation of thin hyperelastic shells of revolution (the thesis's method).

Independent of the 3-D subdivision solver: it imports only numpy, scipy, graspdef.errors and (for its problem
files) graspdef.config / graspdef.units.  Its names are distinct from the 3-D solver's (AxisymMaterial,
AxisymEquilibrium, load_axisym_problem).

Nondimensionalisation (thesis 2.81, derived in docs/axisym.md): lengths / t0 (rho = r/t0, eps = z/t0,
sigma = s0/t0), stresses and distributed loads / C1, stress resultants per unit length / (t0 C1), couples per
unit length / (t0^2 C1), nodal forces *per radian of circumference* (r H) / (t0^2 C1) and nodal couples per
radian (r M) / (t0^3 C1), strain energy per unit undeformed area / (t0 C1).

Modules, one concern each:
    material      3-D strain energies (Mooney-Rivlin, exponential) -> shell energy phi and its derivatives
    meridian      reference geometry of constant-curvature meridian pieces (arcs, lines)
    equations     the first-order system (2.84)-(2.87) and its Jacobian (the rate equations 2.90)
    shooting      RK4 integration of BVP.1 + BVP.2, Newton on the unknown end forces, segment stiffness [KL]
    assembly      nodes/segments/restraints/loads -> nodal forces and system stiffness [K]
    continuation  nodal Newton iteration, constant-arc-length load stepping, stability (det, inertia)
    config        TOML problem files (the thesis's data cards)
    problems      ready-made problems (the thesis's hemispheres, pinched and inflated spheres)
    bench         ``run_axisym_bench`` comparison records
"""
from .material import AxisymMaterial
from .assembly import Model, Node, Segment, NodalLoad, DistributedLoad
from .continuation import PathResult, AxisymEquilibrium, solve_path, solve_load
from .problems import hemisphere_example, pinched_sphere, inflated_sphere, sphere_apex_curve
from .config import load_axisym_problem

__all__ = [
    "AxisymMaterial", "Model", "Node", "Segment", "NodalLoad", "DistributedLoad", "PathResult", "AxisymEquilibrium",
    "solve_path", "solve_load", "hemisphere_example", "pinched_sphere", "inflated_sphere", "sphere_apex_curve",
    "load_axisym_problem",
]
