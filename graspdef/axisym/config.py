"""TOML problem files: the thesis's data cards (nodes, segments, restraints, nodal loads, distributed loads,
material) as a TOML document.  Example (benchmarks/axisym/hemisphere_ring.toml):

    name = "hemisphere_ring"
    [units]                 # declared units: SI ("m", "N", "Pa") or "nondimensional" (t0 = C1 = 1)
    system = "SI"           # SI: plain numbers are SI; lengths, forces, C1 and pressures may carry a unit
    [material]              # kind = "mooney_rivlin" | "exponential"; C1 in Pa; gamma = C2/C1 or exponent
    kind = "mooney_rivlin"
    C1 = "1 MPa"
    gamma = 0.1
    [shell]
    thickness = "1 mm"
    [discretisation]        # optional: longest shooting piece in units of t0, RK4 steps per piece
    max_piece = 0.6
    rk_steps = 2
    [[nodes]]               # meridian order; r, z in m; phi (rad) or phi_deg: tangent angle; fix: restraints
    r = 0.0
    z = 0.01
    phi = 0.0
    [[nodes]]
    r = 0.01
    z = 0.0
    phi_deg = -90.0
    fix = ["z"]
    [[segments]]            # from -> to, constant curvature kappa (1/m) or signed radius (m)
    from = 0
    to = 1
    radius = -0.01
    [[nodal_loads]]         # per radian of circumference: H, V (N/rad), M (N m/rad); or Fr, Fz total (N)
    node = 1
    M = 1.0
    [[distributed_loads]]   # Pa: qH, qV per deformed area, QH, QV per undeformed area, p pressure along e_n
    qV = -1.0
    segments = [0]          # optional, default all
    [path]                  # optional continuation controls (keyword arguments of continuation.solve_path:
    ds = 0.5                # ds, ds_max, ds_min, max_steps, maxit, lam_max, target_iterations, weight,
                            # on_failure = "raise" | "stop", unload_fraction)
    max_steps = 80
    lam_max = 10.0
"""

import numpy as np

from graspdef.config import Table, check_names, read_toml

from .assembly import DistributedLoad, Model, NodalLoad, Node, Segment
from .material import KINDS, AxisymMaterial

_TOP = {"name", "description", "units", "material", "shell", "discretisation", "nodes", "segments", "nodal_loads",
        "distributed_loads", "path"}
_NODE_KEYS = {"r", "z", "phi", "phi_deg", "fix"}
_SEG_KEYS = {"from", "to", "kappa", "radius", "n_sub"}
_NL_KEYS = {"node", "H", "V", "M", "Fr", "Fz"}
_DL_KEYS = {"qH", "qV", "QH", "QV", "p", "segments"}
#: [path] keys: the options of continuation.solve_path a file may set, and their kinds
_PATH = {"ds": "number", "ds_max": "number", "ds_min": "number", "max_steps": "integer", "maxit": "integer",
         "lam_max": "number", "target_iterations": "integer", "weight": "number", "on_failure": "string",
         "unload_fraction": "number"}


def parse_axisym_problem(doc, source="problem"):
    """Model and path options from a parsed TOML document (a dict or a :class:`graspdef.config.Table`)."""
    doc = doc if isinstance(doc, Table) else Table(doc, source)
    doc.check(_TOP, ("units", "material", "shell", "nodes", "segments"))
    system = doc.table("units").check({"system"}).get("system", "")
    if system not in ("SI", "nondimensional"):
        raise doc.table("units").error("system must be declared as \"SI\" or \"nondimensional\"")
    # SI: plain numbers are SI, text may carry a unit ("2 mm"); nondimensional: plain numbers only
    unitless = None if system == "SI" else "the problem is nondimensional"

    def q(t, key, dimension, default=None):
        return t.quantity(key, dimension, default, implied=1.0, unitless=unitless)

    mt = doc.table("material").check({"kind", "C1", "gamma", "volume_factor"}, ("C1",))
    mat = AxisymMaterial(mt.string("kind", "mooney_rivlin", choices=KINDS), q(mt, "C1", "pressure"),
                         mt.number("gamma", 0.0), mt.boolean("volume_factor", False))
    t0 = q(doc.table("shell").check({"thickness"}, ("thickness",)), "thickness", "length")
    if system == "nondimensional" and (t0 != 1.0 or mat.C1 != 1.0):
        raise doc.error("nondimensional problems need [shell] thickness = 1 and [material] C1 = 1")
    nodes = []
    for nd in doc.tables("nodes", start=0):
        nd.check(_NODE_KEYS, ("r", "z"))
        if ("phi" in nd) == ("phi_deg" in nd):
            raise nd.error("give phi (rad) or phi_deg, one of them")
        phi = nd.number("phi") if "phi" in nd else np.radians(nd.number("phi_deg"))
        fix = nd.get("fix", [])
        fix = [fix] if isinstance(fix, str) else fix
        if not isinstance(fix, list):
            raise nd.error(f"must be a restraint or a list of them (r, z, phi), got {fix!r}", "fix")
        check_names(fix, ("r", "z", "phi"), noun="restraint", prefix=f"{nd.where('fix')}: ")
        nodes.append(Node(q(nd, "r", "length"), q(nd, "z", "length"), phi, tuple(c in fix for c in ("r", "z", "phi"))))
    segs = []
    for sg in doc.tables("segments", start=0):
        sg.check(_SEG_KEYS, ("from", "to"))
        if "kappa" in sg and "radius" in sg:
            raise sg.error("give kappa or radius, not both")
        if "radius" in sg:
            rad = q(sg, "radius", "length")
            if rad == 0:
                raise sg.error("must be non-zero (use kappa = 0 for a straight piece)", "radius")
            kap = 1.0 / rad
        else:
            kap = sg.number("kappa", 0.0)
        segs.append(Segment(sg.integer("from"), sg.integer("to"), kap, sg.integer("n_sub", None, positive=True)))
    nls = []
    for nl in doc.tables("nodal_loads", start=0):
        nl.check(_NL_KEYS, ("node",))
        ld = NodalLoad(nl.integer("node"), nl.number("H", 0.0), nl.number("V", 0.0), nl.number("M", 0.0))
        ld.H += q(nl, "Fr", "force", 0.0) / (2 * np.pi)
        ld.V += q(nl, "Fz", "force", 0.0) / (2 * np.pi)
        nls.append(ld)
    dls = []
    for dl in doc.tables("distributed_loads", start=0):
        dl.check(_DL_KEYS)
        dls.append(DistributedLoad(*(q(dl, key, "pressure", 0.0) for key in ("qH", "qV", "QH", "QV", "p")),
                                   segments=dl.list("segments", "integer", None)))
    disc = doc.table("discretisation", required=False).check({"max_piece", "rk_steps"})
    model = Model(mat, t0, nodes, segs, nls, dls, max_piece=disc.number("max_piece", 0.6, positive=True),
                  rk_steps=disc.integer("rk_steps", 2, positive=True), name=str(doc.get("name", source)))
    model.build()  # validate now: clear errors at load time
    path = doc.table("path", required=False).check(_PATH)
    opts = {}
    for key, kind in _PATH.items():
        if key in path:
            opts[key] = (path.string(key, choices=("raise", "stop")) if kind == "string"
                         else getattr(path, kind)(key, positive=key != "lam_max"))
    return model, opts


def load_axisym_problem(path):
    """Read a TOML problem file; returns (Model, path options dict)."""
    return parse_axisym_problem(read_toml(path, "axisymmetric problem file"))
