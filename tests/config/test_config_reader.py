"""graspdef.config: the one TOML reader.  Unknown keys named with a hint and the accepted keys,
missing keys, NaN, wrong types and TOML syntax errors: one line naming file, table and key."""
import pytest

from graspdef.config import REQUIRED, Table, check_names, closest, parse_toml, read_toml
from graspdef.errors import ConfigError, ProblemError

DOC = """
name = "x"
[shell]
thickness = "2.5 mm"
quadrature = 3
flag = true
kind = "clamped"
at = [1.0, 2.0, 3.0]
points = ["[1, 2, 3] mm", "[4, 5, 6] cm"]
dirs = [[1.0, 0.0, 0.0], [0, 1, 0]]
forces = [1.0, 2, 3.5]
names = ["a", "b"]
bad = nan
[materials.soft]
E = "2 MPa"
[materials.hard]
E = "2 GPa"
[[supports]]
kind = "point"
[[supports]]
kind = "clamped"
"""


@pytest.fixture
def doc():
    return parse_toml(DOC, "f.toml")


def test_typed_getters(doc):
    sh = doc.table("shell")
    assert sh.quantity("thickness", "length") == 2.5e-3
    assert sh.integer("quadrature") == 3 and sh.boolean("flag") is True
    assert sh.string("kind", choices=("clamped", "free")) == "clamped"
    assert sh.vector("at") == (1.0, 2.0, 3.0)
    assert sh.quantity_vectors("points", "length") == ((1e-3, 2e-3, 3e-3), (0.04, 0.05, 0.06))
    assert sh.vectors("dirs") == ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    assert sh.list("forces") == [1.0, 2.0, 3.5] and sh.list("names", "string") == ["a", "b"]
    assert sh.number("missing", None) is None and sh.number("missing", 4.0) == 4.0
    assert Table({"length": "mm"}, "u.toml", "units").unit("length", "length") == ("mm", 1e-3)
    assert {k: t.quantity("E", "pressure") for k, t in doc.table("materials").children().items()} == {
        "soft": 2e6, "hard": 2e9}
    assert [t.name for t in doc.tables("supports")] == ["supports 1", "supports 2"]
    assert [t.name for t in doc.tables("supports", start=0)] == ["supports 0", "supports 1"]
    assert doc.tables("loads") == [] and len(doc.table("regions", required=False)) == 0
    assert dict(doc.table("materials").table("soft")) == {"E": "2 MPa"}
    assert doc.table("materials").table("soft").name == "materials.soft"


def test_unknown_key_has_a_hint_and_the_accepted_keys(doc):
    with pytest.raises(ConfigError) as exc:
        doc.check({"name", "shell", "material", "supports"})
    assert str(exc.value) == ("f.toml: unknown key 'materials' in [top level] (did you mean 'material'?); "
                              "accepted: material, name, shell, supports")
    with pytest.raises(ConfigError) as exc:
        doc.table("shell").check({"thickness"})
    assert str(exc.value) == "f.toml: unknown key 'quadrature' in [shell]; accepted: thickness"
    t = Table({"thickness_mm": 2.5}, "g.toml", "shell")
    with pytest.raises(ConfigError, match=r"unknown key 'thickness_mm' in \[shell\] \(did you mean 'thickness'\?\)"):
        t.check({"thickness", "quadrature"})


def test_missing_keys_are_reported(doc):
    with pytest.raises(ConfigError, match=r"^f.toml: missing key 'nu' in \[materials.soft\]$"):
        doc.table("materials").table("soft").check({"E", "nu", "G"}, ("nu",))
    with pytest.raises(ConfigError, match=r"^f.toml: missing keys 'nu', 'G' in \[materials.soft\]$"):
        doc.table("materials").table("soft").check({"E", "nu", "G"}, ("E", "nu", "G"))
    with pytest.raises(ConfigError, match=r"^f.toml: missing key 'p' in \[shell\]$"):
        doc.table("shell").number("p")
    with pytest.raises(ConfigError, match=r"^f.toml: missing table \[geometry\]$"):
        doc.table("geometry")
    with pytest.raises(ConfigError, match=r"\[\[loads\]\] must list at least one entry"):
        doc.tables("loads", required=True)


