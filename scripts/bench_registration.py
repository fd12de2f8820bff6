"""Registration and scoring benchmark (issue 6): speed on a 50k-point scan and the accuracy figures.

Speed: a synthetic 50,000-point scan (scanner model: 6 turntable views, 4 holes, sigma = 0.127 mm,
random pose) of a warped ellipsoid (10,242 vertices) is registered and scored; medians of
``--runs`` runs after one warm-up run (open3d import, first k-d trees), for
(a) ``register`` alone, (b) ``score_surface`` (registration + scan -> surface and surface -> scan
distances) and (c) ``score`` (the prediction and the undeformed baseline: twice (b)).

Accuracy: pose error and residual / sigma over ``--seeds`` synthetic scans, and the real YCB
tennis-ball scan against the sphere model and against its own 5,120-face control mesh.

    python scripts/bench_registration.py --out out/bench_registration.json
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from graspdef.geometry import TriMesh, ellipsoid, icosphere
from graspdef.registration import apply, register, rotation_angle, score, score_surface
from graspdef.registration.distance import SurfaceDistance
from graspdef.scans import NEXTENGINE_SIGMA, Scanner, control_mesh, load_scan, scan_surface


def egg() -> TriMesh:
    """The asymmetric test body of tests/registration/conftest.py."""
    e = ellipsoid(0.04, 0.03, 0.02, 5)
    x, y, z = e.vertices.T
    return TriMesh(np.c_[x, y * (1 + 4.0 * x), z * (1 + 5.0 * y) + 3.0 * x**2], e.faces)


def timed(fn, runs: int) -> dict:
    fn()  # warm-up
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return {"median_s": statistics.median(times), "min_s": min(times), "max_s": max(times),
            "runs": runs}


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--points", type=int, default=50_000)
    parser.add_argument("--out", default="out/bench_registration.json")
    args = parser.parse_args(argv)

    body = egg()
    scan = scan_surface(body, Scanner(n_points=args.points), seed=0)
    speed = {
        "register": timed(lambda: register(scan.points, body), args.runs),
        "register_and_score": timed(lambda: score_surface(scan.points, body), args.runs),
        "score_with_baseline": timed(lambda: score(scan.points, body, body), args.runs),
    }

    pose = []
    for seed in range(args.seeds):
        s = scan if seed == 0 else scan_surface(body, Scanner(n_points=args.points), seed=seed)
        reg = register(s.points, body)
        err = reg.transform @ s.pose
        moved = np.linalg.norm(apply(err, body.vertices) - body.vertices, axis=1).max()
        resid = SurfaceDistance(body).signed(apply(reg.transform, s.points))
        pose.append({"seed": seed,
                     "rotation_error_deg": float(np.degrees(rotation_angle(err[:3, :3]))),
                     "max_vertex_error_mm": float(moved * 1e3),
                     "residual_rms_mm": float(np.sqrt(np.mean(resid**2)) * 1e3),
                     "residual_over_sigma": float(np.sqrt(np.mean(resid**2)) / NEXTENGINE_SIGMA),
                     "converged": reg.converged, "init": reg.init})

    ball = load_scan("ycb_056_tennis_ball")
    pts = ball.vertices
    a = np.c_[2 * pts, np.ones(len(pts))]
    x = np.linalg.lstsq(a, (pts**2).sum(axis=1), rcond=None)[0]
    radius = float(np.sqrt(x[3] + x[:3] @ x[:3]))
    tennis = {"sphere_radius_mm": radius * 1e3}
    for name, model in (("sphere", icosphere(radius, 5)),
                        ("control_mesh_5120", control_mesh(ball, 5120, "project")[0])):
        st = score_surface(pts, model).stats
        tennis[name] = {k: (v if k == "coverage" else v * 1e3) for k, v in st.items()}

    record = {
        "units": {"time": "s", "length": "mm", "angle": "deg"},
        "machine": {"python": sys.version.split()[0], "platform": platform.platform(),
                    "cpus": __import__("os").cpu_count()},
        "scan": {"points": args.points, "surface_vertices": body.n_vertices,
                 "sigma_mm": NEXTENGINE_SIGMA * 1e3},
        "speed": speed, "pose_recovery": pose, "tennis_ball": tennis,
    }
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(record, indent=2) + "\n")

    print(f"{args.points} scan points, surface {body.n_vertices} vertices, medians of {args.runs}:")
    for k, v in speed.items():
        print(f"  {k:22s} {v['median_s']:.3f} s (min {v['min_s']:.3f}, max {v['max_s']:.3f})")
    for p in pose:
        print(f"  seed {p['seed']}: {p['rotation_error_deg']:.4f} deg, "
              f"{p['max_vertex_error_mm']:.4f} mm,"
              f" residual {p['residual_rms_mm']:.4f} mm = {p['residual_over_sigma']:.3f} sigma")
    for name in ("sphere", "control_mesh_5120"):
        t = tennis[name]
        print(f"  tennis ball vs {name}: mean {t['mean']:.3f} mm, RMS {t['rms']:.3f} mm, "
              f"max {t['max']:.3f} mm")
    print(f"wrote {out}")
    return record


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
