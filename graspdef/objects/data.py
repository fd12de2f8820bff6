"""An object's data (``scenes/<scene>/object.toml``): read, checked, in SI.

The file states everything the shell model of a grasped object needs, with units and sources::

    [object]
    body = "tennis_ball"                 # body name in the scene's MJCF
    scan = "ycb_056_tennis_ball"         # scans/manifest.toml id: the outer surface
    # or, for an object of one's own (graspdef object add): the control mesh itself
    # control_mesh = "control_mesh.ply"  # outer surface, a Loop control mesh; PLY 'comment units m'
    # surface = "surface.ply"            # optional: the input surface it was made from (reference)

    [shell]
    thickness = "2.5 mm"
    source = "Tian & Jia 2010, Sec. IX-A"          # optional
    control_faces = 1280                 # optional (1280): faces of the control mesh
    remesh = "project"                   # optional (auto): auto | project | decimate | isotropic
    relax = 0                            # optional (0): tangential smoothing steps on the scan

    [material]
    law = "neo_hookean"                  # neo_hookean | mooney_rivlin | svk | linear
    E = "1 MPa"                          # small-strain Young's modulus
    nu = 0.5                             # Poisson's ratio, 0 <= nu <= 0.5
    source = "Tian & Jia 2010, Sec. IX-A"
    # mooney_rivlin: C2_over_C1 = 0.25 with E, or C1 = "0.69 MPa", C2 = "0.173 MPa" instead of E

    [gas]                                # optional: enclosed air (no table: none)
    p0 = "80 kPa"                        # gauge pressure of the unloaded shell
    source = "..."
    # p_atm = "101.325 kPa"              # optional: ambient pressure (EnclosedGas's default)

    [grasp]
    fingers = ["left", "right"]          # optional: the fingers that press

    [supports]                           # optional: a body fixed in the scene is held here
    fixed_points = ["[47.97, 4.19, -41.65] mm"]    # object frame

    [solver]
    steps = 4                            # optional (8): initial load steps of the nonlinear path

Every key is checked (:mod:`graspdef.config`): an unknown key or table (``[gass]``) is refused by
name with the accepted ones listed, values carry units (:mod:`graspdef.units`) and the material
law is explicit: there is no default material, no E/3 and no built-in pressure anywhere.

The law and nu give the shell material (:meth:`MaterialSpec.shell_material`): a linear analysis
uses the law's small-strain limit LinearElastic(E, nu); a nonlinear one the stated law with that
nu: neo_hookean -> compressible neo-Hookean (nu < 0.5) or incompressible NeoHookean(mu = E/3)
(nu = 0.5); mooney_rivlin -> compressible Mooney-Rivlin (nu < 0.5) or incompressible
MooneyRivlin (nu = 0.5), both with mu = 2 (C1 + C2) = E / (2 (1 + nu)); svk -> Saint
Venant-Kirchhoff (Hooke's law in Green-Lagrange strain, LinearElastic(E, nu)); linear -> linear
analyses only (it has no finite-strain form of its own).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from ..config import Table, read_toml
from ..errors import ConfigError, ProblemError
from ..shell.hyperelastic import CompressibleMooneyRivlin, CompressibleNeoHookean, MooneyRivlin, NeoHookean
from ..shell.materials import LinearElastic
from ..sim.scene import SIDES

#: repository folder of the scenes (a scene is given by name, folder or scene XML)
SCENES = Path(__file__).resolve().parents[2] / "scenes"
#: the object's data file beside its scene XML
OBJECT_FILE = "object.toml"
#: material laws of object data
LAWS = ("neo_hookean", "mooney_rivlin", "svk", "linear")
REMESH = ("auto", "project", "decimate", "isotropic")

_TABLES = {"object", "shell", "material", "gas", "grasp", "supports", "solver"}
_MATERIAL_KEYS = {"law", "E", "nu", "source", "C1", "C2", "C2_over_C1"}


@dataclass(frozen=True)
class MaterialSpec:
    """A material law with its small-strain moduli, in SI.

    Attributes
    ----------
    law : str
        One of :data:`LAWS`.
    E : float
        Small-strain Young's modulus [Pa].
    nu : float
        Poisson's ratio [-], 0 <= nu <= 0.5.
    c2_over_c1 : float or None
        Mooney-Rivlin C2/C1 (mooney_rivlin only).
    source : str
        Where the values come from.
    """

    law: str
    E: float
    nu: float
    c2_over_c1: float | None = None
    source: str = ""

    def __post_init__(self) -> None:
        if self.law not in LAWS:
            raise ProblemError(f"unknown material law {self.law!r}; accepted: {', '.join(LAWS)}")
        LinearElastic(self.E, self.nu)              # E > 0 finite, 0 <= nu <= 0.5
        if (self.law == "mooney_rivlin") != (self.c2_over_c1 is not None):
            raise ProblemError("C2/C1 is given for the Mooney-Rivlin law and for no other")
        if self.c2_over_c1 is not None and not self.c2_over_c1 >= 0:
            raise ProblemError(f"Mooney-Rivlin C2/C1 must be >= 0, got {self.c2_over_c1!r}")

    @property
    def incompressible(self) -> bool:
        return self.nu == 0.5

    def model(self, analysis: str) -> str:
        """The shell material's registry name (:data:`graspdef.shell.hyperelastic.MATERIALS`) for
        ``analysis`` ("linear" or "nonlinear")."""
        return self._build(analysis)[0]

    def shell_material(self, analysis: str):
        """The shell material for ``analysis``: LinearElastic(E, nu) for "linear"; the stated law
        with this nu for "nonlinear" (see the module docstring)."""
        return self._build(analysis)[1]

    def with_E(self, E: float) -> "MaterialSpec":
        """The same law with Young's modulus ``E`` [Pa] (C2/C1 and nu kept)."""
        return dataclasses.replace(self, E=float(E))

    def _build(self, analysis: str):
        E, nu = self.E, self.nu
        if analysis == "linear":
            return "linear_elastic", LinearElastic(E, nu)
        if analysis != "nonlinear":
            raise ProblemError(f"analysis must be 'linear' or 'nonlinear', got {analysis!r}")
        if self.law == "linear":
            raise ProblemError("law = 'linear' has no finite-strain form: a nonlinear analysis needs law = 'svk' "
                               "(Hooke's law in Green-Lagrange strain) or a hyperelastic law (neo_hookean, mooney_rivlin)")
        if self.law == "svk":
            return "saint_venant_kirchhoff", LinearElastic(E, nu)
        if self.law == "neo_hookean":
            if self.incompressible:
                return "neo_hookean", NeoHookean(E / 3.0)
            return "compressible_neo_hookean", CompressibleNeoHookean.from_E_nu(E, nu)
        if self.incompressible:                      # mu = 2 (C1 + C2) = E / 3
            c1 = E / 3.0 / (2.0 * (1.0 + self.c2_over_c1))
            return "mooney_rivlin", MooneyRivlin(c1, self.c2_over_c1 * c1)
        return "compressible_mooney_rivlin", CompressibleMooneyRivlin.from_E_nu(E, nu, self.c2_over_c1)


