"""The paper's patch model (graspdef.pipeline.patch, graspdef.geometry.cut; docs/grasp.md "The
paper's patch model"): the clamped border, the clamped-plate closed form, convergence in the
patch size on the tennis ball, exact 1/E scaling, the bad inputs."""
from __future__ import annotations

import numpy as np
import pytest

from graspdef.errors import ProblemError
from graspdef.geometry import cylinder, icosphere, rectangle
from graspdef.geometry.cut import cut_patch
from graspdef.pipeline.patch import (PATCH_SIZE, border_values, build_patch, patch_measures, refined_control_mesh,
                                     solve_patch)
from graspdef.shell.materials import LinearElastic

A, T, P = 0.045, 0.0025, 1.0


def plate_patch(n: int, E: float = 1e6, nu: float = 0.5):
    """A 45 mm patch cut from the middle of a flat 90 mm plate of 2n x 2n cells (n x n in the patch),
    loaded by 1 N at its centre."""
    m = rectangle(2 * A, 2 * A, 2 * n, 2 * n)
    return build_patch(m.vertices, m.faces, LinearElastic(E, nu), T, (0.0, 0.0, 0.0), P, A, "centre",
                       normal=(0, 0, 1), axis=(1, 0, 0))


@pytest.fixture(scope="module")
def plates():
    out = {}
    for n in (16, 32):
        pp = plate_patch(n)
        us, sol = solve_patch(pp, "linear")
        out[n] = (pp, us[P], sol)
    return out


def test_cut_is_the_square(plates):
    """The cut of a flat plate is exactly the 45 mm square around the point (all of it: n x n cells,
    2 n^2 faces), its one boundary loop on the square's sides."""
    pp, _, _ = plates[16]
    assert len(pp.patch.faces) == 2 * 16 ** 2
    b = pp.patch.vertices[pp.patch.boundary]
    assert np.allclose(np.abs(b[:, :2]).max(axis=1), A / 2, atol=1e-12)


def test_clamped_border_holds(plates):
    """The border is clamped: the displacement at the support's collocation points (two Gauss points
    per boundary edge, Lagrange multipliers) is zero to solver precision; along the whole limit curve
    (4 points per edge) it is below 2e-4 of the maximum and falls with refinement (measured: 1.1e-4 at
    16 x 16 cells, 3.0e-6 at 32 x 32 -- 2.3e-5 before the nearly dependent rows of the closed border
    were dropped instead of re-based: the support's collocation, graspdef.problem.supports); the
    rotation about the border (Nitsche's method: weak, not exact) is below 2.5 % of the mean slope
    w_max / (a/2) and falls with refinement (measured: 0.0059 rad at 16 x 16 cells, 0.00021 rad at
    32 x 32 -- 0.0033 before --, against a mean slope of 0.29 rad)."""
    rot = {}
    for n, (pp, u, sol) in plates.items():
        C, _ = pp.problem.constraints()
        w = patch_measures(pp, u, border=False)["max_displacement_m"]
        assert np.abs(C @ u.ravel()).max() < 1e-10 * w
        bv = border_values(pp, u)
        assert bv["max_displacement_m"] < 2e-4 * w
        slope = w / (A / 2)
        assert bv["max_rotation_rad"] < 0.025 * slope
        rot[n] = bv["max_rotation_rad"]
    assert rot[32] < rot[16]


