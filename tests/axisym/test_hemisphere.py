"""The thesis's hemisphere examples (Chapter 4): R0/t0 = 10, Mooney-Rivlin gamma = 0.1, unrestrained edge.

Nondimensional as in the thesis (2.81): lengths / t0, C1 = 1, nodal loads per radian of circumference, distributed
loads / C1.  Thesis limit loads: edge couples 3.363, ring load 0.958, uniform vertical load 0.0156.

What we reproduce (docs/axisym.md): our limit loads are converged under mesh/step refinement to < 0.2 %.  Edge
couples (turning the edge inward): 3.372 (default) / 3.378 (refined) vs the thesis's 3.363, +0.3 / +0.4 %.
Uniform load (per unit deformed area): 0.02107 vs 0.0156 (+35 %) and ring load at 30 deg (position not given in
the thesis's text): 1.189 vs 0.958 (+24 %) are not reproduced; there the tests assert our converged values and the
behaviour, not the thesis's numbers.
"""
import numpy as np
import pytest

from graspdef.axisym.bench import hemisphere_path
from graspdef.axisym.material import AxisymMaterial

#: converged values measured with max_piece = 0.3, rk_steps = 2 (4x finer than the default)
EDGE_FINE = 3.3776
EDGE_OUT_FINE = 3.5308
UNIFORM_FINE = 0.021074
RING30_FINE = 1.1888


def test_edge_couple_limit_load_matches_thesis():
    """Edge couples turning the edge inward: smooth limit point at 3.372 (thesis 3.363, +0.26 %; refined 3.378,
    +0.43 %), stable (no negative eigenvalue) before it and one negative eigenvalue after it.  The path ends soon
    after the limit, at an edge rotation of 2.2 rad (thesis: 3.097), where the constitutive relations stop being
    invertible in the strongly bent edge zone (thesis Ch. 5)."""
    m, p = hemisphere_path("edge_couple")
    lim = p.limits[0]["lam"]
    assert lim == pytest.approx(3.363, rel=5e-3)
    assert lim == pytest.approx(EDGE_FINE, rel=3e-3)
    k = int(np.argmax(p.lam))
    assert all(q.n_negative == 0 for q in p.points[:k]) and p.points[-1].n_negative == 1
    rot = max(abs(q.nodes[1, 2] - m.nodes[1].phi) for q in p.points)
    assert 2.0 < rot < 2.5


@pytest.mark.slow
def test_outward_edge_couple_turning_point_is_the_section_moment_capacity():
    """Edge couples turning the edge outward: the load rises to 3.537 where the constitutive relations stop being
    invertible at the loaded edge: det [[phi_ll, phi_lc], [phi_lc, phi_cc]] -> 0 (the thesis's matrix 5.1, Ch. 5),
    i.e. the truncated energy's bending moment at zero membrane force has a maximum.  The path ends there (edge
    rotation about 1.9 rad)."""
    m, p = hemisphere_path("edge_couple", edge_sense=1.0)
    lim = p.limits[0]["lam"] if p.limits else max(p.lam)
    assert lim == pytest.approx(EDGE_OUT_FINE, rel=3e-3)
    assert "constitutive relations could not be inverted" in p.stopped_by
    edge = p.points[-1].nodes[1]
    rot = edge[2] - m.nodes[1].phi
    assert 1.7 < rot < 2.1 and edge[0] > 11.5  # the edge flares out (hoop stretch ~1.19) while turning
    # the edge's section is at the moment capacity: at the final state n_xi0 = 0 and dm/dc -> 0
    mat = AxisymMaterial("mooney_rivlin", 1.0, 0.1)
    l2, c2 = edge[0] / 10.0, np.sin(edge[2]) / 10.0
    m_edge = p.points[-1].lam / 10.0
    cs = np.linspace(0.0, 2.0, 401)
    mm = []
    for c in cs:  # moment at zero membrane force as a function of the curvature
        l1 = 1.0
        for _ in range(30):
            _, g, H = mat.shell_energy(l1, l2, c, c2, -0.1, -0.1)
            l1 -= g[0] / H[0, 0]
        mm.append(mat.shell_energy(l1, l2, c, c2, -0.1, -0.1)[1][2])
    assert max(mm) == pytest.approx(m_edge, rel=1e-2)


def test_uniform_vertical_load_limit_point():
    """Uniform vertical load per unit deformed area: sharp turning point at 0.02107 (thesis 0.0156), the path
    continues through it and unloads (apex deflection grows while the load falls); the stiffness has one negative
    eigenvalue past the limit point (Thompson's primary critical state)."""
    m, p = hemisphere_path("uniform")
    assert len(p.limits) >= 1
    lim = p.limits[0]["lam"]
    assert lim == pytest.approx(UNIFORM_FINE, rel=2e-3)
    k = int(np.argmax(p.lam))
    assert all(q.n_negative == 0 for q in p.points[:k])
    assert p.points[-1].n_negative >= 1
    apex = [10.0 - q.nodes[0, 1] for q in p.points]
    assert apex[-1] > apex[k] > 0
    assert p.points[-1].lam < 0.5 * lim + 1e-12


@pytest.mark.slow
def test_ring_load_limit_point():
    """Ring load at 30 deg from the apex: limit 1.189 (thesis 0.958 for a ring "as shown" in a figure the text
    lacks; our sweep puts 0.958 at about 27 deg, docs/axisym.md)."""
    m, p = hemisphere_path("ring")
    assert p.limits[0]["lam"] == pytest.approx(RING30_FINE, rel=3e-3)


@pytest.mark.slow
@pytest.mark.parametrize("case,fine", [("edge_couple", EDGE_FINE), ("uniform", UNIFORM_FINE)])
def test_limit_loads_converge_under_refinement(case, fine):
    """Halving the shooting pieces and doubling the RK4 steps moves the limit load by < 0.2 %."""
    _, p = hemisphere_path(case, max_piece=0.3, rk_steps=2)
    lim = p.limits[0]["lam"] if p.limits else max(p.lam)
    assert lim == pytest.approx(fine, rel=5e-4)
