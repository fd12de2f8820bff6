"""Bad input: clear errors naming the segment / node and the load step."""
import numpy as np
import pytest

from graspdef.axisym import Material, Model, NodalLoad, Node, Segment, hemisphere_example, solve_path
from graspdef.axisym.config import parse_problem
from graspdef.errors import ProblemError, SolverError, SupportError

MAT = Material("mooney_rivlin", 1.0, 0.1)


def _dome(angles_deg, fix=(False, True, False), segs=None):
    nodes = [Node(10 * np.sin(np.radians(a)), 10 * np.cos(np.radians(a)), -np.radians(a)) for a in angles_deg]
    nodes[-1].fix = fix
    segs = segs or [Segment(k, k + 1, -0.1) for k in range(len(nodes) - 1)]
    return Model(MAT, 1.0, nodes, segs, [NodalLoad(len(nodes) - 1, M=1.0)])


def test_non_monotone_meridian():
    with pytest.raises(ProblemError, match=r"not monotone: segment 1 runs backwards from node 1 to node 2"):
        _dome([0, 60, 30, 90]).build()


def test_zero_length_segment():
    with pytest.raises(ProblemError, match=r"segment 1 \(nodes 1 -> 2\) has zero length"):
        _dome([0, 45, 45, 90]).build()


def test_node_off_the_segment():
    m = _dome([0, 90])
    m.nodes[1].z = 0.5
    with pytest.raises(ProblemError, match=r"segment 0 \(nodes 0 -> 1\): node 1 does not lie"):
        m.build()


def test_unsupported_rigid_body_motion():
    """The thesis: [K] is singular without enough restraints (axis conditions + one vertical)."""
    with pytest.raises(SupportError, match="rigid-body motion.*vertical translation"):
        _dome([0, 90], fix=(False, False, False)).build()


def test_point_force_on_the_axis_is_refused():
    m = _dome([0, 90])
    m.nodal_loads = [NodalLoad(0, V=-1.0)]
    with pytest.raises(ProblemError, match="pole node 0.*ring load"):
        m.build()


def test_shooting_divergence_names_segment_and_load_step():
    """A first step far beyond the edge's moment capacity cannot be integrated: SolverError naming the load
    step and the segment (never an unconverged result)."""
    m = hemisphere_example("edge_couple")
    with pytest.raises(SolverError, match=r"load step 1: .*segment 0 \(nodes 0 -> 1\)"):
        solve_path(m, ds=200.0, ds_min=50.0, max_steps=3)


def test_toml_errors_are_clear():
    base = {"units": {"system": "SI"}, "material": {"kind": "mooney_rivlin", "C1": 1e6, "gamma": 0.1},
            "shell": {"thickness": 0.001},
            "nodes": [{"r": 0.0, "z": 0.01, "phi": 0.0}, {"r": 0.01, "z": 0.0, "phi_deg": -90.0, "fix": ["z"]}],
            "segments": [{"from": 0, "to": 1, "radius": -0.01}]}
    parse_problem(base)
    with pytest.raises(ProblemError, match="units"):
        parse_problem({**base, "units": {}})
    with pytest.raises(ProblemError, match="unknown keys"):
        parse_problem({**base, "nodes": [{"r": 0.0, "z": 0.01, "phi": 0.0, "x": 1}] + base["nodes"][1:]})
    with pytest.raises(ProblemError, match="restraint"):
        parse_problem({**base, "nodes": base["nodes"][:1] + [{**base["nodes"][1], "fix": ["q"]}]})
