"""Geometric fingertip contact (graspdef.contact.barrier): derivatives by finite differences,
then a sphere squeezed between two rigid fingertips.

FD checks (graspdef.testing.assert_fd_rate: the central-difference error must fall by 4 when
h halves) of the log barrier, the obstacles' distance functions and the force-controlled
contact potential, whose Hessian includes the rank-one part of the condensed finger advance."""
import numpy as np
import pytest

from graspdef.contact.barrier import Capsule, FingerContact, RoundedBox, log_barrier
from graspdef.errors import ProblemError
from graspdef.geometry import icosphere
from graspdef.problem.loads import PointLoad
from graspdef.problem.problem import Problem
from graspdef.problem.supports import RigidModes
from graspdef.shell.materials import LinearElastic
from graspdef.shell.model import Shell
from graspdef.solve.nonlinear import PathOptions, solve_nonlinear
from graspdef.testing import assert_fd_rate

R, T = 0.03, 0.002


@pytest.fixture(scope="module")
def shell():
    m = icosphere(radius=R, subdivisions=2)
    return Shell(m.vertices, m.faces, LinearElastic(1e6, 0.45), T)


def _pin(side=1.0, r=0.002):
    tip = np.array([side * (R + T / 2), 0.0, 0.0])
    return Capsule(tuple(tip + side * np.array([r + 0.006, 0, 0])), tuple(tip + side * np.array([r, 0, 0])), r)


def _pad(side=1.0, h=0.008, rounding=0.002):
    c = np.array([side * (R + T / 2 + 0.002), 0.0, 0.0])
    return RoundedBox(tuple(c), tuple(map(tuple, np.eye(3))), (0.002, h, h), rounding)


def test_log_barrier_derivatives():
    dh = 1e-3
    d = np.linspace(0.05, 0.95, 7) * dh
    b, b1, b2 = log_barrier(d, dh)
    h = 1e-2 * dh
    fd = lambda f, k, hh: (log_barrier(d + hh, dh)[k] - log_barrier(d - hh, dh)[k]) / (2 * hh)  # noqa: E731
    assert_fd_rate(b1, fd(None, 0, h), fd(None, 0, h / 2), what="b'")
    assert_fd_rate(b2, fd(None, 1, h), fd(None, 1, h / 2), what="b''")
    assert np.all(b > 0) and np.all(b1 < 0) and np.all(b2 > 0)
    z = log_barrier(np.array([dh, 2 * dh, 0.0, -1.0]), dh)
    assert np.all(z[0][:2] == 0) and np.all(z[1][:2] == 0) and np.all(np.isinf(z[0][2:]))


@pytest.mark.parametrize("obstacle", [_pin(), _pad(), RoundedBox((0.0, 0.01, 0.0), tuple(map(tuple, np.linalg.qr(
    np.random.default_rng(3).normal(size=(3, 3)))[0])), (0.003, 0.005, 0.007), 0.001)], ids=["capsule", "box", "tilted box"])
def test_obstacle_distance_derivatives(obstacle):
    rng = np.random.default_rng(1)
    p = np.asarray(obstacle.a if isinstance(obstacle, Capsule) else obstacle.center) + rng.normal(size=(40, 3)) * 0.008
    phi, n, H = obstacle.distance(p)
    # away from the seams where the Hessian jumps (cap/cylinder, box face/edge/corner regions)
    if isinstance(obstacle, Capsule):
        a, b = np.asarray(obstacle.a), np.asarray(obstacle.b)
        t = (p - a) @ (b - a) / ((b - a) @ (b - a))
        ok = np.minimum(np.abs(t), np.abs(t - 1)) * np.linalg.norm(b - a) > 1e-3
    else:
        loc = (p - np.asarray(obstacle.center)) @ np.asarray(obstacle.rotation)
        q = np.abs(loc) - (np.asarray(obstacle.half_extents) - obstacle.rounding)
        ok = np.abs(q).min(axis=1) > 1e-3
    p = p[(phi > 1e-3) & ok]
    assert len(p) > 5
    phi, n, H = obstacle.distance(p)
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0)
    for k in range(3):
        dk = np.zeros(3)
        dk[k] = 1.0

        def fd(h, f):
            return (f(p + h * dk) - f(p - h * dk)) / (2 * h)
        h = 1e-4
        assert_fd_rate(n[:, k], fd(h, lambda q: obstacle.distance(q)[0]), fd(h / 2, lambda q: obstacle.distance(q)[0]),
                       scale=1.0, what="grad phi")
        assert_fd_rate(H[:, :, k], fd(h, lambda q: obstacle.distance(q)[1]), fd(h / 2, lambda q: obstacle.distance(q)[1]),
                       scale=np.abs(H).max(), what="Hessian phi")
    # the compiled kernel along an axis (the condensed finger advance's derivatives), at points
    # shifted by s e: the same phi and normal as the numpy method, -n.e and e.H.e
    e = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    sh = 1.3e-3 * e
    phi, n, H = obstacle.distance(p - sh)
    phi_a, n_a, d1, d2 = obstacle.along(p, sh, e)
    assert np.allclose(phi_a, phi, rtol=0, atol=1e-15) and np.allclose(n_a, n, rtol=0, atol=1e-14)
    assert np.allclose(d1, -(n @ e), rtol=1e-14, atol=1e-15)
    assert np.allclose(d2, np.einsum("i,kij,j->k", e, H, e), rtol=1e-12, atol=1e-12 * np.abs(H).max())
    # the Hessian times e without the (k, 3, 3) array (the condensed advance's B_ss and B_xs)
    assert np.allclose(obstacle.hessian_along(p - sh, e), H @ e, rtol=1e-13, atol=1e-13 * np.abs(H).max())


