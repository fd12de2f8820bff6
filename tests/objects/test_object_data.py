"""An object's data (scenes/<scene>/object.toml, graspdef.objects): read and checked in SI, the
material law explicit with its nu, gas only with a stated pressure and source, and every bad
input one error naming the file, the table and the key."""
import math
from pathlib import Path

import numpy as np
import pytest

from graspdef.errors import ProblemError
from graspdef.objects import LAWS, MaterialSpec, load_object, read_object
from graspdef.shell.hyperelastic import (
    CompressibleMooneyRivlin,
    CompressibleNeoHookean,
    MooneyRivlin,
    NeoHookean,
)
from graspdef.shell.materials import LinearElastic

ROOT = Path(__file__).resolve().parents[2]
BALL = (ROOT / "scenes" / "tennis_ball" / "object.toml").read_text()


def _read(tmp_path, text):
    f = tmp_path / "object.toml"
    f.write_text(text)
    return read_object(f, ROOT / "scenes" / "tennis_ball" / "scene.xml")


def test_every_scene_object_reads_in_si():
    """The four objects: thickness, E, nu, gas in SI from the text with units; the scene XML next to it."""
    ball = load_object("tennis_ball")
    assert (ball.thickness, ball.material.E, ball.material.nu, ball.gas.p0) == (2.5e-3, 1e6, 0.5, 80e3)
    assert ball.material.law == "neo_hookean" and ball.material.source and ball.gas.source
    assert (ball.body, ball.scan, ball.control_faces, ball.remesh, ball.steps) == (
        "tennis_ball", "ycb_056_tennis_ball", 1280, "project", 4)
    assert ball.scene == ROOT / "scenes" / "tennis_ball" / "scene.xml" and ball.file.name == "object.toml"
    assert load_object(ROOT / "scenes" / "tennis_ball" / "scene_pad.xml").scene.name == "scene_pad.xml"
    duck = load_object("duck")
    assert (duck.thickness, duck.material.E, duck.material.nu, duck.gas, duck.relax) == (1e-3, 1e6, 0.45, None, 20)
    poke = load_object("duck_head_poke")
    assert poke.fingers == ("right",)
    np.testing.assert_allclose(poke.fixed_points[0], [0.04797, 0.00419, -0.04165], rtol=1e-15)
    assert len(poke.fixed_points) == 4
    can = load_object("soda_can")
    assert (can.thickness, can.material.law, can.material.E, can.material.nu) == (1e-4, "svk", 69e9, 0.33)


def test_unknown_table_is_named_with_the_accepted_ones(tmp_path):
    """[gass] (a typo of [gas]) used to drop the air silently (24 % in the result): now an error."""
    with pytest.raises(ProblemError) as exc:
        _read(tmp_path, BALL.replace("[gas]", "[gass]"))
    msg = str(exc.value)
    assert msg.startswith(f"{tmp_path / 'object.toml'}: unknown key 'gass' in [top level] (did you mean 'gas'?); ")
    assert msg.endswith("accepted: gas, grasp, material, object, shell, solver, supports")
    assert msg.count("\n") == 0