@pytest.mark.parametrize("call, message", [
    (lambda s: s.number("bad"), r"^f.toml: \[shell\] bad must be finite, got nan$"),
    (lambda s: s.number("kind"), r"^f.toml: \[shell\] kind must be a number, got 'clamped'$"),
    (lambda s: s.number("flag"), r"\[shell\] flag must be a number, got True"),
    (lambda s: s.number("quadrature", positive=True, maximum=2), r"\[shell\] quadrature must be <= 2, got 3"),
    (lambda s: s.number("quadrature", minimum=4), r"\[shell\] quadrature must be >= 4, got 3"),
    (lambda s: s.integer("forces"), r"\[shell\] forces must be an integer, got \[1.0, 2, 3.5\]"),
    (lambda s: s.integer("flag"), r"\[shell\] flag must be an integer, got True"),
    (lambda s: s.boolean("quadrature"), r"\[shell\] quadrature must be true or false, got 3"),
    (lambda s: s.string("quadrature"), r"\[shell\] quadrature must be a non-empty string, got 3"),
    (lambda s: s.string("kind", choices=("clamp", "free")),
     r"^f.toml: \[shell\] unknown kind 'clamped' \(did you mean 'clamp'\?\); accepted: clamp, free$"),
    (lambda s: s.vector("at", 2), r"\[shell\] at must be a list of 2 numbers, got \[1.0, 2.0, 3.0\]"),
    (lambda s: s.vectors("at"), r"\[shell\] at must be a list of 3-vectors"),
    (lambda s: s.list("names"), r"\[shell\] names must hold finite numbers, got 'a'"),
    (lambda s: s.list("forces", "integer"), r"\[shell\] forces must hold integers, got 1.0"),
    (lambda s: s.list("kind"), r"\[shell\] kind must be a list, got 'clamped'"),
    (lambda s: s.quantity("thickness", "pressure"), r"\[shell\] thickness '2.5 mm' is a length; expected a pressure"),
    (lambda s: s.quantity("quadrature", "length"), r"\[shell\] quadrature needs a unit"),
    (lambda s: s.quantity("thickness", "length", unitless="the file is nondimensional"),
     r"\[shell\] thickness has a unit \('2.5 mm'\) but the file is nondimensional: give a plain number"),
    (lambda s: s.unit("kind", "length"), r"\[shell\] kind: unknown length unit 'clamped'"),
    (lambda s: s.table("kind"), r"\[shell.kind\] must be a table, got 'clamped'"),
])
def test_value_errors_name_file_table_and_key(doc, call, message):
    with pytest.raises(ProblemError, match=message) as exc:
        call(doc.table("shell"))
    assert isinstance(exc.value, ConfigError) and "\n" not in str(exc.value)


def test_lists_without_repeats():
    t = Table({"f": [5.0, 5, 6.0], "e": []}, "s.toml", "grid")
    with pytest.raises(ConfigError, match=r"^s.toml: \[grid\] f repeats 5$"):
        t.list("f", unique=True)
    with pytest.raises(ConfigError, match=r"^s.toml: \[grid\] e is empty$"):
        t.list("e")
    assert t.list("e", nonempty=False) == []


def test_toml_syntax_error_is_one_line_with_file_and_line(tmp_path):
    f = tmp_path / "p.toml"
    f.write_text('a = 1\n\n[shell\nthickness = 1\n')
    with pytest.raises(ConfigError) as exc:
        read_toml(f)
    assert str(exc.value) == (f"{f}: line 3, column 7: not valid TOML: Expected ']' at the end of a table "
                              "declaration")
    f.write_text("a = 1\na = 2\n")
    with pytest.raises(ConfigError, match=r"p.toml: line 2, column \d+: not valid TOML"):
        read_toml(f)
    with pytest.raises(ConfigError, match=r"^thing not found: .*none.toml$"):
        read_toml(tmp_path / "none.toml", "thing")
    with pytest.raises(ConfigError, match="cannot read it"):
        read_toml(tmp_path.joinpath("bin.toml").write_bytes(b"\xff\xfe") and tmp_path / "bin.toml")


def test_check_names_and_closest():
    assert closest("gass", ["gas", "grasp"]) == "gas" and closest("zzz", ["gas"]) is None
    assert closest("E_MPa", ["E", "nu"]) == "E" and closest("p0_kPa", ["p0", "source"]) == "p0"
    check_names(["a"], ["a", "b"], ["a"])
    with pytest.raises(ConfigError, match=r"^m: unknown parameter 'c'; accepted: a, b$"):
        check_names(["c"], ["a", "b"], noun="parameter", prefix="m: ")
    with pytest.raises(ConfigError, match=r"^missing restraints 'r', 'z' in \[x\]$"):
        check_names([], ["r", "z"], ["r", "z"], noun="restraint", place=" in [x]")
    assert REQUIRED is not None
