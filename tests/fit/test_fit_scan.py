"""Fitting a parameter to a deformed scan (graspdef.fit.scan, issue 16 item 3), verified by
recovery: a scan made from a known parameter, moved to another frame and given noise, gives that
parameter back.  The forward model here is analytic (no shell solve): an ellipsoid of semi-axes
32.5 / 29.9 / 27.6 mm with a fixed 2 mm bump off its axes (no symmetry left, so the scan's pose
is defined) and two opposite Gaussian dents of depth c / E -- a stand-in with the ball's size whose depth falls as 1/E like a
linear shell's; the fit only sees surfaces, so it tests the scan machinery
(registration, the kept points, signed distances, the least squares) on its own."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from graspdef.errors import ProblemError
from graspdef.fit.scan import fit_scan, prepare_scan
from graspdef.geometry import TriMesh

R, W, C = 32.5e-3, 8e-3, 12e3          # radius [m], dent width [m], depth * E [m Pa] (4 mm at 3 MPa)
LOADS = np.array([[R, 0.0, 0.0], [-R, 0.0, 0.0]])
ROT = Rotation.from_rotvec(np.radians(25) * np.array([1, 2, 3]) / np.sqrt(14)).as_matrix()
BUMP = np.array([0.0, 0.6, 0.8]) * 28e-3    # a fixed bump near the surface, off every axis [m]
SHIFT = np.array([4e-3, -3e-3, 7e-3])       # the scanner's frame: ROT (about 25 deg) and SHIFT [m]


def _sphere():
    import trimesh

    s = trimesh.creation.icosphere(subdivisions=5, radius=R)
    return np.asarray(s.vertices) * np.array([1.0, 0.92, 0.85]), np.asarray(s.faces)


V0, F0 = _sphere()


def dented(theta: dict) -> TriMesh:
    """The sphere with dents of depth C / E at the two load points (radial, Gaussian in the
    distance from the load point)."""
    depth = C / theta["E"]
    n = V0 / np.linalg.norm(V0, axis=1, keepdims=True)
    s = np.min(np.linalg.norm(V0[:, None, :] - LOADS[None], axis=2), axis=1)
    bump = 2e-3 * np.exp(-(np.linalg.norm(V0 - BUMP, axis=1) / W) ** 2)
    return TriMesh(V0 + n * (bump - depth * np.exp(-(s / W) ** 2))[:, None], F0)


def _scan(E_true, sigma, seed=1):
    """Points sampled on the true surface, noise sigma [m], then moved by a rigid motion (the
    scanner's frame: ROT, SHIFT)."""
    from graspdef.registration.icp import sample_surface

    pts = sample_surface(dented({"E": E_true}), 20000, seed=seed)[0]
    rng = np.random.default_rng(seed)
    pts = pts + rng.normal(0.0, sigma, pts.shape)
    return pts @ ROT.T + SHIFT


def test_scan_fit_recovers_E_through_registration_and_noise():
    """E = 3 MPa, scan noise 0.05 mm, scan in another frame: fitted from 1 MPa (dents three times
    too deep at the start), E comes back within 2 % (the issue's criterion; here well inside),
    its standard error covers the truth, chi2/dof is about 1 (the noise is what is left), and the
    final registration undoes the scanner's motion to 0.05 mm and 0.05 deg (the first, against
    the start's too deep dents, is reported as the pose change between the passes)."""
    sigma = 5e-5
    res, sels = fit_scan(dented, _scan(3e6, sigma), LOADS, 10.0, {"E": 1e6}, near=15e-3, sigma=sigma)
    E = res.value("E")
    print(f"\nE = {E / 1e6:.5f} +- {res.std[0] / 1e6:.5f} MPa, chi2/dof {res.s2:.3f}, "
          f"{len(sels[-1].points)} points, pose change {res.model['pose_change_between_passes']}")
    assert res.converged
    assert E == pytest.approx(3e6, rel=0.02)
    assert abs(E - 3e6) < 4 * res.std[0]
    assert 0.7 < res.s2 < 1.4
    T = sels[-1].transform
    assert np.degrees(np.arccos(np.clip((np.trace(T[:3, :3] @ ROT) - 1) / 2, -1, 1))) < 0.05
    assert np.linalg.norm(T[:3, :3] @ SHIFT + T[:3, 3]) < 5e-5
    assert len(sels) == 2 and len(sels[-1].points) == 800


def test_scan_fit_aligned_on_an_undeformed_region():
    """The same recovery with the fine alignment on the band |x| < 12 mm only (the dents sit at
    x = +-32.5 mm and have faded to e^-(20/8)^2 = 0.2 % there; the bump keeps the pose defined),
    as ``graspdef fit --align-region``: E within 2 % and inside 4 standard errors, the pose undone to
    0.05 mm and 0.05 deg, and each pass's registration used only the region's points."""
    sigma = 5e-5
    res, sels = fit_scan(dented, _scan(3e6, sigma), LOADS, 10.0, {"E": 1e6}, near=15e-3, sigma=sigma,
                         region=lambda v: np.abs(v[:, 0]) < 12e-3)
    E = res.value("E")
    assert res.converged
    assert E == pytest.approx(3e6, rel=0.02)
    assert abs(E - 3e6) < 4 * res.std[0]
    T = sels[-1].transform
    assert np.degrees(np.arccos(np.clip((np.trace(T[:3, :3] @ ROT) - 1) / 2, -1, 1))) < 0.05
    assert np.linalg.norm(T[:3, :3] @ SHIFT + T[:3, 3]) < 5e-5
    for sel in sels:
        assert 0 < sel.registration["n_region_points"] < 0.6 * sel.n_scan


def test_bad_scan_inputs_are_one_line():
    """A scan of the wrong shape, a non-positive radius, a scan with no point near the loads."""
    with pytest.raises(ProblemError, match="shape"):
        prepare_scan(np.zeros((10, 2)), None, LOADS, near=1e-2)
    with pytest.raises(ProblemError, match="near"):
        prepare_scan(V0, None, LOADS, near=-1.0)
    with pytest.raises(ProblemError, match="nothing to fit"):
        prepare_scan(V0 + 1.0, None, LOADS, near=1e-2)
    from graspdef.registration.icp import RegistrationError

    with pytest.raises(RegistrationError, match="region"):          # a region with no face of the surface
        prepare_scan(V0, dented({"E": 3e6}), LOADS, near=1e-2, region=lambda v: v[:, 0] > 1.0)