@dataclass(frozen=True)
class GasSpec:
    """Enclosed air: gauge pressure ``p0`` [Pa] of the unloaded shell, ambient ``p_atm`` [Pa] (None:
    EnclosedGas's standard atmosphere), and the source of the value."""

    p0: float
    source: str
    p_atm: float | None = None


@dataclass(frozen=True)
class ObjectSpec:
    """An object's data (``object.toml``) in SI.

    Attributes
    ----------
    file : Path
        The object.toml read.
    scene : Path
        The scene XML (MuJoCo) the object is grasped in.
    body : str
        The object's body name in the scene.
    scan : str or None
        Real scan id of ``scans/manifest.toml`` (the outer surface), or None when the object
        gives its control mesh.
    thickness : float
        Wall thickness [m].
    control_faces, remesh, relax :
        Control mesh from the scan (graspdef.scans.control_mesh).
    material : MaterialSpec
    gas : GasSpec or None
    fingers : tuple of str
        The gripper fingers that press ("left", "right").
    fixed_points : tuple of (x, y, z)
        Points [m, object frame] held when the body is fixed in the scene.
    steps : int
        Initial load steps of a nonlinear path.
    control_mesh : Path or None
        The outer surface as a ready Loop control mesh (graspdef object add), instead of a scan.
    surface : Path or None
        The input surface the control mesh was made from (a reference; not used by the solve).
    """

    file: Path
    scene: Path
    body: str
    scan: str | None
    thickness: float
    control_faces: int
    remesh: str
    relax: int
    material: MaterialSpec
    gas: GasSpec | None
    fingers: tuple[str, ...]
    fixed_points: tuple[tuple[float, float, float], ...]
    steps: int
    control_mesh: Path | None = None
    surface: Path | None = None

    @property
    def folder(self) -> Path:
        return self.file.parent

    def shell_material(self, analysis: str):
        """The shell material for ``analysis`` (:meth:`MaterialSpec.shell_material`); an error
        names the object file."""
        try:
            return self.material.shell_material(analysis)
        except ProblemError as exc:
            raise ProblemError(f"{self.file}: [material] {exc}") from None

    def replace(self, **changes) -> "ObjectSpec":
        """A copy with fields replaced (``E=`` sets the material's Young's modulus [Pa])."""
        if "E" in changes:
            changes["material"] = changes.get("material", self.material).with_E(changes.pop("E"))
        return dataclasses.replace(self, **changes)


#: fingertip variants of a scene folder: the scene file that grips the object with them
FINGERTIPS = {"pin": "scene.xml", "pad": "scene_pad.xml"}


