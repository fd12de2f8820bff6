"""Benchmark sets: every ``benchmarks/*.toml`` with a ``[reference]`` table is solved and the
quantity it names is compared with the published or analytic value.

``quantity`` forms: ``[-]probe.NAME.COMP`` with COMP one of x, y, z, radial (along the position
vector from the origin), radial_xy (along the position's projection on the xy-plane, for
cylinders), norm; or ``max_displacement``.  Values are in the file's units.
"""
from __future__ import annotations

import fnmatch
import time
from pathlib import Path
from typing import Callable

import numpy as np

from .errors import ProblemError
from .problem.config import load_problem
from .solve.linear import solve_linear
from .solve.output import result_record


def ring_pinched_sphere(shell, R: float, a: float, n_ring: int, force: float):
    """A free sphere of radius R (``shell``) squeezed by two rings of ``n_ring`` point loads (total
    ``force`` per ring, axial, towards the equator) at the polar circles of radius a R -- the 3-D
    counterpart of the thesis's ring-loaded ball (scripts/crosscheck_axisym_3d.py,
    scripts/synthetic_scan_study.py); probes "top" and "bottom" at the poles."""
    from .problem.loads import PointLoad
    from .problem.problem import Problem
    from .problem.supports import RigidModes

    pr = Problem(shell, [], [RigidModes()])
    zc = np.sqrt(R ** 2 - (a * R) ** 2)
    for s in (1.0, -1.0):
        for k in range(n_ring):
            th = 2 * np.pi * (k + 0.5) / n_ring
            p = pr.locate((a * R * np.cos(th), a * R * np.sin(th), s * zc))
            pr.loads.append(PointLoad(p.face, p.bary, (0.0, 0.0, -s * force / n_ring)))
    pr.probes["top"] = pr.locate((0.0, 0.0, R))
    pr.probes["bottom"] = pr.locate((0.0, 0.0, -R))
    return pr


def quantity(rec: dict, expr: str) -> float:
    """Evaluate a reference quantity expression on a result record."""
    sign = -1.0 if expr.startswith("-") else 1.0
    body = expr.lstrip("-").strip()
    if body == "max_displacement":
        return sign * rec["max_displacement"]
    parts = body.split(".")
    if len(parts) != 3 or parts[0] != "probe" or parts[1] not in rec["probes"]:
        raise ProblemError(f"reference quantity {expr!r}: expected probe.NAME.COMP with a defined probe")
    p = rec["probes"][parts[1]]
    u, x = np.array(p["displacement"]), np.array(p["position"])
    comp = parts[2]
    if comp in ("x", "y", "z"):
        return sign * float(u["xyz".index(comp)])
    if comp == "radial":
        return sign * float(u @ x / np.linalg.norm(x))
    if comp == "radial_xy":
        return sign * float(u[:2] @ x[:2] / np.linalg.norm(x[:2]))
    if comp == "norm":
        return sign * float(np.linalg.norm(u))
    raise ProblemError(f"reference quantity {expr!r}: unknown component {comp!r}")


def in_file_units(rec, length_scale: float) -> dict:
    """The probes and the max displacement of a run record (SI) in the problem file's length unit,
    the form :func:`quantity` reads."""
    probes = {n: {"position": (np.asarray(p["position"]) / length_scale).tolist(),
                  "displacement": (np.asarray(p["displacement"]) / length_scale).tolist()}
              for n, p in rec["probes"].items()}
    return {"probes": probes, "max_displacement": rec.value("max_displacement") / length_scale}


def run_benchmark(path: Path) -> dict:
    """Solve one benchmark file; return its comparison record."""
    t0 = time.perf_counter()
    spec = load_problem(path)
    sol = solve_linear(spec.problem, backend=spec.backend, precision=spec.precision)
    seconds = time.perf_counter() - t0
    rec = result_record(spec, sol)
    ref = spec.reference
    value = quantity(in_file_units(rec, spec.length_scale), ref["quantity"])
    reference = float(ref["value"])
    tol = ref.get("tolerance")
    rel = (value - reference) / abs(reference)
    return {
        "name": spec.name, "reference": reference, "value": value, "rel_error": rel,
        "tolerance": tol, "passed": bool(tol is None or abs(rel) <= tol),
        "n_control": rec["n_control"], "seconds": seconds, "source": ref.get("source", ""),
        "units": spec.length_unit,
    }


