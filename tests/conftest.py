"""Process set-up of the test session: what ``graspdef`` does at start (graspdef.runtime), so the
tests run the solvers as the command line does."""
import os
import shutil
import tempfile

from graspdef import runtime

_CACHE = "GRASPDEF_CACHE_DIR"


def pytest_configure(config):
    runtime.configure()
    # graspdef.scans.cache: the session's control meshes in a folder of its own (not the user's
    # ~/.cache), shared by xdist's workers (they inherit the environment) and removed at the end
    if _CACHE not in os.environ:
        os.environ[_CACHE] = config._graspdef_cache = tempfile.mkdtemp(prefix="graspdef_test_cache_")


def pytest_unconfigure(config):
    folder = getattr(config, "_graspdef_cache", None)
    if folder:
        shutil.rmtree(folder, ignore_errors=True)
        os.environ.pop(_CACHE, None)


# ------------------------------------------------------------------------------------------------
# A synthetic ranking folder (FIXTURE: made-up numbers, not a simulation), shared by the viewer's
# and the report's ranking tests.  Written through graspdef.runs.ranking.write_ranking, the writer
# 'graspdef rank' uses.  The numbers are consistent with each other (closing = F / k, work =
# F closing / 2, held and pareto flags, ranks and the Spearman correlations follow from the columns)
# but come from a formula, not from a shell.
# ------------------------------------------------------------------------------------------------
import pytest  # noqa: E402

FIXTURE_RADIUS_M = 0.0325
FIXTURE_FORCE_N = 5.0
FIXTURE_FRICTION = 0.5
FIXTURE_N_CANDIDATES = 240          # more than the viewer's default cap of 200 segments
FIXTURE_N_SHAPES = 6                # shapes.npz holds the best 6


def _spearman(a, b) -> float:
    import numpy as np
    from scipy.stats import rankdata

    ra, rb = rankdata(a), rankdata(b)
    return float(np.corrcoef(ra, rb)[0, 1])


def write_synthetic_ranking(out, n_candidates: int = FIXTURE_N_CANDIDATES, n_shapes: int = FIXTURE_N_SHAPES,
                            recheck: bool = True, seed: int = 0):
    """Write a ranking folder of made-up but consistent numbers for an icosphere (radius 32.5 mm,
    162 vertices): compliance NaN on the cap z > 0.8 R ("no pinch fits"), antipodal-ish candidates
    between random vertex pairs, the best ``n_shapes`` with a smooth squeeze as displacement."""
    import math

    import numpy as np
    import trimesh

    from graspdef.runs.ranking import write_ranking

    R, F, mu = FIXTURE_RADIUS_M, FIXTURE_FORCE_N, FIXTURE_FRICTION
    sph = trimesh.creation.icosphere(subdivisions=2, radius=R)
    V, Fc = np.asarray(sph.vertices, float), np.asarray(sph.faces, np.int64)
    rng = np.random.default_rng(seed)
    nrm = V / np.linalg.norm(V, axis=1, keepdims=True)
    pairs = []
    while len(pairs) < n_candidates:
        i, j = rng.integers(0, len(V), 2)
        if nrm[i] @ nrm[j] < -0.85:
            pairs.append((int(i), int(j)))
    mass, g, E, t = 0.1, 9.81, 5e6, 0.002
    phi = math.degrees(math.atan(mu))
    rows = []
    for c, (i, j) in enumerate(pairs):
        p1, p2 = V[i], V[j]
        w = float(np.linalg.norm(p2 - p1))
        d = (p2 - p1) / w
        ang = max(math.degrees(math.acos(np.clip(-nrm[i] @ d, -1, 1))),
                  math.degrees(math.acos(np.clip(nrm[j] @ d, -1, 1))))
        k = 1500.0 * (1.0 + 2.0 * abs(d[2]))                       # N/m: stiffer pinched along z
        closing = F / k
        work = F * closing / 2
        dmargin = (phi - ang) - math.degrees(closing / R) * 8.0    # deformation tilts the normals
        wtr = 0.2 + 1.2 * (1.0 - abs(d[2]))                        # made up: > 1 for horizontal grasps
        wsr = mass * g / (2 * mu * F)
        h = closing / 2
        rows.append({
            "candidate": c, "first_x_m": p1[0], "first_y_m": p1[1], "first_z_m": p1[2],
            "second_x_m": p2[0], "second_y_m": p2[1], "second_z_m": p2[2], "width_m": w,
            "antipodal_angle_deg": ang, "friction_margin_deg": phi - ang, "force_N": F, "closing_m": closing,
            "indentation_per_finger_m": h, "work_J": work, "strain_energy_J": work, "grasp_stiffness_N_per_m": k,
            "max_displacement_m": 0.6 * closing, "peak_strain": 2.0 * h / R, "peak_von_mises_Pa": E * 2.0 * h / R,
            "strain_limit_ratio": float("nan"), "contact_area_m2": math.pi * (2 * R * h - h * h),
            "deformed_friction_margin_deg": dmargin, "weight_torque_ratio": wtr, "weight_slip_ratio": wsr,
            "held": int(dmargin > 0 and wtr < 1 and wsr < 1)})
    rigid = sorted(range(len(rows)), key=lambda r: (-rows[r]["friction_margin_deg"], rows[r]["weight_torque_ratio"]))
    for rr, r in enumerate(rigid):
        rows[r]["rigid_rank"] = rr + 1
    wk = np.array([r["work_J"] for r in rows])
    dm = np.array([r["deformed_friction_margin_deg"] for r in rows])
    for a, r in enumerate(rows):                                   # least work, largest deformed margin
        dominated = np.any((wk <= wk[a]) & (dm >= dm[a]) & ((wk < wk[a]) | (dm > dm[a])))
        r["pareto"] = int(not dominated)
    rows.sort(key=lambda r: (-r["held"], r["work_J"], r["candidate"]))
    for k, r in enumerate(rows):
        r["rank"] = k + 1
    z = V[:, 2] / R
    comp = 1.0 / (1500.0 * (1.0 + 2.0 * np.abs(z)))
    comp[z > 0.8] = np.nan                                         # the cap: no pinch fits (fixture)
    maps = {"compliance_m_per_N": comp, "stiffness_N_per_m": 1.0 / comp,
            "pinch_width_m": np.where(np.isnan(comp), np.nan, 2 * R)}
    best = rows[:n_shapes]
    disp = []
    for r in best:
        p1 = np.array([r["first_x_m"], r["first_y_m"], r["first_z_m"]])
        p2 = np.array([r["second_x_m"], r["second_y_m"], r["second_z_m"]])
        d = (p2 - p1) / np.linalg.norm(p2 - p1)
        s2 = 2 * (0.4 * R) ** 2
        bump = (np.exp(-((V - p1) ** 2).sum(1) / s2) - np.exp(-((V - p2) ** 2).sum(1) / s2))
        disp.append(0.5 * r["closing_m"] * bump[:, None] * d)
    order = [r["rank"] for r in rows]
    record = {
        "fixture": "synthetic ranking for tests: made-up numbers, not a simulation",
        "object": "fixture_icosphere", "force_N": F, "friction": mu, "mass_kg": mass,
        "material": {"model": "linear_elastic", "E_Pa": E, "nu": 0.45}, "thickness_m": t,
        "control_vertices": len(V), "n_candidates": len(rows),
        "ranking": "held candidates first, then least work (fixture)",
        "timings_s": {"candidates": 0.5, "factor": 1.0, "screen": 2.0, "total": 3.5},
        "candidates_per_minute": 60.0 * len(rows) / 2.0,
        "rank_correlation": {"rigid_vs_deformable_spearman": _spearman(order, [r["rigid_rank"] for r in rows])},
    }
    if recheck:
        rc = [{"rank": r["rank"], "candidate": r["candidate"], "linear_closing_m": r["closing_m"],
               "nonlinear_closing_m": r["closing_m"] * (1.08 + 0.01 * k)} for k, r in enumerate(rows[:5])]
        record["recheck"] = rc
        record["recheck_spearman"] = _spearman([x["linear_closing_m"] for x in rc],
                                               [x["nonlinear_closing_m"] for x in rc])
    return write_ranking(out, record, rows, V, Fc, maps, np.array([r["candidate"] for r in best]),
                         np.array(disp))