@pytest.mark.parametrize("obstacle", [_pin(), _pad(), RoundedBox((0.0, 0.01, 0.0), tuple(map(tuple, np.linalg.qr(
    np.random.default_rng(3).normal(size=(3, 3)))[0])), (0.003, 0.005, 0.007), 0.001)], ids=["capsule", "box", "tilted box"])
def test_the_compiled_barrier_sums_equal_the_numpy_ones(obstacle):
    """The condensed advance's (B_s, B_ss, feasible, smallest gap) from the obstacle's compiled
    one-pass sums (``log_barrier_sums``) and from its ``along`` with the barrier summed in numpy
    (``ForceControlledAdvance.derivatives`` without ``sums``), at points spread through the
    barrier's reach: the same to round-off (their sums run in other orders); with a point through
    the obstacle both are infeasible (+inf), with none in reach both are zero."""
    from graspdef.contact.condensation import ForceControlledAdvance

    rng = np.random.default_rng(5)
    e = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    dh = 4e-4
    # points outside the surface, moved along their outward normals to gaps in (0.8, 3) dhat: a
    # shift of the obstacle by |s| <= 0.75 dhat changes a gap by |s| at most (phi is 1-Lipschitz)
    base = np.asarray(obstacle.a if isinstance(obstacle, Capsule) else obstacle.center) + rng.normal(size=(900, 3)) * 0.006
    phi, n = obstacle.distance(base, False)
    base, phi, n = base[phi > 1e-3], phi[phi > 1e-3], n[phi > 1e-3]
    p = base + n * (rng.uniform(0.8 * dh, 3 * dh, len(base)) - phi)[:, None]
    kw = rng.uniform(0.5, 2.0, len(p))
    numpy_way = ForceControlledAdvance(obstacle, e, dh, log_barrier, "numpy")
    compiled = ForceControlledAdvance(obstacle, e, dh, log_barrier, "compiled", sums=obstacle.log_barrier_sums)
    for s in (0.0, 0.75 * dh, -0.5 * dh):
        a, b = numpy_way.derivatives(p, kw, s), compiled.derivatives(p, kw, s)
        assert a[2] is b[2] is True and a[3] == b[3] > 0
        assert b[0] == pytest.approx(a[0], rel=1e-12) and b[1] == pytest.approx(a[1], rel=1e-12)
        assert a[0] != 0 and a[1] > 0                          # points in reach: a real sum
    inside = p.copy()
    inside[7] = base[7] - n[7] * (phi[7] + 1e-5)                 # one point 10 um through the surface
    a, b = numpy_way.derivatives(inside, kw, 0.0), compiled.derivatives(inside, kw, 0.0)
    assert a[:3] == b[:3] == (np.inf, 0.0, False) and a[3] == b[3] == pytest.approx(-1e-5, rel=1e-6)
    far = p + 2 * dh * n                                         # every gap beyond the reach
    a, b = numpy_way.derivatives(far, kw, 0.0), compiled.derivatives(far, kw, 0.0)
    assert a[:3] == b[:3] == (0.0, 0.0, True) and a[3] == b[3] > dh
    assert compiled.derivatives(p[:0], kw[:0], 0.0) == numpy_way.derivatives(p[:0], kw[:0], 0.0) == (0.0, 0.0, True, np.inf)