def benchmark_files(folder: Path, pattern: str = "*") -> list[Path]:
    """The problem files of a benchmark folder whose names match ``pattern`` (a glob)."""
    files = sorted(folder.glob("*.toml"))
    if not files:
        raise ProblemError(f"no benchmark files (*.toml) in {folder}")
    return [f for f in files if fnmatch.fnmatch(f.stem, pattern)]


def run_linear_benchmarks(folder: Path, pattern: str = "*",
                          progress: Callable[[str], None] = lambda m: None) -> list[dict]:
    records = []
    for f in benchmark_files(folder, pattern):
        progress(f"benchmark {f.stem} ...")
        r = run_benchmark(f)
        progress(f"  {r['name']}: {r['value']:.6g} vs {r['reference']:.6g} ({100 * r['rel_error']:+.2f} %), "
                 f"{r['n_control']} control vertices, {r['seconds']:.1f} s")
        records.append(r)
    return records


def format_table(records: list[dict]) -> str:
    lines = ["| benchmark | reference | graspdef | error | tolerance | control vertices | time [s] |",
             "|---|---|---|---|---|---|---|"]
    for r in records:
        tol = r.get("tolerance")
        tol = "report only" if tol is None else f"{100 * tol:.1f} %"
        mark = "" if r.get("passed", True) else " (outside)"
        ref = "–" if r.get("reference") is None else f"{r['reference']:.6g}"
        err = "–" if r.get("rel_error") is None else f"{100 * r['rel_error']:+.3f} %"
        lines.append(f"| {r['name']} | {ref} | {r['value']:.6g} | {err}{mark} | {tol} | {r.get('n_control', '–')} "
                     f"| {r['seconds']:.1f} |")
    return "\n".join(lines)


# ---- the nonlinear set: benchmarks/nonlinear/*.toml --------------------------------------------

def _point_quantity(spec, sol, point, expr: str) -> float:
    """``quantity`` on one path point (same forms as the linear set)."""
    ls = spec.length_scale
    mesh = sol.problem.shell.mesh
    probes = {}
    for name, pt in sol.problem.probes.items():
        st, w = sol.problem.evaluator.values(pt.face, np.asarray(pt.bary))
        probes[name] = {"position": (w @ mesh.vertices[st] / ls).tolist(),
                        "displacement": (np.asarray(point.probes[name]) / ls).tolist()}
    return quantity({"probes": probes, "max_displacement": float("nan")}, expr)


def balloon_pressure(stretch, C1: float, C2: float) -> np.ndarray:
    """Thin incompressible Mooney-Rivlin balloon: true pressure p R0 / t0 at stretch lambda,
    4 C1 (1/l - 1/l^7)(1 + (C2/C1) l^2) (../shared/BENCHMARKS.md 4.2; neo-Hookean: C2 = 0)."""
    lam = np.asarray(stretch, float)
    return 4.0 * (C1 / lam - C1 / lam ** 7) * (1.0 + (C2 / C1) * lam ** 2)


def _balloon_records(spec, sol, ref, tol, n_control, seconds):
    from .problem.potentials import FollowerPressure
    from .shell.volume import EnclosedVolume

    shell = sol.problem.shell
    mat = shell.material
    C1, C2 = (mat.C1, mat.C2) if hasattr(mat, "C2") else (mat.mu / 2.0, 0.0)
    t0 = float(np.asarray(shell.thickness))
    p_ref = next(ld.p for ld in sol.problem.loads if isinstance(ld, FollowerPressure))
    vol = EnclosedVolume(shell)
    V0 = vol.value(shell.rest_positions)
    R0 = (3.0 * V0 / (4.0 * np.pi)) ** (1.0 / 3.0)
    scale = R0 / (C1 * t0)                                   # p in units of C1 t0 / R0
    records = []

    def rec(name, reference, value, tolerance):
        records.append({"name": f"{spec.name} {name}", "reference": float(reference), "value": float(value),
                        "rel_error": float((value - reference) / abs(reference)), "tolerance": tolerance,
                        "passed": bool(abs((value - reference) / reference) <= tolerance), "n_control": n_control,
                        "seconds": seconds, "source": ref.get("source", ""), "units": "C1 t0 / R0"})

    for p in sol.path[1:]:
        if p.kind == "refine":
            continue
        lam = (vol.value(shell.rest_positions + p.u) / V0) ** (1.0 / 3.0)
        rec(f"p(stretch={lam:.4f})", balloon_pressure(lam, C1, C2) / C1, p.load_factor * p_ref * scale, tol)
    params = ref.get("curve_params", {})
    limits = [cp for cp in sol.critical_points if cp["kind"] == "limit point"]
    for which, key in (("max", "p_max"), ("min", "p_min")):
        if key not in params:
            continue
        cands = [cp for cp in limits if (cp["instability_after"] > cp["instability_before"]) == (which == "max")]
        value = cands[0]["load_factor"] * p_ref * scale if cands else float("nan")
        rec(key, params[key], value, tol)
        if cands and f"stretch_at_{key}" in params:
            p = next(pt for pt in sol.path if pt.load_factor == cands[0]["load_factor"])
            lam = (vol.value(shell.rest_positions + p.u) / V0) ** (1.0 / 3.0)
            rec(f"stretch_at_{key}", params[f"stretch_at_{key}"], lam, tol)
    return records


