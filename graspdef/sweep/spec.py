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
    control_faces = [320, 1280]               # optional mesh levels, default: each shell.toml's

    [materials.rubber_air]
    analysis = "nonlinear"                    # required: linear | nonlinear
    E_MPa = 1.0                               # optional, default: shell.toml's
    gas = "on"                                # optional: auto | on | off (default auto)
    steps = 4                                 # optional initial load steps (nonlinear)

Every key is checked (unknown keys get a did-you-mean hint), every axis must be a non-empty
list without repeats, every scene must exist with its shell.toml and every force must lie in
the scene's actuator range -- all before any case runs.  Errors are :class:`ProblemError`
naming the file and the key.

A case's identity is its parameters (the material's resolved options, not just its name) plus
the SHA-256 of the scene's ``scene.xml`` and ``shell.toml``: the case folder name is a readable
slug and the first 10 hex digits of that hash, so an unchanged case keeps its folder (and is
not recomputed on resume) and a changed input gives a new one.
"""
from __future__ import annotations

import difflib
import hashlib
import itertools
import json
import math
import tomllib
from dataclasses import asdict, dataclass
from os import PathLike
from pathlib import Path

from ..errors import ProblemError

#: material presets available without a [materials] table
BUILTIN_MATERIALS = {
    "linear": {"analysis": "linear", "E_MPa": None, "gas": "auto", "steps": None},
    "nonlinear": {"analysis": "nonlinear", "E_MPa": None, "gas": "auto", "steps": None},
}
CONTACTS = ("point", "geometric")
GAS = ("auto", "on", "off")
_TOP = {"sweep", "grid", "materials"}
_SWEEP = {"name", "description"}
_GRID = {"scenes", "forces_N", "materials", "contacts", "control_faces"}
_GRID_REQUIRED = {"scenes", "forces_N", "materials"}
_MATERIAL = {"analysis", "E_MPa", "gas", "steps"}


def _check_keys(table, allowed: set, ctx: str, path: str, required: set = frozenset()) -> None:
    if not isinstance(table, dict):
        raise ProblemError(f"{path}: [{ctx}] must be a table")
    for k in table:
        if k not in allowed:
            hint = difflib.get_close_matches(k, sorted(allowed), n=1)
            extra = f" (did you mean '{hint[0]}'?)" if hint else f" (valid: {', '.join(sorted(allowed))})"
            raise ProblemError(f"{path}: unknown key '{k}' in [{ctx}]{extra}")
    for k in sorted(required):
        if k not in table:
            raise ProblemError(f"{path}: missing key '{k}' in [{ctx}]")


def _axis(grid: dict, key: str, path: str, kind: type, default=None) -> list:
    if key not in grid:
        return list(default)
    v = grid[key]
    if not isinstance(v, list):
        raise ProblemError(f"{path}: [grid] {key} must be a list, got {v!r}")
    if not v:
        raise ProblemError(f"{path}: [grid] {key} is empty: an empty axis gives an empty sweep")
    out = []
    for x in v:
        if kind is float:
            if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
                raise ProblemError(f"{path}: [grid] {key} must hold finite numbers, got {x!r}")
            x = float(x)
        elif kind is int:
            if isinstance(x, bool) or not isinstance(x, int):
                raise ProblemError(f"{path}: [grid] {key} must hold integers, got {x!r}")
        elif not isinstance(x, str) or not x:
            raise ProblemError(f"{path}: [grid] {key} must hold non-empty strings, got {x!r}")
        out.append(x)
    dup = sorted({str(x) for x in out if out.count(x) > 1})
    if dup:
        raise ProblemError(f"{path}: [grid] {key} repeats {', '.join(dup)}")
    return out


def _material(name: str, table, path: str) -> dict:
    ctx = f"materials.{name}"
    _check_keys(table, _MATERIAL, ctx, path, required={"analysis"})
    m = {"analysis": table["analysis"], "E_MPa": table.get("E_MPa"), "gas": table.get("gas", "auto"),
         "steps": table.get("steps")}
    if m["analysis"] not in ("linear", "nonlinear"):
        raise ProblemError(f"{path}: [{ctx}] analysis must be 'linear' or 'nonlinear', got {m['analysis']!r}")
    if m["E_MPa"] is not None:
        e = m["E_MPa"]
        if isinstance(e, bool) or not isinstance(e, (int, float)) or not math.isfinite(e) or e <= 0:
            raise ProblemError(f"{path}: [{ctx}] E_MPa must be a positive number, got {e!r}")
        m["E_MPa"] = float(e)
    if m["gas"] not in GAS:
        raise ProblemError(f"{path}: [{ctx}] gas must be one of {', '.join(GAS)}, got {m['gas']!r}")
    if m["analysis"] == "linear" and m["gas"] == "on":
        raise ProblemError(f"{path}: [{ctx}] an enclosed gas needs analysis = \"nonlinear\" (p V = const is nonlinear)")
    if m["steps"] is not None and (isinstance(m["steps"], bool) or not isinstance(m["steps"], int) or m["steps"] < 1):
        raise ProblemError(f"{path}: [{ctx}] steps must be a positive integer, got {m['steps']!r}")
    return m


@dataclass(frozen=True)
class Case:
    """One grasp of the grid: the arguments of one :func:`run_grasp` call."""

    scene: str                 # as written in the spec (a name under scenes/ or a path)
    scene_name: str            # the scene folder's name (for slugs and tables)
    force_N: float
    material: str              # preset name
    analysis: str
    E_MPa: float | None        # None: shell.toml's
    gas: str                   # auto | on | off
    steps: int | None
    contact: str
    control_faces: int         # the control mesh's number of faces (the mesh level)
    inputs_sha256: str         # of scene.xml + shell.toml

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


def _scene_info(scene: str, path: str) -> tuple[str, int, str, tuple[float, float]]:
    """(folder name, shell.toml control_faces, inputs digest, actuator force range [N])."""
    from ..pipeline.grasp import load_shell_spec, resolve_scene

    try:
        xml = resolve_scene(scene)
        shell = load_shell_spec(xml)
    except ProblemError as exc:
        raise ProblemError(f"{path}: [grid] scenes: {exc}") from exc
    digest = hashlib.sha256(xml.read_bytes() + b"\0" + (xml.parent / "shell.toml").read_bytes()).hexdigest()
    return xml.parent.name, shell.control_faces, digest, _actuator_range(xml, shell.body, path)


def _actuator_range(xml: Path, body: str, path: str) -> tuple[float, float]:
    from ..errors import GraspdefError
    from ..sim.scene import load_scene

    try:
        sc = load_scene(xml, body)
    except GraspdefError as exc:
        raise ProblemError(f"{path}: [grid] scenes: {exc}") from exc
    m = sc.model
    lo, hi = -math.inf, math.inf
    for _b, _q, _d, a in sc.fingers.values():
        if m.actuator_ctrllimited[a]:
            g = float(m.actuator_gear[a, 0])
            lo, hi = max(lo, float(m.actuator_ctrlrange[a, 0]) * g), min(hi, float(m.actuator_ctrlrange[a, 1]) * g)
    return lo, hi


def parse_spec(text: str, path: str = "<spec>") -> SweepSpec:
    """Parse and check a sweep spec given as TOML text (see the module docstring)."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ProblemError(f"{path}: not valid TOML: {exc}") from exc
    _check_keys(doc, _TOP, "top level", path, required={"grid"})
    sw = doc.get("sweep", {})
    _check_keys(sw, _SWEEP, "sweep", path)
    grid = doc["grid"]
    _check_keys(grid, _GRID, "grid", path, required=_GRID_REQUIRED)
    scenes = _axis(grid, "scenes", path, str)
    forces = _axis(grid, "forces_N", path, float)
    for f in forces:
        if f <= 0:
            raise ProblemError(f"{path}: [grid] forces_N must be positive (per finger, N), got {f:g}")
    mats = _axis(grid, "materials", path, str)
    contacts = _axis(grid, "contacts", path, str, default=["point"])
    for c in contacts:
        if c not in CONTACTS:
            hint = difflib.get_close_matches(c, CONTACTS, n=1)
            raise ProblemError(f"{path}: [grid] contacts: unknown contact model {c!r}"
                               + (f" (did you mean '{hint[0]}'?)" if hint else f" (valid: {', '.join(CONTACTS)})"))
    faces = _axis(grid, "control_faces", path, int, default=[]) if "control_faces" in grid else None
    for n in faces or ():
        if n < 20:
            raise ProblemError(f"{path}: [grid] control_faces must be >= 20 (a control mesh's faces), got {n}")
    defined = doc.get("materials", {})
    if not isinstance(defined, dict):
        raise ProblemError(f"{path}: [materials] must be a table of [materials.<name>] tables")
    presets = {}
    for name, table in defined.items():
        if name in BUILTIN_MATERIALS:
            raise ProblemError(f"{path}: [materials.{name}]: '{name}' is a built-in preset; choose another name")
        presets[name] = _material(name, table, path)
    for name in mats:
        if name not in presets and name not in BUILTIN_MATERIALS:
            valid = sorted(presets) + sorted(BUILTIN_MATERIALS)
            hint = difflib.get_close_matches(name, valid, n=1)
            raise ProblemError(f"{path}: [grid] materials: unknown material {name!r}"
                               + (f" (did you mean '{hint[0]}'?)" if hint else "")
                               + f"; define it in a [materials.{name}] table or use one of: {', '.join(valid)}")
    unused = sorted(set(presets) - set(mats))
    if unused:
        raise ProblemError(f"{path}: [materials.{unused[0]}] is defined but not in [grid] materials")
    used = {n: presets.get(n, BUILTIN_MATERIALS.get(n)) for n in mats}
    info = {}
    for s in scenes:
        info[s] = _scene_info(s, path)
        lo, hi = info[s][3]
        bad = [f for f in forces if not lo <= f <= hi]
        if bad:
            raise ProblemError(f"{path}: [grid] forces_N: {bad[0]:g} N is beyond what the actuators of scene "
                               f"{s!r} can exert ({lo:g}..{hi:g} N)")
    cases = []
    for s, f, m, c in itertools.product(scenes, forces, mats, contacts):
        name, default_faces, digest, _ = info[s]
        p = used[m]
        for n in (faces or [default_faces]):
            cases.append(Case(s, name, f, m, p["analysis"], p["E_MPa"], p["gas"], p["steps"], c, int(n), digest))
    ids = [c.id for c in cases]
    if len(set(ids)) != len(ids):       # two spellings of one scene, e.g. a name and its path
        raise ProblemError(f"{path}: [grid] the grid holds the same case twice (a scene given twice?)")
    name = sw.get("name", Path(path).stem)
    if not isinstance(name, str):
        raise ProblemError(f"{path}: [sweep] name must be a string")
    return SweepSpec(str(path), text, name, str(sw.get("description", "")), tuple(scenes), tuple(forces), used,
                     tuple(contacts), tuple(faces) if faces else None, tuple(cases))


def load_spec(path: str | PathLike) -> SweepSpec:
    """Read and check a sweep spec file (``SPEC.toml``); see :func:`parse_spec`."""
    p = Path(path)
    if not p.is_file():
        raise ProblemError(f"sweep spec not found: {p}")
    return parse_spec(p.read_text(), str(p))