def test_plate_matches_timoshenko(plates):
    """A flat 45 mm patch under a central point load is the clamped square plate: w = 0.00560 P a^2 / D,
    D = E t^3 / 12 (1 - nu^2) (Timoshenko & Woinowsky-Krieger; benchmarks/plate_clamped_point.toml).
    Measured: -0.44 % at 16 x 16 cells, +0.13 % at 32 x 32 (0.005607 P a^2 / D, inside the Ritz
    estimate 0.00561 +- 0.00002 of BENCHMARKS.md 2.1; -0.03 % before the closed border's nearly
    dependent support rows were dropped instead of re-based); asserted within 1 % and 0.2 %."""
    E, nu = 1e6, 0.5
    D = E * T ** 3 / (12 * (1 - nu ** 2))
    ref = 0.00560 * P * A ** 2 / D
    for n, tol in ((16, 0.01), (32, 0.002)):
        pp, u, _ = plates[n]
        w = patch_measures(pp, u, border=False)["displacement_along_push_m"]
        assert w == pytest.approx(ref, rel=tol)
        assert patch_measures(pp, u, border=False)["max_displacement_m"] == pytest.approx(w, rel=1e-9)


def test_linear_scales_inverse_E():
    """The linear patch's response is exactly proportional to 1/E (E x 3.7: displacements / 3.7 to
    round-off)."""
    pp1, pp2 = plate_patch(8, 1e6), plate_patch(8, 3.7e6)
    u1, u2 = solve_patch(pp1, "linear")[0][P], solve_patch(pp2, "linear")[0][P]
    assert np.allclose(u2 * 3.7, u1, rtol=0, atol=1e-12 * np.abs(u1).max())


@pytest.fixture(scope="module")
def ball():
    from graspdef.pipeline.grasp import prepare_object

    obj = prepare_object("tennis_ball", "linear", gas=False)
    x = obj.shell.rest_positions[: obj.shell.mesh.n_real]
    c = x.mean(axis=0)
    return obj, x[np.argmax(x[:, 0] - c[0])]       # a point on the ball's +x side (any: it is nearly a sphere)


def test_patch_converges_with_size(ball):
    """The tennis ball's linear patch (E = 1 MPa, nu = 0.5, 1 N, 1 refinement: 490 control vertices at
    45 mm) as the patch grows 45 -> 52 -> 60 mm: the max displacement grows and converges to Reissner's
    shallow-shell point-load value w = sqrt(3 (1 - nu^2)) P R / (4 E t^2) of the whole sphere (1.94 mm/N
    at R = 32.3 mm, the mid-surface's mean radius). Measured: 1.583, 1.777, 1.919 mm/N; the 45 mm patch
    is 17.5 % stiffer than the 60 mm one (level 2: 15.9 %), so for the LINEAR shell the paper's 45 mm is
    not large enough: the clamp sits about three of Reissner's decay lengths sqrt(R t) / (3 (1 - nu^2))^(1/4)
    = 7.4 mm from the load. Asserted: growth, shrinking increments per mm, the 60 mm patch within 3 % of
    Reissner, the 45 -> 60 mm change between 10 % and 25 % (what was measured, not a design bound)."""
    obj, c = ball
    xc, fc = refined_control_mesh(obj.shell, 1)
    x = obj.shell.rest_positions[: obj.shell.mesh.n_real]
    R = float(np.linalg.norm(x - x.mean(axis=0), axis=1).mean())
    t, nu = obj.spec.thickness, 0.5
    reissner = np.sqrt(3 * (1 - nu ** 2)) * R / (4 * 1e6 * t ** 2)
    sizes = (0.045, 0.052, 0.060)
    w = []
    for size in sizes:
        pp = build_patch(xc, fc, LinearElastic(1e6, nu), t, c, 1.0, size, "x", 1)
        w.append(patch_measures(pp, solve_patch(pp, "linear")[0][1.0], border=False)["max_displacement_m"])
    w = np.array(w)
    print(f"max displacement per newton {np.round(w * 1e3, 4)} mm/N at {sizes} m; Reissner {reissner * 1e3:.4f} mm/N")
    slope = np.diff(w) / np.diff(sizes)
    assert np.all(slope > 0) and slope[1] < slope[0]
    assert w[-1] == pytest.approx(reissner, rel=0.03)
    assert 0.10 < (w[-1] - w[0]) / w[-1] < 0.25