@pytest.mark.parametrize("edit, message", [
    (('thickness = "2.5 mm"', 'thickness = "2.5 MPa"'),
     r"\[shell\] thickness '2.5 MPa' is a pressure; expected a length \(m, mm, cm, um, in\)"),
    (('thickness = "2.5 mm"', "thickness = 2.5"), r"\[shell\] thickness needs a unit: 2.5 is a plain number"),
    (('thickness = "2.5 mm"', 'thickness = "-2.5 mm"'), r"\[shell\] thickness must be positive"),
    (('thickness = "2.5 mm"', 'thickness = "2.5 mmm"'), r"\[shell\] thickness '2.5 mmm' has an unknown unit 'mmm'"),
    (('E = "1 MPa"', 'E = "nan MPa"'), r"\[material\] E must be finite"),
    (('E = "1 MPa"', 'E = "1 N"'), r"\[material\] E '1 N' is a force; expected a pressure"),
    (('E = "1 MPa"', 'E_MPa = 1.0'), r"unknown key 'E_MPa' in \[material\] \(did you mean 'E'\?\); accepted: E, law, nu, "
                                     r"source"),
    (('law = "neo_hookean"', 'law = "neo_hooke"'),
     r"\[material\] unknown law 'neo_hooke' \(did you mean 'neo_hookean'\?\); accepted: linear, mooney_rivlin, "
     r"neo_hookean, svk"),
    (('law = "neo_hookean"', ""), r"missing key 'law' in \[material\]"),
    (("\nnu = 0.5", "\nnu = 0.6"), r"\[material\] nu must be <= 0.5, got 0.6"),
    (("\nnu = 0.5", "\nnu = true"), r"\[material\] nu must be a number, got True"),
    (("\nsource = \"Tian & Jia 2010, Sec. IX-A: Young", "\nsourc = \"Tian & Jia 2010, Sec. IX-A: Young"),
     r"unknown key 'sourc' in \[material\] \(did you mean 'source'\?\)"),
    (('p0 = "80 kPa"', 'p0 = "80 kg"'), r"\[gas\] p0 '80 kg' is a mass; expected a pressure"),
    (('p0 = "80 kPa"', "p0_kPa = 80.0"), r"unknown key 'p0_kPa' in \[gas\] \(did you mean 'p0'\?\)"),
    (("source = \"assumed: a pressurised", "note = \"assumed: a pressurised"), r"unknown key 'note' in \[gas\]"),
    (('scan = "ycb_056_tennis_ball"', 'scan = "ycb_056_tenis_ball"'),
     r"\[object\] unknown scan 'ycb_056_tenis_ball' \(did you mean 'ycb_056_tennis_ball'\?\)"),
    (('remesh = "project"', 'remesh = "projected"'), r"\[shell\] unknown remesh 'projected' \(did you mean 'project'\?\)"),
    (("control_faces = 1280", "control_faces = 1280.0"), r"\[shell\] control_faces must be an integer, got 1280.0"),
    (("steps = 4", "steps = 0"), r"\[solver\] steps must be a positive integer, got 0"),
    (("[solver]", "[grasp]\nfingers = [\"middle\"]\n[solver]"), r"\[grasp\] fingers: unknown finger 'middle'"),
    (("[solver]", "[supports]\nfixed_points = [\"[1, 2] mm\"]\n[solver]"),
     r"\[supports\] fixed_points entry 1 must have 3 entries, got 2"),
    (("[solver]", "[supports]\nfixed_points = [\"[1, 2, 3] kPa\"]\n[solver]"),
     r"\[supports\] fixed_points entry 1 '\[1, 2, 3\] kPa' is a pressure; expected a length"),
    (('[object]', '[object'), r"object.toml: line \d+, column \d+: not valid TOML"),
])
def test_bad_object_data_is_one_clear_error(tmp_path, edit, message):
    assert edit[0] in BALL
    with pytest.raises(ProblemError, match=message) as exc:
        _read(tmp_path, BALL.replace(*edit, 1))
    assert str(exc.value).startswith(str(tmp_path / "object.toml")) and "\n" not in str(exc.value)


def test_gas_needs_a_stated_pressure_and_source(tmp_path):
    """No default pressure anywhere: [gas] without p0 or without its source is refused; an object
    without [gas] has none."""
    with pytest.raises(ProblemError, match=r"missing key 'p0' in \[gas\]"):
        _read(tmp_path, BALL.replace('p0 = "80 kPa"', ""))
    with pytest.raises(ProblemError, match=r"missing key 'source' in \[gas\]"):
        _read(tmp_path, BALL.replace("source = \"assumed: a pressurised", "# source = \"assumed: a pressurised"))
    start = BALL.index("[gas]")
    no_gas = BALL[:start] + BALL[BALL.index("[solver]"):]
    assert _read(tmp_path, no_gas).gas is None
    spec = _read(tmp_path, BALL.replace('p0 = "80 kPa"', 'p0 = "80 kPa"\np_atm = "1 bar"'.replace("1 bar", "100 kPa")))
    assert (spec.gas.p0, spec.gas.p_atm) == (80e3, 100e3)


def test_gas_on_without_air_is_an_error_not_80_kPa():
    """--gas on for an object whose data has no [gas] (the duck): an error naming its object.toml,
    raised before the scan is read or MuJoCo runs."""
    from graspdef.pipeline import run_grasp

    with pytest.raises(ProblemError, match=r"duck/object.toml: gas on, but the object has no enclosed air: give "
                                           r"\[gas\] p0"):
        run_grasp("duck", 5.0, "point", "nonlinear", None, gas=True)


def test_scene_without_object_data(tmp_path):
    with pytest.raises(ProblemError, match="no object.toml beside the scene"):
        load_object("test_sphere")
    with pytest.raises(ProblemError, match="scene not found: nowhere"):
        load_object("nowhere")


# ------------------------------------------------------------------------------------------------
# the law and nu -> the shell material
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("law, nu, model, cls", [
    ("neo_hookean", 0.5, "neo_hookean", NeoHookean),
    ("neo_hookean", 0.45, "compressible_neo_hookean", CompressibleNeoHookean),
    ("neo_hookean", 0.0, "compressible_neo_hookean", CompressibleNeoHookean),
    ("mooney_rivlin", 0.5, "mooney_rivlin", MooneyRivlin),
    ("mooney_rivlin", 0.3, "compressible_mooney_rivlin", CompressibleMooneyRivlin),
    ("svk", 0.3, "saint_venant_kirchhoff", LinearElastic),
    ("svk", 0.5, "saint_venant_kirchhoff", LinearElastic),
])
def test_nu_is_honoured_in_every_law(law, nu, model, cls):
    """A nonlinear analysis uses the stated law with the stated nu (incompressible forms only at
    nu = 0.5); its tangent at zero strain is LinearElastic(E, nu) to 1e-10, and a linear analysis
    uses LinearElastic(E, nu) itself."""
    E = 2.7e6
    spec = MaterialSpec(law, E, nu, 0.25 if law == "mooney_rivlin" else None, "test")
    assert spec.model("linear") == "linear_elastic" and spec.shell_material("linear") == LinearElastic(E, nu)
    mat = spec.shell_material("nonlinear")
    assert spec.model("nonlinear") == model and type(mat) is cls
    ri = np.array([[1.0, 1.0, 0.0], [1.3, 0.8, 0.2]])
    t = np.array([1e-3, 0.02])
    ref = LinearElastic(E, nu).tangent(ri, t)
    K = mat.tangent(ri, t)
    for blk in (np.s_[..., :3, :3], np.s_[..., 3:, 3:]):
        assert np.abs(K[blk] - ref[blk]).max() <= 1e-10 * np.abs(ref[blk]).max()
    if law == "mooney_rivlin":
        assert mat.C2 == pytest.approx(0.25 * mat.C1, rel=1e-15)
        assert 2 * (mat.C1 + mat.C2) == pytest.approx(E / (2 * (1 + nu)), rel=1e-15)


