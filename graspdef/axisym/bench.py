"""Comparison records for ``graspdef bench axisym``: the thesis's hemisphere examples, Reissner's point load on a
sphere (small-strain limit) and the Mooney-Rivlin balloon's pressure maximum.

Each record is {name, reference, value, rel_error, seconds, note}; reference (and rel_error) is None where there is
no published value.  Nondimensional values follow the thesis (lengths / t0, stresses / C1, nodal loads per radian).
"""
import time

import numpy as np

from .continuation import solve_load, solve_path
from .material import AxisymMaterial
from .problems import hemisphere_example, inflated_sphere, pinched_sphere

#: the thesis's Chapter 4 numbers
THESIS = {"edge_couple_limit": 3.363, "edge_max_rotation": 3.097, "ring_limit": 0.958, "ring_max_apex": 7.578,
          "uniform_limit": 0.0156}
#: path controls used for the hemispheres (arc-length in the weighted norm of continuation.solve_path)
PATH = dict(ds=1.0, ds_max=3.0, max_steps=200, on_failure="stop", ds_min=1e-3, unload_fraction=0.5)
RING_ANGLE_DEG = 30.0


def _rec(name, reference, value, seconds, note=""):
    rel = None if reference is None else abs(value - reference) / abs(reference)
    return dict(name=name, reference=reference, value=float(value), rel_error=rel, seconds=round(seconds, 3),
                note=note)


def hemisphere_path(case, **kw):
    """Trace one thesis hemisphere path: start -> limit point -> unloading to half the limit load (ring: to the
    post-buckling minimum of the load), or until the constitutive relations stop being invertible.
    Returns (model, PathResult)."""
    opts = dict(rk_steps=1, max_piece=0.6)
    if case == "ring":
        opts["ring_angle"] = np.radians(RING_ANGLE_DEG)
    opts.update(kw)
    m = hemisphere_example(case, **opts)
    path = dict(PATH)
    if case == "ring":
        hist = []

        def valley(eq):  # past the maximum, stop when the load starts rising again
            hist.append(eq.lam)
            k = int(np.argmax(hist))
            return k < len(hist) - 2 and hist[-1] > hist[-2]

        path.update(unload_fraction=None, stop=valley)
    return m, solve_path(m, **path)


def reissner_point_load(R_over_t=300.0, contact=0.1):
    """Pole deflection of a sphere squeezed by two opposite point forces, small strain: (value, reference) in m.

    Reissner (1946) / ../shared/BENCHMARKS.md 2.4: delta = sqrt(3 (1 - nu^2)) F R / (4 E t^2), nu = 1/2,
    E = 3 mu = 6 (C1 + C2).  Load chosen so that delta = 0.01 t (linear range)."""
    mat = AxisymMaterial("mooney_rivlin", C1=1.0e5, gamma=0.1)
    R, t = 1.0, 1.0 / R_over_t
    E = 3.0 * mat.mu
    F = 0.01 * t * E * t * t / (0.375 * R)
    m = pinched_sphere(R, t, mat, F=F, contact_radius=contact * t, max_piece=1e3)  # small strain: ell-graded only
    eq = solve_load(m, 1.0)
    return -(eq.nodes[0, 1] * t - R), 0.375 * F * R / (E * t * t)


def balloon_pmax(R_over_t=20.0, gamma=0.1):
    """Maximum inflation pressure p_max R0/(C1 t0) of a Mooney-Rivlin sphere (BENCHMARKS.md 4.2: 2.98124 for
    gamma = 0.1, membrane theory; bending adds O((t/R)^2))."""
    mat = AxisymMaterial("mooney_rivlin", C1=1.0, gamma=gamma)
    m = inflated_sphere(1.0, 1.0 / R_over_t, mat, p=1.0 / R_over_t, max_piece=0.4)
    path = solve_path(m, ds=10.0, ds_max=100.0, max_steps=80, unload_fraction=0.999, on_failure="stop")
    return path.limits[0]["lam"] if path.limits else float("nan")


def run_axisym_bench(progress=None):
    """Run the axisymmetric benchmarks; progress(name) is called before each.  Returns a list of records."""
    out = []

    def say(name):
        if progress:
            progress(name)

    say("hemisphere edge couples")
    t0 = time.perf_counter()
    m, p = hemisphere_path("edge_couple")
    s = time.perf_counter() - t0
    lim = p.limits[0]["lam"] if p.limits else max(p.lam)
    edge = len(m.nodes) - 1
    rot = max(abs(q.nodes[edge, 2] - m.nodes[edge].phi) for q in p.points)
    out.append(_rec("hemisphere_edge_couple_limit_load", THESIS["edge_couple_limit"], lim, s,
                    "couple turning the edge inward"))
    out.append(_rec("hemisphere_edge_couple_max_edge_rotation", THESIS["edge_max_rotation"], rot, s,
                    "our path ends shortly after the limit point: " + p.stopped_by[:120]))
    say("hemisphere ring load")
    t0 = time.perf_counter()
    m, p = hemisphere_path("ring")
    s = time.perf_counter() - t0
    out.append(_rec(f"hemisphere_ring{RING_ANGLE_DEG:g}deg_limit_load", THESIS["ring_limit"], p.limits[0]["lam"], s,
                    "ring position not given in the thesis text (Fig. 11); see docs/axisym.md for the sweep"))
    k = int(np.argmin(p.lam[int(np.argmax(p.lam)):])) + int(np.argmax(p.lam))
    out.append(_rec(f"hemisphere_ring{RING_ANGLE_DEG:g}deg_apex_deflection_at_postbuckling_load_minimum", None,
                    m.nodes[0].z - p.points[k].nodes[0, 1], s,
                    f"thesis: maximum apex deflection 7.578 over its traced path (not the same quantity); "
                    f"load there {p.lam[k]:.4f}"))
    say("hemisphere uniform vertical load")
    t0 = time.perf_counter()
    m, p = hemisphere_path("uniform")
    s = time.perf_counter() - t0
    out.append(_rec("hemisphere_uniform_limit_load", THESIS["uniform_limit"], p.limits[0]["lam"], s,
                    "load per unit deformed area"))
    say("Reissner point load on a sphere")
    t0 = time.perf_counter()
    val, ref = reissner_point_load()
    out.append(_rec("sphere_point_load_R_t_300_pole_deflection", ref, val, time.perf_counter() - t0,
                    "m; linear shallow-shell formula, deep-shell correction O(sqrt(t/R))"))
    say("Mooney-Rivlin balloon")
    t0 = time.perf_counter()
    out.append(_rec("balloon_mooney_rivlin_gamma0.1_pmax", 2.98124, balloon_pmax(), time.perf_counter() - t0,
                    "p_max R0/(C1 t0), R/t = 20 (membrane reference; bending O(t/R))"))
    return out
