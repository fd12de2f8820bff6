"""Problem files through graspdef.config: the same SI values as before, values with their own units
where the file has physical units, and errors naming file, table and key."""
import pytest

from graspdef.errors import ProblemError
from graspdef.problem.config import load_problem
from graspdef.testing import plate_problem

BASE = plate_problem("small_plate", 4, load='kind = "pressure"\np = 0.01')


def _load(tmp_path, text):
    f = tmp_path / "p.toml"
    f.write_text(text)
    return load_problem(f)


def test_file_units_to_si(tmp_path):
    """N and mm: E = 1000 N/mm^2 = 1 GPa, t = 1 mm, p = 0.01 N/mm^2 = 10 kPa, 100 mm wide."""
    spec = _load(tmp_path, BASE)
    sh = spec.problem.shell
    assert (sh.material.E, sh.material.nu) == (1000.0 * (1.0 / 1e-3 ** 2), 0.3)
    assert (spec.length_scale, spec.force_scale) == (1e-3, 1.0)
    assert sh.mesh.vertices[: sh.mesh.n_real, 0].max() == pytest.approx(0.05, rel=1e-15)
    assert spec.problem.loads[0].p == 0.01 * 1.0 / 1e-3 ** 2


def test_values_with_their_own_units_are_the_same(tmp_path):
    """thickness = "1 mm", E = "1 GPa", p = "10 kPa", lx = "10 cm": the same shell and load as the
    plain numbers in the file's units (to round-off of the two conversions)."""
    a = _load(tmp_path, BASE).problem
    b = _load(tmp_path, BASE.replace("thickness = 1.0", 'thickness = "1 mm"').replace("E = 1000.0", 'E = "1 GPa"')
              .replace("p = 0.01", 'p = "10 kPa"').replace("lx = 100.0", 'lx = "10 cm"')).problem
    assert b.shell.material.E == pytest.approx(a.shell.material.E, rel=1e-15)
    assert b.loads[0].p == pytest.approx(a.loads[0].p, rel=1e-15)
    assert float(b.shell.thickness) == float(a.shell.thickness) == 1e-3
    assert abs(b.shell.mesh.vertices - a.shell.mesh.vertices).max() <= 1e-17


@pytest.mark.parametrize("edit, message", [
    (('thickness = 1.0', 'thickness = "1 MPa"'), r"p.toml: \[shell\] thickness '1 MPa' is a pressure; expected a length"),
    (('length = "mm"\nforce = "N"', 'length = "consistent"\nforce = "consistent"'), None),
    (('E = 1000.0', 'E = 1000.0\nEE = 1.0'),
     r"p.toml: unknown key 'EE' in \[material\] \(did you mean 'E'\?\); accepted: E, model, nu"),
    (('[[probes]]', '[[probes]]\nnmae = "x"'), r"unknown key 'nmae' in \[probes 1\] \(did you mean 'name'\?\)"),
    (('kind = "pressure"', 'kind = "presure"'), r"\[loads 1\] unknown kind 'presure' \(did you mean 'pressure'\?\)"),
    (('p = 0.01', 'p = "0.01"'), None),
    (('name = "centre"', 'name = 3'), r"\[probes 1\] name must be a non-empty string, got 3"),
    (('[[loads]]', '[solver]\ntype = "linear"\nsteps = 3\n[[loads]]'),
     r"p.toml: \[solver\] steps only apply to type = \"nonlinear\""),
    (('[[loads]]', '[solver]\nnitsche_gamma = 0.0\n[[loads]]'),
     r"p.toml: \[solver\] nitsche_gamma \(the Nitsche rotation penalty of clamped / symmetry edges, dimensionless; "
     r"default 20\) must be positive, got 0.0"),
    (('[[loads]]', '[solver]\nnitsche_gamma = "big"\n[[loads]]'), r"p.toml: \[solver\] nitsche_gamma must be a number"),
    (('[[loads]]', '[solver]\ntype = "nonlin"\n[[loads]]'), r"\[solver\] unknown type 'nonlin' \(did you mean 'nonlinear'\?\)"),
    (('[[loads]]', '[solver]\nprecision = "single"\n[[loads]]'),
     r"\[solver\] unknown precision 'single'"),
    (('nx = 4', 'nx = 4.0'), r"\[geometry\] nx must be an integer, got 4.0"),
    (('[units]', '[units'), r"p.toml: line \d+, column \d+: not valid TOML"),
])
def test_errors_name_file_table_and_key(tmp_path, edit, message):
    text = BASE.replace(*edit)
    if message is None:                 # a consistent file takes plain numbers: the text value is refused
        text = text.replace("thickness = 1.0", 'thickness = "1 mm"') if "consistent" in text else text
        if "consistent" in text:
            message = (r"p.toml: \[shell\] thickness has a unit \('1 mm'\) but the file's units are 'consistent': give "
                       r"a plain number")
        else:                           # a number in a string: the file's unit is implied
            assert _load(tmp_path, text).problem.loads[0].p == 0.01 / 1e-3 ** 2
            return
    with pytest.raises(ProblemError, match=message) as exc:
        _load(tmp_path, text)
    assert "\n" not in str(exc.value)