def test_bad_patches(ball):
    """Bad inputs are one-line ProblemErrors: a non-positive or non-finite size; a patch wider than the
    object; a cut that covers the whole closed surface; a cut that is not a disc (an annulus of a
    cylinder); a contact off the surface."""
    from graspdef.pipeline.patch import check_object_size

    obj, c = ball
    xc, fc = refined_control_mesh(obj.shell, 0)
    for bad in (0.0, -0.01, float("nan"), "x"):
        with pytest.raises(ProblemError, match="patch size"):
            build_patch(xc, fc, LinearElastic(1e6, 0.5), T, c, 1.0, bad)
    with pytest.raises(ProblemError, match="larger than the object"):
        check_object_size(obj.shell, 0.2)
    s = icosphere(0.03, 2)
    with pytest.raises(ProblemError, match="larger than the object"):
        cut_patch(s.vertices, s.faces, s.vertices[0], 0.5)
    cyl = cylinder(0.01, 0.2, 24, 20)
    with pytest.raises(ProblemError, match="not a disc-like"):
        cut_patch(cyl.vertices, cyl.faces, cyl.vertices[len(cyl.vertices) // 2], 0.05)
    d = (c - xc.mean(axis=0)) / np.linalg.norm(c - xc.mean(axis=0))
    with pytest.raises(ProblemError, match="off the surface"):
        build_patch(xc, fc, LinearElastic(1e6, 0.5), T, c + 0.02 * d, 1.0, PATCH_SIZE)


def test_run_grasp_patch_record(tmp_path):
    """``run_grasp(model="patch")`` end to end (linear, tennis ball, 21.48 N, the default 45 mm): the
    run folder's record states ``model: patch`` and ``patch_size_m``, holds each finger's patch with its
    max displacement, and ``derived.max_displacement`` is the larger finger's; the record's border
    values show the clamp (|u| below 1e-3 of the maximum)."""
    from graspdef.pipeline.grasp import run_grasp
    from graspdef.runs import read_run

    run = run_grasp("tennis_ball", 21.48, analysis="linear", out=tmp_path / "run", model="patch")
    r = read_run(run.out).record
    assert r["model"] == "patch" and r["patch_size_m"] == PATCH_SIZE
    assert r["material"]["nu"] == 0.5 and r["gas_p0_Pa"] == 0.0
    per = {s: p["max_displacement_m"] for s, p in r["patches"].items()}
    assert set(per) == {"left", "right"}
    assert r["derived"]["max_displacement"]["value"] == pytest.approx(max(per.values()), rel=1e-12)
    assert r["derived"]["max_displacement_per_finger"]["value"] == pytest.approx(per)
    for p in r["patches"].values():
        assert p["border"]["max_displacement_m"] < 1e-3 * p["max_displacement_m"]
        assert p["refine_levels"] == 2 and p["size_m"] == PATCH_SIZE


@pytest.mark.slow
def test_fit_object_model_patch():
    """graspdef.fit's ObjectModel with ``model="patch"`` (``graspdef fit --model patch``): its linear
    prediction of a max-displacement row scales exactly as 1/E through the chain (patches rebuilt per
    E), and pressure, which the patch model has no air for, is refused in one line.
    Slow (15-26 s on 2 cores): `make test-slow`."""
    from graspdef.fit.models import ObjectModel
    from graspdef.fit.table import MeasuredTable

    table = MeasuredTable(np.array([10.63]), np.array([2.56e-3]), ("max",))
    with pytest.raises(ProblemError, match="no air"):
        ObjectModel("tennis_ball", table, ["pressure"], "nonlinear", model="patch")
    m = ObjectModel("tennis_ball", table, ["E"], "linear", model="patch")
    y1, y2 = m({"E": 2e6})[0], m({"E": 8e6})[0]
    assert y1 == pytest.approx(4 * y2, rel=1e-9)
    assert m.description["model"] == "patch" and m.description["patch_size_m"] == PATCH_SIZE
