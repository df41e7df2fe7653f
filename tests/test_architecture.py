"""The layout's rules, checked on the source: what may import what, and one vocabulary.

* The renderer core (``mcengine``) never imports Blender (``bpy``, ``mathutils``),
  and only its ``evaluation`` package may import matplotlib; the renderer proper
  (everything else in ``mcengine``) never imports ``mcengine.evaluation``.
* No import cycles between the project's modules (``mcengine``, and the add-on
  ``mcengine_blender`` in ``addon/``), counting imports inside functions too.
* The integrator vocabulary (names and Blender enum identifiers) is written in
  ``mcengine/integrators.py`` only.
* Every scene generator in ``blend_scenes/`` is one that ``make_all.py`` builds.
"""
from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PACKAGES = {"mcengine": REPO / "mcengine", "mcengine_blender": REPO / "addon"}


def _modules() -> dict[str, Path]:
    """Module name -> source file for every module of the two packages."""
    found = {}
    for package, root in PACKAGES.items():
        for path in root.rglob("*.py"):
            parts = list(path.relative_to(root).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            found[".".join([package, *parts])] = path
    return found


MODULES = _modules()


def _imports(name: str, path: Path) -> set[str]:
    """Every module ``name`` imports (absolute names), anywhere in the file."""
    is_package = path.name == "__init__.py"
    here = name if is_package else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here.split(".")
                base = base[:len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module
            out.add(target)
            # "from . import x" may name submodules.
            out.update(f"{target}.{alias.name}" for alias in node.names
                       if f"{target}.{alias.name}" in MODULES)
    return out


IMPORTS = {name: _imports(name, path) for name, path in MODULES.items()}


def _in_core(name: str) -> bool:
    return name == "mcengine" or name.startswith("mcengine.")


def _project_edges(name: str) -> set[str]:
    """Project modules that ``name`` depends on (a package's own __init__ excluded)."""
    edges = set()
    for target in IMPORTS[name]:
        while target and target not in MODULES:
            target = target.rpartition(".")[0]
        if target and target != name and not name.startswith(target + "."):
            edges.add(target)
    return edges


def test_core_never_imports_blender():
    for name, imports in IMPORTS.items():
        if _in_core(name):
            bad = {i for i in imports if i.split(".")[0] in ("bpy", "mathutils", "mcengine_blender")}
            assert not bad, f"{name} imports {sorted(bad)}"


def test_matplotlib_only_in_the_evaluation_package():
    for name, imports in IMPORTS.items():
        if any(i.split(".")[0] == "matplotlib" for i in imports):
            assert name.startswith("mcengine.evaluation."), f"{name} imports matplotlib"


def test_renderer_does_not_depend_on_the_evaluation_code():
    for name in MODULES:
        if _in_core(name) and not name.startswith("mcengine.evaluation"):
            bad = {t for t in _project_edges(name) if t.startswith("mcengine.evaluation")}
            assert not bad, f"{name} imports {sorted(bad)}"


def test_no_import_cycles():
    graph = {name: _project_edges(name) for name in MODULES}
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node):
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                cycle = stack[stack.index(nxt):] + [nxt]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt)
        stack.pop()
        state[node] = 2

    for name in sorted(graph):
        if name not in state:
            visit(name)


def test_integrator_vocabulary_is_declared_once():
    from mcengine.integrators import INTEGRATORS
    words = set(INTEGRATORS) | {info.enum_id for info in INTEGRATORS.values()}
    # Also ordinary words: file paths, a metavar, Blender's "distribution" node property,
    # the render passes' "light" readout and the scratch's last light sample.
    words -= {"path", "PATH", "distribution", "light"}
    home = REPO / "mcengine" / "integrators.py"
    for name, path in MODULES.items():
        if path == home:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Constant) and isinstance(node.value, str):
                assert node.value not in words, (
                    f"{path.relative_to(REPO)}:{node.lineno} spells the integrator "
                    f"{node.value!r}; read it from mcengine.integrators")


def test_importing_the_core_loads_no_blender_module():
    """At run time too (a third-party import could pull bpy in)."""
    core = [n for n in MODULES if _in_core(n)]
    code = (f"import importlib, sys\nfor m in {core!r}: importlib.import_module(m)\n"
            "print(sorted(m for m in ('bpy', 'mathutils') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_make_all_builds_every_scene():
    """``blend_scenes/make_all.py`` lists every generator script there (holdout_objects and
    material_thin_film were missing from it for a day)."""
    import re

    folder = REPO / "blend_scenes"
    listed = re.findall(r'^    "(\w+)",$', (folder / "make_all.py").read_text(), re.M)
    scripts = {p.stem for p in folder.glob("*.py")
               if not p.stem.startswith("_") and p.stem not in ("make_all", "render_cycles")}
    assert sorted(listed) == sorted(scripts)
