"""The public API: what a researcher calls is importable from ``davis_ag``, loaded only when used."""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path

import pytest

import davis_ag

PACKAGE = Path(davis_ag.__file__).parent

#: Every public name of ``davis_ag`` and the module that defines it.
PUBLIC = {
    "open_dataset": "davis_ag.data.reader",
    "Dataset": "davis_ag.data.reader",
    "Scene": "davis_ag.data.reader",
    "View": "davis_ag.data.reader",
    "exposure_rate": "davis_ag.data.reader",
    "evaluate": "davis_ag.benchmark.evaluation",
    "Policy": "davis_ag.benchmark.policies",
    "TVMEnv": "davis_ag.benchmark.tvm",
    "TVMContinuousEnv": "davis_ag.live.tvm_continuous",
    "RowMappingEnv": "davis_ag.mapping.env",
    "evaluate_mapping": "davis_ag.mapping.evaluation",
}

#: What ``import davis_ag`` must not load: no stage, nor the heavy libraries the stages use.
HEAVY = ("torch", "gymnasium", "numpy", "pydantic", "pyhelios")


def run_python(code: str, cwd: Path | None = None) -> str:
    """Run ``code`` in a fresh interpreter (nothing imported yet) and return what it prints."""
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        cwd=cwd,
        env={"PYTHONPATH": str(PACKAGE.parent), "PATH": "/usr/bin:/bin"},
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


@pytest.mark.parametrize("name", sorted(PUBLIC))
def test_every_public_name_is_the_object_its_module_defines(name: str) -> None:
    namespace: dict[str, object] = {}
    exec(f"from davis_ag import {name}", namespace)
    assert namespace[name] is getattr(importlib.import_module(PUBLIC[name]), name)
    assert getattr(davis_ag, name) is namespace[name]


def test_all_lists_the_public_names_and_the_version() -> None:
    assert sorted(davis_ag.__all__) == sorted([*PUBLIC, "__version__"])
    assert set(davis_ag.__all__) <= set(dir(davis_ag))


def test_an_unknown_name_is_an_attribute_error_and_submodules_still_import() -> None:
    with pytest.raises(AttributeError, match="no_such_name"):
        davis_ag.no_such_name  # noqa: B018
    from davis_ag import errors

    assert errors.UserError


def test_importing_davis_ag_loads_no_stage_and_no_heavy_library() -> None:
    loaded = run_python(
        "import sys, davis_ag; "
        f"print(sorted(m for m in sys.modules if m.split('.')[0] in {HEAVY!r} or m.startswith('davis_ag.')))"
    )
    assert loaded == "['davis_ag.environments']"  # the ids, registered by name: a helper, no stage


def test_a_public_name_loads_its_own_stage_only() -> None:
    loaded = run_python(
        "import sys; from davis_ag import open_dataset; "
        "print(sorted(m for m in ('davis_ag.benchmark', 'davis_ag.live', 'gymnasium', 'torch') if m in sys.modules))"
    )
    assert loaded == "[]"


def test_gymnasium_makes_the_environment_by_its_module_and_id_with_nothing_imported(sp_root: Path) -> None:
    """Gymnasium's own ``"module:id"`` form imports davis_ag itself, which registers both ids."""
    out = run_python(
        "import gymnasium as gym; "
        f"env = gym.make('davis_ag:davis_ag/TVM-v0', dataset={str(sp_root)!r}, scenario='sp', split='all'); "
        "observation, info = env.reset(seed=0); "
        "print(observation.shape, sorted(i for i in gym.registry if i.startswith('davis_ag/')))"
    )
    assert out == "(224, 224, 4) ['davis_ag/RowMapping-v0', 'davis_ag/TVM-v0', 'davis_ag/TVMContinuous-v0']"


def test_the_readme_imports_make_the_environment(sp_root: Path) -> None:
    """``import gymnasium`` then ``from davis_ag import ...`` registers the ids: no other import."""
    out = run_python(
        "import gymnasium as gym; from davis_ag import open_dataset; "
        f"env = gym.make('davis_ag/TVM-v0', dataset=open_dataset({str(sp_root)!r}), scenario='sp', split='all'); "
        "print(type(env.unwrapped).__name__)"
    )
    assert out == "TVMEnv"


@pytest.mark.parametrize(
    "imports",
    [
        "import davis_ag; import gymnasium as gym",
        "import gymnasium as gym; import davis_ag",
        "from davis_ag import open_dataset; from gymnasium.envs.registration import registry; import gymnasium as gym",
        "import davis_ag, importlib.util; importlib.util.find_spec('gymnasium'); import gymnasium as gym",
    ],
)
def test_the_ids_are_registered_whichever_is_imported_first(imports: str) -> None:
    """No import order to remember: davis_ag registers at once, or the moment Gymnasium loads."""
    out = run_python(f"{imports}; print(sorted(i for i in gym.registry if i.startswith('davis_ag/')))")
    assert out == "['davis_ag/RowMapping-v0', 'davis_ag/TVM-v0', 'davis_ag/TVMContinuous-v0']"


def test_importing_davis_ag_alone_loads_no_gymnasium() -> None:
    assert run_python("import sys, davis_ag; print('gymnasium' in sys.modules)") == "False"


SUBPACKAGES = sorted(p.parent.name for p in PACKAGE.glob("*/__init__.py"))


@pytest.mark.parametrize("subpackage", SUBPACKAGES)
def test_each_subpackages_all_names_what_it_has(subpackage: str) -> None:
    module = importlib.import_module(f"davis_ag.{subpackage}")
    for name in getattr(module, "__all__", []):
        assert getattr(module, name, None) is not None, f"davis_ag.{subpackage}.__all__ lists {name}, which it lacks"


def test_the_benchmarks_all_leaves_its_helpers_out() -> None:
    benchmark = importlib.import_module("davis_ag.benchmark")
    assert set(benchmark.__all__) == {
        "CONTINUOUS_ID",
        "ENV_IDS",
        "MAX_START_OER",
        "OBS_SIZE",
        "TVM_ID",
        "TVMEnv",
        "evaluate",
    }
    assert benchmark.benchmark_steps and importlib.import_module("davis_ag.benchmark.cache").SceneCache
