"""Problem files: a TOML document declaring geometry, units, material, thickness, supports (by
named region predicates), loads, probe points and solver options.

All numbers in the file are in the file's declared units (``[units] length``/``force``); they are
converted to SI here and nowhere else.  ``length = "consistent"`` with ``force = "consistent"``
declares a self-consistent unit set that is used as it is (the textbook benchmarks).  Every key
is checked: an unknown or misspelled key, a missing one, a NaN or a wrong type raises
:class:`~graspdef.errors.ProblemError` naming the key and the file.  See ``benchmarks/*.toml``.
"""
from __future__ import annotations

import difflib
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import GraspdefError, ProblemError
from ..geometry import io as gio
from ..geometry import primitives as prim
from ..geometry.regions import compile_predicate
from ..shell.hyperelastic import MATERIALS, PARAMETERS, make_material
from ..shell.model import Shell
from .loads import BodyForce, EdgeLoad, PointLoad, Pressure
from .potentials import EdgeMoment, EnclosedGas, FollowerPressure
from .problem import BACKENDS, Problem, SurfacePoint, locate
from .supports import KINDS, EdgeSupport, PointSupport, RigidModes

FORCE_UNITS = {"N": 1.0, "kN": 1e3, "mN": 1e-3}

_TOP = {"name", "description", "units", "geometry", "material", "shell", "regions", "supports",
        "loads", "probes", "solver", "reference"}
_GEOMETRY = {
    "rectangle": {"lx", "ly", "nx", "ny", "center"},
    "square_plate": {"a", "n"},
    "cylinder": {"radius", "length", "n_theta", "n_z", "theta0_deg", "theta1_deg"},
    "sphere": {"radius", "subdivisions"},
    "ellipsoid": {"a", "b", "c", "subdivisions"},
    "hemisphere": {"radius", "n_rings", "hole_angle_deg"},
    "monkey_saddle": {"half_width", "n", "scale"},
    "mesh": {"path", "units"},
}
#: [solver] keys and their kinds ("length" values are converted from the file's length unit)
_SOLVER = {"backend": "str", "collocation": "int", "type": "str", "method": "str", "steps": "int",
           "max_load": "float", "targets": "list", "max_steps": "int", "max_iterations": "int", "tol": "float",
           "min_step": "float", "desired_iterations": "int", "max_growth": "float", "line_search": "bool",
           "max_probe_displacement": "length", "refine_critical": "int",
           "reuse_factorisation": "bool", "reuse_ratio": "float", "anderson": "int", "inertia_rtol": "float"}
_LENGTH_KEYS = {"lx", "ly", "center", "a", "b", "c", "radius", "length", "half_width", "scale"}


@dataclass
class ProblemSpec:
    """A parsed problem file: the Problem plus what is needed to report in the file's units."""

    problem: Problem
    name: str
    length_unit: str
    force_unit: str
    length_scale: float
    force_scale: float
    backend: str = "auto"
    reference: dict = field(default_factory=dict)
    source: dict = field(default_factory=dict)
    solver: dict = field(default_factory=dict)


def _where(path: str, ctx: str) -> str:
    return f"{path}: {ctx}"


def _check_keys(table: dict, allowed: set, ctx: str, path: str, required: set = frozenset()) -> None:
    if not isinstance(table, dict):
        raise ProblemError(_where(path, f"[{ctx}] must be a table"))
    for k in table:
        if k not in allowed:
            hint = difflib.get_close_matches(k, sorted(allowed), n=1)
            extra = f" (did you mean '{hint[0]}'?)" if hint else f" (valid: {', '.join(sorted(allowed))})"
            raise ProblemError(_where(path, f"unknown key '{k}' in [{ctx}]{extra}"))
    for k in required:
        if k not in table:
            raise ProblemError(_where(path, f"missing key '{k}' in [{ctx}]"))


