"""Problem files: a TOML document declaring geometry, units, material, thickness, supports (by
named region predicates), loads, probe points and solver options.

All numbers in the file are in the file's declared units (``[units] length``/``force``); they are
converted to SI here and nowhere else.  ``length = "consistent"`` with ``force = "consistent"``
declares a self-consistent unit set that is used as it is (the textbook benchmarks).  A scalar with
a dimension (a length, a thickness, a modulus, a pressure, a density) may also be written with its
own unit, ``thickness = "2.5 mm"``, ``E = "1 MPa"`` (not in a consistent file).  The file is read
with :mod:`graspdef.config`: an unknown or misspelled key, a missing one, a NaN or a wrong type
raises a ProblemError naming the file, the table and the key.  See ``benchmarks/*.toml``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..config import REQUIRED, Table, read_toml
from ..errors import ConfigError, GraspdefError, ProblemError
from ..geometry import io as gio
from ..geometry import primitives as prim
from ..geometry.regions import compile_predicate
from ..shell.hyperelastic import MATERIALS, PARAMETERS, make_material
from ..shell.memory import check_memory
from ..shell.model import Shell
from ..units import FORCE_UNITS  # noqa: F401  (re-exported: the unit tables live in graspdef.units)
from .edges import face_centroids
from .loads import BodyForce, EdgeLoad, PointLoad, Pressure
from .potentials import EdgeMoment, EnclosedGas, FollowerPressure
from .nitsche import NITSCHE_GAMMA
from .problem import BACKENDS, PRECISIONS, Problem, SurfacePoint, locate
from .supports import KINDS, EdgeSupport, PointSupport, RigidModes

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
    "annulus": {"r_inner", "r_outer", "n_theta", "n_r", "slit_deg"},
    "polygon": {"outer", "holes", "edge_length", "refinements"},
    "disk": {"radius", "edge_length", "refinements", "center"},
    "spherical_cap": {"radius", "rise", "edge_length", "refinements"},
    "mesh": {"path", "units"},
}
_GEOMETRY_OPTIONAL = {"center", "theta0_deg", "theta1_deg", "hole_angle_deg", "scale", "units", "slit_deg", "holes", "refinements"}
_INTEGER_KEYS = {"nx", "ny", "n", "n_theta", "n_z", "n_rings", "subdivisions", "n_r", "refinements"}
#: [solver] keys and their kinds ("length" values are converted from the file's length unit)
_SOLVER = {"backend": "str", "precision": "str", "collocation": "int", "nitsche_gamma": "float", "type": "str", "method": "str", "steps": "int",
           "max_load": "float", "targets": "list", "max_steps": "int", "max_iterations": "int", "tol": "float",
           "min_step": "float", "desired_iterations": "int", "max_growth": "float", "max_step": "float",
           "line_search": "bool",
           "max_probe_displacement": "length", "refine_critical": "int",
           "reuse_factorisation": "bool", "reuse_ratio": "float", "anderson": "int", "inertia_rtol": "float",
           "krylov": "int", "krylov_rtol": "float", "local_rings": "int", "jump_ratio": "float", "limit_points": "str",
           "bifurcation": "str", "predictor": "str"}
_LENGTH_KEYS = {"lx", "ly", "center", "a", "b", "c", "radius", "length", "half_width", "scale", "r_inner", "r_outer",
                "edge_length", "rise"}
_REFERENCE = {"value", "quantity", "tolerance", "source", "formula", "load_factors", "values", "curve",
              "curve_params", "compare", "abscissa", "abscissa_scale", "range_normalised",
              "reaction_scale", "limit_point", "context"}
_SUPPORT_KEYS = {"rigid_modes": ({"kind", "name"}, ()),
                 "point": ({"kind", "name", "at", "face", "bary", "directions", "tolerance", "displacement", "side"},
                           ())}
_LOAD_KEYS = {"point": ({"kind", "at", "face", "bary", "force", "tolerance", "side"}, ("force",)),
              "pressure": ({"kind", "p", "region"}, ("p",)),
              "gravity": ({"kind", "density", "g"}, ("density", "g")),
              "follower_pressure": ({"kind", "p"}, ("p",)),
              "gas": ({"kind", "p0", "p_atm"}, ("p0",)),
              "edge_load": ({"kind", "region", "force", "name", "side"}, ("region", "force")),
              "edge_moment": ({"kind", "region", "moment", "axis", "name", "side"}, ("region", "moment", "axis"))}


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
    precision: str = "auto"      # the factors' precision ([solver] precision; graspdef.solve.sparse.KKTSystem)


@dataclass(frozen=True)
class FileUnits:
    """A problem file's declared units: names and SI factors (1.0 for "consistent")."""

    length: str
    force: str
    length_scale: float
    force_scale: float

    @property
    def consistent(self) -> bool:
        return self.length == "consistent"

    def quantity(self, t: Table, key: str, dimension: str, default=REQUIRED, implied=None) -> float:
        """``t[key]`` in SI: a plain number in the file's unit of ``dimension`` (or ``implied``: the
        SI factor or conversion of a plain number), or a string with its own unit (not in a
        consistent file)."""
        if implied is None:
            ls, fs = self.length_scale, self.force_scale
            implied = {"length": ls, "force": fs, "pressure": fs / ls ** 2, "density": 1.0}[dimension]
        return t.quantity(key, dimension, default, implied=implied,
                          unitless="the file's units are 'consistent'" if self.consistent else None)

    def pressure(self, t: Table, key: str, default=REQUIRED) -> float:
        """A pressure load in SI (a plain number converted as force / length^2)."""
        ls, fs = self.length_scale, self.force_scale
        return self.quantity(t, key, "pressure", default, implied=lambda v: v * fs / ls ** 2)