def benchmark_path_options(spec, context: dict | None = None):
    """The path options a benchmark file is solved with: its [solver] options, plus its tabulated
    load factors (and its context's) as path targets, or -- for a curve compared along a load- or
    displacement-controlled path (method "load") -- a step of at most max_load / steps (the levels are abscissa
    values, e.g. P/P_max, interpolated between path points, not load factors)."""
    from dataclasses import replace

    from .solve.nonlinear import path_options

    ref = spec.reference
    opts = path_options(spec.solver)
    if ref.get("compare") != "curve":
        extra = {float(v) for v in ref.get("load_factors", [])} | set(context["load_factors"] if context else ())
        if extra:
            opts = replace(opts, targets=tuple(sorted(set(opts.targets) | extra - {opts.max_load})))
    elif opts.method == "load" and opts.max_step is None:
        # grown steps left the pull-out's points 0.05 apart at its snap and the linear
        # interpolation there 5.7 % off
        opts = replace(opts, max_step=abs(opts.max_load) / opts.steps)
    return opts


def run_nonlinear_benchmark(path: Path, progress: Callable[[str], None] = lambda m: None) -> list[dict]:
    """Solve one nonlinear benchmark file; one record per compared point of its path."""
    from .solve.nonlinear import solve_nonlinear

    t0 = time.perf_counter()
    spec = load_problem(path)
    ref = spec.reference
    lfs = [float(v) for v in ref.get("load_factors", [])]
    context = _context(path, ref)
    opts = benchmark_path_options(spec, context)
    sol = solve_nonlinear(spec.problem, opts, backend=spec.backend,
                          progress=lambda i: progress(f"    point {i['step']}: load factor {i['load_factor']:.4g}"),
                          precision=spec.precision)
    seconds = time.perf_counter() - t0
    n_control = int(spec.problem.shell.mesh.n_real)
    tol = ref.get("tolerance")
    if ref.get("curve") == "balloon":
        return _balloon_records(spec, sol, ref, tol, n_control, seconds)
    records = []
    values = ref.get("values", {})
    for expr, vals in values.items():
        if len(vals) != len(lfs):
            raise ProblemError(f"{path}: [reference.values] {expr} has {len(vals)} values for {len(lfs)} load factors")

    def recorder(prefix, tolerance, source):
        def record(name, reference, value, rel):
            records.append({"name": f"{spec.name} {prefix}{name}", "reference": float(reference), "value": float(value),
                            "rel_error": float(rel), "tolerance": tolerance,
                            "passed": bool(tolerance is None or abs(rel) <= tolerance),
                            "n_control": n_control, "seconds": seconds, "source": source, "units": spec.length_unit})
        return record

    record = recorder("", tol, ref.get("source", ""))
    if "limit_point" in ref:
        _limit_point_records(spec, sol, ref, record)
    _compare(spec, sol, ref, lfs, values, record)
    if context:
        # a second reference, reported beside the first and never judged (tolerance: report only)
        _compare(spec, sol, ref, context["load_factors"], context["values"],
                 recorder("context: ", None, context["source"]))
    return records


