"""The thesis's Figures 10-13 (hemisphere, R0/t0 = 10, Mooney-Rivlin gamma = 0.1; edge on a
roller: z held, r and phi free) traced by graspdef.axisym (docs/axisym.md).

Fig. 10  load vs edge rotation, edge couples          (thesis: limit 3.363, max rotation 3.097)
Fig. 11  load vs apex deflection, ring load           (thesis: limit 0.958, max apex deflection 7.578)
Fig. 12  load vs apex deflection, uniform vertical    (thesis: limit 0.0156)
Fig. 13  deformed shapes, uniform vertical load       (thesis: A 0.0132747, B 0.0022892, C -0.00658208)

Reproduced: the edge-couple limit load (3.372 vs 3.363, +0.3 %).  Not reproduced: the maximum
edge rotation (our path ends at 2.21 rad where the constitutive relations stop being invertible,
thesis Ch. 5), the ring-load limit (the ring's position is in a figure missing from the text;
1.189 with the ring at 30 deg) and the uniform-load limit (0.02107 vs 0.0156; load/support
definition not recoverable) -- docs/axisym.md.  seed_readings.py computes every reading of the
ring and uniform loads we tried (ring angle, per radian / total / per length, C1 vs C1 + C2 vs mu;
load per deformed / undeformed / projected area, follower pressure, hinged or clamped edge, R0 to
the inner or outer surface): none reproduces 0.958 or 0.0156 (issue 16 item 5).

Full mode: each path runs until it cannot be continued or the load falls below -limit (the ring
load to full eversion).  Fast mode: each path stops shortly after its limit point (load below
90 % of the limit); the limit loads are the same.

    python scripts/gallery/thesis_fig10_13_hemisphere.py [--out DIR] [--fast] [--ring-angle 30]
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import numpy as np  # noqa: E402

import _common as C  # noqa: E402
from graspdef.axisym import hemisphere_example, solve_path  # noqa: E402
from graspdef.axisym.bench import THESIS  # noqa: E402

NAME = "thesis_fig10_13_hemisphere"
UNIFORM_A = 0.0132747          # the thesis's state A of Fig. 13


def trace(case: str, ring_angle_deg: float = 30.0, fast: bool = False):
    """The hemisphere path of ``case`` (edge_couple | ring | uniform): (model, PathResult)."""
    kw = {"ring_angle": np.radians(ring_angle_deg)} if case == "ring" else {}
    m = hemisphere_example(case, **kw)
    state = {}

    def stop(eq):
        state.setdefault("max", eq.lam)
        state["max"] = max(state["max"], eq.lam)
        return eq.lam < -state["max"] or 10.0 - eq.nodes[0, 1] > 19.0

    p = solve_path(m, ds=1.0, ds_max=3.0, max_steps=250, on_failure="stop", ds_min=1e-3, stop=stop,
                   unload_fraction=0.9 if fast else None)
    print(f"{case}: {len(p.points) - 1} steps, {p.seconds:.1f} s, limits "
          f"{[round(lim['lam'], 5) for lim in p.limits]}; end: {p.stopped_by[:90] or 'stop criterion'}")
    return m, p


def curve_plot(ax, x, lam, limits, ref, xlabel, title):
    ax.plot(x, lam, "-", color="C0", lw=1.5, label="graspdef.axisym")
    for lim in limits[:1]:
        ax.axhline(lim["lam"], color="C0", ls=":", lw=0.8)
        ax.annotate(f"limit {lim['lam']:.4g}", (x[int(np.argmax(lam))], lim["lam"]), textcoords="offset points",
                    xytext=(5, 5), color="C0", fontsize=8)
    ax.axhline(ref, color="C3", ls="--", lw=0.8, label=f"thesis limit {ref:g}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("nondimensional load  Λ")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)


def _limit(p) -> float:
    return float(p.limits[0]["lam"]) if p.limits else float("nan")


def main(argv: list[str] | None = None) -> dict:
    a = C.parse(NAME, __doc__, argv, lambda ap: ap.add_argument(
        "--ring-angle", type=float, default=30.0, help="ring position, deg from the apex"))
    clock = C.Timer()
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(2, 2, figsize=(10, 7.5))
    curves, key = {}, []

    m, p = trace("edge_couple", a.ring_angle, a.fast)
    rot = np.array([abs(q.nodes[1, 2] - m.nodes[1].phi) for q in p.points])
    curve_plot(axs[0, 0], rot, p.lam, p.limits, THESIS["edge_couple_limit"], "edge rotation |Δφ| (rad)",
               "Fig. 10: edge couples")
    axs[0, 0].axvline(THESIS["edge_max_rotation"], color="C3", ls=":", lw=0.8, label="thesis max rotation 3.097")
    axs[0, 0].legend(fontsize=7)
    curves["edge_couple"] = dict(lam=p.lam, edge_rotation_rad=rot, limits=p.limits, seconds=p.seconds)
    key.append({"figure": "10", "quantity": "edge couples, limit load", "thesis": THESIS["edge_couple_limit"],
                "graspdef": _limit(p), "verdict": "reproduced"})
    key.append({"figure": "10", "quantity": "edge couples, max edge rotation [rad]",
                "thesis": THESIS["edge_max_rotation"], "graspdef": float(rot.max()),
                "verdict": "not reproduced (path ends at the constitutive breakdown)"})

    m, p = trace("ring", a.ring_angle, a.fast)
    apex = 10.0 - np.array([q.nodes[0, 1] for q in p.points])
    curve_plot(axs[0, 1], apex, p.lam, p.limits, THESIS["ring_limit"], "apex deflection / t0",
               f"Fig. 11: ring load at {a.ring_angle:g}° from the apex")
    curves["ring"] = dict(lam=p.lam, apex=apex, limits=p.limits, ring_angle_deg=a.ring_angle, seconds=p.seconds)
    key.append({"figure": "11", "quantity": f"ring load at {a.ring_angle:g} deg, limit load",
                "thesis": THESIS["ring_limit"], "graspdef": _limit(p),
                "verdict": "not reproduced (ring position not in the text)"})

    m, p = trace("uniform", a.ring_angle, a.fast)
    apex = 10.0 - np.array([q.nodes[0, 1] for q in p.points])
    curve_plot(axs[1, 0], apex, p.lam, p.limits, THESIS["uniform_limit"], "apex deflection / t0",
               "Fig. 12: uniform vertical load")
    curves["uniform"] = dict(lam=p.lam, apex=apex, limits=p.limits, seconds=p.seconds)
    key.append({"figure": "12", "quantity": "uniform vertical load, limit load", "thesis": THESIS["uniform_limit"],
                "graspdef": _limit(p), "verdict": "not reproduced (load/support definition)"})

    # Fig. 13: deformed shapes -- before the limit at the thesis's A load, at the limit, the last state traced
    lam = p.lam
    k_lim = int(np.argmax(lam))
    k_a = int(np.argmin(np.abs(lam[:k_lim + 1] - UNIFORM_A)))
    picks = [(k_a, "A (pre-limit)"), (k_lim, "limit point"), (len(lam) - 1, "last traced")]
    ax = axs[1, 1]
    s = np.linspace(0, np.pi / 2, 100)
    ax.plot(10 * np.sin(s), 10 * np.cos(s), color="0.6", ls="--", lw=1, label="undeformed")
    shapes = {}
    for (k, lab), c in zip(picks, ("C0", "C1", "C2")):
        sh = p.points[k].shape
        ax.plot(sh[:, 0], sh[:, 1], color=c, lw=1.5, label=f"{lab}: Λ = {lam[k]:.5f}")
        shapes[lab] = dict(lam=float(lam[k]), r_over_t0=sh[:, 0], z_over_t0=sh[:, 1])
    ax.set_aspect("equal")
    ax.set_xlabel("r / t0")
    ax.set_ylabel("z / t0")
    ax.set_title("Fig. 13: deformed shapes, uniform load\n(thesis: A 0.0132747, B 0.0022892, C -0.00658208)",
                 fontsize=9)
    ax.legend(fontsize=7, loc="lower left")
    ax.grid(alpha=0.3)
    curves["uniform"]["shapes"] = shapes
    key.append({"figure": "13", "quantity": "uniform load, lowest post-limit load reached",
                "thesis": "B 0.0022892, C -0.00658208", "graspdef": float(lam[k_lim:].min()),
                "verdict": "B and C not reached (constitutive breakdown in the fold)"})
    fig.tight_layout()
    for k in key:
        if isinstance(k["thesis"], float) and np.isfinite(k["graspdef"]):
            k["difference_%"] = 100 * (k["graspdef"] - k["thesis"]) / k["thesis"]
    print(C.table(key, ["figure", "quantity", "thesis", "graspdef", "difference_%", "verdict"]))
    rec = {"figures": "thesis Figs. 10-13", "fast": a.fast, "key": key, "curves": curves, "seconds": clock()}
    return C.finish(a.out, NAME, rec, fig)


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
