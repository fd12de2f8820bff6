"""Bad input: clear errors naming the segment / node and the load step."""
import numpy as np
import pytest

from graspdef.axisym import AxisymMaterial, Model, NodalLoad, Node, Segment, hemisphere_example, solve_path
from graspdef.axisym.config import parse_axisym_problem
from graspdef.errors import ProblemError, SolverError, SupportError

MAT = AxisymMaterial("mooney_rivlin", 1.0, 0.1)


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
    parse_axisym_problem(base)
    with pytest.raises(ProblemError, match="units"):
        parse_axisym_problem({**base, "units": {}})
    with pytest.raises(ProblemError, match=r"unknown key .x. in \[nodes 0\]"):
        parse_axisym_problem({**base, "nodes": [{"r": 0.0, "z": 0.01, "phi": 0.0, "x": 1}] + base["nodes"][1:]})
    with pytest.raises(ProblemError, match="restraint"):
        parse_axisym_problem({**base, "nodes": base["nodes"][:1] + [{**base["nodes"][1], "fix": ["q"]}]})


def _si_base():
    return {"units": {"system": "SI"}, "material": {"kind": "mooney_rivlin", "C1": 1e6, "gamma": 0.1},
            "shell": {"thickness": 0.001},
            "nodes": [{"r": 0.0, "z": 0.01, "phi": 0.0}, {"r": 0.01, "z": 0.0, "phi_deg": -90.0, "fix": ["z"]}],
            "segments": [{"from": 0, "to": 1, "radius": -0.01}]}


def test_toml_values_with_units_in_si_files_only():
    """In an SI file a length, force, C1 or pressure may carry its unit; the model is the same as with plain SI
    numbers.  A nondimensional file refuses text with a unit; a quantity of the wrong dimension is named."""
    base = _si_base()
    plain, _ = parse_axisym_problem(base)
    texts = {**base, "material": {**base["material"], "C1": "1 MPa"}, "shell": {"thickness": "1 mm"},
             "nodes": [{"r": "0 mm", "z": "10 mm", "phi": 0.0}, {**base["nodes"][1], "r": "1 cm"}],
             "segments": [{"from": 0, "to": 1, "radius": "-10 mm"}]}
    model, _ = parse_axisym_problem(texts)
    assert (model.material, model.thickness) == (plain.material, plain.thickness)
    assert [(n.r, n.z) for n in model.nodes] == [(n.r, n.z) for n in plain.nodes]
    assert model.segments[0].kappa == plain.segments[0].kappa
    with pytest.raises(ProblemError, match=r"\[shell\] thickness '1 MPa' is a pressure; expected a length"):
        parse_axisym_problem({**base, "shell": {"thickness": "1 MPa"}})
    nd = {**base, "units": {"system": "nondimensional"}, "material": {"C1": "1 Pa"}, "shell": {"thickness": 1.0}}
    with pytest.raises(ProblemError, match=r"\[material\] C1 has a unit \('1 Pa'\) but the problem is nondimensional"):
        parse_axisym_problem(nd)


@pytest.mark.parametrize("edit, message", [
    (lambda d: d.update(path={"ds": 1.0, "dss": 2.0}), r"problem: unknown key 'dss' in \[path\] \(did you mean 'ds'\?\); "
                                                       r"accepted: ds, ds_max, ds_min, lam_max"),
    (lambda d: d.update(path={"on_failure": "continue"}), r"\[path\] unknown on_failure 'continue'.*accepted: raise, stop"),
    (lambda d: d.update(path={"max_steps": 2.5}), r"\[path\] max_steps must be a positive integer, got 2.5"),
    (lambda d: d["material"].update(C1=float("nan")), r"\[material\] C1 must be finite"),
    (lambda d: d["material"].update(kind="ogden"), r"unknown kind 'ogden'.*accepted: exponential, mooney_rivlin"),
    (lambda d: d["segments"][0].pop("to"), r"missing key 'to' in \[segments 0\]"),
    (lambda d: d["nodes"][1].update(phi=0.0), r"\[nodes 1\] give phi \(rad\) or phi_deg, one of them"),
    (lambda d: d.pop("shell"), r"missing key 'shell' in \[top level\]"),
])
def test_toml_errors_name_table_and_key(edit, message):
    doc = _si_base()
    edit(doc)
    with pytest.raises(ProblemError, match=message):
        parse_axisym_problem(doc)


def test_toml_syntax_error_names_the_line(tmp_path):
    from graspdef.axisym import load_axisym_problem

    f = tmp_path / "p.toml"
    f.write_text('name = "x"\n[units]\nsystem = "SI"\n[material\n')
    with pytest.raises(ProblemError, match=r"p.toml: line 4, column \d+: not valid TOML"):
        load_axisym_problem(f)
    with pytest.raises(ProblemError, match="axisymmetric problem file not found"):
        load_axisym_problem(tmp_path / "none.toml")
