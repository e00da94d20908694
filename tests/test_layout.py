"""The package's layout is its pipeline: stages import only earlier stages, with no import cycles.

Every import counts, at module level or inside a function: a late import still ties a stage to a
later one. Only imports under ``if TYPE_CHECKING:``, which never run, are left out where what counts
is what runs: the import cycles, and the root ``davis_ag/__init__.py``, which names the public API
of every stage for type checkers and loads each name only when it is used. The order is docs/architecture.md's "Layout" section, and each stage package's docstring opens
with its number there ("Stage 3, formats: ...").
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest

import davis_ag

PACKAGE = Path(davis_ag.__file__).parent

#: The pipeline, earliest first; a module may import its own stage and those before it.
STAGES: tuple[tuple[str, ...], ...] = (
    # helpers every stage may use, and the environments' ids (registered by name, nothing imported)
    ("errors", "atomic_files", "stage_timer", "provenance", "seeds", "environments"),
    ("scene",),
    ("formats",),  # the dataset's files, split rule and schemas: shared by writer, reader and benchmark
    ("render",),
    ("labels",),
    ("generate",),
    ("data",),
    ("robot",),  # real arms on a base: reads generated scenes, restricts the benchmark's moves
    ("benchmark",),
    ("mapping",),  # row mapping: the benchmark's tables read as a coverage task
    ("live",),  # regrows and renders: after the benchmark, which knows nothing of Helios
    ("detection",),
    ("worlds",),  # 3-D exports (USD, meshes, nerfstudio): reads the live scene's geometry
    ("figures",),
    ("workflows",),
    ("commands", "cli"),
)
RANK = {name: rank for rank, names in enumerate(STAGES) for name in names}
#: Stages that must import without Helios or a renderer: they are pure geometry and reading.
NO_HELIOS_AT_IMPORT = ("scene", "formats", "data", "robot", "benchmark", "mapping", "detection")


def module_name(path: Path) -> str:
    parts = ("davis_ag", *path.relative_to(PACKAGE).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def type_checking_only(tree: ast.Module) -> set[int]:
    """The ids of the nodes under ``if TYPE_CHECKING:`` (or ``typing.TYPE_CHECKING``): they never run."""
    blocks = [
        node
        for node in ast.walk(tree)
        if isinstance(node, ast.If) and ast.unparse(node.test) in ("TYPE_CHECKING", "typing.TYPE_CHECKING")
    ]
    return {id(inner) for block in blocks for statement in block.body for inner in ast.walk(statement)}


def imports(path: Path, top_level_only: bool = False, runtime_only: bool = False) -> list[tuple[str, int, list[str]]]:
    """``(module, line, names)`` for every import in a file (absolute names, davis_ag or not).

    ``runtime_only`` leaves out the imports under ``if TYPE_CHECKING:``, which never run.
    """
    tree = ast.parse(path.read_text(), str(path))
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    if runtime_only:
        never_run = type_checking_only(tree)
        nodes = [node for node in nodes if id(node) not in never_run]
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
    """Module -> the davis_ag modules it imports when it runs (a cycle is a run-time failure)."""
    return {
        name: {m for m, _, _ in imports(path, runtime_only=True) if m in MODULES and m != name}
        for name, path in MODULES.items()
    }


def test_every_module_belongs_to_a_stage_and_says_what_it_is() -> None:
    for name, path in MODULES.items():
        if name == "davis_ag":
            continue
        assert stage(name) in RANK, f"{name}: add its stage to STAGES (and to docs/architecture.md's Layout)"
        doc = ast.get_docstring(ast.parse(path.read_text()))
        assert doc and len(doc.splitlines()[0]) > 10, f"{path}: its first line should say what it is"


@pytest.mark.parametrize("name", list(MODULES))
def test_imports_point_to_earlier_stages(name: str) -> None:
    # The root __init__ runs before any stage is imported, so it may use the helpers only; it names
    # every stage's public API for type checkers (never run) and loads each name on first use.
    rank = RANK[stage(name)] if name != "davis_ag" else 0
    for module, line, _ in imports(MODULES[name], runtime_only=name == "davis_ag"):
        if module.startswith("davis_ag.") and stage(module) in RANK:
            assert RANK[stage(module)] <= rank, f"{MODULES[name]}:{line}: {stage(name)} imports {module}, a later stage"


def test_no_import_cycles() -> None:
    edges = own_edges()
    state: dict[str, int] = {}

    def visit(node: str, path: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(edges[node]):
            if state.get(nxt) == 1:
                cycle = [*path[path.index(nxt) :], nxt] if nxt in path else [node, nxt]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt, [*path, nxt])
        state[node] = 2

    for start in sorted(edges):
        if start not in state:
            visit(start, [start])


@pytest.mark.parametrize("name", [n for n in MODULES if stage(n) in NO_HELIOS_AT_IMPORT])
def test_geometry_and_benchmark_never_load_helios_or_a_renderer_at_import(name: str) -> None:
    for module, line, _ in imports(MODULES[name], top_level_only=True):
        assert not module.startswith(("pyhelios", "davis_ag.render", "moderngl")), (
            f"{MODULES[name]}:{line}: imports {module} at module level"
        )


def test_data_and_benchmark_know_nothing_of_helios() -> None:
    """They read any dataset in the published layout, the original download included."""
    for name, path in MODULES.items():
        if stage(name) in ("data", "benchmark", "detection"):
            for module, line, _ in imports(path):
                assert not module.startswith(("pyhelios", "davis_ag.render", "davis_ag.generate")), (
                    f"{path}:{line}: imports {module}"
                )


def test_no_module_imports_another_modules_private_names() -> None:
    for name, path in MODULES.items():
        for module, line, names in imports(path):
            private = [n for n in names if n.startswith("_") and not n.startswith("__")]
            assert not (module.startswith("davis_ag") and private), f"{path}:{line}: imports {private} from {module}"


#: The roles inside workflows/: each imports only the shared stage helpers and its own modules.
WORKFLOW_ROLES = ("stages", "demo", "transfer", "reproduce", "bench", "scene_stats")
#: Longest module, in lines: past it a module holds two things (docs/architecture.md).
MAX_MODULE_LINES = 450


def workflow_role(module: str) -> str:
    return module.split(".")[2] if module.startswith("davis_ag.workflows.") else ""


@pytest.mark.parametrize("name", [n for n in MODULES if workflow_role(n)])
def test_each_workflow_imports_only_the_shared_stages_and_its_own_role(name: str) -> None:
    role = workflow_role(name)
    assert role in WORKFLOW_ROLES, f"{MODULES[name]}: add its role to WORKFLOW_ROLES and docs/architecture.md"
    for module, line, _ in imports(MODULES[name]):
        other = workflow_role(module)
        assert other in ("", "stages", role), f"{MODULES[name]}:{line}: the {role} workflow imports {module}"
        # reproduce's pages read the run's records; the run writes the pages, never the reverse
        if name.startswith("davis_ag.workflows.reproduce.pages"):
            assert not module.startswith(("davis_ag.workflows.reproduce.run", "davis_ag.workflows.reproduce.status")), (
                f"{MODULES[name]}:{line}: a page imports {module}, the run that writes it"
            )


def test_no_module_is_longer_than_its_limit() -> None:
    long = {
        str(p.relative_to(PACKAGE)): n
        for p in MODULES.values()
        if (n := len(p.read_text().splitlines())) > MAX_MODULE_LINES
    }
    assert not long, f"split these modules (over {MAX_MODULE_LINES} lines): {long}"


def test_the_layout_reads_as_the_pipeline() -> None:
    """`ls src/davis_ag` shows every stage as a folder."""
    folders = {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    assert {
        "scene",
        "render",
        "labels",
        "generate",
        "data",
        "benchmark",
        "figures",
        "workflows",
        "commands",
        "detection",
    } <= folders


ARCHITECTURE = PACKAGE.parents[1] / "docs" / "architecture.md"


def test_stage_numbers_agree_in_the_package_docstrings_and_architecture_md() -> None:
    """One list of stages: STAGES here, "N. `name/`" in docs/architecture.md, "Stage N, " atop each package."""
    layout = ARCHITECTURE.read_text().split("## Layout", 1)[1].split("\n## ", 1)[0]
    listed = {int(number): names for number, names in re.findall(r"^(\d+)\. (.+?):", layout, re.MULTILINE)}
    assert sorted(listed) == list(range(1, len(STAGES) + 1)), "docs/architecture.md: number the stages 1..N"
    for rank, names in enumerate(STAGES):
        for name in names:
            assert f"`{name}" in listed[rank + 1], f"docs/architecture.md: stage {rank + 1} should list {name}"
            package = PACKAGE / name / "__init__.py"
            if package.exists():
                doc = ast.get_docstring(ast.parse(package.read_text())) or ""
                assert doc.startswith(f"Stage {rank + 1}, "), (
                    f"{package}: its docstring should open 'Stage {rank + 1}, '"
                )


def test_importing_the_specs_loads_neither_gymnasium_nor_torch() -> None:
    """``import davis_ag`` is light: the environments are registered by name, not by importing them."""
    code = (
        "import sys, davis_ag.scene.specs, davis_ag.formats.layout; "
        "print(sorted(m for m in ('gymnasium', 'torch', 'davis_ag.benchmark', 'pyhelios') if m in sys.modules))"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        env={"PYTHONPATH": str(PACKAGE.parent), "PATH": "/usr/bin:/bin"},
    ).stdout.strip()
    assert loaded == "[]"


def test_the_environments_are_made_by_name_after_importing_gymnasium_then_davis_ag() -> None:
    code = (
        "import gymnasium, davis_ag, sys; from davis_ag.environments import ENTRY_POINTS; "
        "print([gymnasium.spec(i).entry_point for i in ENTRY_POINTS], 'davis_ag.benchmark' in sys.modules)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        env={"PYTHONPATH": str(PACKAGE.parent), "PATH": "/usr/bin:/bin"},
    ).stdout.strip()
    assert (
        out
        == "['davis_ag.benchmark.tvm:TVMEnv', 'davis_ag.live.tvm_continuous:TVMContinuousEnv', 'davis_ag.mapping.env:RowMappingEnv'] False"
    )