def read_units(doc: Table) -> FileUnits:
    """The [units] table: length and force units (or both "consistent")."""
    if "units" not in doc:
        raise ConfigError(f"{doc.source}: missing [units] table (e.g. length = \"m\", force = \"N\", or "
                          "both \"consistent\" for a self-consistent unit set)")
    u = doc.table("units").check({"length", "force"}, ("length", "force"))
    lu, fu = u.string("length"), u.string("force")
    if (lu == "consistent") != (fu == "consistent"):
        raise u.error("'consistent' must be used for both length and force")
    if lu == "consistent":
        return FileUnits(lu, fu, 1.0, 1.0)
    return FileUnits(lu, fu, u.unit("length", "length")[1], u.unit("force", "force")[1])


def _geometry(g: Table, units: FileUnits, base: Path, out_of_core: bool = False, linear: str | None = None):
    if "type" not in g:
        raise g.error("needs a 'type' (" + ", ".join(_GEOMETRY) + ")")
    kind = g.string("type", choices=_GEOMETRY)
    g.check(_GEOMETRY[kind] | {"type", "interpolate"}, sorted(_GEOMETRY[kind] - _GEOMETRY_OPTIONAL))
    ls = units.length_scale
    if kind == "mesh":
        if "units" not in g:
            raise g.error("a mesh file needs 'units' (its length unit, e.g. \"mm\")")
        mesh_path = Path(g.string("path"))
        if not mesh_path.is_absolute():
            mesh_path = base / mesh_path
        return gio.load_mesh(mesh_path, g.unit("units", "length")[0])
    args = {}
    for k in g:
        if k in ("type", "interpolate"):
            continue
        if k == "center":
            args[k] = tuple(np.array(g.vector(k, 2)) * ls)
        elif k == "outer":
            args[k] = _points(g, k, g[k]) * ls
        elif k == "holes":
            holes = g[k]
            if not isinstance(holes, list):
                raise g.error(f"must be a list of polygons (lists of [x, y] points), got {holes!r}", k)
            args[k] = [_points(g, k, h, f" hole {i + 1}") * ls for i, h in enumerate(holes)]
        elif k.endswith("_deg"):
            args[k[:-4]] = math.radians(g.number(k))
        elif k in _INTEGER_KEYS:
            args[k] = g.integer(k)
        elif k == "scale":                   # a length^2 (see below): file units only
            args[k] = g.number(k) * ls
        elif k in _LENGTH_KEYS:
            args[k] = units.quantity(g, k, "length")
        else:
            args[k] = g.number(k)
    n_est = _vertex_count(kind, args)
    if n_est is not None:                 # before the mesh is generated: a huge one would exhaust memory
        check_memory(n_est, f"{g.where()}: this {kind}", out_of_core=out_of_core, linear=linear)
    if kind == "monkey_saddle":   # x^3 - 3 x y^2 = scale z, scale in length^2 (one factor above)
        hw = args.pop("half_width")
        scale = args.pop("scale", 5000.0 * ls) * ls
        return prim.height_field(lambda x, y: (x ** 3 - 3 * x * y ** 2) / scale, (-hw, hw), (-hw, hw), args["n"], args["n"])
    if kind == "sphere":
        return prim.icosphere(**args)
    try:
        return getattr(prim, kind)(**args)
    except ProblemError as exc:
        raise g.error(str(exc)) from None


