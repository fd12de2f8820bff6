"""Sweep specs: the grid, case identity, and every kind of bad input rejected with one clear
error before any work (no folder written, no cluster started)."""
import dataclasses

import pytest

import mujoco  # noqa: F401  (the sim extra is part of make test: scenes are checked against MuJoCo)

from graspdef.cli import main
from graspdef.errors import ProblemError
from graspdef.sweep import parse_spec

GOOD = """
[sweep]
name = "t"
[grid]
scenes = ["tennis_ball"]
forces_N = [5.0, 10.0]
materials = ["linear", "soft"]
contacts = ["point"]
control_faces = [320, 1280]
[materials.soft]
analysis = "nonlinear"
E_MPa = 2.0
gas = "off"
"""


def test_grid_is_the_product_of_the_axes():
    spec = parse_spec(GOOD, "good.toml")
    assert len(spec.cases) == 1 * 2 * 2 * 1 * 2
    soft = [c for c in spec.cases if c.material == "soft"][0]
    assert (soft.analysis, soft.E_Pa, soft.gas) == ("nonlinear", 2e6, "off")
    assert len({c.id for c in spec.cases}) == 8
    assert spec.cases[0].id.startswith("tennis_ball_5N_linear_point_320f_")


def test_case_identity_is_stable_and_covers_the_options():
    a = parse_spec(GOOD, "a.toml").cases
    b = parse_spec(GOOD.replace('name = "t"', 'name = "other"'), "b.toml").cases
    assert [c.id for c in a] == [c.id for c in b]                  # the sweep's name is not part of a case
    changed = parse_spec(GOOD.replace("E_MPa = 2.0", "E_MPa = 3.0"), "c.toml").cases
    assert {c.id for c in changed if c.material == "linear"} == {c.id for c in a if c.material == "linear"}
    assert not {c.id for c in changed if c.material == "soft"} & {c.id for c in a if c.material == "soft"}
    c = a[0]
    assert dataclasses.replace(c, inputs_sha256="0" * 64).id != c.id   # an edited object.toml is a new case
    text = parse_spec(GOOD.replace("E_MPa = 2.0", 'E = "2 MPa"'), "d.toml").cases
    assert [c.id for c in text] == [c.id for c in a]                # E as a quantity: the same cases


def test_default_axes():
    spec = parse_spec('[grid]\nscenes = ["tennis_ball"]\nforces_N = [5]\nmaterials = ["linear"]\n', "d.toml")
    (c,) = spec.cases
    assert (c.contact, c.control_faces, c.E_Pa, c.gas) == ("point", 1280, None, "auto")
    assert spec.name == "d"


@pytest.mark.parametrize("edit, message", [
    (("forces_N = [5.0, 10.0]", "force_N = [5.0, 10.0]"), "unknown key 'force_N' in [grid] (did you mean 'forces_N'?)"),
    (("[sweep]", "[sweeps]"), "unknown key 'sweeps' in [top level] (did you mean 'sweep'?); accepted: grid, "
                              "materials, sweep"),
    (("gas = \"off\"", "gass = \"off\""), "unknown key 'gass' in [materials.soft] (did you mean 'gas'?)"),
    (("forces_N = [5.0, 10.0]", "forces_N = []"), "[grid] forces_N is empty"),
    (("scenes = [\"tennis_ball\"]", "scenes = []"), "[grid] scenes is empty"),
    (("control_faces = [320, 1280]", "control_faces = []"), "[grid] control_faces is empty"),
    (("forces_N = [5.0, 10.0]", ""), "missing key 'forces_N' in [grid]"),
    (("scenes = [\"tennis_ball\"]", "scenes = [\"tenis_ball\"]"), "scene not found: tenis_ball"),
    (("materials = [\"linear\", \"soft\"]", "materials = [\"linear\", \"sofft\"]"),
     "unknown material 'sofft' (did you mean 'soft'?)"),
    (("contacts = [\"point\"]", "contacts = [\"pointt\"]"), "unknown contact model 'pointt' (did you mean 'point'?)"),
    (("forces_N = [5.0, 10.0]", "forces_N = [5.0, 450.0]"), "450 N is beyond what the actuators"),
    (("forces_N = [5.0, 10.0]", "forces_N = [5.0, 5.0]"), "[grid] forces_N repeats 5"),
    (("forces_N = [5.0, 10.0]", "forces_N = [-5.0]"), "forces_N must be positive"),
    (("analysis = \"nonlinear\"", "analysis = \"nonlinar\""),
     "[materials.soft] unknown analysis 'nonlinar' (did you mean 'nonlinear'?); accepted: linear, nonlinear"),
    (("E_MPa = 2.0", "E_MPa = -2.0"), "[materials.soft] E_MPa must be positive, got -2.0"),
    (("E_MPa = 2.0", 'E = "2 mm"'), "[materials.soft] E '2 mm' is a length; expected a pressure"),
    (("E_MPa = 2.0", 'E = "2 MPa"\nE_MPa = 2.0'), "[materials.soft] give E"),
    (("E_MPa = 2.0", "E_MPa = nan"), "[materials.soft] E_MPa must be finite"),
    (("control_faces = [320, 1280]", "control_faces = [10]"), "control_faces must be >= 20"),
    (("control_faces = [320, 1280]", "control_faces = [320.5]"), "control_faces must hold integers"),
    (("[sweep]", "[sweep"), "line 2, column 7: not valid TOML"),
])
def test_bad_spec_is_one_clear_error(edit, message):
    with pytest.raises(ProblemError) as exc:
        parse_spec(GOOD.replace(*edit), "bad.toml")
    assert message in str(exc.value) and str(exc.value).startswith("bad.toml: ")


