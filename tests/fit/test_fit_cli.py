"""``graspdef fit`` at the command line: every bad input is one line ``graspdef: error: ...`` with
exit status 2 and nothing written; and an end-to-end fit of the tennis ball's E (linear shell,
MuJoCo settled once) to data its own grasp chain made at E = 1.5 MPa, written to fit.json in SI."""
from __future__ import annotations

import json

import numpy as np
import pytest

from graspdef.cli import main

GOOD = "force_N,displacement_mm,point\n10,20.0,finger\n10,21.0,max\n"


def _csv(tmp_path, text: str, name: str = "t.csv") -> str:
    p = tmp_path / name
    p.write_text(text)
    return str(p)


CASES = {
    "missing data file": (lambda t: ["tennis_ball", "--data", str(t / "nope.csv"), "--params", "E"],
                          "data table not found"),
    "unknown parameter": (lambda t: ["tennis_ball", "--data", _csv(t, GOOD), "--params", "E,stiffness"],
                          "unknown parameter 'stiffness'; accepted: E, pressure, thickness"),
    "parameter twice": (lambda t: ["tennis_ball", "--data", _csv(t, GOOD), "--params", "E,E"], "'E' given twice"),
    "header without units": (lambda t: ["tennis_ball", "--data", _csv(t, "force,displacement\n10,2\n"), "--params",
                                        "E"], "column 'force' states no unit"),
    "non-positive force": (lambda t: ["tennis_ball", "--data", _csv(t, "force_N,displacement_mm\n0,2\n"),
                                      "--params", "E"], "force must be positive"),
    "fewer rows than parameters": (lambda t: ["tennis_ball", "--data", _csv(t, "force_N,displacement_mm\n10,2\n"),
                                              "--params", "E,pressure"], "1 rows for 2 parameters"),
    "start without unit": (lambda t: ["tennis_ball", "--data", _csv(t, GOOD), "--params", "E", "--start", "E=2"],
                           "needs a unit"),
    "start of another parameter": (lambda t: ["tennis_ball", "--data", _csv(t, GOOD), "--params", "E", "--start",
                                              "thickness=2mm"], "not a parameter being fitted"),
    "unknown scene": (lambda t: ["no_such_scene", "--data", _csv(t, GOOD), "--params", "E"], "scene not found"),
    "force beyond the gripper": (lambda t: ["tennis_ball", "--data", _csv(t, "force_N,displacement_mm\n1e9,2\n"),
                                            "--params", "E"], "beyond what the gripper can exert"),
    "unknown point": (lambda t: ["tennis_ball", "--data", _csv(t, "force_N,displacement_mm,point\n10,2,elbow\n"),
                                 "--params", "E"], "unknown point 'elbow'"),
    "pressure with the linear shell": (lambda t: ["tennis_ball", "--data", _csv(t, GOOD), "--params", "E,pressure",
                                                  "--analysis", "linear"], "needs --analysis nonlinear"),
    "pressure of an object without air": (lambda t: ["duck", "--data", _csv(t, GOOD), "--params", "E,pressure"],
                                           "no [gas] table"),
    "--out holds other files": (lambda t: ["tennis_ball", "--data", _csv(t, GOOD), "--params", "E", "--out",
                                           str(t / "photos")], "not a graspdef run folder"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_bad_input_is_one_line(name, tmp_path, capsys):
    """Each bad input: exit 2, stderr one line 'graspdef: error: ...' with the phrase, no fit.json."""
    (tmp_path / "photos").mkdir()
    (tmp_path / "photos" / "cat.jpg").write_text("x")
    argv, phrase = CASES[name]
    argv = argv(tmp_path)
    out = tmp_path / "out"
    if "--out" not in argv:
        argv += ["--out", str(out)]
    code = main(["-q", "fit", *argv])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, (code, err)
    assert err[0].startswith("graspdef: error: ") and phrase in err[0], err[0]
    assert not out.exists()


@pytest.mark.slow
def test_fit_of_the_tennis_balls_E_end_to_end(tmp_path, capsys):
    """Data made by the tennis ball's grasp chain (linear shell, point loads, 10 N per finger) at
    E = 1.5 MPa, fitted from object.toml's 1 MPa: E to 1e-4, converged, fit.json in SI with units,
    the table copied beside it.
    Slow (15-26 s on 2 cores): `make test-slow`."""
    from graspdef.fit import ObjectModel, read_table

    data = _csv(tmp_path, "force_N,displacement_mm,point\n10,1,finger\n10,1,max\n")
    model = ObjectModel("tennis_ball", read_table(data), ["E"], "linear")
    exact = model({"E": 1.5e6})
    data = _csv(tmp_path, "force_N,displacement_mm,point\n" + "".join(
        f"10,{u * 1e3:.9f},{p}\n" for u, p in zip(exact, ("finger", "max"))), "data.csv")
    out = tmp_path / "fit"
    code = main(["-q", "fit", "tennis_ball", "--data", data, "--params", "E", "--analysis", "linear", "--out", str(out)])
    text = capsys.readouterr().out
    assert code == 0, text
    doc = json.loads((out / "fit.json").read_text())
    assert doc["converged"] is True and doc["units"]["E"] == "Pa" and doc["units"]["displacement"] == "m"
    assert doc["parameters"]["E"]["value"] == pytest.approx(1.5e6, rel=1e-4)
    assert doc["parameters"]["E"]["start"] == pytest.approx(1e6)
    assert np.allclose([r["residual_m"] for r in doc["rows"]], 0.0, atol=1e-4 * max(exact))
    assert doc["cost"]["forward_solves"] >= doc["cost"]["forward_evaluations"] >= 2
    assert (out / "data.csv").read_text() == (tmp_path / "data.csv").read_text()
    assert "E" in text and "MPa" in text and "RMS residual" in text
    print(f"\nend to end: {doc['cost']}")