def _context(path, ref) -> dict | None:
    """``[reference.context]``: another published curve of the same quantities (``source``,
    ``load_factors``, ``values``), compared the same way and reported only -- e.g. a
    shear-deformable element's curve beside the Kirchhoff-Love reference that is judged."""
    ctx = ref.get("context")
    if ctx is None:
        return None
    where = f"{path}: [reference.context]"
    if not isinstance(ctx, dict):
        raise ProblemError(f"{where} must be a table with source, load_factors and values")
    unknown = set(ctx) - {"source", "load_factors", "values"}
    if unknown:
        raise ProblemError(f"{where}: unknown key(s) {', '.join(sorted(unknown))} (expected source, load_factors, values)")
    missing = {"source", "load_factors", "values"} - set(ctx)
    if missing:
        raise ProblemError(f"{where}: missing {', '.join(sorted(missing))}")
    lfs = [float(v) for v in ctx["load_factors"]]
    values = dict(ctx["values"])
    unknown_q = set(values) - set(ref.get("values", {}))
    if unknown_q:
        raise ProblemError(f"{where}: values {', '.join(sorted(unknown_q))} are not among [reference.values]")
    for expr, vals in values.items():
        if len(vals) != len(lfs):
            raise ProblemError(f"{where}: values {expr} has {len(vals)} values for {len(lfs)} load factors")
    return {"source": str(ctx["source"]), "load_factors": lfs,
            "values": {k: [float(v) for v in vals] for k, vals in values.items()}}


def _compare(spec, sol, ref, lfs, values, record):
    """One record per tabulated load factor and quantity, in the file's ``compare`` mode."""
    mode = ref.get("compare", "each")
    if mode == "curve":
        _curve_records(spec, sol, ref, lfs, values, record)
        return
    if mode == "vector":
        # the quantities are the components of one vector (e.g. the tip position): error norm
        # relative to the reference vector's norm, per load factor
        for k, lf in enumerate(lfs):
            pt = sol.at(lf)
            r = np.array([vals[k] for vals in values.values()])
            v = np.array([_point_quantity(spec, sol, pt, expr) for expr in values])
            record(f"|{', '.join(values)}| @ {lf:g}", np.linalg.norm(r), np.linalg.norm(v),
                   np.linalg.norm(v - r) / np.linalg.norm(r))
        return
    rn = set(ref.get("range_normalised", []))
    for expr, vals in values.items():
        denom = max(abs(x) for x in vals) if expr in rn else None
        for lf, reference in zip(lfs, vals):
            value = _path_quantity(spec, sol, sol.at(lf), expr, ref)
            record(f"{expr} @ {lf:g}", reference, value, (value - reference) / (denom or abs(reference)))


def _path_quantity(spec, sol, point, expr: str, ref) -> float:
    """``[-]reaction.NAME`` (times ``[reference] reaction_scale``), ``load_factor`` or a
    ``quantity`` form."""
    sign, body = (-1.0, expr[1:]) if expr.startswith("-") else (1.0, expr)
    if body == "load_factor":
        return sign * float(point.load_factor)
    if body.startswith("reaction."):
        return sign * _abscissa(point, body, float(ref.get("reaction_scale", 1.0)))
    return _point_quantity(spec, sol, point, expr)


def _limit_point_records(spec, sol, ref, record):
    """``[reference.limit_point]``: the first maximum of ``load`` (e.g. ``reaction.C``, scaled by
    ``reaction_scale``, or ``load_factor``) along the path against ``displacement`` (e.g. ``-probe.C.y``): the
    parabola through the largest path point and its two neighbours gives the limit load and the
    displacement at it (compared with the keys ``value`` and ``at``, pointwise relative errors).
    With ``load = "load_factor"`` the path's first located limit point is taken instead
    (``critical_points``: bracketed to 2^-refine_critical of its step; a parabola through the
    steps of an arc-length path that are 0.1 apart in load there was 1 % off on the shallow cap)."""
    lp = ref["limit_point"]
    if lp["load"] == "load_factor":
        cp = next((c for c in sol.critical_points if c["kind"].startswith("limit point")), None)
        at = None if cp is None else next((p for p in sol.path if p.load_factor == cp["load_factor"]), None)
        p, w = ((float("nan"), float("nan")) if at is None
                else (at.load_factor, _path_quantity(spec, sol, at, lp["displacement"], ref)))
        record("limit load", lp["value"], p, (p - lp["value"]) / abs(lp["value"]))
        record("displacement at the limit load", lp["at"], w, (w - lp["at"]) / abs(lp["at"]))
        return
    pts = [p for p in sol.path if p.kind != "refine"]
    P = np.array([_path_quantity(spec, sol, p, lp["load"], ref) for p in pts])
    W = np.array([_path_quantity(spec, sol, p, lp["displacement"], ref) for p in pts])
    peaks = [i for i in range(1, len(P) - 1) if P[i] >= P[i - 1] and P[i] > P[i + 1]]
    if not peaks:
        record("limit load", lp["value"], float("nan"), float("nan"))
        record("displacement at the limit load", lp["at"], float("nan"), float("nan"))
        return
    w, p = parabola_peak(W[peaks[0] - 1:peaks[0] + 2], P[peaks[0] - 1:peaks[0] + 2])
    record("limit load", lp["value"], p, (p - lp["value"]) / abs(lp["value"]))
    record("displacement at the limit load", lp["at"], w, (w - lp["at"]) / abs(lp["at"]))


