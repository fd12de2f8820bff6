"""TOML problem files: the thesis's data cards (nodes, segments, restraints, nodal loads, distributed loads,
material) as a TOML document.  Example (benchmarks/axisym/hemisphere_ring.toml):

    name = "hemisphere_ring"
    [units]                 # declared units: SI ("m", "N", "Pa") or "nondimensional" (t0 = C1 = 1)
    system = "SI"
    [material]              # kind = "mooney_rivlin" | "exponential"; C1 in Pa; gamma = C2/C1 or exponent
    kind = "mooney_rivlin"
    C1 = 1.0e6
    gamma = 0.1
    [shell]
    thickness = 0.001       # m
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
    [path]                  # optional continuation controls
    ds = 0.5
    max_steps = 80
    lam_max = 10.0
"""
import tomllib
from pathlib import Path

import numpy as np

from graspdef.errors import ProblemError

from .assembly import DistributedLoad, Model, NodalLoad, Node, Segment
from .material import Material

_NODE_KEYS = {"r", "z", "phi", "phi_deg", "fix"}
_SEG_KEYS = {"from", "to", "kappa", "radius", "n_sub"}
_NL_KEYS = {"node", "H", "V", "M", "Fr", "Fz"}
_DL_KEYS = {"qH", "qV", "QH", "QV", "p", "segments"}


def _check_keys(tbl, allowed, where):
    extra = set(tbl) - allowed
    if extra:
        raise ProblemError(f"{where}: unknown keys {sorted(extra)} (allowed: {sorted(allowed)})")


def _num(tbl, key, where, default=None):
    if key not in tbl:
        if default is None:
            raise ProblemError(f"{where}: missing '{key}'")
        return default
    v = tbl[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
        raise ProblemError(f"{where}: '{key}' must be a finite number, got {v!r}")
    return float(v)


def parse_problem(doc: dict, source="problem"):
    """Model and path options from a parsed TOML document."""
    units = doc.get("units", {})
    system = units.get("system", "")
    if system not in ("SI", "nondimensional"):
        raise ProblemError(f"{source}: [units] system must be declared as \"SI\" or \"nondimensional\"")
    mt = doc.get("material")
    if not isinstance(mt, dict):
        raise ProblemError(f"{source}: missing [material]")
    _check_keys(mt, {"kind", "C1", "gamma", "volume_factor"}, f"{source} [material]")
    mat = Material(mt.get("kind", "mooney_rivlin"), _num(mt, "C1", "[material]"),
                   _num(mt, "gamma", "[material]", 0.0), bool(mt.get("volume_factor", False)))
    t0 = _num(doc.get("shell", {}), "thickness", f"{source} [shell]")
    if system == "nondimensional" and (t0 != 1.0 or mat.C1 != 1.0):
        raise ProblemError(f"{source}: nondimensional problems need thickness = 1 and C1 = 1")
    nodes = []
    for k, nd in enumerate(doc.get("nodes", [])):
        where = f"{source} node {k}"
        _check_keys(nd, _NODE_KEYS, where)
        if "phi" in nd and "phi_deg" in nd:
            raise ProblemError(f"{where}: give phi or phi_deg, not both")
        phi = _num(nd, "phi", where) if "phi" in nd else np.radians(_num(nd, "phi_deg", where))
        fix = nd.get("fix", [])
        if isinstance(fix, str):
            fix = [fix]
        bad = set(fix) - {"r", "z", "phi"}
        if bad:
            raise ProblemError(f"{where}: unknown restraint(s) {sorted(bad)}; use r, z, phi")
        nodes.append(Node(_num(nd, "r", where), _num(nd, "z", where), phi, tuple(c in fix for c in ("r", "z", "phi"))))
    segs = []
    for k, sg in enumerate(doc.get("segments", [])):
        where = f"{source} segment {k}"
        _check_keys(sg, _SEG_KEYS, where)
        if "kappa" in sg and "radius" in sg:
            raise ProblemError(f"{where}: give kappa or radius, not both")
        if "radius" in sg:
            rad = _num(sg, "radius", where)
            if rad == 0:
                raise ProblemError(f"{where}: radius must be non-zero (use kappa = 0 for a straight piece)")
            kap = 1.0 / rad
        else:
            kap = _num(sg, "kappa", where, 0.0)
        segs.append(Segment(int(sg.get("from", -1)), int(sg.get("to", -1)), kap,
                            int(sg["n_sub"]) if "n_sub" in sg else None))
    nls = []
    for k, nl in enumerate(doc.get("nodal_loads", [])):
        where = f"{source} nodal load {k}"
        _check_keys(nl, _NL_KEYS, where)
        ld = NodalLoad(int(nl.get("node", -1)), _num(nl, "H", where, 0.0), _num(nl, "V", where, 0.0),
                       _num(nl, "M", where, 0.0))
        ld.H += _num(nl, "Fr", where, 0.0) / (2 * np.pi)
        ld.V += _num(nl, "Fz", where, 0.0) / (2 * np.pi)
        nls.append(ld)
    dls = []
    for k, dl in enumerate(doc.get("distributed_loads", [])):
        where = f"{source} distributed load {k}"
        _check_keys(dl, _DL_KEYS, where)
        dls.append(DistributedLoad(*(_num(dl, key, where, 0.0) for key in ("qH", "qV", "QH", "QV", "p")),
                                   segments=dl.get("segments")))
    disc = doc.get("discretisation", {})
    model = Model(mat, t0, nodes, segs, nls, dls, max_piece=_num(disc, "max_piece", "[discretisation]", 0.6),
                  rk_steps=int(disc.get("rk_steps", 2)), name=str(doc.get("name", source)))
    model.build()  # validate now: clear errors at load time
    path = dict(doc.get("path", {}))
    return model, path


def load_problem(path):
    """Read a TOML problem file; returns (Model, path options dict)."""
    p = Path(path)
    try:
        doc = tomllib.loads(p.read_text())
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise ProblemError(f"{p}: {exc}") from None
    return parse_problem(doc, str(p))