def _number(v, key: str, ctx: str, path: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ProblemError(_where(path, f"[{ctx}] {key} must be a number, got {v!r}"))
    if not math.isfinite(v):
        raise ProblemError(_where(path, f"[{ctx}] {key} must be finite, got {v!r}"))
    return float(v)


def _vector(v, key: str, ctx: str, path: str, n: int = 3) -> np.ndarray:
    if not isinstance(v, list) or len(v) != n:
        raise ProblemError(_where(path, f"[{ctx}] {key} must be a list of {n} numbers, got {v!r}"))
    return np.array([_number(x, key, ctx, path) for x in v])


def _integer(v, key: str, ctx: str, path: str) -> int:
    if isinstance(v, bool) or not isinstance(v, int):
        raise ProblemError(_where(path, f"[{ctx}] {key} must be an integer, got {v!r}"))
    return v


def read_units(doc: dict, path: str) -> tuple[str, str, float, float]:
    if "units" not in doc:
        raise ProblemError(_where(path, "missing [units] table (e.g. length = \"m\", force = \"N\", or "
                                        "both \"consistent\" for a self-consistent unit set)"))
    u = doc["units"]
    _check_keys(u, {"length", "force"}, "units", path, {"length", "force"})
    lu, fu = u["length"], u["force"]
    if (lu == "consistent") != (fu == "consistent"):
        raise ProblemError(_where(path, "[units] 'consistent' must be used for both length and force"))
    if lu == "consistent":
        return lu, fu, 1.0, 1.0
    try:
        ls = gio.length_scale(lu)
    except ProblemError as exc:
        raise ProblemError(_where(path, f"[units] length: {exc}")) from None
    if fu not in FORCE_UNITS:
        raise ProblemError(_where(path, f"[units] unknown force unit {fu!r}; valid: {', '.join(FORCE_UNITS)}, consistent"))
    return lu, fu, ls, FORCE_UNITS[fu]


def _geometry(g: dict, path: str, ls: float, base: Path):
    if not isinstance(g, dict) or "type" not in g:
        raise ProblemError(_where(path, "[geometry] needs a 'type' (" + ", ".join(_GEOMETRY) + ")"))
    kind = g["type"]
    if kind not in _GEOMETRY:
        hint = difflib.get_close_matches(str(kind), list(_GEOMETRY), n=1)
        raise ProblemError(_where(path, f"[geometry] unknown type {kind!r}" + (f" (did you mean '{hint[0]}'?)" if hint else "")))
    allowed = _GEOMETRY[kind] | {"type", "interpolate"}
    _check_keys(g, allowed, "geometry", path, _GEOMETRY[kind] - {"center", "theta0_deg", "theta1_deg", "hole_angle_deg", "scale", "units"})
    if kind == "mesh":
        units = g.get("units")
        if units is None:
            raise ProblemError(_where(path, "[geometry] a mesh file needs 'units' (its length unit, e.g. \"mm\")"))
        mesh_path = Path(g["path"])
        if not mesh_path.is_absolute():
            mesh_path = base / mesh_path
        return gio.load_mesh(mesh_path, units)
    args = {}
    for k, v in g.items():
        if k in ("type", "interpolate"):
            continue
        if k == "center":
            args[k] = tuple(_vector(v, k, "geometry", path, 2) * ls)
        elif k.endswith("_deg"):
            args[k[:-4]] = math.radians(_number(v, k, "geometry", path))
        elif k in ("nx", "ny", "n", "n_theta", "n_z", "n_rings", "subdivisions"):
            args[k] = _integer(v, k, "geometry", path)
        else:
            args[k] = _number(v, k, "geometry", path) * (ls if k in _LENGTH_KEYS else 1.0)
    if kind == "monkey_saddle":   # x^3 - 3 x y^2 = scale z, scale in length^2 (one factor above)
        hw = args.pop("half_width")
        scale = args.pop("scale", 5000.0 * ls) * ls
        return prim.height_field(lambda x, y: (x ** 3 - 3 * x * y ** 2) / scale, (-hw, hw), (-hw, hw), args["n"], args["n"])
    if kind == "sphere":
        return prim.icosphere(**args)
    return getattr(prim, kind)(**args)


def load_problem(path: str | Path) -> ProblemSpec:
    """Read and validate a problem file; build the Shell and Problem (SI inside)."""
    p = Path(path)
    sp_ = str(p)
    if not p.is_file():
        raise ProblemError(f"problem file not found: {sp_}")
    try:
        doc = tomllib.loads(p.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ProblemError(_where(sp_, f"not valid TOML: {exc}")) from None
    _check_keys(doc, _TOP, "top level", sp_, {"geometry", "material", "shell", "supports"})
    lu, fu, ls, fs = read_units(doc, sp_)
    mesh = _geometry(doc["geometry"], sp_, ls, p.parent)

    mat = doc["material"]
    if not isinstance(mat, dict):
        raise ProblemError(_where(sp_, "[material] must be a table"))
    model = mat.get("model", "linear_elastic")
    if model not in MATERIALS:
        hint = difflib.get_close_matches(str(model), list(MATERIALS), n=1)
        raise ProblemError(_where(sp_, f"[material] unknown model {model!r}" + (f" (did you mean '{hint[0]}'?)" if hint
                                        else f" (valid: {', '.join(MATERIALS)})")))
    units = PARAMETERS[model]
    _check_keys(mat, set(units) | {"model"}, "material", sp_)
    params = {}
    for k, v in mat.items():
        if k == "model":
            continue
        if units[k] == "count":
            params[k] = _integer(v, k, "material", sp_)
        else:
            params[k] = _number(v, k, "material", sp_) * (fs / ls ** 2 if units[k] == "Pa" else 1.0)
    try:
        material = make_material(model, params)
    except ProblemError as exc:
        raise ProblemError(_where(sp_, f"[material] {exc}")) from None

    sh = doc["shell"]
    _check_keys(sh, {"thickness", "quadrature"}, "shell", sp_, {"thickness"})
    thickness = _number(sh["thickness"], "thickness", "shell", sp_)
    if thickness <= 0:
        raise ProblemError(_where(sp_, f"[shell] thickness must be positive, got {thickness}"))
    nq = _integer(sh.get("quadrature", 3), "quadrature", "shell", sp_)
    if nq not in (3, 6, 12):
        raise ProblemError(_where(sp_, f"[shell] quadrature must be 3, 6 or 12 points per face, got {nq}"))
    interp = doc["geometry"].get("interpolate")
    if interp is not None and not isinstance(interp, bool):
        raise ProblemError(_where(sp_, "[geometry] interpolate must be true or false"))
    shell = Shell(mesh.vertices, mesh.faces, material, thickness * ls, n_quad=nq, interpolate=interp)

    regions = doc.get("regions", {})
    if not isinstance(regions, dict):
        raise ProblemError(_where(sp_, "[regions] must be a table of name = \"expression\""))
    preds = {}
    for name, expr in regions.items():
        if not isinstance(expr, str):
            raise ProblemError(_where(sp_, f"[regions] {name} must be an expression string"))
        f = compile_predicate(expr, name, length_scale=1.0, atol=1e-9 * max(1.0, float(np.abs(mesh.vertices).max()) / ls))
        preds[name] = (lambda pts, f=f: f(pts / ls))

    ev = shell.evaluator

    def surface_point(entry: dict, ctx: str) -> SurfacePoint:
        if ("at" in entry) == ("face" in entry):
            raise ProblemError(_where(sp_, f"[{ctx}] give either 'at' (a position) or 'face' and 'bary'"))
        if "face" in entry:
            face = _integer(entry["face"], "face", ctx, sp_)
            bary = _vector(entry.get("bary"), "bary", ctx, sp_)
            if not (0 <= face < len(shell.faces)):
                raise ProblemError(_where(sp_, f"[{ctx}] face {face} does not exist (the mesh has {len(shell.faces)} faces)"))
            if np.any(bary < -1e-12) or abs(bary.sum() - 1.0) > 1e-9:
                raise ProblemError(_where(sp_, f"[{ctx}] bary must be non-negative and sum to 1, got {bary.tolist()}"))
            return SurfacePoint(face, tuple(float(b) for b in bary))
        at = _vector(entry["at"], "at", ctx, sp_) * ls
        tol = entry.get("tolerance")
        tol = None if tol is None else _number(tol, "tolerance", ctx, sp_) * ls
        try:
            return locate(shell, ev, at, ctx, tol)[0]
        except ProblemError as exc:
            raise ProblemError(_where(sp_, f"[{ctx}] {exc}")) from None

    supports = []
    sups = doc["supports"]
    if not isinstance(sups, list) or not sups:
        raise ProblemError(_where(sp_, "[[supports]] must list at least one support"))
    for i, s in enumerate(sups):
        ctx = f"supports {i + 1}"
        kind = s.get("kind") if isinstance(s, dict) else None
        valid = list(KINDS) + ["point", "rigid_modes"]
        if kind not in valid:
            hint = difflib.get_close_matches(str(kind), valid, n=1)
            raise ProblemError(_where(sp_, f"[{ctx}] unknown kind {kind!r}" + (f" (did you mean '{hint[0]}'?)" if hint else f" (valid: {', '.join(valid)})")))
        if kind == "rigid_modes":
            _check_keys(s, {"kind", "name"}, ctx, sp_)
            supports.append(RigidModes())
        elif kind == "point":
            _check_keys(s, {"kind", "name", "at", "face", "bary", "directions", "tolerance", "displacement"}, ctx, sp_)
            dirs = s.get("directions", [[1, 0, 0], [0, 1, 0], [0, 0, 1]])
            if not isinstance(dirs, list) or not dirs:
                raise ProblemError(_where(sp_, f"[{ctx}] directions must be a list of 3-vectors"))
            d = tuple(tuple(_vector(x, "directions", ctx, sp_)) for x in dirs)
            disp = None
            if "displacement" in s:                       # prescribed, per direction, at load factor 1
                disp = tuple(_vector(s["displacement"], "displacement", ctx, sp_, len(d)) * ls)
            pt = surface_point(s, ctx)
            try:
                supports.append(PointSupport(pt.face, pt.bary, d, s.get("name", ctx), disp))
            except ProblemError as exc:
                raise ProblemError(_where(sp_, f"[{ctx}] {exc}")) from None
        else:
            _check_keys(s, {"kind", "name", "region", "normal"}, ctx, sp_, {"region"})
            reg = s["region"]
            if reg not in preds:
                hint = difflib.get_close_matches(str(reg), list(preds), n=1)
                raise ProblemError(_where(sp_, f"[{ctx}] unknown region {reg!r}" + (f" (did you mean '{hint[0]}'?)" if hint else f" (defined: {', '.join(preds) or 'none'})")))
            normal = tuple(_vector(s["normal"], "normal", ctx, sp_)) if "normal" in s else None
            try:
                supports.append(EdgeSupport(kind, preds[reg], normal, s.get("name", reg)))
            except ProblemError as exc:
                raise ProblemError(_where(sp_, f"[{ctx}] {exc}")) from None

    loads = []
    for i, ld in enumerate(doc.get("loads", [])):
        ctx = f"loads {i + 1}"
        kind = ld.get("kind") if isinstance(ld, dict) else None
        if kind == "point":
            _check_keys(ld, {"kind", "at", "face", "bary", "force", "tolerance"}, ctx, sp_, {"force"})
            pt = surface_point(ld, ctx)
            loads.append(PointLoad(pt.face, pt.bary, tuple(_vector(ld["force"], "force", ctx, sp_) * fs)))
        elif kind == "pressure":
            _check_keys(ld, {"kind", "p", "region"}, ctx, sp_, {"p"})
            mask = None
            if "region" in ld:
                if ld["region"] not in preds:
                    raise ProblemError(_where(sp_, f"[{ctx}] unknown region {ld['region']!r}"))
                f_real = shell.faces
                cent = shell.vertices[f_real].mean(axis=1)
                mask = preds[ld["region"]](cent)
            loads.append(Pressure(_number(ld["p"], "p", ctx, sp_) * fs / ls ** 2, mask))
        elif kind == "gravity":
            _check_keys(ld, {"kind", "density", "g"}, ctx, sp_, {"density", "g"})
            # density [kg/m^3] and g [m/s^2] are SI whatever the file's length unit (as stated in
            # the README); with consistent units they are taken as they are
            loads.append(BodyForce(_number(ld["density"], "density", ctx, sp_), tuple(_vector(ld["g"], "g", ctx, sp_))))
        elif kind == "follower_pressure":
            _check_keys(ld, {"kind", "p"}, ctx, sp_, {"p"})
            loads.append(FollowerPressure(_number(ld["p"], "p", ctx, sp_) * fs / ls ** 2))
        elif kind == "gas":
            _check_keys(ld, {"kind", "p0", "p_atm"}, ctx, sp_, {"p0"})
            p_atm = ld.get("p_atm")
            loads.append(EnclosedGas(_number(ld["p0"], "p0", ctx, sp_) * fs / ls ** 2,
                                     *(() if p_atm is None else (_number(p_atm, "p_atm", ctx, sp_) * fs / ls ** 2,))))
        elif kind in ("edge_load", "edge_moment"):
            keys = {"kind", "region", "force"} if kind == "edge_load" else {"kind", "region", "moment", "axis"}
            _check_keys(ld, keys | {"name"}, ctx, sp_, keys - {"kind"})
            if ld["region"] not in preds:
                hint = difflib.get_close_matches(str(ld["region"]), list(preds), n=1)
                raise ProblemError(_where(sp_, f"[{ctx}] unknown region {ld['region']!r}" + (f" (did you mean '{hint[0]}'?)" if hint else "")))
            name = ld.get("name", ld["region"])
            if kind == "edge_load":             # force per unit length
                loads.append(EdgeLoad(preds[ld["region"]], tuple(_vector(ld["force"], "force", ctx, sp_) * fs / ls), name))
            else:                               # moment per unit length = force
                loads.append(EdgeMoment(preds[ld["region"]], _number(ld["moment"], "moment", ctx, sp_) * fs,
                                        tuple(_vector(ld["axis"], "axis", ctx, sp_)), name))
        else:
            raise ProblemError(_where(sp_, f"[{ctx}] unknown load kind {kind!r} (valid: point, pressure, gravity, "
                                           "edge_load, edge_moment, follower_pressure, gas)"))

    probes = {}
    for i, pr in enumerate(doc.get("probes", [])):
        ctx = f"probes {i + 1}"
        _check_keys(pr, {"name", "at", "face", "bary", "tolerance"}, ctx, sp_, {"name"})
        if pr["name"] in probes:
            raise ProblemError(_where(sp_, f"[{ctx}] duplicate probe name {pr['name']!r}"))
        probes[pr["name"]] = surface_point(pr, f"probe '{pr['name']}'")

    solver = doc.get("solver", {})
    _check_keys(solver, set(_SOLVER), "solver", sp_)
    backend = solver.get("backend", "auto")
    if backend not in BACKENDS:
        raise ProblemError(_where(sp_, f"[solver] unknown backend {backend!r} (valid: {', '.join(BACKENDS)})"))
    ncol = _integer(solver.get("collocation", 2), "collocation", "solver", sp_)
    opts = {}
    for k, v in solver.items():
        kind = _SOLVER[k]
        if kind == "str":
            if not isinstance(v, str):
                raise ProblemError(_where(sp_, f"[solver] {k} must be a string, got {v!r}"))
            opts[k] = v
        elif kind == "int":
            opts[k] = _integer(v, k, "solver", sp_)
        elif kind == "bool":
            if not isinstance(v, bool):
                raise ProblemError(_where(sp_, f"[solver] {k} must be true or false, got {v!r}"))
            opts[k] = v
        elif kind == "list":
            if not isinstance(v, list):
                raise ProblemError(_where(sp_, f"[solver] {k} must be a list of numbers, got {v!r}"))
            opts[k] = tuple(_number(x, k, "solver", sp_) for x in v)
        else:
            opts[k] = _number(v, k, "solver", sp_) * (ls if kind == "length" else 1.0)
    if opts.get("type", "linear") not in ("linear", "nonlinear"):
        raise ProblemError(_where(sp_, f"[solver] type must be \"linear\" or \"nonlinear\", got {opts['type']!r}"))
    path_keys = set(opts) - {"type", "backend", "collocation"}
    if opts.get("type", "linear") == "linear" and path_keys:
        raise ProblemError(_where(sp_, f"[solver] {', '.join(sorted(path_keys))} only apply to type = \"nonlinear\""))
    ref = doc.get("reference", {})
    _check_keys(ref, {"value", "quantity", "tolerance", "source", "formula", "load_factors", "values", "curve",
                      "curve_params", "compare", "abscissa", "abscissa_scale", "range_normalised"}, "reference", sp_)
    try:
        problem = Problem(shell, loads, supports, probes, n_collocation=ncol)
    except GraspdefError as exc:
        raise type(exc)(_where(sp_, str(exc))) from None
    return ProblemSpec(problem, str(doc.get("name", p.stem)), lu, fu, ls, fs, backend, ref, doc, opts)
