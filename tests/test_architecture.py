"""One-way dependencies (ARCHITECTURE.md): a module may import only from its own layer or the
layers below it, the core never imports the heavy optional packages, and importing graspdef
changes nothing in the process."""
import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "graspdef"
#: lowest first; a module may import graspdef modules of its own layer or of a lower one
LAYERS = ["errors", "units", "runtime", "compiled", "config", "testing", "geometry", "runs", "subdivision", "shell", "axisym",
          "problem", "solve", "contact", "sim", "scans", "registration", "objects", "viewer", "report", "pipeline", "ranking",
          "fit", "sweep", "bench", "cli"]
#: sibling rooms that must not import each other (ARCHITECTURE.md: "viewer | report")
SIBLINGS = [("viewer", "report")]
HEAVY = {"mujoco", "open3d", "viser"}
#: layers below "bench" that may import a heavy package (lazily), by package
HEAVY_ALLOWED = {"open3d": {"scans", "registration"}, "mujoco": {"sim"}, "viser": {"viewer"}}


def _layer(module: str) -> int:
    top = module.split(".")[1] if module.startswith("graspdef.") else module
    return LAYERS.index(top)


def _resolve(path: Path, node: ast.ImportFrom) -> str:
    """The absolute module name of a ``from ... import`` in ``path``."""
    rel = path.relative_to(PKG.parent).with_suffix("")
    package = ".".join(rel.parts[:-1]) if rel.name != "__init__" else ".".join(rel.parts)
    if node.level:
        base = package.split(".")[: len(package.split(".")) - node.level + 1]
        return ".".join(base + ([node.module] if node.module else []))
    return node.module or ""


def _imports(path: Path) -> list[str]:
    tree = ast.parse(path.read_text())
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            out.append(_resolve(path, node))
    return out


MODULES = sorted(p for p in PKG.rglob("*.py") if p.name != "__init__.py" or p.parent != PKG)


@pytest.mark.parametrize("path", MODULES, ids=[str(p.relative_to(PKG)) for p in MODULES])
def test_imports_point_down(path):
    rel = path.relative_to(PKG)
    own = _layer("graspdef." + (rel.parts[0][:-3] if len(rel.parts) == 1 else rel.parts[0]))
    for mod in _imports(path):
        root = mod.split(".")[0]
        assert (root not in HEAVY or own >= LAYERS.index("bench")
                or LAYERS[own] in HEAVY_ALLOWED.get(root, ())), f"{rel} imports {mod}"
        if mod.startswith("graspdef.") or mod == "graspdef":
            if mod == "graspdef":
                continue
            assert _layer(mod) <= own, f"{rel} (layer {LAYERS[own]}) imports {mod} from a higher layer"


def _room(rel: Path) -> str:
    return rel.parts[0][:-3] if len(rel.parts) == 1 else rel.parts[0]


@pytest.mark.parametrize("path", MODULES, ids=[str(p.relative_to(PKG)) for p in MODULES])
def test_siblings_do_not_import_each_other(path):
    """report does not import viewer, nor viewer report: both read runs through graspdef.runs."""
    room = _room(path.relative_to(PKG))
    for a, b in SIBLINGS:
        other = {a: b, b: a}.get(room)
        if other is None:
            continue
        for mod in _imports(path):
            assert not mod.startswith(f"graspdef.{other}"), f"{path.relative_to(PKG)} imports {mod} (sibling)"


#: private members of *third-party* objects a module needs (not graspdef's rooms): pypardiso has no
#: public API for PARDISO's phases (analysis once, factorisation per step; ../shared/MEASURED.md),
#: nor for a call on zero-based 32-bit indices or single-precision values (graspdef.solve.pardiso.call uses its
#: loaded MKL function and handle type),
#: nor for the MKL library it loaded (the sweep records which one its workers use); ``os._exit`` is
#: Python's documented way to end a process without its teardown (the out-of-core worker, which ran
#: MKL's out-of-core mode: graspdef.solve.pardiso_ooc)
THIRD_PARTY_PRIVATE = {"solve/pardiso.py": {"_mkl_pardiso", "_pt_type"}, "sweep/run.py": {"_name"},
                       "solve/pardiso_ooc.py": {"_exit"}}


def _defined_private_names(tree) -> set:
    """Underscore names a module defines itself: functions, classes, attributes it assigns."""
    out = set()
    for n in ast.walk(tree):
        if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            out.add(n.name)
        elif isinstance(n, ast.Attribute) and isinstance(n.ctx, ast.Store):
            out.add(n.attr)
        elif isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store):
            out.add(n.id)
    return {x for x in out if x.startswith("_") and not x.startswith("__")}


@pytest.mark.parametrize("path", MODULES, ids=[str(p.relative_to(PKG)) for p in MODULES])
def test_no_private_members_of_other_rooms(path):
    """No module imports an underscore name from another room, or reads a private member
    (``obj._name``) that its own module does not define: what a room offers another is its public
    API (e.g. the pipeline uses the path solver's public methods, the solver reads the enclosed
    gas through ``record``, not its private volume)."""
    rel = path.relative_to(PKG)
    room = _room(rel)
    tree = ast.parse(path.read_text())
    own = _defined_private_names(tree)
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            mod = _resolve(path, node)
            for a in node.names:
                if a.name.startswith("_") and not a.name.startswith("__") and mod.startswith("graspdef."):
                    assert mod.split(".")[1] == room, f"{rel}:{node.lineno} imports the private {a.name} from {mod}"
        if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__"):
            if isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"):
                continue
            if node.attr in THIRD_PARTY_PRIVATE.get(str(rel), ()):
                continue
            assert node.attr in own, f"{rel}:{node.lineno} reads the private member {ast.unparse(node)}"


@pytest.mark.parametrize("path", MODULES, ids=[str(p.relative_to(PKG)) for p in MODULES])
def test_no_process_state_at_import(path):
    """No module sets environment variables at import, except graspdef.runtime, which does it
    only when a program calls configure()."""
    rel = path.relative_to(PKG)
    if rel.parts == ("runtime.py",):
        return
    tree = ast.parse(path.read_text())

    def is_environ(n) -> bool:
        return isinstance(n, ast.Attribute) and n.attr == "environ" and isinstance(n.value, ast.Name)

    for node in ast.walk(tree):
        writes = (isinstance(node, (ast.Assign, ast.AugAssign, ast.Delete))
                  and any(isinstance(t, ast.Subscript) and is_environ(t.value)
                          for t in (node.targets if hasattr(node, "targets") else [node.target])))
        writes |= (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and is_environ(node.func.value)
                   and node.func.attr in ("setdefault", "update", "pop", "clear", "__setitem__"))
        assert not writes, f"{rel}:{node.lineno} changes os.environ (process state belongs in graspdef.runtime)"

def test_import_changes_nothing():
    """``import graspdef`` (and its CLI parser) leaves the environment as it was and loads no
    numerical package beyond the standard library (start-up stays fast)."""
    code = ("import os, sys; before = dict(os.environ); import graspdef, graspdef.cli; "
            "graspdef.cli.build_parser(); "
            "assert dict(os.environ) == before, set(os.environ.items()) ^ set(before.items()); "
            "heavy = sorted(m for m in ('numpy', 'scipy', 'numba', 'trimesh', 'mujoco', 'open3d', 'viser') "
            "if m in sys.modules); assert not heavy, heavy")
    env = {k: v for k, v in os.environ.items() if k not in ("OMP_WAIT_POLICY", "PYPARDISO_MKL_RT", "NUMBA_THREADING_LAYER")}
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
