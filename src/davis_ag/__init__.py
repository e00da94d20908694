"""davis-ag: generate, read and benchmark DAVIS-Ag active-vision datasets.

The names a researcher calls are here, each loaded from the module that defines it when first
used, so importing the package loads no stage (nor numpy, pydantic, Gymnasium or torch)::

    from davis_ag import open_dataset, exposure_rate, evaluate, TVMEnv

The Gymnasium environments are registered by name (:mod:`davis_ag.environments`): at once when
Gymnasium is imported already, else as soon as it is, so ``import davis_ag`` and ``import
gymnasium`` may come in either order and neither loads the other's stages.
"""

import importlib as _importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.2.0"

from davis_ag.environments import register_when_gymnasium_loads as _register_when_gymnasium_loads

_register_when_gymnasium_loads()

#: Each public name and where it is defined, as ``"module:attribute"``; imported on first use.
_PUBLIC: dict[str, str] = {
    "open_dataset": "davis_ag.data.reader:open_dataset",
    "Dataset": "davis_ag.data.reader:Dataset",
    "Scene": "davis_ag.data.reader:Scene",
    "View": "davis_ag.data.reader:View",
    "exposure_rate": "davis_ag.data.reader:exposure_rate",
    "evaluate": "davis_ag.benchmark.evaluation:evaluate",
    "Policy": "davis_ag.benchmark.policies:Policy",
    "TVMEnv": "davis_ag.benchmark.tvm:TVMEnv",
    "TVMContinuousEnv": "davis_ag.live.tvm_continuous:TVMContinuousEnv",
    "RowMappingEnv": "davis_ag.mapping.env:RowMappingEnv",
    "evaluate_mapping": "davis_ag.mapping.evaluation:evaluate_mapping",
}

if TYPE_CHECKING:  # for type checkers and editors; at run time __getattr__ loads them
    from davis_ag.benchmark.evaluation import evaluate
    from davis_ag.benchmark.policies import Policy
    from davis_ag.benchmark.tvm import TVMEnv
    from davis_ag.data.reader import Dataset, Scene, View, exposure_rate, open_dataset
    from davis_ag.live.tvm_continuous import TVMContinuousEnv
    from davis_ag.mapping.env import RowMappingEnv
    from davis_ag.mapping.evaluation import evaluate_mapping

__all__ = [
    "Dataset",
    "Policy",
    "RowMappingEnv",
    "Scene",
    "TVMContinuousEnv",
    "TVMEnv",
    "View",
    "__version__",
    "evaluate",
    "evaluate_mapping",
    "exposure_rate",
    "open_dataset",
]


def __getattr__(name: str) -> Any:
    """A public name, imported from its module the first time it is asked for (PEP 562)."""
    if name not in _PUBLIC:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module, attribute = _PUBLIC[name].split(":")
    value = getattr(_importlib.import_module(module), attribute)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