def _points(g: Table, key: str, value, what: str = "") -> np.ndarray:
    """A polygon's points (n, 2) as written in the file (finite numbers, file units)."""
    if (not isinstance(value, list) or len(value) < 3
            or not all(isinstance(p, list) and len(p) == 2 for p in value)
            or not all(isinstance(c, (int, float)) and not isinstance(c, bool) and math.isfinite(c)
                       for p in value for c in p)):
        raise g.error(f"{what} must be a list of at least 3 [x, y] points of finite numbers, "
                      f"got {value!r}".lstrip(), key)
    return np.array(value, dtype=float)


def _vertex_count(kind: str, args: dict) -> int | None:
    """The control-vertex count of a generated geometry, known before it is generated."""
    if kind in ("sphere", "ellipsoid"):
        return 10 * 4 ** max(0, min(int(args.get("subdivisions", 0)), 30)) + 2
    if kind == "rectangle":
        return (args["nx"] + 1) * (args["ny"] + 1)
    if kind in ("square_plate", "monkey_saddle"):
        return (args["n"] + 1) ** 2
    if kind == "cylinder":
        return (args["n_theta"] + 1) * (args["n_z"] + 1)
    if kind == "annulus":
        return (args["n_theta"] + 1) * (args["n_r"] + 1)
    return None


def _material(mat: Table, units: FileUnits):
    model = mat.string("model", "linear_elastic", choices=MATERIALS)
    kinds = PARAMETERS[model]
    mat.check(set(kinds) | {"model"})
    params = {}
    for k in mat:
        if k == "model":
            continue
        if kinds[k] == "count":
            params[k] = mat.integer(k)
        elif kinds[k] == "Pa":
            params[k] = units.quantity(mat, k, "pressure")
        else:
            params[k] = mat.number(k)
    try:
        return make_material(model, params)
    except ProblemError as exc:
        raise ConfigError(f"{mat.where()} {exc}") from None


