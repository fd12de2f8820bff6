"""The cross-validation script (scripts/gallery/paper_cross_validation.py, issue 16 item 4): its
fitting schemes checked against closed forms.  A linear shell's displacement is exactly
proportional to 1/E, y_i = c_i / E, so least squares on a subset S of rows has the closed form
1/E = sum_S c_i d_i / sum_S c_i^2 and each prediction is c_k / E."""
import numpy as np
import pytest

from graspdef.fit.table import MeasuredTable

MEASURED = np.array([2.56, 6.05, 9.12, 10.27]) * 1e-3      # Tian & Jia 2010, Table I [m]
FORCES = np.array([10.63, 16.50, 20.37, 21.48])


def _closed_form_E(c, d, rows):
    return float(np.sum(c[rows] ** 2) / np.sum(c[rows] * d[rows]))


def test_schemes_match_the_closed_form_of_a_linear_model():
    """A synthetic linear model (compliances c_i [m Pa]): every scheme's fitted E equals the closed
    form to 1e-6 and its predictions are c_k / E; leave-one-out leaves out exactly one row each."""
    import paper_cross_validation as X

    c = np.array([1.9, 3.0, 3.7, 3.9]) * 1e-3 * 1e6          # like the ball's linear shell at 1 MPa
    table = MeasuredTable(FORCES, MEASURED, ("max",) * 4)
    fw = X.Forward(FORCES, per_force=lambda th, f: c[list(FORCES).index(f)] / th["E"])
    sch = X.schemes(4)
    assert [s[0] for s in sch][:2] == ["all rows (fit)", "row 1 -> rows 2-4"]
    assert [s[2] for s in sch[2:]] == [[0], [1], [2], [3]]
    for label, train, test in sch:
        r = X.run_scheme(fw, table, train, test, {"E": 1e6}, {}, label)
        E = _closed_form_E(c, MEASURED, train)
        assert r["parameters"]["E"] == pytest.approx(E, rel=1e-6), label
        for row in r["rows"]:
            k = row["row"] - 1
            assert row["role"] == ("fitted" if k in train else "predicted")
            assert row["predicted_m"] == pytest.approx(c[k] / E, rel=1e-6)
            assert row["error_rel"] == pytest.approx(c[k] / E / MEASURED[k] - 1, rel=1e-5, abs=1e-9)
        assert sorted(x["row"] - 1 for x in r["rows"]) == sorted(train + test)


def test_one_row_fits_one_parameter_and_holds_the_rest():
    """With one fitted row a two-parameter model fits E alone and keeps the pressure at its start
    (one number cannot give two); a prediction whose forward solve fails is reported as failed,
    not dropped; the summary counts predictions within 15 %."""
    import paper_cross_validation as X
    from graspdef.errors import SolverError

    seen = []

    def per_force(th, f):
        seen.append(th["pressure"])
        if f > 21:
            raise SolverError("the load path stopped at 0.9")
        return 2.0e3 * f / th["E"] * (1 + 1e4 / th["pressure"])

    table = MeasuredTable(FORCES, MEASURED, ("max",) * 4)
    fw = X.Forward(FORCES, per_force=per_force)
    r = X.run_scheme(fw, table, [0], [1, 2, 3], {"E": 1e6, "pressure": 8e4}, {}, "row 1")
    assert list(r["parameters"]) == ["E"] and r["held_at_start"] == {"pressure": 8e4}
    assert set(seen) == {8e4}
    assert r["rows"][0]["predicted_m"] == pytest.approx(MEASURED[0], rel=1e-6)
    assert r["rows"][3]["predicted_m"] is None and "stopped" in r["rows"][3]["failure"]
    s = X.summary([r])
    assert s["predictions"] == 3 and s["failed"] == 1
    errs = [x["error_rel"] for x in r["rows"][1:3]]
    assert s["within_goal"] == sum(abs(e) <= 0.15 for e in errs)
    md = X.markdown({"cases": [{"case": "tennis ball, Table I", "measured_m": MEASURED.tolist(),
                                "force_N": FORCES.tolist(), "models": {"m": {"label": "synthetic", "schemes": [r],
                                                                              "summary": s, "seconds": 0.0}}}]})
    assert "path stopped" in md and "*2.56 (+0 %)*" in md


@pytest.mark.slow
def test_fast_mode_linear_ball_obeys_the_closed_form(tmp_path):
    """--fast (the ball's full linear shell through MuJoCo and the shell, about 5 min): each
    scheme's E is the closed-form least squares of the compliances c_i = y_i E read from the
    all-rows fit (the shell is linear, so y_i = c_i / E at every E), to 1e-4."""
    import paper_cross_validation as X

    rec = X.main(["--fast", "--out", str(tmp_path)])
    m = rec["cases"][0]["models"]["full-linear"]
    allrows = m["schemes"][0]
    c = np.array([r["predicted_m"] for r in allrows["rows"]]) * allrows["parameters"]["E"]
    for s in m["schemes"]:
        train = [k - 1 for k in s["fitted_rows"]]
        assert s["parameters"]["E"] == pytest.approx(_closed_form_E(c, MEASURED, train), rel=1e-4), s["scheme"]
    assert (tmp_path / "paper_cross_validation.md").read_text().count("|") > 20


def test_a_start_whose_path_stops_is_doubled_until_the_path_runs():
    """The duck's nonlinear fit starts from the linear fit's E; a load path that stops there (too
    soft: a limit point before the force) is no start, so E doubles until the path reaches the
    force; every stopped start is listed with its reason; when no start runs, the original is
    returned and all tries are listed."""
    import paper_cross_validation as X
    from graspdef.errors import SolverError

    def per_force(th, f):
        if th["E"] < 100e6:
            raise SolverError(f"the load path stopped at {th['E'] * 1e-8:.2f}")
        return f / th["E"]

    fw = X.Forward([19.22], per_force=per_force)
    start, stopped = X.running_start(fw, {"E": 30e6}, 19.22)
    assert start == {"E": 120e6}
    assert [t["E"] for t in stopped] == [30e6, 60e6] and "stopped" in stopped[0]["failure"]
    start, stopped = X.running_start(fw, {"E": 1e6}, 19.22, tries=3)
    assert start == {"E": 1e6} and [t["E"] for t in stopped] == [1e6, 2e6, 4e6, 8e6]
    assert X.running_start(fw, {"E": 2e8}, 19.22) == ({"E": 2e8}, [])