def test_nitsche_gamma_reaches_the_problem_and_applies_to_linear_files(tmp_path):
    """``[solver] nitsche_gamma`` is a discretisation setting (like ``collocation``), so a linear
    file takes it too; it sets the Problem's penalty, default 20."""
    assert _load(tmp_path, BASE).problem.nitsche_gamma == 20.0
    spec = _load(tmp_path, BASE.replace("[[loads]]", '[solver]\ntype = "linear"\nnitsche_gamma = 80.0\n[[loads]]', 1))
    assert spec.problem.nitsche_gamma == 80.0


def test_precision_reaches_the_linear_solve_and_its_record(tmp_path):
    """``[solver] precision`` (a linear file's, ``ProblemSpec.precision``: also what ``graspdef
    bench linear`` and the viewer's live re-solves use) is what ``graspdef solve`` factorises with, and
    result.json says which factor solved it; the two give the same centre deflection to 1e-9."""
    import json

    from graspdef.cli import main

    out = {}
    for precision in ("mixed", "double"):
        f = tmp_path / f"{precision}.toml"
        f.write_text(BASE.replace("[[loads]]", f'[solver]\nprecision = "{precision}"\n[[loads]]', 1))
        assert main(["-q", "solve", str(f), "--out", str(tmp_path / precision)]) == 0
        rec = json.loads((tmp_path / precision / "result.json").read_text())
        assert rec["solver"]["precision"] == precision
        assert load_problem(f).precision == precision            # the one value every linear consumer reads
        out[precision] = rec["probes"]["centre"]["displacement"][2]
    assert out["double"] != 0 and abs(out["mixed"] / out["double"] - 1) < 1e-9, out
    assert load_problem(tmp_path / "double.toml").precision == "double" and _load(tmp_path, BASE).precision == "auto"


def test_precision_reaches_a_nonlinear_path_and_its_record(tmp_path):
    """A nonlinear file's ``[solver] precision`` is what its path's tangents are factorised with:
    "mixed" gives single-precision factors (each one whose inertia became a point's stability
    certified, graspdef.solve.sparse.KKTSystem.certify_inertia), result.json counts them, and the
    centre deflection is the double path's to 1e-8 (both converge to the Newton tolerance); "auto"
    is double at this size (below 20,000 unknowns)."""
    import json

    from graspdef.cli import main

    out = {}
    for precision in ("mixed", "double", "auto"):
        f = tmp_path / f"{precision}.toml"
        f.write_text(BASE.replace("[[loads]]", f'[solver]\ntype = "nonlinear"\nsteps = 2\nprecision = "{precision}"\n[[loads]]', 1)
                     .replace("p = 0.01", "p = 0.0005"))
        assert load_problem(f).precision == precision
        assert main(["-q", "solve", str(f), "--out", str(tmp_path / precision)]) == 0
        rec = json.loads((tmp_path / precision / "result.json").read_text())
        conv = rec["convergence"]
        out[precision] = (rec["probes"]["centre"]["displacement"][2], conv["n_single_precision_factorisations"],
                          conv["n_factorisations"])
    w_m, single_m, n_m = out["mixed"]
    w_d, single_d, _ = out["double"]
    assert single_m == n_m > 0 and single_d == 0 and out["auto"][1] == 0
    assert w_d != 0 and abs(w_m / w_d - 1) < 1e-8, out
