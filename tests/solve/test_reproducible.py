"""PARDISO's factorisation is reproducible to the bit (iparm 34, conditional numerical
reproducibility, with the sequential METIS ordering it requires; graspdef.solve.sparse._cnr_threads).

Without it the parallel factorisation of one matrix differs in its last bits from call to call: on
2 cores the 10k ball's tangent (30,732 unknowns) factorised 6 times gave two different factors at
random, in single and double precision, and a path through snaps (the 192 x 96 pinched cylinder)
took 230 and 519 factorisations in two runs of the same code.  Smaller systems (7,686 unknowns)
were reproducible either way, so the check needs the 10k ball.
"""
import hashlib

import numpy as np
import pytest
import scipy.sparse as sp

from graspdef.solve import sparse as S
from graspdef.solve.equilibrium import Equilibrium

from test_inexact_newton import _ball       # the bench's air-filled neo-Hookean ball pinched at its poles

pytestmark = pytest.mark.skipif(not S.pardiso_available(), reason="PARDISO (pypardiso) not installed")


def test_the_settings_ask_for_reproducible_factors():
    """The ordering is the sequential METIS one (the parallel one rules the reproducible mode out),
    and a solver is created with iparm 34 = MKL's thread count (at least 1)."""
    assert S._PARDISO_IPARM[2] == 2 and all(v.get(2, 2) != 3 for v in S._PARDISO_FALLBACKS)
    with S.KKTSystem(sp.eye(1, 3, format="csr"), "pardiso") as kkt:
        kkt.factor(sp.eye(3, format="csr"))
        assert kkt._solver.get_iparm(34) >= 1


@pytest.mark.parametrize("precision", ["mixed", "double"])
def test_a_tangent_factorised_again_gives_the_same_bits(precision):
    """The 10k ball's tangent (30,732 unknowns; its six rigid-mode rows and the gas's rank-one part)
    factorised 8 times -- repeatedly on one PARDISO handle and on fresh handles -- and solved for one
    right-hand side: one raw back-substitution and the refined solve give the same bits every time.
    (With the parallel factorisation of 1b24a65 the chance that 8 factors agree was about 1 %.)"""
    pr = _ball(5, 20.0)
    eq = Equilibrium(pr, precision=precision)
    try:
        st = eq.evaluate(np.zeros(eq.n), 0.5, 2)
        f = np.concatenate([-st.gradient, np.zeros(eq.kkt.m)])
        raw, refined = set(), set()
        for k in range(8):
            if k % 4 == 0:
                eq.kkt.close()                     # a fresh handle: a new analysis as well
            eq.factor(st, inertia=False)
            raw.add(hashlib.sha256(eq.kkt._back(f).tobytes()).hexdigest())
            refined.add(hashlib.sha256(eq.solve(-st.gradient).tobytes()).hexdigest())
        assert len(raw) == 1 and len(refined) == 1
        assert eq.kkt.single == (precision == "mixed")
    finally:
        eq.close()
