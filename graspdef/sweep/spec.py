"""Sweep specifications: a TOML file -> the grid of grasp cases.

A spec names the axes of a grid; every combination is one case, i.e. one
:func:`graspdef.pipeline.grasp.run_grasp` call::

    [sweep]
    name = "tennis_ball_forces"               # optional; the summary's title

    [grid]
    scenes = ["tennis_ball"]                  # names under scenes/ or scene.xml paths
    forces_N = [10.63, 16.50, 20.37, 21.48]   # squeezing force per finger
    materials = ["linear", "rubber_air"]      # built-in presets or [materials.<name>] tables
    contacts = ["point"]                      # optional, default ["point"]
    control_faces = [320, 1280]               # optional mesh levels, default: each object.toml's

    [materials.rubber_air]
    analysis = "nonlinear"                    # required: linear | nonlinear
    E = "1 MPa"                               # optional, default: object.toml's (E_MPa = 1.0: the same)
    gas = "on"                                # optional: auto | on | off (default auto)
    steps = 4                                 # optional initial load steps (nonlinear)

The file is read with :mod:`graspdef.config`: every key is checked (unknown keys get a
did-you-mean hint and the accepted keys), every axis must be a non-empty list without repeats,
every scene must exist with its object.toml, every force must lie in the scene's actuator range,
``gas = "on"`` needs the object's [gas] and a nonlinear analysis a law that has a finite-strain
form -- all before any case runs.  Errors are ProblemErrors naming the file, the table and the key.

A case's identity is its parameters (the material's resolved options, not just its name) plus
the SHA-256 of the scene's ``scene.xml`` and ``object.toml``: the case folder name is a readable
slug and the first 10 hex digits of that hash, so an unchanged case keeps its folder (and is
not recomputed on resume) and a changed input gives a new one.
"""
from __future__ import annotations

import hashlib
import itertools
import json
from dataclasses import asdict, dataclass
from os import PathLike
from pathlib import Path

from ..config import Table, parse_toml, read_toml, unknown_name
from ..errors import ConfigError, ProblemError

#: material presets available without a [materials] table
BUILTIN_MATERIALS = {
    "linear": {"analysis": "linear", "E_Pa": None, "gas": "auto", "steps": None},
    "nonlinear": {"analysis": "nonlinear", "E_Pa": None, "gas": "auto", "steps": None},
}
CONTACTS = ("point", "geometric")
GAS = ("auto", "on", "off")
_TOP = {"sweep", "grid", "materials"}
_SWEEP = {"name", "description"}
_GRID = {"scenes", "forces_N", "materials", "contacts", "control_faces"}
_GRID_REQUIRED = ("scenes", "forces_N", "materials")
#: E_MPa: the spelling before units were written as text (a number in MPa); E: a quantity
_MATERIAL = {"analysis", "E", "E_MPa", "gas", "steps"}


def _material(t: Table) -> dict:
    t.check(_MATERIAL, ("analysis",))
    if "E" in t and "E_MPa" in t:
        raise t.error("give E (e.g. \"8.17 MPa\") or E_MPa, not both")
    E = (t.quantity("E", "pressure", None, positive=True) if "E" in t
         else t.quantity("E_MPa", "pressure", None, implied="MPa", positive=True))
    m = {"analysis": t.string("analysis", choices=("linear", "nonlinear")), "E_Pa": E,
         "gas": t.string("gas", "auto", choices=GAS), "steps": t.integer("steps", None, positive=True)}
    if m["analysis"] == "linear" and m["gas"] == "on":
        raise t.error("an enclosed gas needs analysis = \"nonlinear\" (p V = const is nonlinear)")
    return m


@dataclass(frozen=True)
class Case:
    """One grasp of the grid: the arguments of one :func:`run_grasp` call."""

    scene: str                 # as written in the spec (a name under scenes/ or a path)
    scene_name: str            # the scene folder's name (for slugs and tables)
    force_N: float
    material: str              # preset name
    analysis: str
    E_Pa: float | None         # Young's modulus [Pa]; None: object.toml's
    gas: str                   # auto | on | off
    steps: int | None
    contact: str
    control_faces: int         # the control mesh's number of faces (the mesh level)
    inputs_sha256: str         # of scene.xml + object.toml

    @property
    def key(self) -> str:
        """SHA-256 of the case's parameters and inputs (hex)."""
        return hashlib.sha256(json.dumps(asdict(self), sort_keys=True).encode()).hexdigest()

    @property
    def id(self) -> str:
        """Folder name: readable slug + 10 hex digits of :attr:`key`."""
        return (f"{self.scene_name}_{self.force_N:g}N_{self.material}_{self.contact}_{self.control_faces}f_"
                f"{self.key[:10]}").replace("/", "_").replace(" ", "_")

    def label(self) -> str:
        """Short human-readable description for progress lines."""
        return f"{self.scene_name}, {self.force_N:g} N, {self.material}, {self.contact}, {self.control_faces} faces"

    def record(self) -> dict:
        return dict(asdict(self), id=self.id, key=self.key)

    @classmethod
    def from_record(cls, rec: dict) -> "Case":
        return cls(**{k: rec[k] for k in cls.__dataclass_fields__})


