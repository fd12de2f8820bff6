"""The pure parts of three evidence scripts of issue 16 (scripts/ball_softening_study.py,
scripts/duck_poke_study.py, scripts/can_half_study.py), checked against closed forms and
invariants: Pogorelov-type data F = c sqrt(d) have local exponents 1/2 and a constant F/sqrt(d); the
air's force p (-dV/dd)/2 of a linear volume law is exact; a sweep of a homogeneous law d0(F) =
(F/k)^2 fitted by scaling gives E back; a rigid motion of a surface leaves no dent, a pure dent turns
no ring; the half can's quarter model equals the whole can."""
from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"


def _load(name):
    spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_pogorelov_data_have_exponent_one_half_and_scaling_recovers_E():
    B = _load("ball_softening_study")
    F = np.array([10.63, 16.50, 20.37, 21.48])
    d = (F / 6.7) ** 2 * 1e-3                       # F = 6.7 N/sqrt(mm) sqrt(d)
    m = B.measured_shape(F, d)
    assert np.allclose(m["local_exponents"], 0.5, atol=1e-12)
    assert np.allclose(m["F_over_sqrt_d_N_per_sqrt_mm"], 6.7) and m["spread_rel"] < 1e-12
    # a response homogeneous in E: d(F; E) = (F / (k E))^2, swept at E0, fitted by scaling
    E0, E, k = 7.5e6, 11e6, 6.7 / 9e6 / np.sqrt(1e-3)
    Fs = np.geomspace(1.0, 40.0, 40)
    E_fit, pred = B.fit_scaled(Fs, (Fs / (k * E0)) ** 2, E0, F, (F / (k * E)) ** 2)
    assert E_fit == pytest.approx(E, rel=1e-6) and np.allclose(pred, (F / (k * E)) ** 2, rtol=1e-6)


def test_air_force_of_a_linear_volume_law():
    """V = V0 - A d (per finger d), constant gauge pressure p: F_air = p A / 2 exactly."""
    B = _load("ball_softening_study")
    A, p, V0 = 3e-4, 8e3, 1.4e-4
    F = np.array([10.63, 14.0, 16.5, 20.37, 21.48])
    d = np.array([2.5, 4.0, 6.0, 9.3, 10.0]) * 1e-3
    pts = [{"force_N": f, "max_m": x, "finger_m": x, "volume_m3": V0 - A * x, "gauge_pressure_Pa": p}
           for f, x in zip(F, d)]
    air = B.air_share(pts, F[[0, 2, 3, 4]])
    assert np.allclose(air["air_force_N"], p * A / 2, rtol=1e-9)
    assert np.allclose(air["rows"]["air_force_N"], p * A / 2)
    # the wall's secants are the whole ball's less nothing (a constant air force has no stiffness) ...
    assert np.allclose(air["rows"]["wall_secant_N_per_mm"][1:], air["rows"]["secant_N_per_mm"][1:])


def test_rigid_motion_leaves_no_dent_and_a_dent_turns_no_ring():
    from scipy.spatial.transform import Rotation

    P = _load("duck_poke_study")
    rng = np.random.default_rng(0)
    X = rng.normal(size=(2000, 3)) * 0.03
    p = X[0]
    push = np.array([1.0, 0.0, 0.0])
    R = Rotation.from_rotvec([0.1, -0.2, 0.15]).as_matrix()
    Y = X @ R.T + np.array([0.004, -0.001, 0.002])
    s = P.split(X, Y, p, push, 0.01, 0.02)
    assert abs(s["dent_along_push_m"]) < 1e-12 and s["ring_misfit_rms_m"] < 1e-12
    assert s["ring_rotation_deg"] == pytest.approx(np.degrees(np.linalg.norm([0.1, -0.2, 0.15])), rel=1e-9)
    dist = np.linalg.norm(X - p, axis=1)
    Y = X + np.outer(np.where(dist < 0.01, 0.003 * (1 - dist / 0.01), 0.0), push)
    s = P.split(X, Y, p, push, 0.01, 0.02)
    assert s["ring_rotation_deg"] < 1e-9 and s["dent_along_push_m"] == pytest.approx(0.003, rel=1e-9)


def test_half_can_quarter_model_equals_the_whole_can():
    """Symmetry invariant of scripts/can_half_study.py's model: its quarter half-can (symmetry planes
    y = 0 and x = 0, F/2 at the load point on y = 0) gives the load point's displacement of the whole
    can of scenes/soda_can/half_can_pinched.toml (no symmetry planes) at the same cell size (32 x 48 cells
    of the quarter, 128 x 48 of the whole), linear: they differ only by the discretisation next to the
    symmetry planes (measured 0.2 %); a quarter loaded or supported wrongly would be off by 2x or more."""
    from graspdef.problem.config import load_problem
    from graspdef.solve.linear import solve_linear

    H = _load("can_half_study")
    root = SCRIPTS.parent

    q = H.build(32, 48)
    d_quarter = -solve_linear(q).probe("A")[0] * H.F_PAPER              # load factor 1 = 1 N per finger
    spec = load_problem(root / "scenes" / "soda_can" / "half_can_pinched.toml")
    d_whole = -solve_linear(spec.problem).probe("A")[0]                  # the file's loads: 0.76 N per finger
    assert d_quarter == pytest.approx(d_whole, rel=0.01)
