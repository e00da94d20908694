"""The Gymnasium ids of davis-ag's environments, registered by name so that nothing loads until one is made.

Registration names each environment's class as a ``"module:Class"`` string: registering imports
Gymnasium's registry, not the benchmark (numpy caches, torch) nor the live renderer (Helios).
``import davis_ag`` registers them in either order: at once when Gymnasium is imported already,
else the moment Gymnasium is (:func:`register_when_gymnasium_loads`), so importing davis_ag never
loads Gymnasium itself. ``gymnasium.make("davis_ag:davis_ag/TVM-v0")`` imports davis_ag first.
Gymnasium 1.x reads no plugin entry points, so an id cannot be registered with no import at all.
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import importlib.util
import sys
from collections.abc import Sequence
from types import ModuleType
from typing import Any

#: The grid environment (:class:`davis_ag.benchmark.tvm.TVMEnv`).
TVM_ID = "davis_ag/TVM-v0"
#: The continuous-pose environment (:class:`davis_ag.live.tvm_continuous.TVMContinuousEnv`).
CONTINUOUS_ID = "davis_ag/TVMContinuous-v0"
#: Row mapping (:class:`davis_ag.mapping.env.RowMappingEnv`).
MAPPING_ID = "davis_ag/RowMapping-v0"
#: Every environment id and its class, as Gymnasium's ``"module:Class"`` entry point.
ENTRY_POINTS: dict[str, str] = {
    TVM_ID: "davis_ag.benchmark.tvm:TVMEnv",
    CONTINUOUS_ID: "davis_ag.live.tvm_continuous:TVMContinuousEnv",
    MAPPING_ID: "davis_ag.mapping.env:RowMappingEnv",
}


def register_environments() -> None:
    """Register every davis-ag environment with Gymnasium (again: a no-op)."""
    from gymnasium.envs.registration import register, registry

    for env_id, entry_point in ENTRY_POINTS.items():
        if env_id not in registry:
            # No max_episode_steps: the environments end their own episodes at tau with
            # terminated=True (a TimeLimit would report truncated and make learners bootstrap past
            # the final reward).
            register(id=env_id, entry_point=entry_point)


class _RegisteringLoader(importlib.abc.Loader):
    """Gymnasium's own loader, which registers the environments once Gymnasium's module has run
    (and then takes the finder off ``sys.meta_path``); everything else (resources, code) is asked
    of the loader it wraps."""

    def __init__(self, loader: importlib.abc.Loader, finder: _RegisterAfterGymnasium) -> None:
        self._loader = loader
        self._finder = finder

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType | None:
        return self._loader.create_module(spec)

    def exec_module(self, module: ModuleType) -> None:
        self._loader.exec_module(module)
        register_environments()
        if self._finder in sys.meta_path:
            sys.meta_path.remove(self._finder)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._loader, name)


class _RegisterAfterGymnasium(importlib.abc.MetaPathFinder):
    """Finds Gymnasium as the other finders do, with a loader that registers the environments.

    It stays on ``sys.meta_path`` until Gymnasium has run, so a look that imports nothing
    (``importlib.util.find_spec("gymnasium")``) leaves the import after it registering."""

    def __init__(self) -> None:
        self._searching = False

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        if fullname != "gymnasium" or self._searching:
            return None
        self._searching = True  # the search below asks every finder, this one too
        try:
            spec = importlib.util.find_spec(fullname)
        finally:
            self._searching = False
        if spec is not None and spec.loader is not None:
            spec.loader = _RegisteringLoader(spec.loader, self)
        return spec


def register_when_gymnasium_loads() -> None:
    """Register the environments now if Gymnasium is imported, else right after it is imported."""
    if "gymnasium" in sys.modules:
        register_environments()
    elif not any(isinstance(finder, _RegisterAfterGymnasium) for finder in sys.meta_path):
        sys.meta_path.insert(0, _RegisterAfterGymnasium())