@pytest.mark.parametrize("obstacle", [_pin(), _pad()], ids=["pin", "pad"])
def test_contact_potential_derivatives(shell, obstacle):
    """Value -> gradient -> Hessian (sparse B_xx plus the rank-one -B_xs B_xs^T / B_ss of the
    eliminated finger advance) -> load (-d grad / d lam), all by central differences."""
    fc = FingerContact(obstacle, (-1.0, 0, 0), 4.0, offset=T / 2).build(shell, shell.evaluator)
    rng = np.random.default_rng(0)
    x = shell.rest_positions + rng.normal(size=shell.rest_positions.shape) * 2e-5
    lam = 0.7
    t = fc.evaluate(x, lam, 2)
    assert t.rank_one and t.rank_one[0][0] < 0
    dx = rng.normal(size=x.shape)
    dx /= np.abs(dx).max()
    h = 2e-6

    def val(y):
        return fc.evaluate(y, lam, 1).value

    def grad(y):
        return fc.evaluate(y, lam, 1).gradient
    fd = lambda f, hh: (f(x + hh * dx) - f(x - hh * dx)) / (2 * hh)  # noqa: E731
    assert_fd_rate(t.gradient @ dx.ravel(), fd(val, h), fd(val, h / 2), what="gradient")
    Hdx = t.hessian @ dx.ravel() + sum(c * v * (v @ dx.ravel()) for c, v in t.rank_one)
    assert_fd_rate(Hdx, fd(grad, h), fd(grad, h / 2), scale=np.abs(Hdx).max(), what="Hessian")
    fc.evaluate(x, lam, 2)
    q = fc.load(x)
    dl = 1e-3
    fdl = [-(fc.evaluate(x, lam + k, 1).gradient - fc.evaluate(x, lam - k, 1).gradient) / (2 * k) for k in (dl, dl / 2)]
    assert_fd_rate(q, fdl[0], fdl[1], scale=np.abs(q).max(), what="load")


@pytest.mark.parametrize("obstacle", [_pin(), _pad()], ids=["pin", "pad"])
def test_the_advance_window_leaves_out_only_inactive_samples(shell, obstacle):
    """The contact terms summed over the samples of the finger advance's final window equal those
    summed over all samples, to the bit: a sample outside the window had a gap >= dhat + W at its
    centre and |d gap / d s| <= 1, so it is beyond the barrier's reach at the solution (the
    window, not all samples, is what every evaluation after an advance measures)."""
    fc = FingerContact(obstacle, (-1.0, 0, 0), 4.0, offset=T / 2).build(shell, shell.evaluator)
    x = shell.rest_positions + np.random.default_rng(1).normal(size=shell.rest_positions.shape) * 2e-5
    s, value, grad, H, Bss, v = fc._terms(x, 2.8, 3)
    window = fc._cond.window
    assert window is not None and 0 < window[1].size < fc._kw.size          # it does leave samples out
    s_all, value_all, grad_all, H_all, Bss_all, v_all = fc._terms(x, 2.8, 3, s_at=s)   # every sample
    assert (s_all, value_all, Bss_all) == (s, value, Bss)
    assert np.array_equal(grad_all, grad) and np.array_equal(v_all, v)
    assert (H_all != H).nnz == 0 and np.array_equal(H_all.indices, H.indices)


@pytest.mark.parametrize("obstacle", [_pin(), _pad()], ids=["pin", "pad"])
def test_the_advance_balances_the_force_from_any_start(shell, obstacle):
    """The condensed finger advance s* solves dB/ds = F (graspdef.contact.condensation) to 1e-12 F
    with no sample through the fingertip, whatever the advance it starts from: its own solution
    (then it only checks it: one evaluation), a fingertip retracted far beyond the barrier's
    reach, one pushed deep into the shell (infeasible: it must retreat); every start gives the
    same root (dB/ds is increasing in s, so the root is unique)."""
    fc = FingerContact(obstacle, (-1.0, 0, 0), 4.0, offset=T / 2).build(shell, shell.evaluator)
    x = shell.rest_positions + np.random.default_rng(2).normal(size=shell.rest_positions.shape) * 2e-5
    adv, P, F = fc._cond, fc._ops.points(x), 2.8
    calls = []
    derivatives = adv.derivatives

    def counted(*a):
        calls.append(a[2])
        return derivatives(*a)
    adv.derivatives = counted
    s = fc.advance(x, F)
    roots = []
    for start in (s, s - 50 * adv._dh, s + 30 * adv._dh):
        adv.s = start
        calls.clear()
        roots.append(fc.advance(x, F))
        Bs, Bss, ok, dmin = derivatives(P, fc._kw, roots[-1])
        assert ok and dmin > 0 and Bss > 0
        assert abs(Bs - F) <= 1e-12 * F
        if start == s:
            assert calls == [s]
    assert np.ptp(roots) <= 1e-12 * adv._dh


