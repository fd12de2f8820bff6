"""Gallery: the thesis's Figs. 10-13 (hemisphere) in fast mode."""


def test_thesis_fig10_13_hemisphere(run_fast):
    """Edge couples: limit load within 1 % of the thesis's 3.363 (reproduced).  Ring load (ring
    at 30 deg) and uniform load are not reproduced (0.958 and 0.0156 in the thesis; ours 1.19 and
    0.0211, converged to < 0.2 % under mesh and step refinement, docs/axisym.md): a miss, reported
    in the gallery, not asserted against our own earlier output.  Asserted: the paths reach a limit
    point, and Fig. 13's pre-limit state A lies below it."""
    rec = run_fast("thesis_fig10_13_hemisphere")
    lim = {k["quantity"]: k["graspdef"] for k in rec["key"]}
    assert abs(lim["edge couples, limit load"] / 3.363 - 1) < 0.01, lim
    assert lim["ring load at 30 deg, limit load"] > 0 and lim["uniform vertical load, limit load"] > 0, lim
    shapes = rec["curves"]["uniform"]["shapes"]
    assert 0 < shapes["A (pre-limit)"]["lam"] < lim["uniform vertical load, limit load"], shapes
