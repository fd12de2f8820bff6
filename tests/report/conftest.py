"""Small run folders written through the real solve path (a linear ball in mm/N, a nonlinear
cantilever in consistent units) and a synthetic scan of the ball's deformed surface (scanner
model), shared by the report tests."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from graspdef.testing import cantilever_problem

BALL_MM = """
name = "ball_mm"
[units]
length = "mm"
force = "N"
[geometry]
type = "sphere"
radius = 32.5
subdivisions = 2
[material]
E = 8.0             # N/mm^2 = 8 MPa
nu = 0.45
[shell]
thickness = 2.5
[[supports]]
kind = "rigid_modes"
[[loads]]
kind = "point"
at = [0.0, 0.0, 32.5]
force = [0.0, 0.0, -10.63]
[[loads]]
kind = "point"
at = [0.0, 0.0, -32.5]
force = [0.0, 0.0, 10.63]
[[probes]]
name = "top"
at = [0.0, 0.0, 32.5]
"""

CANTILEVER = cantilever_problem(nx=6, force=0.1, steps=3)


def solve_into(folder: Path, text: str) -> Path:
    """``graspdef solve`` of a problem text into ``folder`` (the real writer)."""
    from graspdef.cli import main

    src = folder.parent / f"{folder.name}.toml"
    src.write_text(text)
    assert main(["-q", "solve", str(src), "--out", str(folder)]) == 0
    return folder


@pytest.fixture(scope="session")
def report_root(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("report_runs")


@pytest.fixture(scope="session")
def ball_run(report_root) -> Path:
    """Linear ball (R = 32.5 mm, 162 control vertices) squeezed by 10.63 N at its poles."""
    return solve_into(report_root / "ball", BALL_MM)


@pytest.fixture(scope="session")
def cantilever_run(report_root) -> Path:
    return solve_into(report_root / "cantilever", CANTILEVER)


@pytest.fixture(scope="session")
def ball_scan(report_root, ball_run) -> Path:
    """A synthetic scan (scanner model: 6 views, holes, sigma = 0.127 mm, random pose; 4,000
    points, metres) of the ball's deformed outer surface (mid-surface + t/2 = 1.25 mm) moved
    0.3 mm further outward: a known shape error at the default (outer-surface) offset."""
    import trimesh

    from graspdef.geometry import TriMesh
    from graspdef.scans import Scanner, scan_surface, write_scan

    m = trimesh.load(ball_run / "deformed.ply", process=False)
    v = np.asarray(m.vertices)                                   # run folders are SI (metres)
    n = v - v.mean(axis=0)
    v = v + (1.25e-3 + 3e-4) * n / np.linalg.norm(n, axis=1, keepdims=True)
    scan = scan_surface(TriMesh(v, np.asarray(m.faces)), Scanner(n_points=4000), seed=3)
    return write_scan(scan, report_root / "scans" / "ball_scan.ply", units="m")


@pytest.fixture(scope="session")
def scored_report(ball_run, ball_scan, tmp_path_factory) -> Path:
    """A copy of the ball's run folder with its report, scored against the synthetic scan through
    ``--scan`` (the score written to RUN/score)."""
    import shutil

    from graspdef.cli import main

    d = tmp_path_factory.mktemp("scored") / "ball"
    shutil.copytree(ball_run, d)
    assert main(["report", str(d), "--scan", str(ball_scan)]) == 0
    return d