def _squeeze(shell, contacts, loads, max_load=1.0, targets=()):
    pr = Problem(shell, list(contacts) + list(loads), [RigidModes()])
    return solve_nonlinear(pr, PathOptions(steps=4, max_load=max_load, targets=targets))


def test_pads_squeeze_force_matched_no_penetration_area_grows(shell):
    """Two rigid pads squeeze a hollow sphere (R = 30 mm, t = 2 mm, E = 1 MPa) with 0.5 N each:
    at every converged load the contact force along each finger's axis is the target (to the
    solver's tolerance), no sample -- nor a 3x finer check grid -- penetrates, and the contact
    area grows with the load (contact area: the sampled surface with gap < dhat, i.e. pressure > 0)."""
    F = 0.5
    fingers = [FingerContact(_pad(+1), (-1.0, 0, 0), F, offset=T / 2, name="right"),
               FingerContact(_pad(-1), (1.0, 0, 0), F, offset=T / 2, name="left")]
    sol = _squeeze(shell, fingers, [], targets=(0.25, 0.5))
    assert sol.completed
    areas = []
    for lam in (0.25, 0.5, 1.0):
        x = shell.rest_positions + sol.at(lam).u
        reps = [fc.build(shell, shell.evaluator).report(x, lam) for fc in fingers]
        for r in reps:
            assert r["contact_force_along_axis_N"] == pytest.approx(lam * F, rel=1e-9)
            assert r["min_gap_m"] > 0 and r["min_gap_fine_m"] > 0
            assert r["contact_area_m2"] > 0
        areas.append(reps[0]["contact_area_m2"])
    assert areas[0] < areas[1] < areas[2]
    assert all(p.instability == 0 for p in sol.path[1:])


@pytest.mark.slow
def test_small_pin_matches_point_loads_away_from_contact(shell):
    """Point-load limit (Saint-Venant's principle: statically equivalent loads give the same
    response away from where they act): a 0.1 mm pin (1.1 mm inflated by t/2) against two
    antipodal point loads of the same force, 0.05 N (small: linear range).  The approach of the
    poles agrees to 2 % (measured 0.7 %).  The approach of the rings at |x| = R/2 (mean axial
    displacement of the limit vertices with 0.4 R < |x| < 0.6 R, 40x smaller than the poles')
    differs by 11.5 % on this 162-vertex mesh (asserted: < 15 %): the pressure sits on the few
    samples nearest the pin, so the contact resultant carries ~5 % of lateral force, and the ring
    is only ~3 control edges from the load -- not a converged far-field comparison."""
    F = 0.05
    pin = [FingerContact(_pin(+1, 1e-4), (-1.0, 0, 0), F, offset=T / 2, dhat=2e-5),
           FingerContact(_pin(-1, 1e-4), (1.0, 0, 0), F, offset=T / 2, dhat=2e-5)]
    sol_c = _squeeze(shell, pin, [])
    pr = Problem(shell, [], [RigidModes()])
    loads = []
    for side in (1.0, -1.0):
        sp_ = pr.locate((side * R, 0, 0))
        loads.append(PointLoad(sp_.face, sp_.bary, (-side * F, 0.0, 0.0)))
    sol_p = _squeeze(shell, [], loads)
    L = sol_c.limit_map()
    X = L @ shell.mesh.vertices
    uc, up = L @ sol_c.u, L @ sol_p.u
    pos, neg = np.argmax(X[:, 0]), np.argmin(X[:, 0])
    assert uc[pos, 0] - uc[neg, 0] == pytest.approx(up[pos, 0] - up[neg, 0], rel=0.02)
    band = (np.abs(X[:, 0]) > 0.4 * R) & (np.abs(X[:, 0]) < 0.6 * R)
    ring = [band & (np.sign(X[:, 0]) == s) for s in (1, -1)]
    ac, ap = (u[ring[0], 0].mean() - u[ring[1], 0].mean() for u in (uc, up))
    assert ap < 0 and ac == pytest.approx(ap, rel=0.15)


