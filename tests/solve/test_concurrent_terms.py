"""The shell's elastic term evaluated in a thread beside the other terms (graspdef.solve.equilibrium,
``Equilibrium.concurrent``; graspdef.compiled: the ahead-of-time kernels release the GIL).

Invariants: the sum of the terms -- energy, gradient, load, Hessian and rank-one parts -- and a
whole contact path are the same to the bit with and without the thread; an error in either thread
reaches the caller with no thread left running; the thread is used only where every kernel of the
shell's evaluation runs serially ahead of time (never beside numba's parallel build)."""
from __future__ import annotations

import threading
from pathlib import Path

import numpy as np
import pytest

from graspdef import compiled
from graspdef.contact.barrier import CONTACT_PATH, FingerContact, RoundedBox
from graspdef.contact.friction import FingerFriction
from graspdef.geometry import icosphere
from graspdef.problem.potentials import EnclosedGas
from graspdef.problem.problem import Problem
from graspdef.problem.supports import RigidModes
from graspdef.problem.terms import ShellElastic
from graspdef.shell.hyperelastic import NeoHookean
from graspdef.shell.model import Shell
from graspdef.solve import equilibrium
from graspdef.solve.equilibrium import Equilibrium
from graspdef.solve.nonlinear import PathOptions, PathSolver

R, T, F = 0.03, 0.002, 1.0

def _pad(side):
    c = np.array([side * (R + T / 2 + 0.002), 0.0, 0.0])
    return RoundedBox(tuple(c), tuple(map(tuple, np.eye(3))), (0.002, 0.008, 0.008), 0.002)


@pytest.fixture(scope="module")
def ball():
    """642 control vertices: a neo-Hookean sphere with air, squeezed by two pads with friction."""
    m = icosphere(radius=R, subdivisions=3)
    sh = Shell(m.vertices, m.faces, NeoHookean(1e6 / 3), T)
    fingers = [FingerContact(_pad(+1), (-1.0, 0, 0), F, offset=T / 2, name="right"),
               FingerContact(_pad(-1), (1.0, 0, 0), F, offset=T / 2, name="left")]
    return Problem(sh, [EnclosedGas(2e4)] + fingers + [FingerFriction(f, 0.5) for f in fingers], [RigidModes()])


def _path(problem, concurrent: bool):
    ps = PathSolver(problem, PathOptions(steps=2, **CONTACT_PATH))
    if not concurrent:
        ps.eq.concurrent = None
    try:
        return ps.eq.concurrent, ps.run()
    finally:
        ps.eq.close()


def test_the_ahead_of_time_module_releases_the_gil():
    """The module's wrappers call PyEval_SaveThread (numba's GIL manager around each kernel): the
    name is among its dynamic symbols only when some export releases the GIL."""
    mod = compiled._aot_module()
    assert mod is not None, compiled.aot_status()
    assert b"PyEval_SaveThread" in Path(mod.__file__).read_bytes()


def test_the_shell_term_is_the_concurrent_one_and_the_sums_are_the_same_to_the_bit(ball):
    eq = Equilibrium(ball)
    assert eq.concurrent == 0 and isinstance(eq.terms[0], ShellElastic)
    rng = np.random.default_rng(7)
    u = 2e-4 * rng.standard_normal(eq.n)
    for order in (0, 1, 2):
        eq.concurrent = 0
        a = eq.evaluate(u, 1.0, order)
        eq.concurrent = None
        b = eq.evaluate(u, 1.0, order)
        assert a.energy == b.energy and np.isfinite(a.energy)
        if order >= 1:
            assert np.array_equal(a.gradient, b.gradient) and np.array_equal(a.load, b.load)
        if order == 2:
            assert (a.hessian != b.hessian).nnz == 0 and np.array_equal(a.hessian.indices, b.hessian.indices)
            assert len(a.rank_one) == len(b.rank_one) == 3          # the gas and the two condensed advances
            for (ca, va), (cb, vb) in zip(a.rank_one, b.rank_one):
                assert ca == cb and np.array_equal(va, vb)
    eq.close()


def test_a_contact_path_is_the_same_to_the_bit_with_the_thread(ball):
    """The pads' path (2 load steps, damped Newton steps, line searches, factorisations): every
    converged state and the counts are identical."""
    c1, a = _path(ball, True)
    c0, b = _path(ball, False)
    assert (c1, c0) == (0, None)
    assert a.completed and b.completed
    assert a.n_factorisations == b.n_factorisations and a.iterations() == b.iterations()
    assert len(a.path) == len(b.path) == 3
    for p, q in zip(a.path, b.path):
        assert p.load_factor == q.load_factor and np.array_equal(p.u, q.u)
    assert np.abs(a.path[-1].u).max() > 1e-3              # a real squeeze: the pads moved the shell by mm


def _no_term_thread_alive():
    return not any(t.name == "graspdef-term" and t.is_alive() for t in threading.enumerate())


def test_an_error_in_either_thread_reaches_the_caller_and_no_thread_is_left(ball, monkeypatch):
    eq = Equilibrium(ball)
    u = np.zeros(eq.n)

    def boom(*a, **k):
        raise ValueError("the shell's evaluation failed")

    monkeypatch.setattr(eq.terms[0], "evaluate", boom)
    with pytest.raises(ValueError, match="shell's evaluation failed"):
        eq.evaluate(u, 1.0, 2)
    assert _no_term_thread_alive()
    monkeypatch.undo()
    done = threading.Event()
    shell_evaluate = eq.terms[0].evaluate

    def slow_shell(*a, **k):
        v = shell_evaluate(*a, **k)
        done.set()
        return v

    monkeypatch.setattr(eq.terms[0], "evaluate", slow_shell)
    monkeypatch.setattr(eq.terms[1], "evaluate", lambda *a, **k: (_ for _ in ()).throw(KeyError("gas")))
    with pytest.raises(KeyError, match="gas"):
        eq.evaluate(u, 1.0, 2)
    assert done.is_set() and _no_term_thread_alive()           # joined before the error left evaluate
    eq.close()


def test_no_thread_for_a_small_shell_nor_beside_numbas_parallel_build(ball, monkeypatch):
    m = icosphere(radius=R, subdivisions=2)                    # 162 control vertices
    small = Problem(Shell(m.vertices, m.faces, NeoHookean(1e6 / 3), T), [EnclosedGas(2e4)], [RigidModes()])
    assert small.shell.n_control < equilibrium.CONCURRENT_MIN_VERTICES
    assert Equilibrium(small).concurrent is None
    # every parallel kernel to numba's JIT (as for a shell past SERIAL_MAX faces): no thread
    monkeypatch.setattr(compiled, "SERIAL_MAX", 0)
    assert not ShellElastic(ball.shell).concurrent()
    assert Equilibrium(ball).concurrent is None
