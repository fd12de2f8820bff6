"""Convergence of the linear Loop-subdivision shell: error vs number of control vertices.

Thin wrapper over the gallery scripts (scripts/gallery/paper_fig08_plate_convergence.py and
paper_fig11_cylinder_convergence.py, which hold the studies): both studies in one table and one
plot (docs/convergence.png), each up to >= 50,000 control vertices.

Writes ``convergence.json``, ``convergence.csv`` and ``convergence.png`` to ``--out`` and prints
a Markdown table.

    python scripts/convergence.py [--out out/convergence] [--fast]
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent / "gallery"))
import _common as C  # noqa: E402
import paper_fig08_plate_convergence as fig08  # noqa: E402
import paper_fig11_cylinder_convergence as fig11  # noqa: E402

# names other scripts and tests import from here
PLATE_REF, plate = fig08.PLATE_REF, fig08.plate
CYL_REF, pinched_cylinder, pinched_cylinder_problem = fig11.CYL_REF, fig11.pinched_cylinder, fig11.pinched_cylinder_problem
order = C.order
STUDIES = {
    "plate_ss_uniform": (plate, PLATE_REF, fig08.SIZES, fig08.FAST_SIZES),
    "pinched_cylinder": (pinched_cylinder, CYL_REF, fig11.SIZES, fig11.FAST_SIZES),
}


def run(fast: bool = False, progress=print) -> dict:
    return {name: C.run_study(name, fn, ref, fast_sizes if fast else sizes, progress)
            for name, (fn, ref, sizes, fast_sizes) in STUDIES.items()}


def main(fast: bool = False, out: str = "out/convergence") -> dict:
    res = run(fast)
    o = Path(out)
    o.mkdir(parents=True, exist_ok=True)
    (o / "convergence.json").write_text(json.dumps(res, indent=2) + "\n")
    C.write_csv(o / "convergence.csv", [r for rows in res.values() for r in rows])
    print("| study | control vertices | value | reference | error |")
    print("|---|---|---|---|---|")
    for name, rows in res.items():
        for r in rows:
            print(f"| {name} | {r['n_control']} | {r['value']:.6g} | {r['reference']:.6g} | {100 * r['rel_error']:+.4f} % |")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for name, rows in res.items():
        C.convergence_axes(ax, name, rows)
    ax.set_title("graspdef linear shell: convergence")
    ax.legend()
    fig.tight_layout()
    fig.savefig(o / "convergence.png", dpi=120)
    return res


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/convergence")
    ap.add_argument("--fast", action="store_true", help="small meshes only")
    a = ap.parse_args()
    main(a.fast, a.out)