def test_the_linear_predictor_reaches_the_same_equilibria(shell):
    """PathOptions(predictor="linear"), the finger-contact paths' setting (barrier.CONTACT_PATH):
    only the first iterate of each step changes, so every path point is the same equilibrium as
    with the default quadratic predictor -- the pads' squeeze above at 0.25, 0.5 and 1 of the force
    to the Newton tolerance (1e-8 of the force scale: the displacements to ~1e-7 of the largest)."""
    F = 0.5
    fingers = [FingerContact(_pad(+1), (-1.0, 0, 0), F, offset=T / 2, name="right"),
               FingerContact(_pad(-1), (1.0, 0, 0), F, offset=T / 2, name="left")]
    pr = Problem(shell, list(fingers), [RigidModes()])
    sols = [solve_nonlinear(pr, PathOptions(steps=4, targets=(0.25, 0.5), predictor=p)) for p in ("quadratic", "linear")]
    assert all(s.completed for s in sols)
    for lam in (0.25, 0.5, 1.0):
        a, b = (s.at(lam).u for s in sols)
        assert np.abs(a - b).max() <= 1e-6 * np.abs(a).max()
    with pytest.raises(ProblemError, match="predictor must be one of quadratic, linear, cubic"):
        PathOptions(predictor="quartic")


def test_sample_operator_gathers_and_scatters_like_the_stencils(shell):
    """SampleOperator (graspdef.contact.sampling): p = S x equals the stencil sum sum_s N x[st];
    the gradient it scatters is S^T g and its Hessian is the sum of (S_k (x) I3)^T H_k (S_k (x) I3)
    -- the same quadratic form g-dual: v.H.v = sum_k (S_k v)^T H_k (S_k v) for any v."""
    from graspdef.contact.sampling import SampleOperator, sample_faces

    st, N, w = sample_faces(shell, shell.evaluator, np.arange(0, 60, 3), 3)
    assert np.all(w > 0) and np.all(np.isfinite(N))
    ops = SampleOperator(st, N, shell.n_control)
    rng = np.random.default_rng(4)
    x = shell.rest_positions + rng.normal(size=shell.rest_positions.shape) * 1e-3
    ref = np.einsum("fqs,fsd->fqd", N, x[st]).reshape(-1, 3)
    assert np.allclose(ops.points(x), ref, rtol=0, atol=1e-15)
    rows = np.sort(rng.choice(len(ref), 40, replace=False))
    assert np.allclose(ops.points(x, rows), ref[rows], rtol=0, atol=1e-15)
    g = rng.normal(size=(40, 3))
    v = rng.normal(size=x.shape)
    Sv = ops.points(v, rows)
    assert np.isclose(ops.gradient(g, rows) @ v.ravel(), (g * Sv).sum(), rtol=1e-12)
    Hk = rng.normal(size=(40, 3, 3))
    Hk = Hk + Hk.transpose(0, 2, 1)
    H = ops.hessian(Hk, rows)
    assert H.shape == (3 * shell.n_control,) * 2 and abs(H - H.T).max() < 1e-12 * abs(H).max()
    assert np.isclose(v.ravel() @ (H @ v.ravel()), np.einsum("ki,kij,kj->", Sv, Hk, Sv), rtol=1e-12)


def test_sample_operator_on_the_shell_pattern_equals_the_general_one(shell):
    """With the shell's block pattern the Hessian is assembled on the pattern's own index arrays
    (so that it sums with the shell's Hessian entry by entry): the same matrix as the general
    sparse product (S3^T H S3) to round-off, every sample pair found in the pattern."""
    from graspdef.contact.sampling import SampleOperator, sample_faces
    from graspdef.solve.sparse import same_array

    st, N, _ = sample_faces(shell, shell.evaluator, np.arange(0, 60, 3), 3)
    pat = shell.block_pattern
    ops = SampleOperator(st, N, shell.n_control, pat)
    gen = SampleOperator(st, N, shell.n_control)
    assert ops._pattern is pat and gen._pattern is None
    rng = np.random.default_rng(5)
    rows = np.sort(rng.choice(ops.S.shape[0], 50, replace=False))
    Hk = rng.normal(size=(50, 3, 3))
    H = ops.hessian(Hk, rows)
    assert same_array(H.indices, pat.scalar_indices) and same_array(H.indptr, pat.scalar_indptr)
    D = (H - gen.hessian(Hk, rows)).toarray()
    assert abs(D).max() <= 1e-14 * abs(H).max()
    assert ops.hessian(Hk[:0], rows[:0]).nnz == pat.scalar_indices.size and not ops.hessian(Hk[:0], rows[:0]).data.any()
