"""``graspdef score PREDICTION SCAN --out DIR``: register a scan to a predicted surface, score it."""
from __future__ import annotations

import argparse

from ._common import progress

DESCRIPTION = ("Rigid registration (open3d ICP) of a scan to a predicted surface; writes score.json and per-vertex "
               "errors, with the undeformed shape as the baseline.")


def add_arguments(c: argparse.ArgumentParser) -> None:
    c.add_argument("prediction", help="a run folder (its deformed.ply is scored, offset to the outer surface by "
                                      "half the shell thickness) or a predicted surface file")
    c.add_argument("scan", help="scan file or a scans/manifest.toml id (e.g. ycb_056_tennis_ball)")
    c.add_argument("--out", required=True, help="output folder")
    c.add_argument("--undeformed", help="undeformed surface (default: undeformed.ply beside the prediction)")
    c.add_argument("--prediction-units", help="length unit of the prediction file (default: its 'comment units')")
    c.add_argument("--scan-units", help="length unit of the scan file")
    c.add_argument("--init", default="pca", choices=["pca", "centroid", "identity"], help="coarse alignment")
    c.add_argument("--region", help="undeformed region to align on, e.g. 'z < -10' (prediction units)")
    c.add_argument("--surface-offset-mm", type=float, default=None,
                   help="mid-surface to outer-surface offset [mm] (default: half the run's shell thickness for a run "
                        "folder, 0 for a surface file)")


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..registration import score_cli

    pred, offset = Path(args.prediction), args.surface_offset_mm
    if not pred.exists():
        from ..errors import ProblemError

        raise ProblemError(f"prediction {pred} does not exist (give a run folder or its deformed.ply)")
    folder = pred if pred.is_dir() else (pred.parent if (pred.parent / "result.json").is_file() else None)
    if folder is not None:                 # a run folder: read (and check) it with the one reader
        from ..runs.read import read_run

        run_ = read_run(folder)
        if run_.length_unit == "consistent":
            from ..errors import ProblemError

            raise ProblemError(f"run folder {folder} is in consistent units: it cannot be compared with a scan")
        pred = folder / "deformed.ply"
        if offset is None:
            offset = run_.outer_offset * 1e3
            progress(args, f"scoring the outer surface: mid-surface offset by {offset:.4g} mm (half the thickness)")
    rec = score_cli(pred, args.scan, args.out, undeformed_path=args.undeformed,
                    prediction_units=args.prediction_units, scan_units=args.scan_units,
                    init=args.init, region=args.region, surface_offset_mm=offset or 0.0)
    print(rec["summary"])
    if not rec["ok"]:
        progress(args, f"the score is flagged ({', '.join(rec.get('flags', [])) or 'see score.json'}); "
                       f"wrote {args.out}/score.json")
        return 1
    return 0
