"""Screenshots of the browser viewer for docs/viewer.md (headless Debian chromium + selenium).

Solves a tennis-ball-sized sphere pinched by two 2 N point forces (linear and nonlinear, mm/N),
adds a synthetic grasp (contacts.json: two finger pads and their forces) and a synthetic scan
score (score.json + scan_errors.ply: the nonlinear surface with a known bump), serves both runs
side by side and saves docs/viewer_*.png.

    python scripts/viewer_screenshots.py [--out out/viewer_demo] [--docs docs]
"""
from __future__ import annotations

import argparse
import io
import json
import time
from pathlib import Path

import numpy as np

BALL = """
name = "ball_{kind}"
[units]
length = "mm"
force = "N"
[geometry]
type = "sphere"
radius = 32.5
subdivisions = 3
[material]
model = "{model}"
E = 1.0            # N/mm^2 = 1 MPa
nu = 0.45
[shell]
thickness = 2.5
[[supports]]
kind = "rigid_modes"
[[loads]]
kind = "point"
at = [0.0, 0.0, 32.5]
force = [0.0, 0.0, -2.0]
[[loads]]
kind = "point"
at = [0.0, 0.0, -32.5]
force = [0.0, 0.0, 2.0]
[[probes]]
name = "top"
at = [0.0, 0.0, 32.5]
{solver}
"""


def solve(out: Path, kind: str) -> Path:
    from graspdef.problem.config import load_problem
    from graspdef.solve.output import write_run

    text = BALL.format(kind=kind, model="linear_elastic" if kind == "linear" else "saint_venant_kirchhoff",
                       solver="" if kind == "linear" else '[solver]\ntype = "nonlinear"\nsteps = 5')
    src = out / f"ball_{kind}.toml"
    src.parent.mkdir(parents=True, exist_ok=True)
    src.write_text(text)
    spec = load_problem(src)
    if kind == "linear":
        from graspdef.solve.linear import solve_linear
        sol = solve_linear(spec.problem)
    else:
        from graspdef.solve.nonlinear import path_options, solve_nonlinear
        sol = solve_nonlinear(spec.problem, path_options(spec.solver), allow_partial=True)
    d = write_run(out / f"ball_{kind}", spec, sol, text)          # nonlinear: path_u.npz included
    top = sol.probe("top")[2] * 1e3
    contacts = {"units": {"length": "mm", "force": "N"},
                "fingers": [{"name": "top_pad", "position": [0, 0, 32.5 + top + 4], "size": [14, 14, 8]},
                            {"name": "bottom_pad", "position": [0, 0, -32.5 - top - 4], "size": [14, 14, 8]}],
                "contacts": [{"position": [0, 0, 32.5 + top], "force": [0, 0, -2.0], "finger": "top_pad"},
                             {"position": [0, 0, -32.5 - top], "force": [0, 0, 2.0], "finger": "bottom_pad"}]}
    (d / "contacts.json").write_text(json.dumps(contacts, indent=1))
    return d


def synthetic_score(run: Path) -> None:
    """A 'scan' = the predicted surface plus a 0.4 mm bump on one side (errors known)."""
    from graspdef.geometry.io import save_ply
    from graspdef.runs.read import read_run

    r = read_run(run)
    x = r.deformed_vertices
    n = x / np.linalg.norm(x, axis=1, keepdims=True)
    err = 0.4 * np.exp(-((n[:, 0] - 1) ** 2 + n[:, 1] ** 2) / 0.3)              # mm
    scan = x + n * err[:, None] * 1e-3
    d = run / "score"
    d.mkdir(exist_ok=True)
    save_ply(d / "scan_errors.ply", scan, np.zeros((0, 3), int), units="mm",
             vertex_scalars={"error_mm": err, "baseline_error_mm": err})
    rec = {"prediction": {"errors": {"mean_mm": float(err.mean()), "rms_mm": float(np.sqrt((err ** 2).mean())),
                                     "max_mm": float(err.max())},
                          "registration": {"transform_scan_to_surface": np.eye(4).tolist()}},
           "baseline": {"errors": {}}, "summary": "synthetic scan (the prediction plus a 0.4 mm bump)",
           "files": {"scan_errors": "scan_errors.ply"}}
    (d / "score.json").write_text(json.dumps(rec, indent=1))


def browser(width: int, height: int, profile: Path):
    from graspdef.testing import headless_chromium

    return headless_chromium(profile, window=f"{width},{height}")


def save_small(driver, path: Path) -> None:
    from PIL import Image

    img = Image.open(io.BytesIO(driver.get_screenshot_as_png())).convert("RGB")
    img = img.quantize(colors=256, method=Image.Quantize.MEDIANCUT)
    img.save(path, optimize=True)
    print(f"{path}: {path.stat().st_size / 1e3:.0f} kB")


def close_notices(d) -> None:
    """Close viser's "software WebGL" notice (headless chromium renders on the CPU)."""
    from selenium.webdriver.common.by import By

    for b in d.find_elements(By.CSS_SELECTOR, "button.mantine-Notification-closeButton, "
                                              "button[class*=CloseButton]"):
        try:
            b.click()
        except Exception:  # noqa: BLE001 - a notice may vanish by itself
            pass
    time.sleep(2)


def grasp_shot(runs: list[str], out: Path, docs: Path) -> None:
    from graspdef.viewer.server import Viewer

    with Viewer(runs, port=0, live=False) as v:
        d = browser(1280, 1000, out / "chromium_profile_grasp")
        try:
            d.get(v.url)
            time.sleep(6)
            close_notices(d)
            save_small(d, docs / "viewer_grasp.png")
        finally:
            d.quit()


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="out/viewer_demo")
    ap.add_argument("--docs", default="docs")
    ap.add_argument("--reuse", action="store_true", help="reuse the demo runs in --out if they exist")
    ap.add_argument("--grasp", nargs="+", help="only a screenshot of these grasp run folders (graspdef grasp "
                                                "--out), side by side: docs/viewer_grasp.png")
    args = ap.parse_args()
    out, docs = Path(args.out), Path(args.docs)
    if args.grasp:
        grasp_shot(args.grasp, out, docs)
        return
    lin, nl = out / "ball_linear", out / "ball_nonlinear"
    if not (args.reuse and (lin / "result.json").is_file() and (nl / "path_u.npz").is_file()):
        lin, nl = solve(out, "linear"), solve(out, "nonlinear")
    synthetic_score(nl)
    from selenium.webdriver.common.by import By

    from graspdef.viewer.server import Viewer

    with Viewer([lin, nl], port=0) as v:
        v.wait_ready(300)
        d = browser(1280, 1000, out / "chromium_profile")
        try:
            d.get(v.url)
            time.sleep(6)
            close_notices(d)
            save_small(d, docs / "viewer_side_by_side.png")
            v.show_path_point(1, 2)
            v.set_live(0, 2.0, 1.0)
            time.sleep(3)
            save_small(d, docs / "viewer_path_live.png")
        finally:
            d.quit()


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
