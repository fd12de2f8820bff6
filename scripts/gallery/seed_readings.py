"""Issue 16 item 5: the four seed numbers graspdef does not reproduce, each under every reading of
the garbled seed text (or unstated convention) that is cheap to compute.  One row per reading:
number | reading | graspdef | published | matches (within 2 %)?

Sources (line numbers in ../shared/seeds/):

thesis_axisymmetric_hyperelastic_shells.txt (hemisphere R0/t0 = 10, Mooney-Rivlin gamma = 0.1,
"unrestrained edges", l. 2115-2118; edge on a roller as in thesis_fig10_13_hemisphere.py):
* Fig. 11 ring load, limit 0.958, "maximum nondimensional apex deflection experienced during the
  deformation is 7.578" (l. 2130-2140).  The ring is "applied as shown" (l. 2133): its position is
  only in the missing figure.  Nodal forces are nondimensionalised per radian as F/(t0^2 C1)
  ((2.81), l. 938-957, garbled; the same normalisation of the couple reproduces Fig. 10's 3.363,
  the control row).  Readings: ring at 30 deg (the gallery default), 45 deg, 60 deg; small angles
  (8 deg) for the total-force reading; load per radian / C1 (the solver's), total ring force
  (x 2 pi), per unit undeformed ring length (/ rho0), divided by C1 + C2 or mu = 2 (C1 + C2)
  instead of C1 (the input card's "G - material constant", l. 1951); and the ring angle fitted to
  0.958 (26.94 deg) -- a fit, checked against the second number, the apex deflection at the
  post-buckling load minimum (thesis 7.578; also at 30 and 32 deg, where it comes closer).
* Fig. 12 uniform vertical load, limit 0.0156 (l. 2143-2150; Fig. 13 states A 0.0132747,
  B 0.0022892, C -0.00658208, l. 2169-2175; "the horizontal position of the supports is nearly
  identical", l. 2153-2156).  Distributed loads are "measured ... per unit of deformed area"
  (l. 522-524); the program's cards have horizontal, vertical and normal distributed loads
  (DPH, DPV, DPN, l. 2003-2013); the nondimensional distributed load is not legible in (2.81).
  Readings: per deformed area (the solver's default), per undeformed area, per undeformed
  projected (horizontal) area, follower pressure (DPN), edge hinged (r, z held) or clamped
  instead of the roller, R0/t0 = 10 measured to the inner (R_mid = 10.5) or outer (9.5) surface,
  the shell energy with the volume element kept, and the C1 + C2 and mu normalisations.

paper_shell_objects_grasped_by_robot_hand.txt (Tian & Jia 2010, Fig. 6, l. 739-763):
* Monkey saddle x^3 - 3xy^2 = 5000 z on [-50, 50]^2, E 100, nu 0, t 1.0, P 5.0 N, max.
  displacement "286" (l. 756: the decimal point is lost, so 28.6, 2.86 or 286; the table's other
  decimals are legible, "34:3", "0:3", "1.0").  "simply supported shells ... its edge does not
  change position" (l. 739-745).  SI units throughout (l. 736-738); a consistent change of units
  (MPa with mm) leaves the number unchanged, so units are not a reading.  Readings: edges hinged
  (all three displacements held; the gallery default), clamped, shear diaphragm (normal and
  tangential displacement held, in-plane normal free), vertical rollers (only z held on the
  boundary; corners pinned in plane against rigid motion), free edges with the four corners
  pinned, and the height coefficient read as 50000 or 500 instead of 5000.
* Half ellipsoid, E 1000, nu 0.3, t 1.0, P 20.0 N, max. displacement 34.3 (l. 752-760); its
  semi-axes are illegible ("(%z,Z + i'? + 5z =1", l. 761).  Readings: a = b = 50 (the saddle's
  footprint) with c = 25 (the gallery's assumption), 50, 5; a = b = 100 with c = 50, 25.  Bound:
  a flat simply supported circular plate of radius a under a central load deflects
  P a^2 (3 + nu) / (16 pi D (1 + nu)) (Timoshenko) = 27.57 for a = 50; a curved shell on the same
  footprint is stiffer, so 34.3 needs a footprint radius >= 55.8.

Full mode: the thesis ring paths are traced to eversion or breakdown at 8, 26.94, 30, 32, 45, 60 deg
(about 8 s each); saddle 40 x 40 cells; ellipsoid 32 rings.  Fast mode (the test): the control
row (edge couples), the ring at 30 deg, the uniform load per deformed area and as a pressure,
the arithmetic normalisations, the saddle (hinged) at 16 x 16 cells, the plate bound.

    python scripts/gallery/seed_readings.py [--out DIR] [--fast]
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import numpy as np  # noqa: E402

import _common as C  # noqa: E402
import paper_fig06_point_loads as F6  # noqa: E402
from graspdef.axisym import DistributedLoad, Model, Segment, hemisphere_example, solve_path  # noqa: E402
from graspdef.axisym.problems import _sphere_nodes  # noqa: E402

NAME = "seed_readings"
GAMMA = 0.1
PUBLISHED = {"ring": 0.958, "ring_apex": 7.578, "uniform": 0.0156, "saddle": (28.6, 2.86, 286.0),
             "ellipsoid": 34.3, "edge_couple": 3.363}
RING_FIT_DEG = 26.94          # the ring angle at which the per-radian / C1 limit is 0.958


# ---- thesis: hemisphere paths (graspdef.axisym) -----------------------------------------------

def _path(m, fast: bool):
    """Trace ``m`` as thesis_fig10_13_hemisphere.trace does: (limit load, apex deflection at the
    first post-limit load minimum or None, edge radius at the limit, path)."""
    st = {}

    def stop(eq):
        st["max"] = max(st.get("max", eq.lam), eq.lam)
        return eq.lam < -st["max"] or 10.0 - eq.nodes[0, 1] > 19.0

    p = solve_path(m, ds=1.0, ds_max=3.0, max_steps=250, on_failure="stop", ds_min=1e-3, stop=stop,
                   unload_fraction=0.9 if fast else None)
    lam = np.asarray(p.lam)
    apex = 10.0 - np.array([q.nodes[0, 1] for q in p.points])
    k = int(np.argmax(lam))
    mins = [i for i in range(max(k, 1), len(lam) - 1) if lam[i] < lam[i - 1] and lam[i] <= lam[i + 1]]
    limit = float(p.limits[0]["lam"]) if p.limits else float("nan")
    print(f"  {m.name}: {len(lam) - 1} steps, {p.seconds:.1f} s, limits {[round(x['lam'], 4) for x in p.limits]}",
          flush=True)
    apex_min = None
    if mins:                         # the load minimum is flat: vertex of the parabola lam(apex) through 3 points
        i = mins[0]
        a2, a1, _ = np.polyfit(apex[i - 1:i + 2], lam[i - 1:i + 2], 2)
        apex_min = float(-a1 / (2 * a2)) if a2 > 0 else float(apex[i])
    return limit, apex_min, float(p.points[k].shape[-1, 0]), p


def _projected_uniform():
    """Uniform vertical load per unit undeformed *projected* (horizontal) area: 18 bands of 5 deg,
    each with the band's exact mean of cos(theta) per undeformed area (the band's total is exact)."""
    base = hemisphere_example("uniform")
    th = np.linspace(0.0, np.pi / 2, 19)
    nodes = _sphere_nodes(10.0, list(th), (False, True, False))
    segs = [Segment(k, k + 1, kappa=-0.1) for k in range(18)]
    dl = [DistributedLoad(QV=-(np.sin(b) ** 2 - np.sin(a) ** 2) / 2 / (np.cos(a) - np.cos(b)), segments=[k])
          for k, (a, b) in enumerate(zip(th[:-1], th[1:]))]
    return Model(base.material, 1.0, nodes, segs, [], dl, max_piece=0.6, rk_steps=1, name="hemisphere_projected")


def _uniform_variant(kind: str):
    if kind == "projected":
        return _projected_uniform()
    m = hemisphere_example("uniform", **({"R_over_t": 10.5} if kind == "R10.5" else {"R_over_t": 9.5} if kind == "R9.5"
                                          else {"volume_factor": True} if kind == "volume" else
                                          {"load_basis": "reference"} if kind == "undeformed" else {}))
    if kind == "pressure":
        m.distributed_loads = [DistributedLoad(p=-1.0)]        # inward (external) follower pressure
    if kind in ("hinged", "clamped"):
        m.nodes[-1].fix = (True, True, kind == "clamped")
    m.name = f"hemisphere_uniform_{kind}"
    return m


def thesis_rows(fast: bool) -> list[dict]:
    rows = []

    def row(number, reading, value, published, source, note="", verdict=None):
        r = {"number": number, "reading": reading, "graspdef": value, "published": published, "source": source,
             "note": note}
        r["ratio"] = value / published if value is not None and np.isfinite(value) else None
        r["matches"] = verdict or ("yes" if r["ratio"] is not None and abs(r["ratio"] - 1) < 0.02 else "no")
        rows.append(r)
        return r

    lim, _, _, _ = _path(hemisphere_example("edge_couple"), fast)
    row("thesis Fig. 10 edge couples 3.363 (control)", "couple per radian / (t0^3 C1), roller edge", lim,
        PUBLISHED["edge_couple"], "l. 2121-2128", "the normalisation of the nodal loads is right")

    ring = {}
    for ang in ([30.0] if fast else [8.0, RING_FIT_DEG, 30.0, 32.0, 45.0, 60.0]):
        lim, apex_min, _, _ = _path(hemisphere_example("ring", ring_angle=np.radians(ang)), fast)
        ring[ang] = (lim, apex_min)
    n = "thesis Fig. 11 ring load 0.958"
    src = "l. 2130-2140; (2.81) l. 938-957"
    rho0 = lambda a: 10.0 * np.sin(np.radians(a))                            # noqa: E731
    for ang in (30.0, 45.0, 60.0):
        if ang not in ring:
            continue
        lim, apex_min = ring[ang]
        note = f"apex at post-buckling minimum {apex_min:.2f} (thesis max. apex 7.578)" if apex_min else ""
        row(n, f"ring at {ang:g} deg, force per radian / (t0^2 C1)", lim, 0.958, src, note)
        row(n, f"ring at {ang:g} deg, total ring force / (t0^2 C1) (= 2 pi x)", 2 * np.pi * lim, 0.958, src)
        row(n, f"ring at {ang:g} deg, force per unit undeformed ring length / (t0 C1) (= / rho0)", lim / rho0(ang),
            0.958, src)
        row(n, f"ring at {ang:g} deg, per radian / (C1 + C2)", lim / (1 + GAMMA), 0.958, src + "; l. 1951")
        row(n, f"ring at {ang:g} deg, per radian / mu, mu = 2 (C1 + C2)", lim / (2 * (1 + GAMMA)), 0.958,
            src + "; l. 1951")
    if 8.0 in ring:
        row(n, "ring at 8 deg (near the apex), total ring force / (t0^2 C1)", 2 * np.pi * ring[8.0][0], 0.958, src,
            "the lowest first limit found (per radian 0.28); exploratory runs at 5-7 deg: first limit 0.59 or none")
    if RING_FIT_DEG in ring:
        lim, apex_min = ring[RING_FIT_DEG]
        row(n, f"ring at {RING_FIT_DEG:g} deg (FITTED to 0.958), per radian / (t0^2 C1)", lim, 0.958, src,
            f"second number: apex at the post-buckling load minimum {apex_min:.2f} vs 7.578",
            verdict="fit, not a reproduction")
        for ang in (RING_FIT_DEG, 30.0, 32.0):
            lim, apex_min = ring[ang]
            row("thesis Fig. 11 max. apex deflection 7.578", f"ring at {ang:g} deg (limit {lim:.3f} per radian), "
                "apex deflection at the post-buckling load minimum (the path then runs on to eversion, 19)",
                apex_min, 7.578, "l. 2137-2140",
                "32 deg was chosen (exploratory runs) to bring this near 7.578; its limit is then "
                f"{lim:.3f}, not 0.958: no one ring angle gives both" if ang == 32.0 else "",
                verdict="fit, not a reproduction" if ang == 32.0 else None)
    n = "thesis Fig. 12 uniform load 0.0156"
    src = "l. 2143-2150; loads per deformed area l. 522-524; DPV/DPN l. 2003-2013"
    kinds = (["deformed", "pressure"] if fast else
             ["deformed", "undeformed", "projected", "pressure", "hinged", "clamped", "R10.5", "R9.5", "volume"])
    label = {"deformed": "dead vertical load per unit deformed area, roller edge (the solver's)",
             "undeformed": "vertical load per unit undeformed area",
             "projected": "vertical load per unit undeformed projected (horizontal) area",
             "pressure": "follower pressure (normal, DPN) instead of a vertical load",
             "hinged": "per deformed area, edge hinged (r and z held)",
             "clamped": "per deformed area, edge clamped",
             "R10.5": "R0/t0 = 10 to the inner surface (mid-surface R = 10.5)",
             "R9.5": "R0/t0 = 10 to the outer surface (mid-surface R = 9.5)",
             "volume": "shell energy keeping the volume element (not the thesis's 2.73)"}
    for kind in kinds:
        lim, _, r_edge, p = _path(_uniform_variant(kind), fast)
        row(n, label[kind], lim, 0.0156, src, f"edge radius at the limit {r_edge:.2f} (undeformed 10)")
        if kind == "clamped" and len(p.limits) > 1:
            # the clamped path falls from its limit and then creeps along a flat plateau near 0.0155 while the
            # inverted cap grows; a second, flat maximum there lies within 2 % of 0.0156 -- see the note
            lam = np.asarray(p.lam)
            apex = 10.0 - np.array([q.nodes[0, 1] for q in p.points])
            k2 = int(p.limits[1]["step"])
            k1 = int(np.argmax(lam))
            j = k1 + int(np.argmax(lam[k1:] < 0.0158))
            row(n, "per deformed area, edge clamped: the SECOND, flat load maximum (after the limit)",
                float(p.limits[1]["lam"]), 0.0156, src,
                f"plateau: load within 0.0150-0.0158 for apex {apex[j]:.1f}-{apex[-1]:.1f}, "
                f"maximum at apex {apex[k2]:.1f}; not the thesis's curve: its first (sharp) limit is 0.0432, the "
                f"load never falls below {lam[k2:].min():.4f} (thesis B 0.0023, C -0.0066 at apex 9.7), and the "
                "thesis's edges are 'unrestrained'",
                verdict="coincidence, not a reproduction")
        if kind == "deformed":
            row(n, "per deformed area, load divided by C1 + C2", lim / (1 + GAMMA), 0.0156, src + "; l. 1951")
            row(n, "per deformed area, load divided by mu = 2 (C1 + C2)", lim / (2 * (1 + GAMMA)), 0.0156,
                src + "; l. 1951")
    return rows


# ---- paper Fig. 6: linear shells (graspdef 3-D solver) -----------------------------------------

def saddle(n: int, kind: str = "simply_supported", scale: float = 5000.0) -> float:
    """Max. displacement of the monkey saddle under 5 N at the centre with edge condition ``kind``:
    simply_supported | clamped | diaphragm | roller | corners."""
    from graspdef.geometry import monkey_saddle
    from graspdef.problem.loads import PointLoad
    from graspdef.problem.problem import Problem
    from graspdef.problem.supports import EdgeSupport, PointSupport
    from graspdef.shell.materials import LinearElastic
    from graspdef.shell.model import Shell
    from graspdef.solve.linear import solve_linear

    mesh = monkey_saddle(50.0, n, scale)
    sh = Shell(mesh.vertices, mesh.faces, LinearElastic(100.0, 0.0), 1.0)
    ex = lambda p: np.abs(np.abs(p[:, 0]) - 50) < 1e-6                      # noqa: E731
    ey = lambda p: np.abs(np.abs(p[:, 1]) - 50) < 1e-6                      # noqa: E731
    v = mesh.vertices
    if kind == "diaphragm":
        sup = [EdgeSupport("diaphragm", ex, normal=(1, 0, 0), name="x edges"),
               EdgeSupport("diaphragm", ey, normal=(0, 1, 0), name="y edges")]
    elif kind in ("roller", "corners"):
        base = Problem(sh, [], [EdgeSupport("free", lambda p: ex(p) | ey(p))])
        corner = np.all(np.isclose(np.abs(v[:, :2]), 50.0), axis=1)
        picks = np.where((ex(v) | ey(v)) if kind == "roller" else corner)[0]
        sup = []
        for i in picks:
            pt = base.locate(v[i], f"b{i}")
            dirs = ((0, 0, 1),)
            if corner[i] or kind == "corners":
                dirs = ((1, 0, 0), (0, 1, 0), (0, 0, 1))
            sup.append(PointSupport(pt.face, pt.bary, directions=dirs, name=f"b{i}"))
    else:
        sup = [EdgeSupport(kind, lambda p: ex(p) | ey(p))]
    pt = Problem(sh, [], sup).locate([0.0, 0.0, 0.0], "load point")
    sol = solve_linear(Problem(sh, [PointLoad(pt.face, pt.bary, (0.0, 0.0, -5.0))], sup, {"P": pt}))
    return float(sol.max_displacement())


def paper_rows(fast: bool) -> list[dict]:
    rows = []
    n = 16 if fast else 40
    src = "l. 739-763"
    readings = [("simply_supported", 5000.0, "edges hinged (all displacements held; the gallery's)")]
    if not fast:
        readings += [("clamped", 5000.0, "edges clamped"),
                     ("diaphragm", 5000.0, "shear diaphragm (normal + tangential held, in-plane normal free)"),
                     ("roller", 5000.0, "vertical rollers (only z held on the edge; corners pinned)"),
                     ("corners", 5000.0, "free edges, the four corners pinned"),
                     ("simply_supported", 50000.0, "hinged, height coefficient 50000 (a 10x flatter saddle)"),
                     ("simply_supported", 500.0, "hinged, height coefficient 500 (10x deeper)")]
    for kind, scale, lab in readings:
        u = saddle(n, kind, scale)
        near = min(PUBLISHED["saddle"], key=lambda x: abs(np.log(u / x)))
        print(f"  saddle {kind} {scale:g}: {u:.4g}", flush=True)
        rows.append({"number": 'paper Fig. 6 saddle "286" (28.6 / 2.86 / 286)', "reading": f"{lab}, {n} x {n} cells",
                     "graspdef": u, "published": near, "ratio": u / near, "source": src,
                     "matches": "yes" if abs(u / near - 1) < 0.02 else "no",
                     "note": f"nearest decimal reading {near:g}"})
    axes = [] if fast else [(50.0, 50.0, 25.0), (50.0, 50.0, 50.0), (50.0, 50.0, 5.0),
                                             (100.0, 100.0, 50.0), (100.0, 100.0, 25.0)]
    rings = 16 if fast else 32
    for ax in axes:
        u = F6.half_ellipsoid(rings, ax)[0]
        print(f"  ellipsoid {ax}: {u:.4g}", flush=True)
        rows.append({"number": "paper Fig. 6 half ellipsoid 34.3", "reading": f"semi-axes {ax}, {rings} rings",
                     "graspdef": u, "published": 34.3, "ratio": u / 34.3, "source": src + "; axes l. 761",
                     "matches": "yes" if abs(u / 34.3 - 1) < 0.02 else "no", "note": ""})
    plate = 20.0 * 50.0 ** 2 * 3.3 / (16 * np.pi * (1000.0 / (12 * (1 - 0.09))) * 1.3)
    rows.append({"number": "paper Fig. 6 half ellipsoid 34.3", "reading": "bound: flat circular plate a = 50, "
                 "simply supported, Timoshenko (no run)", "graspdef": plate, "published": 34.3,
                 "ratio": plate / 34.3, "source": "Timoshenko & Woinowsky-Krieger, eq. (90)", "matches": "no",
                 "note": "a shell on the same footprint is stiffer: no a = b <= 50 reaches 34.3"})
    return rows


def figure(rows: list[dict]):
    import matplotlib.pyplot as plt
    groups = list(dict.fromkeys(r["number"] for r in rows))
    fig, axs = plt.subplots(len(groups), 1, sharex=True,
                            figsize=(10, 1.1 + 0.3 * len(rows) + 0.45 * len(groups)),
                            gridspec_kw={"height_ratios": [sum(r["number"] == g for r in rows) + 1 for g in groups]})
    for ax, g in zip(np.atleast_1d(axs), groups):
        rs = [r for r in rows if r["number"] == g and r["ratio"] is not None]
        y = np.arange(len(rs))
        for yi, r in zip(y, rs):
            c = "C2" if r["matches"] == "yes" else "C1" if r["matches"].startswith(("fit", "coincidence")) else "C0"
            ax.plot([1.0, r["ratio"]], [yi, yi], color=c, lw=2)
            ax.plot(r["ratio"], yi, "o", color=c, ms=5)
        ax.axvline(1.0, color="C3", lw=1)
        ax.axvspan(0.98, 1.02, color="C3", alpha=0.2)
        ax.set_xscale("log")
        ax.set_xlim(0.01, 30)
        ax.set_ylim(len(rs) - 0.4, -0.6)
        ax.set_yticks(y, [r["reading"][:75] for r in rs], fontsize=6)
        ax.set_title(g, fontsize=8, loc="left")
        ax.grid(axis="x", alpha=0.3)
    last = np.atleast_1d(axs)[-1]
    last.set_xticks([0.01, 0.03, 0.1, 0.3, 0.5, 1, 2, 3, 10, 30], ["0.01", "0.03", "0.1", "0.3", "0.5", "1", "2", "3",
                                                                "10", "30"], fontsize=7)
    last.set_xlabel("graspdef / published (log; band = ±2 %; green = match, orange = fitted or coincidence)")
    fig.tight_layout()
    return fig


def main(argv: list[str] | None = None) -> dict:
    a = C.parse(NAME, __doc__, argv)
    clock = C.Timer()
    rows = thesis_rows(a.fast) + paper_rows(a.fast)
    print(C.table(rows, ["number", "reading", "graspdef", "published", "ratio", "matches", "note"]))
    status = {}
    for key, label in (("ring", "thesis Fig. 11 ring load 0.958"), ("uniform", "thesis Fig. 12 uniform load 0.0156"),
                       ("saddle", 'paper Fig. 6 saddle "286" (28.6 / 2.86 / 286)'),
                       ("ellipsoid", "paper Fig. 6 half ellipsoid 34.3")):
        m = [r["reading"] for r in rows if r["number"] == label and r["matches"] == "yes"]
        status[key] = {"readings_tried": sum(r["number"] == label for r in rows), "reproduced_by": m}
    control = rows[0]
    key = {"control_edge_couple_limit": control["graspdef"], "control_published": control["published"],
           "status": status}
    rec = {"issue": "16 item 5", "fast": a.fast, "rows": rows, "key": key, "seconds": clock()}
    print(f"{clock():.0f} s")
    return C.finish(a.out, NAME, rec, figure(rows), rows)


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
