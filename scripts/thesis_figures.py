"""Reproduce the thesis's Figures 10-13 (hemisphere, R0/t0 = 10, Mooney-Rivlin gamma = 0.1) as PNG files.

    .venv/bin/python scripts/thesis_figures.py [--out out/thesis] [--ring-angle 30]

Fig. 10  load vs edge rotation, edge couples          (thesis: limit 3.363, max rotation 3.097)
Fig. 11  load vs apex deflection, ring load           (thesis: limit 0.958, max apex deflection 7.578)
Fig. 12  load vs apex deflection, uniform vertical    (thesis: limit 0.0156)
Fig. 13  deformed shapes, uniform vertical load       (thesis: A 0.0132747, B 0.0022892, C -0.00658208)
Each path runs until it can no longer be continued (the constitutive relations stop being invertible under very
large bending, thesis Ch. 5) or until the load has fallen below -limit.  Also writes curves.json.
"""
import argparse
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from graspdef.axisym import hemisphere_example, solve_path  # noqa: E402
from graspdef.axisym.bench import THESIS  # noqa: E402


def trace(case, ring_angle_deg):
    kw = {"ring_angle": np.radians(ring_angle_deg)} if case == "ring" else {}
    m = hemisphere_example(case, **kw)
    state = {}

    def stop(eq):
        state.setdefault("max", eq.lam)
        state["max"] = max(state["max"], eq.lam)
        return eq.lam < -state["max"] or 10.0 - eq.nodes[0, 1] > 19.0

    p = solve_path(m, ds=1.0, ds_max=3.0, max_steps=250, on_failure="stop", ds_min=1e-3, stop=stop)
    print(f"{case}: {len(p.points) - 1} steps, {p.seconds:.1f} s, limits "
          f"{[round(l['lam'], 5) for l in p.limits]}; end: {p.stopped_by[:90] or 'stop criterion'}")
    return m, p


def curve_plot(ax, x, lam, limits, ref, xlabel, title):
    ax.plot(x, lam, "-", color="C0", lw=1.5, label="this code")
    for k, lim in enumerate(limits[:1]):
        ax.axhline(lim["lam"], color="C0", ls=":", lw=0.8)
        ax.annotate(f"limit {lim['lam']:.4g}", (x[int(np.argmax(lam))], lim["lam"]), textcoords="offset points",
                    xytext=(5, 5), color="C0")
    ax.axhline(ref, color="C3", ls="--", lw=0.8, label=f"thesis limit {ref:g}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("nondimensional load  Λ")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/thesis")
    ap.add_argument("--ring-angle", type=float, default=30.0, help="ring position, deg from the apex")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    curves = {}

    m, p = trace("edge_couple", args.ring_angle)
    rot = np.array([abs(q.nodes[1, 2] - m.nodes[1].phi) for q in p.points])
    fig, ax = plt.subplots(figsize=(5.5, 4))
    curve_plot(ax, rot, p.lam, p.limits, THESIS["edge_couple_limit"], "edge rotation |Δφ| (rad)",
               "Fig. 10: hemisphere with edge couples")
    ax.axvline(THESIS["edge_max_rotation"], color="C3", ls=":", lw=0.8, label="thesis max rotation 3.097")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "fig10_edge_couples.png", dpi=130)
    curves["edge_couple"] = dict(lam=p.lam.tolist(), edge_rotation=rot.tolist(), limits=p.limits)

    m, p = trace("ring", args.ring_angle)
    apex = 10.0 - np.array([q.nodes[0, 1] for q in p.points])
    fig, ax = plt.subplots(figsize=(5.5, 4))
    curve_plot(ax, apex, p.lam, p.limits, THESIS["ring_limit"], "apex deflection / t0",
               f"Fig. 11: hemisphere with ring load at {args.ring_angle:g}° from the apex")
    fig.tight_layout()
    fig.savefig(out / "fig11_ring_load.png", dpi=130)
    curves["ring"] = dict(lam=p.lam.tolist(), apex=apex.tolist(), limits=p.limits, ring_angle_deg=args.ring_angle)

    m, p = trace("uniform", args.ring_angle)
    apex = 10.0 - np.array([q.nodes[0, 1] for q in p.points])
    fig, ax = plt.subplots(figsize=(5.5, 4))
    curve_plot(ax, apex, p.lam, p.limits, THESIS["uniform_limit"], "apex deflection / t0",
               "Fig. 12: hemisphere with uniform vertical load")
    fig.tight_layout()
    fig.savefig(out / "fig12_uniform_load.png", dpi=130)
    curves["uniform"] = dict(lam=p.lam.tolist(), apex=apex.tolist(), limits=p.limits)

    # Fig. 13: deformed shapes -- before the limit at the thesis's A load, at the limit, and the last state traced
    lam = p.lam
    k_lim = int(np.argmax(lam))
    k_a = int(np.argmin(np.abs(lam[:k_lim + 1] - 0.0132747)))
    picks = [(k_a, "A (pre-limit)"), (k_lim, "limit point"), (len(lam) - 1, "last traced (post-limit)")]
    fig, ax = plt.subplots(figsize=(6, 4))
    s = np.linspace(0, np.pi / 2, 100)
    ax.plot(10 * np.sin(s), 10 * np.cos(s), color="0.6", ls="--", lw=1, label="undeformed")
    for (k, lab), c in zip(picks, ("C0", "C1", "C2")):
        sh = p.points[k].shape
        ax.plot(sh[:, 0], sh[:, 1], color=c, lw=1.5, label=f"{lab}: Λ = {lam[k]:.5f}")
    ax.set_aspect("equal")
    ax.set_xlabel("r / t0")
    ax.set_ylabel("z / t0")
    ax.set_title("Fig. 13: deformed shapes, uniform vertical load\n(thesis: A 0.0132747, B 0.0022892, "
                 "C -0.00658208)", fontsize=9)
    ax.legend(fontsize=7, loc="lower left")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "fig13_deformed_shapes.png", dpi=130)
    (out / "curves.json").write_text(json.dumps(curves, indent=1, default=float))
    print(f"wrote {out}/fig10..fig13 PNGs and curves.json")


if __name__ == "__main__":
    main()
