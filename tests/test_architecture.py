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
LAYERS = ["errors", "units", "runtime", "config", "testing", "geometry", "runs", "subdivision", "shell", "axisym",
          "problem", "solve", "contact", "sim", "scans", "registration", "objects", "viewer", "report", "pipeline",
          "sweep", "bench", "cli"]
HEAVY = {"mujoco", "open3d", "viser"}
#: layers below "bench" that may import a heavy package (lazily), by package
HEAVY_ALLOWED = {"open3d": {"scans", "registration"}, "mujoco": {"sim"}, "viser": {"viewer"}}


def _layer(module: str) -> int:
    top = module.split(".")[1] if module.startswith("graspdef.") else module
    return LAYERS.index(top)


def _imports(path: Path) -> list[str]:
    tree = ast.parse(path.read_text())
    rel = path.relative_to(PKG.parent).with_suffix("")
    package = ".".join(rel.parts[:-1]) if rel.name != "__init__" else ".".join(rel.parts)
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            out.append(mod)
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
    env = {k: v for k, v in os.environ.items() if k not in ("OMP_WAIT_POLICY", "PYPARDISO_MKL_RT")}
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