def _solver(solver: Table, units: FileUnits) -> tuple[str, int, float, dict]:
    """(backend, collocation points per edge, Nitsche penalty, options in SI) of the [solver] table."""
    solver.check(_SOLVER)
    backend = solver.string("backend", "auto", choices=BACKENDS)
    ncol = solver.integer("collocation", 2)
    gamma = solver.number("nitsche_gamma", NITSCHE_GAMMA)
    if not gamma > 0:
        raise solver.error(f"nitsche_gamma (the Nitsche rotation penalty of clamped / symmetry edges, "
                           f"dimensionless; default {NITSCHE_GAMMA:g}) must be positive, got {gamma!r}")
    opts = {}
    for k in solver:
        kind = _SOLVER[k]
        if kind == "str":
            opts[k] = solver.string(k)
        elif kind == "int":
            opts[k] = solver.integer(k)
        elif kind == "bool":
            opts[k] = solver.boolean(k)
        elif kind == "list":
            opts[k] = tuple(solver.list(k, "number", nonempty=False))
        elif kind == "length":
            opts[k] = units.quantity(solver, k, "length")
        else:
            opts[k] = solver.number(k)
    solver.string("type", "linear", choices=("linear", "nonlinear"))
    solver.string("precision", "auto", choices=PRECISIONS)
    path_keys = set(opts) - {"type", "backend", "precision", "collocation", "nitsche_gamma"}
    if opts.get("type", "linear") == "linear" and path_keys:
        raise solver.error(f"{', '.join(sorted(path_keys))} only apply to type = \"nonlinear\"")
    return backend, ncol, gamma, opts


