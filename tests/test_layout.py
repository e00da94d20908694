"""The package's layout is its pipeline: stages import only earlier stages, with no import cycles.

Every import counts, at module level or inside a function: a late import still ties a stage to a
later one. The order is docs/architecture.md's "Layout" section.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import davis_ag

PACKAGE = Path(davis_ag.__file__).parent

#: The pipeline, earliest first; a module may import its own stage and those before it.
STAGES: tuple[tuple[str, ...], ...] = (
    ("errors", "atomic_files", "stage_timer", "provenance"),  # helpers every stage may use
    ("scene",),
    ("formats",),  # the dataset's files, split rule and schemas: shared by writer, reader and benchmark
    ("render",),
    ("labels",),
    ("generate",),
    ("data",),
    ("benchmark",),
    ("live",),  # regrows and renders: after the benchmark, which knows nothing of Helios
    ("detection",),
    ("figures",),
    ("workflows",),
    ("commands", "cli"),
)
RANK = {name: rank for rank, names in enumerate(STAGES) for name in names}
#: Stages that must import without Helios or a renderer: they are pure geometry and reading.
NO_HELIOS_AT_IMPORT = ("scene", "formats", "data", "benchmark", "detection")


def module_name(path: Path) -> str:
    parts = ("davis_ag",) + path.relative_to(PACKAGE).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def imports(path: Path, top_level_only: bool = False) -> list[tuple[str, int, list[str]]]:
    """``(module, line, names)`` for every import in a file (absolute names, davis_ag or not)."""
    tree = ast.parse(path.read_text(), str(path))
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    found = []
    for node in nodes:
        if isinstance(node, ast.Import):
            found += [(alias.name, node.lineno, []) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module:
            names = [alias.name for alias in node.names]
            # `from davis_ag.scene import specs` imports the module davis_ag.scene.specs
            submodules = [f"{node.module}.{n}" for n in names if f"{node.module}.{n}" in MODULES]
            found += [(m, node.lineno, []) for m in submodules] or [(node.module, node.lineno, names)]
    return found


def stage(module: str) -> str:
    return module.split(".")[1] if module.count(".") else ""


def own_edges() -> dict[str, set[str]]:
    """Module -> the davis_ag modules it imports."""
    return {name: {m for m, _, _ in imports(path) if m in MODULES and m != name}
            for name, path in MODULES.items()}


def test_every_module_belongs_to_a_stage_and_says_what_it_is() -> None:
    for name, path in MODULES.items():
        if name == "davis_ag":
            continue
        assert stage(name) in RANK, f"{name}: add its stage to STAGES (and to docs/architecture.md's Layout)"
        doc = ast.get_docstring(ast.parse(path.read_text()))
        assert doc and len(doc.splitlines()[0]) > 10, f"{path}: its first line should say what it is"


@pytest.mark.parametrize("name", [n for n in MODULES if n != "davis_ag"])
def test_imports_point_to_earlier_stages(name: str) -> None:
    rank = RANK[stage(name)]
    for module, line, _ in imports(MODULES[name]):
        if module.startswith("davis_ag.") and stage(module) in RANK:
            assert RANK[stage(module)] <= rank, (
                f"{MODULES[name]}:{line}: {stage(name)} imports {module}, a later stage")


def test_no_import_cycles() -> None:
    edges = own_edges()
    state: dict[str, int] = {}

    def visit(node: str, path: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(edges[node]):
            if state.get(nxt) == 1:
                cycle = path[path.index(nxt):] + [nxt] if nxt in path else [node, nxt]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt, path + [nxt])
        state[node] = 2

    for start in sorted(edges):
        if start not in state:
            visit(start, [start])


@pytest.mark.parametrize("name", [n for n in MODULES if stage(n) in NO_HELIOS_AT_IMPORT])
def test_geometry_and_benchmark_never_load_helios_or_a_renderer_at_import(name: str) -> None:
    for module, line, _ in imports(MODULES[name], top_level_only=True):
        assert not module.startswith(("pyhelios", "davis_ag.render", "moderngl")), (
            f"{MODULES[name]}:{line}: imports {module} at module level")


def test_data_and_benchmark_know_nothing_of_helios() -> None:
    """They read any dataset in the published layout, the original download included."""
    for name, path in MODULES.items():
        if stage(name) in ("data", "benchmark", "detection"):
            for module, line, _ in imports(path):
                assert not module.startswith(("pyhelios", "davis_ag.render", "davis_ag.generate")), (
                    f"{path}:{line}: imports {module}")


def test_no_module_imports_another_modules_private_names() -> None:
    for name, path in MODULES.items():
        for module, line, names in imports(path):
            private = [n for n in names if n.startswith("_") and not n.startswith("__")]
            assert not (module.startswith("davis_ag") and private), f"{path}:{line}: imports {private} from {module}"


def test_the_layout_reads_as_the_pipeline() -> None:
    """`ls src/davis_ag` shows every stage as a folder."""
    folders = {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    assert {"scene", "render", "labels", "generate", "data", "benchmark", "figures", "workflows",
            "commands", "detection"} <= folders
