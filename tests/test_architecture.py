"""One-way dependencies (../shared/STYLE.md section 4): a module may import only from its own
layer or the layers below it, and the core never imports the heavy optional packages."""
import ast
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "graspdef"
#: lowest first; a module may import graspdef modules of its own layer or of a lower one
LAYERS = ["errors", "units", "config", "testing", "geometry", "subdivision", "shell", "axisym", "problem", "solve", "contact", "sim",
          "scans", "registration", "objects", "viewer", "report", "pipeline", "sweep", "bench", "cli"]
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