def load_problem(path: str | Path, backend: str | None = None) -> ProblemSpec:
    """Read and validate a problem file; build the Shell and Problem (SI inside).  ``backend``:
    the solver backend that will be used if not the file's (the memory check before the mesh is
    built allows for "pardiso-ooc", which keeps the factor on disk)."""
    p = Path(path)
    doc = read_toml(p, "problem file")
    doc.check(_TOP, ("geometry", "material", "shell", "supports"))
    units = read_units(doc)
    ls, fs = units.length_scale, units.force_scale
    # the [solver] table first: its backend decides the memory check before the mesh is built
    file_backend, ncol, gamma, opts = _solver(doc.table("solver", required=False), units)
    ooc = (backend or file_backend) == "pardiso-ooc"
    precision = opts.get("precision", "auto")
    # the memory check's kind of solve: a linear one's factor precision, or None for a path
    linear = precision if opts.get("type", "linear") == "linear" else None
    geo = doc.table("geometry")
    mesh = _geometry(geo, units, p.parent, ooc, linear)
    material = _material(doc.table("material"), units)

    sh = doc.table("shell").check({"thickness", "quadrature"}, ("thickness",))
    thickness = units.quantity(sh, "thickness", "length")
    if thickness <= 0:
        raise sh.error(f"must be positive, got {sh['thickness']!r}", "thickness")
    nq = sh.integer("quadrature", 3)
    if nq not in (3, 6, 12):
        raise sh.error(f"must be 3, 6 or 12 points per face, got {nq}", "quadrature")
    interp = geo.boolean("interpolate", None)
    check_memory(mesh.n_vertices, f"{p}: the mesh", out_of_core=ooc, linear=linear)
    shell = Shell(mesh.vertices, mesh.faces, material, thickness, n_quad=nq, interpolate=interp)

    regions = doc.table("regions", required=False)
    preds = {}
    for name in regions:
        expr = regions.string(name)
        f = compile_predicate(expr, name, length_scale=1.0, atol=1e-9 * max(1.0, float(np.abs(mesh.vertices).max()) / ls))
        preds[name] = (lambda pts, f=f: f(pts / ls))

    ev = shell.evaluator

    def side(entry: Table):
        """The optional ``side`` region (evaluated at face centroids: one lip of a slit)."""
        return preds[entry.string("side", choices=preds)] if "side" in entry else None

    def surface_point(entry: Table, label: str) -> SurfacePoint:
        if ("at" in entry) == ("face" in entry):
            raise entry.error("give either 'at' (a position) or 'face' and 'bary'")
        if "face" in entry:
            if "side" in entry:
                raise entry.error("'side' only applies with 'at' (a position)")
            face = entry.integer("face")
            bary = np.array(entry.vector("bary"))
            if not (0 <= face < len(shell.faces)):
                raise entry.error(f"face {face} does not exist (the mesh has {len(shell.faces)} faces)")
            if np.any(bary < -1e-12) or abs(bary.sum() - 1.0) > 1e-9:
                raise entry.error(f"bary must be non-negative and sum to 1, got {bary.tolist()}")
            return SurfacePoint(face, tuple(float(b) for b in bary))
        at = np.array(entry.vector("at")) * ls
        tol = units.quantity(entry, "tolerance", "length", None)
        on = side(entry)
        try:
            return locate(shell, ev, at, label, tol, faces=None if on is None else on(face_centroids(shell)))[0]
        except ProblemError as exc:
            raise entry.error(str(exc)) from None

    supports = []
    for s in doc.tables("supports", required=True):
        kind = s.string("kind", choices=list(KINDS) + ["point", "rigid_modes"])
        if kind == "rigid_modes":
            s.check(*_SUPPORT_KEYS[kind])
            supports.append(RigidModes())
        elif kind == "point":
            s.check(*_SUPPORT_KEYS[kind])
            d = s.vectors("directions", 3, ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))
            disp = None
            if "displacement" in s:                       # prescribed, per direction, at load factor 1
                disp = tuple(np.array(s.vector("displacement", len(d))) * ls)
            pt = surface_point(s, s.name)
            try:
                supports.append(PointSupport(pt.face, pt.bary, d, s.string("name", s.name), disp))
            except ProblemError as exc:
                raise s.error(str(exc)) from None
        else:
            s.check({"kind", "name", "region", "normal", "side"}, ("region",))
            reg = s.string("region", choices=preds)
            normal = s.vector("normal", 3, None)
            try:
                supports.append(EdgeSupport(kind, preds[reg], normal, s.string("name", reg), side(s)))
            except ProblemError as exc:
                raise s.error(str(exc)) from None

    loads = []
    for ld in doc.tables("loads"):
        kind = ld.string("kind", choices=_LOAD_KEYS)
        ld.check(*_LOAD_KEYS[kind])
        if kind == "point":
            pt = surface_point(ld, ld.name)
            loads.append(PointLoad(pt.face, pt.bary, tuple(np.array(ld.vector("force")) * fs)))
        elif kind == "pressure":
            mask = None
            if "region" in ld:
                cent = shell.vertices[shell.faces].mean(axis=1)
                mask = preds[ld.string("region", choices=preds)](cent)
            loads.append(Pressure(units.pressure(ld, "p"), mask))
        elif kind == "gravity":
            # density [kg/m^3] and g [m/s^2] are SI whatever the file's length unit (as stated in
            # the README); with consistent units they are taken as they are
            loads.append(BodyForce(units.quantity(ld, "density", "density"), ld.vector("g")))
        elif kind == "follower_pressure":
            loads.append(FollowerPressure(units.pressure(ld, "p")))
        elif kind == "gas":
            p_atm = units.pressure(ld, "p_atm", None)
            loads.append(EnclosedGas(units.pressure(ld, "p0"), *(() if p_atm is None else (p_atm,))))
        else:
            region = ld.string("region", choices=preds)
            name = ld.string("name", region)
            if kind == "edge_load":             # force per unit length
                loads.append(EdgeLoad(preds[region], tuple(np.array(ld.vector("force")) * fs / ls), name,
                                      side=side(ld)))
            else:                               # moment per unit length = force
                loads.append(EdgeMoment(preds[region], ld.number("moment") * fs, ld.vector("axis"), name,
                                        side=side(ld)))

    probes = {}
    for pr in doc.tables("probes"):
        pr.check({"name", "at", "face", "bary", "tolerance", "side"}, ("name",))
        name = pr.string("name")
        if name in probes:
            raise pr.error(f"duplicate probe name {name!r}")
        probes[name] = surface_point(pr, f"probe '{name}'")

    ref = doc.table("reference", required=False).check(_REFERENCE)
    try:
        problem = Problem(shell, loads, supports, probes, n_collocation=ncol, nitsche_gamma=gamma)
    except GraspdefError as exc:
        raise type(exc)(f"{p}: {exc}") from None
    return ProblemSpec(problem, str(doc.get("name", p.stem)), units.length, units.force, ls, fs, file_backend,
                       dict(ref), dict(doc), opts, precision)