def test_neo_hookean_at_nu_one_half_is_the_old_mu_e_over_3():
    """The tennis ball's data (neo_hookean, nu = 0.5): exactly NeoHookean(E / 3), the material of
    the runs before the object data stated its law."""
    assert load_object("tennis_ball").shell_material("nonlinear") == NeoHookean(1e6 / 3.0)


def test_mooney_rivlin_by_constants_or_by_e_and_ratio(tmp_path):
    """C1, C2 (with nu) are the same law as E = 4 (C1 + C2)(1 + nu) with C2_over_C1; giving both
    forms, or neither, is an error."""
    mr = BALL.replace('law = "neo_hookean"', 'law = "mooney_rivlin"')
    a = _read(tmp_path, mr.replace('E = "1 MPa"', 'C1 = "0.69 MPa"\nC2 = "0.1725 MPa"').replace("nu = 0.5", "nu = 0.45"))
    b = _read(tmp_path, mr.replace('E = "1 MPa"', f'E = "{4 * 0.8625 * 1.45} MPa"\nC2_over_C1 = 0.25')
              .replace("nu = 0.5", "nu = 0.45"))
    assert a.material.c2_over_c1 == pytest.approx(0.25, rel=1e-14)
    assert a.material.E == pytest.approx(b.material.E, rel=1e-14)
    ma, mb = a.shell_material("nonlinear"), b.shell_material("nonlinear")
    assert (ma.C1, ma.C2, ma.lam) == pytest.approx((0.69e6, 0.1725e6, mb.lam), rel=1e-13)
    with pytest.raises(ProblemError, match=r"\[material\] give E and C2_over_C1, or C1 and C2"):
        _read(tmp_path, mr.replace('E = "1 MPa"', 'E = "1 MPa"\nC1 = "0.1 MPa"\nC2 = "0.1 MPa"'))
    with pytest.raises(ProblemError, match=r"missing key 'C2_over_C1' in \[material\]"):
        _read(tmp_path, mr)
    with pytest.raises(ProblemError, match=r"unknown key 'C2_over_C1' in \[material\]"):
        _read(tmp_path, BALL.replace('E = "1 MPa"', 'E = "1 MPa"\nC2_over_C1 = 0.25'))


def test_linear_law_refuses_a_nonlinear_analysis(tmp_path):
    spec = _read(tmp_path, BALL.replace('law = "neo_hookean"', 'law = "linear"'))
    assert spec.shell_material("linear") == LinearElastic(1e6, 0.5)
    with pytest.raises(ProblemError, match=r"object.toml: \[material\] law = 'linear' has no finite-strain form: a "
                                           r"nonlinear analysis needs law = 'svk'"):
        spec.shell_material("nonlinear")


def test_e_override_keeps_the_law():
    """--E-MPa / run_grasp(E=...) overrides E of the stated law: nu, C2/C1 and the law stay."""
    duck = load_object("duck").replace(E=8.17e6, control_faces=600)
    assert (duck.material.law, duck.material.E, duck.material.nu, duck.control_faces) == ("neo_hookean", 8.17e6, 0.45, 600)
    mat = duck.shell_material("nonlinear")
    assert isinstance(mat, CompressibleNeoHookean) and mat.E == pytest.approx(8.17e6, rel=1e-14)
    mr = MaterialSpec("mooney_rivlin", 1e6, 0.3, 0.25).with_E(2e6).shell_material("nonlinear")
    assert (mr.E, mr.nu, mr.C2 / mr.C1) == pytest.approx((2e6, 0.3, 0.25), rel=1e-14)


def test_material_spec_checks_its_values():
    for bad, match in [(dict(law="rubber"), "unknown material law 'rubber'"),
                       (dict(E=-1.0), "Young's modulus"), (dict(nu=0.51), "Poisson's ratio"),
                       (dict(E=math.nan), "Young's modulus"), (dict(c2_over_c1=0.1), "C2/C1")]:
        kw = dict(law="neo_hookean", E=1e6, nu=0.3, c2_over_c1=None) | bad
        with pytest.raises(ProblemError, match=match):
            MaterialSpec(**kw)
    assert set(LAWS) == {"neo_hookean", "mooney_rivlin", "svk", "linear"}