@pytest.fixture(scope="session")
def synthetic_ranking(tmp_path_factory):
    """A ranking folder of made-up numbers (see write_synthetic_ranking); do not modify it: copy it."""
    return write_synthetic_ranking(tmp_path_factory.mktemp("ranking") / "fixture_rank")


@pytest.fixture(scope="session")
def ranking_writer():
    """write_synthetic_ranking, for tests that need a variant (the per-folder conftest modules share
    the name 'conftest', so tests take it as a fixture instead of importing it)."""
    return write_synthetic_ranking


# ------------------------------------------------------------------------------------------------
# The hinged cylindrical roof (benchmarks/nonlinear/hinged_roof.toml) under a central *force*
# instead of its prescribed centre deflection, at a given mesh and [solver] table: shared by the
# arc-length benchmark test and the load-control limit-point tests.
# ------------------------------------------------------------------------------------------------
ROOF_FORCE_1_4 = 750.0              # P_max = 3000 on the whole roof, a quarter on the 1/4 model


@pytest.fixture(scope="session")
def roof_under_force():
    """write(path, cells, solver_table) -> path of the roof's problem file with the central force
    P_max (750 on the 1/4 model), ``cells`` x ``cells`` cells and the given [solver] table text."""
    from pathlib import Path

    src = Path(__file__).resolve().parents[1] / "benchmarks" / "nonlinear" / "hinged_roof.toml"

    def write(path: Path, cells: int, solver: str) -> Path:
        text = src.read_text()
        assert "n_theta = 32" in text and "n_z = 32" in text
        text = text.replace("n_theta = 32", f"n_theta = {cells}").replace("n_z = 32", f"n_z = {cells}")
        support = ('[[supports]]\nkind = "point"\nname = "C"\nat = [0.0, 2540.0, 0.0]\n'
                   'directions = [[0.0, 1.0, 0.0]]\ndisplacement = [-30.0]\n')
        old = '[solver]\ntype = "nonlinear"\nmethod = "load"\nsteps = 60\nmax_steps = 2000\n'
        assert support in text and old in text
        text = text.replace(support, '[[loads]]\nkind = "point"\nat = [0.0, 2540.0, 0.0]\n'
                                     f'force = [0.0, -{ROOF_FORCE_1_4}, 0.0]\n')
        path.write_text(text.replace(old, solver))
        return path

    return write