def scene_xml(scene, fingertips: str | None = None) -> Path:
    """A scene folder, its scene*.xml, or a name under scenes/ -> the scene XML path;
    ``fingertips`` ("pin" or "pad") picks the folder's scene with those fingertips."""
    if fingertips is not None and fingertips not in FINGERTIPS:
        raise ProblemError(f"unknown fingertips {fingertips!r}; accepted: {', '.join(FINGERTIPS)}")
    name = FINGERTIPS[fingertips or "pin"]
    p = Path(scene)
    if p.is_dir():
        p = p / name
    elif not p.exists() and (SCENES / str(scene)).is_dir():
        p = SCENES / str(scene) / name
    elif fingertips is not None and p.is_file():
        p = p.parent / name
    if not p.is_file():
        if fingertips is not None and p.parent.is_dir():
            raise ProblemError(f"scene {scene}: no {name} for {fingertips} fingertips in {p.parent} "
                               f"(has: {', '.join(sorted(q.name for q in p.parent.glob('scene*.xml'))) or 'none'})")
        raise ProblemError(f"scene not found: {scene} (give a scene.xml, its folder, or a name in {SCENES})")
    return p


def load_object(scene) -> ObjectSpec:
    """The object of ``scene`` (a name under scenes/, a scene folder or a scene XML): its
    ``object.toml`` beside the scene XML, read and checked (:func:`read_object`)."""
    xml = scene_xml(scene)
    f = xml.parent / OBJECT_FILE
    if not f.is_file():
        raise ProblemError(f"{xml.parent}: no {OBJECT_FILE} beside the scene (the object's data: scan, thickness, "
                           "material law, gas, supports)")
    return read_object(f, xml)


def _material(m: Table) -> MaterialSpec:
    law = m.string("law", choices=LAWS)
    accepted = {"law", "nu", "source"} | ({"E", "C1", "C2", "C2_over_C1"} if law == "mooney_rivlin" else {"E"})
    m.check(accepted, ("law", "nu", "source"))
    nu = m.number("nu", minimum=0.0, maximum=0.5)
    ratio = None
    if law == "mooney_rivlin":
        by_c = "C1" in m or "C2" in m
        if by_c == ("E" in m or "C2_over_C1" in m):
            raise m.error("give E and C2_over_C1, or C1 and C2 (mooney_rivlin)")
        if by_c:
            m.check(accepted, ("C1", "C2"))
            c1 = m.quantity("C1", "pressure", positive=True)
            c2 = m.quantity("C2", "pressure")
            if c2 < 0:
                raise m.error(f"must be >= 0, got {m['C2']!r}", "C2")
            E, ratio = 4.0 * (c1 + c2) * (1.0 + nu), c2 / c1    # mu = 2 (C1 + C2) = E / (2 (1 + nu))
        else:
            m.check(accepted, ("E", "C2_over_C1"))
            E, ratio = m.quantity("E", "pressure", positive=True), m.number("C2_over_C1", minimum=0.0)
    else:
        m.check(accepted, ("E",))
        E = m.quantity("E", "pressure", positive=True)
    return MaterialSpec(law, E, nu, ratio, m.string("source"))


def read_object(path, scene=None) -> ObjectSpec:
    """Read and check an object file (see the module docstring); ``scene``: the scene XML it
    belongs to (default: ``scene.xml`` beside it)."""
    from ..scans.manifest import load_manifest

    path = Path(path)
    doc = read_toml(path, "object file").check(_TABLES, ("object", "shell", "material"))
    o = doc.table("object").check({"body", "scan", "control_mesh", "surface"}, ("body",))
    if ("scan" in o) == ("control_mesh" in o):
        raise o.error("give scan (a scans/manifest.toml id) or control_mesh (a PLY file beside object.toml), "
                      "one of them")
    scan = o.string("scan", choices=load_manifest().real) if "scan" in o else None
    files = {}
    for key in ("control_mesh", "surface"):
        if key in o:
            f = path.parent / o.string(key)
            if not f.is_file():
                raise ConfigError(f"{o.where(key)}: file not found: {f}")
            files[key] = f
    sh = doc.table("shell").check({"thickness", "source", "control_faces", "remesh", "relax"}, ("thickness",))
    thickness = sh.quantity("thickness", "length", positive=True)
    sh.string("source", "")
    material = _material(doc.table("material"))
    gas = None
    if "gas" in doc:
        g = doc.table("gas").check({"p0", "source", "p_atm"}, ("p0", "source"))
        gas = GasSpec(g.quantity("p0", "pressure", positive=True), g.string("source"),
                      g.quantity("p_atm", "pressure", None, positive=True))
    grasp = doc.table("grasp", required=False).check({"fingers"})
    fingers = tuple(grasp.list("fingers", "string", list(SIDES), unique=True))
    for f in fingers:
        if f not in SIDES:
            raise ConfigError(f"{grasp.where('fingers')}: unknown finger {f!r}; accepted: {', '.join(SIDES)}")
    fixed = doc.table("supports", required=False).check({"fixed_points"}).quantity_vectors("fixed_points", "length",
                                                                                          default=())
    solver = doc.table("solver", required=False).check({"steps"})
    return ObjectSpec(path, Path(scene) if scene is not None else path.parent / "scene.xml", o.string("body"), scan,
                      thickness, sh.integer("control_faces", 1280, minimum=20), sh.string("remesh", "auto", choices=REMESH),
                      sh.integer("relax", 0, minimum=0), material, gas, fingers, fixed,
                      solver.integer("steps", 8, positive=True), files.get("control_mesh"), files.get("surface"))
