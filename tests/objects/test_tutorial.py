"""The README's five-minute tutorial, run as written from an empty folder (issue 15): the YCB
mustard bottle -- non-convex, hollow, not shipped with the repository -- exported as an STL in
millimetres, added with ``graspdef object add``, grasped at 50 N per finger with the nonlinear
shell at nu = 0.45, and its run folder read by the report and the viewer."""
from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from graspdef.cli import main
from graspdef.scans import shared_scans_dir

README = Path(__file__).resolve().parents[2] / "README.md"


def tutorial_lines() -> list[str]:
    text = README.read_text()
    block = re.search(r"<!-- tutorial:[^>]*-->\n```sh\n(.*?)```\n<!-- /tutorial -->", text, re.S)
    assert block, "README: the tutorial block is missing"
    return [ln.strip() for ln in block.group(1).splitlines() if ln.strip() and not ln.startswith("#")]


@pytest.fixture(scope="module")
def tutorial(tmp_path_factory):
    """Run every line of the tutorial in an empty folder; the viewer's line last, in-process."""
    folder = tmp_path_factory.mktemp("tutorial")
    assert not any(folder.iterdir())
    scans = str(shared_scans_dir())
    lines = tutorial_lines()
    assert lines[0].startswith("SCANS=")
    cwd = os.getcwd()
    os.chdir(folder)
    outputs = {}
    try:
        for line in lines[1:]:
            line = line.replace("$SCANS", scans)
            argv = shlex.split(line)
            if argv[0] == "python":
                subprocess.run([sys.executable, *argv[1:]], check=True, cwd=folder)
            elif argv[:2] == ["graspdef", "view"]:
                outputs.setdefault("view", []).append(argv[2:])
            else:
                assert argv[0] == "graspdef", line
                assert main(["-q", *argv[1:]]) == 0, line
    finally:
        os.chdir(cwd)
    return folder, outputs


def test_tutorial_object_folder(tutorial):
    folder, _ = tutorial
    obj = folder / "mustard"
    for f in ("object.toml", "control_mesh.ply", "surface.ply", "scene.xml", "scene_pad.xml", "README.md",
              "object_add.json", "gripper/parallel_gripper_pin.xml", "gripper/parallel_gripper_pad.xml"):
        assert (obj / f).is_file(), f
    rec = json.loads((obj / "object_add.json").read_text())
    assert rec["input"]["units"] == "mm"
    # the bottle is 50 x 85 x 190 mm or so (YCB 006): read in mm, stored in m
    assert 0.18 < max(rec["input"]["size_mm"]) * 1e-3 < 0.2
    cm = rec["control_mesh"]
    assert 1500 < cm["n_faces"] < 2200 and cm["euler"] == 2
    assert cm["min_angle_deg"] > 15.0                        # isotropic remeshing, not decimation slivers
    assert cm["hausdorff_m"] < 5e-3
    assert rec["collision"].startswith("CoACD") and len(list((obj / "assets").glob("*.obj"))) > 1   # non-convex
    assert rec["mass_kg"] == pytest.approx(0.060, rel=1e-9)
    g = rec["grasp"]
    assert g["antipodal_angle_deg"] < np.degrees(np.arctan(0.8))
    assert 0.018 <= g["width_m"] <= 0.126


def test_tutorial_folder_works_from_any_directory(tutorial, tmp_path, monkeypatch):
    """The scene's gripper include resolves inside the folder, wherever the process runs."""
    from graspdef.objects import load_object, scene_xml
    from graspdef.sim.scene import load_scene

    folder, _ = tutorial
    monkeypatch.chdir(tmp_path)
    for tip in ("pin", "pad"):
        xml = scene_xml(folder / "mustard", tip)
        sc = load_scene(xml, "mustard")
        assert sc.free and sc.object_geoms.size > 1
    assert load_object(folder / "mustard").material.nu == 0.45


def test_tutorial_grasp_at_50N_nonlinear_nu_045(tutorial):
    folder, _ = tutorial
    r = json.loads((folder / "runs" / "mustard_50N" / "result.json").read_text())
    assert r["analysis"] == "nonlinear" and r["force_N"] == 50.0
    assert r["material"]["model"] == "compressible_neo_hookean" and r["material"]["nu"] == 0.45
    assert r["convergence"]["completed"] and r["convergence"]["load_factor"] == 1.0
    for s in ("left", "right"):
        assert r["fingers"][s]["axial_force_N"] == pytest.approx(50.0, rel=1e-6)
    # the fingers press the ~50 mm wide bottle: an indentation, not a collapse through it
    ind = r["derived"]["indentation_per_finger"]["value"]
    assert 1e-3 < ind < 25e-3
    assert np.linalg.norm(r["residual"]["net_force_N"]) < 0.01 * 50.0


def test_tutorial_report_and_viewer(tutorial):
    from graspdef.viewer.server import Viewer

    folder, outputs = tutorial
    run = folder / "runs" / "mustard_50N"
    html = (run / "report.html").read_text()
    assert "mustard" in html and "max. displacement" in html
    assert outputs["view"][0] == ["runs/mustard_50N"]
    with Viewer([folder / outputs["view"][0][0]], port=0) as v:
        assert v.wait_ready(120)


def test_tutorial_rank(tutorial):
    """``graspdef rank`` in the tutorial's object folder: a ranking folder with held candidates,
    its report (with the Pareto front) and the viewer's ranking page."""
    from graspdef.runs.ranking import read_ranking
    from graspdef.viewer.ranking import RankingViewer

    folder, outputs = tutorial
    r = read_ranking(folder / "runs" / "mustard_rank")
    assert r.record["force_N"] == 20.0 and r.n >= 500 and r.record["n_held"] > 0
    assert r.table["held"][0] == 1
    assert "Pareto" in (folder / "runs" / "mustard_rank" / "report.html").read_text()
    assert outputs["view"][1] == ["runs/mustard_rank"]
    v = RankingViewer(folder / outputs["view"][1][0], port=0)
    try:
        assert v.n_drawn == min(200, r.n)
    finally:
        v.stop()