@dataclass(frozen=True)
class SweepSpec:
    """A parsed sweep spec: the grid's axes, the material presets and the cases."""

    path: str
    text: str
    name: str
    description: str
    scenes: tuple[str, ...]
    forces_N: tuple[float, ...]
    materials: dict
    contacts: tuple[str, ...]
    control_faces: tuple[int, ...] | None
    cases: tuple[Case, ...]


def _scene_info(scene: str, path: str):
    """(object data, inputs digest, actuator force range [N]) of a scene of the grid."""
    from ..objects import load_object

    try:
        obj = load_object(scene)
    except ProblemError as exc:
        raise ProblemError(f"{path}: [grid] scenes: {exc}") from exc
    digest = hashlib.sha256(obj.scene.read_bytes() + b"\0" + obj.file.read_bytes()).hexdigest()
    return obj, digest, _actuator_range(obj.scene, obj.body, path)


def _actuator_range(xml: Path, body: str, path: str) -> tuple[float, float]:
    from ..errors import GraspdefError
    from ..sim.scene import load_scene

    try:
        sc = load_scene(xml, body)
    except GraspdefError as exc:
        raise ProblemError(f"{path}: [grid] scenes: {exc}") from exc
    from ..sim.grasp import force_range

    ranges = force_range(sc).values()               # the force every finger can exert
    return max(float(r[0]) for r in ranges), min(float(r[1]) for r in ranges)


def parse_spec(text: str, path: str = "<spec>") -> SweepSpec:
    """Parse and check a sweep spec given as TOML text (see the module docstring)."""
    return _parse(parse_toml(text, str(path)), text)


def _parse(doc: Table, text: str) -> SweepSpec:
    path = doc.source
    doc.check(_TOP, ("grid",))
    sw = doc.table("sweep", required=False).check(_SWEEP)
    grid = doc.table("grid").check(_GRID, _GRID_REQUIRED)
    scenes = grid.list("scenes", "string", unique=True)
    forces = grid.list("forces_N", "number", unique=True)
    for f in forces:
        if f <= 0:
            raise grid.error(f"must be positive (per finger, N), got {f:g}", "forces_N")
    mats = grid.list("materials", "string", unique=True)
    contacts = grid.list("contacts", "string", ["point"], unique=True)
    for c in contacts:
        if c not in CONTACTS:
            raise ConfigError(f"{grid.where('contacts')}: " + unknown_name(c, CONTACTS, noun="contact model"))
    faces = grid.list("control_faces", "integer", None, unique=True)
    for n in faces or ():
        if n < 20:
            raise grid.error(f"must be >= 20 (a control mesh's faces), got {n}", "control_faces")
    presets = {}
    for name, table in doc.table("materials", required=False).children().items():
        if name in BUILTIN_MATERIALS:
            raise table.error(f"'{name}' is a built-in preset; choose another name")
        presets[name] = _material(table)
    for name in mats:
        if name not in presets and name not in BUILTIN_MATERIALS:
            valid = sorted(presets) + sorted(BUILTIN_MATERIALS)
            raise ConfigError(f"{grid.where('materials')}: " + unknown_name(name, valid, noun="material")
                              + f"; or define it in a [materials.{name}] table")
    unused = sorted(set(presets) - set(mats))
    if unused:
        raise ProblemError(f"{path}: [materials.{unused[0]}] is defined but not in [grid] materials")
    used = {n: presets.get(n, BUILTIN_MATERIALS.get(n)) for n in mats}
    info = {}
    for s in scenes:
        obj, digest, (lo, hi) = info[s] = _scene_info(s, path)
        bad = [f for f in forces if not lo <= f <= hi]
        if bad:
            raise ProblemError(f"{path}: [grid] forces_N: {bad[0]:g} N is beyond what the actuators of scene "
                               f"{s!r} can exert ({lo:g}..{hi:g} N)")
        for n, m in used.items():
            if m["gas"] == "on" and obj.gas is None:
                raise ProblemError(f"{path}: [materials.{n}] gas = \"on\", but scene {s!r} has no enclosed air "
                                   f"([gas] in {obj.file})")
            if m["analysis"] == "nonlinear":
                obj.shell_material("nonlinear")          # a law without a finite-strain form: an error here
    cases = []
    for s, f, m, c in itertools.product(scenes, forces, mats, contacts):
        obj, digest, _ = info[s]
        p = used[m]
        for n in (faces or [obj.control_faces]):
            cases.append(Case(s, obj.scene.parent.name, f, m, p["analysis"], p["E_Pa"], p["gas"], p["steps"], c,
                              int(n), digest))
    ids = [c.id for c in cases]
    if len(set(ids)) != len(ids):       # two spellings of one scene, e.g. a name and its path
        raise ProblemError(f"{path}: [grid] the grid holds the same case twice (a scene given twice?)")
    return SweepSpec(str(path), text, sw.string("name", Path(path).stem), sw.string("description", ""),
                     tuple(scenes), tuple(forces), used, tuple(contacts), tuple(faces) if faces else None,
                     tuple(cases))


def load_spec(path: str | PathLike) -> SweepSpec:
    """Read and check a sweep spec file (``SPEC.toml``); see :func:`parse_spec`."""
    doc = read_toml(path, "sweep spec")
    return _parse(doc, Path(path).read_text())