def test_gas_on_needs_the_objects_air():
    """gas = "on" for an object whose data has no [gas] is refused before any case runs (no built-in pressure)."""
    duck = GOOD.replace('scenes = ["tennis_ball"]', 'scenes = ["duck"]').replace('gas = "off"', 'gas = "on"')
    with pytest.raises(ProblemError, match=r"bad.toml: \[materials.soft\] gas = \"on\", but scene 'duck' has no "
                                           r"enclosed air \(\[gas\] in .*scenes/duck/object.toml\)"):
        parse_spec(duck, "bad.toml")
    assert parse_spec(duck.replace('gas = "on"', 'gas = "off"'), "ok.toml").cases


def test_material_table_not_in_grid_and_builtin_shadowing():
    with pytest.raises(ProblemError, match=r"\[materials.soft\] is defined but not in \[grid\] materials"):
        parse_spec(GOOD.replace('materials = ["linear", "soft"]', 'materials = ["linear"]'), "x.toml")
    with pytest.raises(ProblemError, match="'linear' is a built-in preset"):
        parse_spec(GOOD + '[materials.linear]\nanalysis = "linear"\n', "x.toml")


def test_cli_bad_spec_and_unreachable_scheduler_leave_nothing(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(GOOD.replace("forces_N = [5.0, 10.0]", "forces_N = []"))
    out = tmp_path / "sweep"
    assert main(["-q", "sweep", str(bad), "--out", str(out)]) == 2
    assert "forces_N is empty" in capsys.readouterr().err
    good = tmp_path / "good.toml"
    good.write_text(GOOD)
    # a port nobody listens on: refused at once, reported after the (short) connect timeout
    assert main(["-q", "sweep", str(good), "--out", str(out), "--scheduler", "tcp://127.0.0.1:9",
                 "--connect-timeout", "1"]) == 2
    err = capsys.readouterr().err
    assert "cannot reach the dask scheduler at tcp://127.0.0.1:9" in err and err.count("\n") == 1
    assert main(["-q", "sweep", str(good), "--out", str(out), "--scheduler", "127.0.0.1:9"]) == 2
    assert "must look like tcp://HOST:PORT" in capsys.readouterr().err
    assert main(["-q", "sweep", str(good)]) == 2
    assert "give --out" in capsys.readouterr().err
    assert not out.exists()


def test_help_lists_every_subcommand_with_examples(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    text = capsys.readouterr().out
    for cmd in ("solve", "bench", "grasp", "score", "report", "view", "sweep"):
        assert f"graspdef {cmd} " in text, cmd


def test_example_specs_are_valid():
    from pathlib import Path

    from graspdef.sweep import load_spec

    files = sorted((Path(__file__).resolve().parents[2] / "sweeps").glob("*.toml"))
    assert files
    for f in files:
        assert load_spec(f).cases, f


def test_help_example_spec_parses():
    from graspdef.cli.sweep import EPILOG

    text = "\n".join(line[2:] for line in EPILOG.split("a spec (docs/sweep.md):\n")[1].splitlines())
    assert len(parse_spec(text, "help.toml").cases) == 2 * 2 * 2
