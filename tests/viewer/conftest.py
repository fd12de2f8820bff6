"""Small run folders written through the real solve path (linear plate in mm/N, nonlinear
cantilever with and without path_u.npz), plus synthetic contacts.json and score folders."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from graspdef.testing import cantilever_problem

PLATE_MM = """
name = "plate_mm"
[units]
length = "mm"
force = "N"
[geometry]
type = "rectangle"
lx = 100.0
ly = 100.0
nx = 10
ny = 10
[material]
E = 2000.0          # N/mm^2 = 2 GPa
nu = 0.3
[shell]
thickness = 1.0
[regions]
edges = "abs(abs(x) - 50) < 1e-6 or abs(abs(y) - 50) < 1e-6"
[[supports]]
kind = "simply_supported"
region = "edges"
[[loads]]
kind = "point"
at = [0.0, 0.0, 0.0]
force = [0.0, 0.0, -2.0]
[[probes]]
name = "centre"
at = [0.0, 0.0, 0.0]
"""

CANTILEVER = cantilever_problem()


def _solve(folder: Path, text: str, path_u: bool = True) -> Path:
    from graspdef.cli import main

    src = folder.parent / f"{folder.name}.toml"
    src.write_text(text)
    assert main(["-q", "solve", str(src), "--out", str(folder)]) == 0
    if not path_u:
        (folder / "path_u.npz").unlink(missing_ok=True)     # an older run folder, without it
    return folder


@pytest.fixture(scope="session")
def run_root(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("viewer_runs")


@pytest.fixture(scope="session")
def plate_run(run_root) -> Path:
    """Linear plate in mm and N, with a synthetic grasp (contacts.json) and scan score."""
    d = _solve(run_root / "plate", PLATE_MM)
    write_synthetic_contacts(d)
    write_synthetic_score(d / "score")
    return d


@pytest.fixture(scope="session")
def cantilever_run(run_root) -> Path:
    return _solve(run_root / "cantilever", CANTILEVER)


@pytest.fixture(scope="session")
def cantilever_run_no_path(run_root) -> Path:
    return _solve(run_root / "cantilever_nopath", CANTILEVER, path_u=False)


def write_synthetic_contacts(d: Path) -> None:
    """Two fingers pinching the plate centre (mm, N): the layout graspdef.runs.read accepts."""
    doc = {"units": {"length": "mm", "force": "N"},
           "fingers": [{"name": "top_pad", "position": [0, 0, 6], "wxyz": [1, 0, 0, 0], "size": [8, 8, 10]},
                       {"name": "bottom_pad", "position": [0, 0, -6], "size": [8, 8, 10]}],
           "contacts": [{"position": [0, 0, 0.5], "force": [0, 0, -2.0], "finger": "top_pad"},
                        {"position": [0, 0, -0.5], "force": [0, 0, 1.0], "finger": "bottom_pad"}]}
    (d / "contacts.json").write_text(json.dumps(doc))


def write_synthetic_score(d: Path) -> None:
    """A score folder as graspdef score writes it: a scan (mm) 10 mm above the plate in its own
    frame, registered by a translation of -10 mm in z, errors growing with x."""
    from graspdef.geometry.io import save_ply

    d.mkdir(parents=True, exist_ok=True)
    g = np.linspace(-45, 45, 10)
    x, y = np.meshgrid(g, g)
    pts = np.c_[x.ravel(), y.ravel(), np.full(x.size, 10.0)] * 1e-3          # [m]
    err = x.ravel() / 45.0 * 0.5                                             # [mm]
    save_ply(d / "scan_errors.ply", pts, np.zeros((0, 3), int), units="mm",
             vertex_scalars={"error_mm": err, "baseline_error_mm": 2 * err})
    T = np.eye(4)
    T[2, 3] = -10.0                                                          # t in mm
    rec = {"units": {"length": "mm"}, "inputs": {"scan_units": "mm"},
           "prediction": {"errors": {"mean_mm": 0.25, "rms_mm": 0.29, "max_mm": 0.5},
                          "registration": {"transform_scan_to_surface": T.tolist()}},
           "baseline": {"errors": {"mean_mm": 0.5, "rms_mm": 0.58, "max_mm": 1.0}},
           "summary": "synthetic score", "flags": [], "ok": True,
           "files": {"scan_errors": "scan_errors.ply"}}
    (d / "score.json").write_text(json.dumps(rec))