def parabola_peak(x, y) -> tuple[float, float]:
    """Vertex (x, y) of the parabola through three points (x increasing, the middle y largest)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    c = np.polyfit(x - x[1], y, 2)
    xm = -c[1] / (2.0 * c[0])
    return float(x[1] + xm), float(np.polyval(c, xm))


def _abscissa(point, expr: str, scale: float) -> float:
    """``reaction.NAME``: the summed reactions of the prescribed-displacement support NAME."""
    if not expr.startswith("reaction."):
        raise ProblemError(f"reference abscissa {expr!r}: expected reaction.NAME")
    name = expr.split(".", 1)[1]
    vals = [v for k, v in point.extra.items() if k.startswith(f"reaction[{name}:")]
    if not vals:
        raise ProblemError(f"reference abscissa {expr!r}: no prescribed displacement named {name!r}")
    return scale * float(sum(vals))


def _curve_records(spec, sol, ref, levels, values, record):
    """Compare along a displacement-controlled path: at each tabulated abscissa level (e.g. the
    load P/P_max, from the reactions), the quantities are interpolated linearly on the LAST path
    segment that crosses the level -- the branch a load-controlled experiment ends on after a
    snap.  Quantities listed in ``range_normalised`` (those crossing zero) are compared
    relative to their largest tabulated magnitude, the others pointwise."""
    scale = float(ref.get("abscissa_scale", 1.0))
    pts = [p for p in sol.path if p.kind != "refine"]
    a = np.array([_abscissa(p, ref["abscissa"], scale) for p in pts])
    q = {expr: np.array([_point_quantity(spec, sol, p, expr) for p in pts]) for expr in values}
    rn = set(ref.get("range_normalised", []))
    for k, level in enumerate(levels):
        cross = np.flatnonzero((a[:-1] - level) * (a[1:] - level) <= 0)
        for expr, vals in values.items():
            if not len(cross):
                record(f"{expr} @ {level:g}", vals[k], float("nan"), float("nan"))
                continue
            i = cross[-1]
            w = 0.0 if a[i + 1] == a[i] else (level - a[i]) / (a[i + 1] - a[i])
            v = (1 - w) * q[expr][i] + w * q[expr][i + 1]
            denom = max(abs(x) for x in vals) if expr in rn else abs(vals[k])
            record(f"{expr} @ {level:g}", vals[k], v, (v - vals[k]) / denom)


def run_nonlinear_benchmarks(folder: Path, pattern: str = "*",
                             progress: Callable[[str], None] = lambda m: None) -> list[dict]:
    records = []
    for f in benchmark_files(folder, pattern):
        progress(f"benchmark {f.stem} ...")
        rs = run_nonlinear_benchmark(f, progress)
        judged = [r for r in rs if r["tolerance"] is not None] or rs      # context records are reported only
        worst = max(judged, key=lambda r: abs(r["rel_error"]) if np.isfinite(r["rel_error"]) else np.inf)
        progress(f"  {f.stem}: {len(rs)} compared points, worst {100 * worst['rel_error']:+.3f} % "
                 f"({worst['name']}), {worst['seconds']:.1f} s")
        records += rs
    return records


# ---------------------------------------------------------------------------------------------
# the compiled kernels' two builds (graspdef.compiled)
def kernel_workout(progress: Callable[[str], None] = lambda m: None) -> None:
    """Small solves that call every compiled kernel with an ahead-of-time export: the Tian & Jia
    plate (linear: patterns, strains, the shell's assembly, the KKT matrix), a neo-Hookean ball
    holding gas between two point loads (densities, enclosed volume, the tangent's products), two pads with friction and
    two pins squeezing a sphere (box and capsule distances, the contact samples' gather, scatter
    and Hessian)."""
    from .contact.barrier import Capsule, FingerContact, RoundedBox
    from .contact.friction import FingerFriction
    from .geometry import icosphere
    from .problem.loads import PointLoad
    from .problem.potentials import EnclosedGas
    from .problem.problem import Problem
    from .problem.supports import RigidModes
    from .shell.hyperelastic import NeoHookean
    from .shell.materials import LinearElastic
    from .shell.model import Shell
    from .solve.nonlinear import PathOptions, solve_nonlinear

    progress("kernels: the plate (linear)")
    solve_linear(load_problem(Path(__file__).resolve().parents[1] / "benchmarks" / "plate_ss_uniform.toml").problem)
    R, t = 0.0325, 0.0025
    m = icosphere(radius=R, subdivisions=2)
    progress("kernels: a neo-Hookean ball with gas")
    pr = Problem(Shell(m.vertices, m.faces, NeoHookean(1e6 / 3), t), [EnclosedGas(8e4)], [RigidModes()])
    top, bot = pr.locate((0, 0, R)), pr.locate((0, 0, -R))
    pr.loads += [PointLoad(top.face, top.bary, (0, 0, -2.0)), PointLoad(bot.face, bot.bary, (0, 0, 2.0))]
    sol = solve_nonlinear(pr, PathOptions(steps=2))
    if not sol.completed:
        raise RuntimeError("kernel workout: the ball's path stopped")
    # the tangent's products (csr_products): below SERIAL_MAX scipy multiplies, so the kernel is
    # called here on the ball's tangent at its last point and two columns of its displacement
    from .solve._kernels import csr_products
    from .solve.equilibrium import Equilibrium

    H = Equilibrium(pr).evaluate(sol.u.ravel(), sol.load_factor).hessian.tocsr()
    X = np.ascontiguousarray(np.column_stack([sol.u.ravel(), np.roll(sol.u.ravel(), 1)]))
    csr_products(H.indptr, H.indices, np.ascontiguousarray(H.data), X, np.empty((H.shape[0], 2)))
    shell = Shell(m.vertices, m.faces, LinearElastic(1e6, 0.45), 0.002)
    h = 0.001                                            # half the wall

    def pad(side):
        c = np.array([side * (R + h + 0.002), 0.0, 0.0])
        return RoundedBox(tuple(c), tuple(map(tuple, np.eye(3))), (0.002, 0.008, 0.008), 0.002)

    def pin(side, r=0.002):
        tip = np.array([side * (R + h), 0.0, 0.0])
        return Capsule(tuple(tip + side * np.array([r + 0.006, 0, 0])), tuple(tip + side * np.array([r, 0, 0])), r)
    for kind, tip in (("pads", pad), ("pins", pin)):
        progress(f"kernels: two {kind} with friction squeezing a sphere")
        fingers = [FingerContact(tip(s), (-s, 0.0, 0.0), 0.5, offset=h, name=n) for s, n in ((1.0, "r"), (-1.0, "l"))]
        terms = fingers + [FingerFriction(f, 0.5) for f in fingers]
        if not solve_nonlinear(Problem(shell, terms, [RigidModes()]), PathOptions(steps=2)).completed:
            raise RuntimeError(f"kernel workout: the {kind}' path stopped")


def check_kernels(progress: Callable[[str], None] = lambda m: None) -> dict:
    """Run :func:`kernel_workout`, recording the arguments of every ahead-of-time export, and
    compare each export with numba's JIT build on them (which also leaves numba's on-disk cache
    warm for those argument types).  Returns {"status": the ahead-of-time module's status line,
    "records": :func:`graspdef.compiled.compare`'s, "missing": exports no call reached}."""
    from . import compiled

    exports = {k.export_name(i) for k in compiled.kernels() for i in range(len(k.signatures))}
    if not compiled.aot_available():
        return {"status": compiled.aot_status(), "records": [], "missing": sorted(exports)}
    with compiled.recording() as rec:
        kernel_workout(progress)
    progress("kernels: each export against the JIT build")
    return {"status": compiled.aot_status(), "records": compiled.compare(rec), "missing": sorted(exports - set(rec))}
