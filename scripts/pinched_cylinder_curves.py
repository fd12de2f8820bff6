"""The large-deformation pinched cylinder (Sze, Liu & Lo 2004, 3.6) as curves: graspdef's 1/8 model
on 32 x 32 and 48 x 48 cells against nligaStruct's Kirchhoff-Love IGA curve (the benchmark file's
judged reference) and Sze's Abaqus S4R curve (its reported context), -W_A and U_B against P/P_max,
with the snap enlarged.  Writes docs/pinched_cylinder_curves.png (README, nonlinear benchmarks, 2).

    python scripts/pinched_cylinder_curves.py [--cells 32,48] [--out docs] [--cache out/pinched_cylinder_curves]

Each mesh's path is solved as ``graspdef bench nonlinear`` solves the file (load control of the
load point's displacement, at least the file's step; no targets) and kept in the cache folder as
``path_<cells>.npz`` (P/P_max, -W_A, U_B per path point); a cached path is reused.  About 1 and 3
minutes on the 2-core machine for 32 x 32 and 48 x 48.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
FILE = ROOT / "benchmarks" / "nonlinear" / "pinched_cylinder_large.toml"


def solve_path(cells: int) -> dict:
    """The file's path on cells x cells (the bench's options); P/P_max, -W_A, U_B per point."""
    from graspdef.bench import _abscissa, _point_quantity, benchmark_path_options, load_problem
    from graspdef.solve.nonlinear import solve_nonlinear

    text = FILE.read_text()
    assert "n_theta = 48" in text and "n_z = 48" in text
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / FILE.name
        p.write_text(text.replace("n_theta = 48", f"n_theta = {cells}").replace("n_z = 48", f"n_z = {cells}"))
        spec = load_problem(p)
    ref = spec.reference
    opts = benchmark_path_options(spec)
    t0 = time.perf_counter()
    sol = solve_nonlinear(spec.problem, opts, backend=spec.backend)
    pts = [q for q in sol.path if q.kind != "refine"]
    return {"P": np.array([_abscissa(q, ref["abscissa"], float(ref["abscissa_scale"])) for q in pts]),
            "W": np.array([_point_quantity(spec, sol, q, "-probe.A.x") for q in pts]),
            "U": np.array([_point_quantity(spec, sol, q, "probe.B.y") for q in pts]),
            "seconds": time.perf_counter() - t0}


def references() -> dict:
    """The file's judged curve (nligaStruct) and its context (Sze's S4R): levels and values."""
    from graspdef.bench import load_problem

    ref = load_problem(FILE).reference
    return {"Kirchhoff-Love IGA (nligaStruct)": (np.array(ref["load_factors"]), ref["values"]),
            "Abaqus S4R (Sze et al.)": (np.array(ref["context"]["load_factors"]), ref["context"]["values"])}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", default="32,48")
    ap.add_argument("--out", default=str(ROOT / "docs"))
    ap.add_argument("--cache", default=str(ROOT / "out" / "pinched_cylinder_curves"))
    a = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    from graspdef import runtime

    runtime.configure()
    cache = Path(a.cache)
    cache.mkdir(parents=True, exist_ok=True)
    paths = {}
    for cells in (int(c) for c in a.cells.split(",")):
        f = cache / f"path_{cells}.npz"
        if not f.exists():
            print(f"solving {cells} x {cells} ...", flush=True)
            r = solve_path(cells)
            np.savez(f, P=r["P"], W=r["W"], U=r["U"])
            print(f"  {len(r['P'])} path points, {r['seconds']:.0f} s", flush=True)
        d = np.load(f)
        paths[cells] = (d["P"], d["W"], d["U"])

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    refs = references()
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    for col, (q, label) in enumerate((("-probe.A.x", "−W_A (inward at the load point)"),
                                      ("probe.B.y", "U_B (outward, 90° from A)"))):
        for row, (lo, hi) in enumerate(((0.0, 1.0), (0.13, 0.20))):
            ax = axes[row, col]
            for cells, (P, W, U) in paths.items():
                v = W if q.startswith("-") else U
                keep = P <= 1.02
                ax.plot(P[keep], v[keep], "-", lw=1.4 if cells == max(paths) else 0.9,
                        label=f"graspdef 1/8, {cells} × {cells}")
            for (name, (lv, vals)), mk in zip(refs.items(), ("o", "s")):
                ax.plot(lv, vals[q], mk, ms=3.5 if mk == "o" else 5, mfc="none", label=name)
            ax.set_xlim(lo, hi)
            if row:
                sel = [np.asarray(vals[q])[(lv >= lo) & (lv <= hi)] for lv, vals in refs.values()]
                vv = np.concatenate(sel)
                ax.set_ylim(vv.min() - 0.1 * np.ptp(vv), vv.max() + 0.1 * np.ptp(vv))
            ax.set_xlabel("P / P_max")
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
            ax.set_title(("whole path" if row == 0 else "the snap, enlarged") + f": {label.split(' ')[0]}")
    axes[0, 0].legend(fontsize=8, loc="lower right")
    fig.suptitle("Pinched cylinder, large deformation (Sze 3.6): Kirchhoff–Love curves agree; the S4R curve is shear-deformable",
                 fontsize=10)
    fig.tight_layout()
    out = Path(a.out) / "pinched_cylinder_curves.png"
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
