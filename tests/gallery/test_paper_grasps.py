"""Gallery: the paper's grasps (Tian & Jia 2010 Table I, Figs. 13-15) through MuJoCo and the shell,
in fast mode.  The published values are not reproduced with the paper's E = 1 MPa (docs/grasp.md);
the assertions are analytic values where they exist, invariants of the chain, and mesh trends.
The duck tests are marked slow: building the duck's shell (decimated scan, mostly irregular faces,
exact Loop evaluation) and solving took 30-80 s per test on the shared machine, even on the coarse
control mesh."""
import pytest


def test_table1_grasps(run_fast):
    """Table I, first row, linear shell: the indentation per finger equals Reissner's point load
    on a sphere 0.375 F R / (E t^2) (nu = 1/2; BENCHMARKS.md 2.4; 20.55 mm) within 5 %, and each
    finger pushes with 10.63 N along its axis."""
    rec = run_fast("paper_table1_grasps")
    row = rec["rows"][0]
    assert row["force_N"] == 10.63 and row["measured_mm"] == 2.56
    assert abs(row["linear_mm"] / row["reissner_linear_mm"] - 1) < 0.05, row
    for v in row["linear_run"]["finger_axial_N"].values():
        assert abs(v - 10.63) < 1e-4


def test_fig13_tennis_ball(run_fast):
    """Fig. 13 (neo-Hookean, 80 kPa air, 162 control vertices): the two contact points move
    equally, rigid motion removed (5 %); the dimples dominate (far-field |u| below the
    indentation).  The indentation itself (19.57 mm at 642 vertices, measured 10.27 mm) is the
    paper's comparison, reported as a miss in the gallery; it is not asserted against our own
    earlier output."""
    k = run_fast("paper_fig13_tennis_ball")["key"]
    a = list(k["contact_displacement_mm"].values())
    assert len(a) == 2 and abs(a[0] / a[1] - 1) < 0.05, a
    assert k["completed"]
    assert k["far_field_max_displacement_mm"] < k["indentation_per_finger_mm"], k


def _chain_invariants(run: dict, force: float) -> None:
    for v in run["finger_axial_N"].values():
        assert abs(v - force) < 1e-4 * force, run["finger_axial_N"]
    assert run["force_defect_N"] < 1e-10 and run["moment_defect_Nm"] < 1e-10, run


@pytest.mark.slow
def test_fig14_duck(run_fast):
    """Fig. 14 (linear, coarse): each finger pushes with 19.22 N along its axis, the point loads
    keep the contacts' force and moment, and both contact points move inward."""
    rec = run_fast("paper_fig14_duck")
    _chain_invariants(rec["runs"]["linear"], 19.22)
    f = rec["key"]["fingers_shown_run"]
    assert set(f) == {"left", "right"} and all(v["along_normal_mm"] > 0 for v in f.values()), f


@pytest.mark.slow
def test_fig15_duck_head_poke(run_fast):
    """Fig. 15 (linear, coarse): the finger pushes with 18.33 N along its axis, the load keeps the
    contact's force and moment, and the contact point moves along the push."""
    rec = run_fast("paper_fig15_duck_head_poke")
    _chain_invariants(rec["runs"]["linear"], 18.33)
    f = rec["key"]["fingers_shown_run"]
    assert list(f) == ["right"] and f["right"]["along_normal_mm"] > 0, f
