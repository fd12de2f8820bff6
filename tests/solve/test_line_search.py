"""The load path's line search (graspdef.solve.nonlinear.PathSolver.newton): a back-tracked Newton
step on its iterate's own tangent takes one more energy trial, at the minimum of the parabola
through the trials (``parabola_step``), and keeps it only where the energy is lower still.

The parabola is checked against exact parabolas (its minimum recovered to round-off from either
pair of data a back-tracking search has); on a path with fingertip contact the extra trial changes
how the equilibria are reached, not which: the same states at every load as without it.  The
patient descent past a limit point (``newton(patient=True)``) back-tracks by halving alone, as
before: with the parabola there, the paper duck at 0.5 N (point loads) lost the jump past its limit
point at load factor 0.712 and stopped there instead of at 0.846."""
import numpy as np
import pytest

from graspdef.contact.barrier import CONTACT_PATH, FingerContact, RoundedBox
from graspdef.geometry import icosphere
from graspdef.problem.problem import Problem
from graspdef.problem.supports import RigidModes
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell
from graspdef.solve import nonlinear as nl
from graspdef.solve.nonlinear import PathOptions, parabola_step, solve_nonlinear

E0, SLOPE, CURV = 2.0, -3.0, 4.0          # E(a) = E0 + SLOPE a + CURV a^2, least at a = 0.375


def _E(a):
    return E0 + SLOPE * a + CURV * a * a


@pytest.mark.parametrize("a", [0.25, 0.5])
def test_the_parabola_through_the_trials_has_the_exact_minimum(a):
    """On an exact parabola both models -- through E(0), E(a) and E(2a), and through E(0), E'(0) and
    E(a) (when E(2a) is not finite, e.g. a trial through a contact barrier) -- give its minimum,
    -SLOPE / (2 CURV) = 0.375, to round-off, whenever it lies in the bracket [a/2, 2a]."""
    assert parabola_step(E0, SLOPE, a, _E(a), _E(2 * a)) == pytest.approx(0.375, rel=1e-12)
    assert parabola_step(E0, SLOPE, a, _E(a)) == pytest.approx(0.375, rel=1e-12)
    assert parabola_step(E0, SLOPE, a, _E(a), np.inf) == pytest.approx(0.375, rel=1e-12)


def test_the_parabola_step_stays_in_the_bracket_and_is_skipped_where_it_gains_nothing():
    """Clamped to [a/2, 2a] (the model is only trusted between the trials); None within
    PARABOLA_MIN_MOVE a of a (no trial worth its evaluation) and for a parabola that is not convex
    (no minimum: the back-tracked step stands)."""
    a = 0.0625                                    # minimum 0.375 far beyond 2a
    assert parabola_step(E0, SLOPE, a, _E(a), _E(2 * a)) == 2 * a
    a = 1.0                                       # far below a/2
    assert parabola_step(E0, SLOPE, a, _E(a), _E(2 * a)) == 0.5 * a
    a = 0.36                                      # within 10 % of a
    assert abs(0.375 - a) <= nl.PARABOLA_MIN_MOVE * a
    assert parabola_step(E0, SLOPE, a, _E(a), _E(2 * a)) is None

    def concave(x):
        return E0 + SLOPE * x - CURV * x * x
    assert parabola_step(E0, SLOPE, 0.25, concave(0.25), concave(0.5)) is None
    assert parabola_step(E0, SLOPE, 0.25, concave(0.25)) is None


def _pads(F):
    """Two rigid pads squeezing a hollow sphere (R = 30 mm, t = 2 mm, E = 1 MPa, 162 control vertices) with F each."""
    R, T = 0.03, 0.002
    m = icosphere(radius=R, subdivisions=2)
    shell = Shell(m.vertices, m.faces, LinearElastic(1e6, 0.45), T)

    def pad(side):
        c = np.array([side * (R + T / 2 + 0.002), 0.0, 0.0])
        return RoundedBox(tuple(c), tuple(map(tuple, np.eye(3))), (0.002, 0.008, 0.008), 0.002)

    fingers = [FingerContact(pad(+1), (-1.0, 0, 0), F, offset=T / 2, name="right"),
               FingerContact(pad(-1), (1.0, 0, 0), F, offset=T / 2, name="left")]
    return Problem(shell, fingers, [RigidModes()])


def test_the_patient_descent_past_a_limit_point_back_tracks_by_halving_alone():
    """Newton from rest straight to the whole force of the pads' squeeze (``_pads``, 1 N each), the
    damped steps on fresh tangents of a descent: as an ordinary attempt it takes a trial at a
    parabola's minimum, as the patient descent past a limit point none; both reach the same
    equilibrium (to 1e-6 of the largest displacement: the Newton tolerance)."""
    pr = _pads(1.0)
    out = {}
    for patient in (False, True):
        solver = nl.PathSolver(pr, PathOptions(steps=4, **CONTACT_PATH))
        try:
            u = solver.newton(np.zeros(solver.eq.n), 1.0, patient=patient)[0]
        finally:
            solver.eq.close()
        out[patient] = (u, solver.n_parabola)
    assert out[False][1] >= 1 and out[True][1] == 0
    assert np.abs(out[False][0] - out[True][0]).max() <= 1e-6 * np.abs(out[True][0]).max()


def test_the_parabola_step_reaches_the_same_equilibria_on_a_contact_path(monkeypatch):
    """Two rigid pads squeeze a hollow sphere (R = 30 mm, t = 2 mm, E = 1 MPa, 162 control
    vertices) with 1 N each, on the contact paths' settings (barrier.CONTACT_PATH): the first steps'
    Newton iterations are damped (the patch grows into the barrier during each step).  With the
    parabola's trial (taken at least once) and without it (PARABOLA_MIN_MOVE = inf: never) the path
    points at 0.25, 0.5 and 1 of the force are the same equilibria, to the Newton tolerance (1e-8 of
    the force scale: the displacements to 1e-6 of the largest)."""
    def squeeze():
        return solve_nonlinear(_pads(1.0), PathOptions(steps=4, targets=(0.25, 0.5), **CONTACT_PATH))

    with_parabola = squeeze()
    monkeypatch.setattr(nl, "PARABOLA_MIN_MOVE", np.inf)
    without = squeeze()
    assert with_parabola.completed and without.completed
    assert with_parabola.n_parabola >= 1 and without.n_parabola == 0
    for lam in (0.25, 0.5, 1.0):
        a, b = with_parabola.at(lam).u, without.at(lam).u
        assert np.abs(a - b).max() <= 1e-6 * np.abs(b).max()
