"""The policy protocol every davis-ag environment is benchmarked with, and policies named by a SPEC.

A policy (:class:`Policy`) has a ``name`` (its row in results tables) and two methods:
``reset(seed)`` at the start of each episode (``seed`` fixes the policy's own randomness) and
``act(observation, info) -> action`` once per step, with the observation and the ``info`` dict the
environment just returned. The same protocol serves TVM-v0 (an action index, or an action name
such as ``"left"``) and TVMContinuous-v0 (an array in [-1, 1], or a move name, which
:meth:`TVMContinuousEnv.action_for` turns into a unit move). A policy that needs to know the
environment before it plays (its action names, its tables, whether a model's spaces fit) also
defines ``prepare(env)``: the evaluation calls it once, before any episode, and a policy that
does not fit raises :class:`davis_ag.errors.UserError` there.

A SPEC (``davis-ag evaluate --policy``, :func:`policy_from_spec`) is one of:

- ``MODEL.zip``: a saved Stable-Baselines3 or sb3-contrib model; the algorithm is read from
  the file (:func:`davis_ag.benchmark.sb3_models.model_algorithm`) and names the row (``PPO``,
  ``A2C``, ``DQN``, ``RecurrentPPO``...). A recurrent policy keeps its LSTM state through an
  episode and starts each afresh; MaskablePPO is given the environment's ``action_masks()``;
- ``module:attr`` or ``path/to/file.py:attr``: a callable ``(observation, info) -> action``, a
  class with ``reset``/``act`` (made with no arguments) or such an object.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import os
import sys
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Protocol, TypeVar, runtime_checkable

import numpy as np

from davis_ag.benchmark.sb3_models import (
    CONTRIB_ALGORITHMS,
    SB3_ALGORITHMS,
    load_model,
    recurrent_batch,
)
from davis_ag.benchmark.training_record import check_trained_split
from davis_ag.errors import UserError

#: How a trained model plays by default (one owner for every SB3 model: ``davis-ag evaluate``,
#: ``reproduce``, the train-split score that picks a snapshot): False samples each action from
#: the policy. Played deterministically, a policy repeats a refused move for the rest of the
#: episode (the observation after a refused move is the same image), and a policy whose most
#: likely action is the same at every start is exactly a fixed action: on the train split
#: (docs/benchmark.md) a short-trained A2C played deterministically was "always forward" while
#: sampling it scored higher; trained longer, deterministic play scored about one standard
#: deviation higher than sampling. Sampling is kept as the safe default on unseen scenes, where
#: the policy is least sure; ``davis-ag evaluate --deterministic`` plays the most likely action,
#: and ``reproduce`` reports it as the row ``A2C (deterministic)``.
DETERMINISTIC_PLAY = False

#: Algorithms a saved model may be, by the name :func:`~davis_ag.benchmark.sb3_models.model_algorithm` reads (sb3-contrib's with the extra).
ALGORITHMS: tuple[str, ...] = (*SB3_ALGORITHMS, *CONTRIB_ALGORITHMS)


@runtime_checkable
class Policy(Protocol):
    """What the evaluation loop needs from a policy (see the module docstring)."""

    name: str

    def reset(self, seed: int | None = None) -> None:
        """Start an episode; ``seed`` fixes the policy's own randomness (if any)."""

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> Any:
        """The action for ``observation`` (``info``: what the environment said with it)."""


EnvT = TypeVar("EnvT")


def unwrapped(env: object, kind: type[EnvT], env_id: str) -> EnvT:
    """The environment of class ``kind`` under any wrappers (what a policy's ``prepare`` reads).

    Raises:
        UserError: when ``env`` is another environment.
    """
    inner = getattr(env, "unwrapped", env)
    if not isinstance(inner, kind):
        raise UserError(f"expected a {env_id} environment, got {type(inner).__name__}")
    return inner


class SeededPolicy:
    """Base of the policies with a random stream of their own: ``reset(seed)`` reseeds it."""

    def __init__(self, seed: int | None = None) -> None:
        """Args:
        seed: Seed of the policy's generator until :meth:`reset` gets one.
        """
        self._rng = np.random.default_rng(seed)

    def reset(self, seed: int | None = None) -> None:
        """Reseed the policy's draws (``None`` keeps the current stream)."""
        if seed is not None:
            self._rng = np.random.default_rng(seed)


def baselines_by_name(names: list[str], makers: Mapping[str, Callable[[], Policy]], kind: str = "") -> list[Policy]:
    """An environment's baselines by name, in the order given (any case).

    Args:
        names: The names asked for.
        makers: Each baseline's name and a function making it.
        kind: How error messages call the environment's policies (``"continuous "``).

    Raises:
        UserError: for an unknown name (a trained model is a ``--policy MODEL.zip``).
    """
    canonical = {k.lower(): k for k in makers}
    made = []
    for name in names:
        key = name.strip().lower()
        if key in canonical:
            made.append(makers[canonical[key]]())
        elif key in ("model", *(a.lower() for a in ALGORITHMS)):
            raise UserError(f"{name} is not a baseline: give the trained model with --policy MODEL.zip")
        else:
            raise UserError(f"unknown {kind}policy {name!r}: choose from {', '.join(makers)}")
    return made


def prepare(policy: Policy, env: Any) -> None:
    """Call the policy's optional ``prepare(env)`` (learn the environment, refuse a misfit)."""
    method = getattr(policy, "prepare", None)
    if callable(method):
        method(env)


class FunctionPolicy:
    """A plain callable ``(observation, info) -> action`` as a :class:`Policy` (no randomness)."""

    def __init__(self, function: Callable[[np.ndarray, dict[str, Any]], Any], name: str | None = None) -> None:
        """Args:
        function: The callable.
        name: Row name (default: the callable's ``__name__``).
        """
        self.function = function
        self.name: str = name if name else str(getattr(function, "__name__", type(function).__name__))

    def reset(self, seed: int | None = None) -> None:
        """Seed NumPy's global generator, which a plain function may draw from."""
        if seed is not None:
            np.random.seed(seed % 2**32)

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> Any:
        """The function's action."""
        return self.function(observation, info)


def as_policy(thing: Any, name: str | None = None) -> Policy:
    """A :class:`Policy` from a policy object, a class with ``reset``/``act`` or a callable.

    Raises:
        UserError: when ``thing`` is none of them.
    """
    if inspect.isclass(thing):
        if not callable(getattr(thing, "act", None)):
            raise UserError(
                f"class {thing.__name__} has no act(observation, info) method: give a policy class "
                "with reset(seed) and act(observation, info), or a function"
            )
        try:
            thing = thing()
        except TypeError as error:
            raise UserError(
                f"class {thing.__name__} cannot be made without arguments ({error}): give it "
                "defaults, or name an object of it or a function in the file instead"
            ) from None
    if callable(getattr(thing, "act", None)):
        if not callable(getattr(thing, "reset", None)):
            raise UserError(f"{type(thing).__name__} has act but no reset(seed) method: add one")
        if name or not isinstance(getattr(thing, "name", None), str):
            thing.name = name or type(thing).__name__
        return thing
    if callable(thing):
        return FunctionPolicy(thing, name)
    raise UserError(
        f"{thing!r} is not a policy: give a function (observation, info) -> action, or an object "
        "with reset(seed) and act(observation, info)"
    )


def _space_text(space: Any) -> str:
    return f"{space.n} actions" if hasattr(space, "n") else f"actions of shape {getattr(space, 'shape', None)}"


class ModelPolicy:
    """A trained Stable-Baselines3 model (any algorithm with ``predict``) as a :class:`Policy`.

    Evaluations play its episodes in step (:meth:`act_batch`, :mod:`davis_ag.benchmark.lockstep`):
    the episodes :meth:`reset` and :meth:`act` would play one at a time, for one forward pass a step.
    """

    def __init__(
        self, model: Any, deterministic: bool = DETERMINISTIC_PLAY, name: str | None = None, device: str = "cpu"
    ) -> None:
        """Args:
            model: A loaded SB3 model, or the path of a saved ``.zip``.
            deterministic: Take the most likely action instead of sampling (see
                :data:`DETERMINISTIC_PLAY`, the default).
            name: Row name (default: the algorithm, e.g. ``PPO``).
            device: Torch device to load a saved model on.

        Raises:
            UserError: when the file is missing or not an SB3 model.
        """
        #: The scenes it was trained on, where its training record says (``davis-ag train``'s).
        self.trained_on: list[str] | None = None
        #: The split rule its training record names (None: none recorded, i.e. ``scenes``).
        self.split_rule: str | None = None
        #: The zip it was loaded from (None: a model given in memory); its digest names the code.
        self.path: Path | None = None
        if isinstance(model, (str, os.PathLike)):
            self.path = Path(os.fspath(model)).expanduser()
            from davis_ag.benchmark.training_record import recorded_split_rule, recorded_train_scenes

            self.trained_on = recorded_train_scenes(model)
            self.split_rule = recorded_split_rule(model)
            model = load_model(model, device)
        # A Q-learner's policy is its greedy action: SB3's "sampled" DQN (and QR-DQN) is
        # epsilon-greedy with training's exploration rate, which is no distribution of the learnt policy.
        greedy = hasattr(model, "q_net") or hasattr(model, "quantile_net")
        self.model, self.deterministic = model, bool(deterministic) or greedy
        self.name = name or type(model).__name__
        #: A recurrent policy (RecurrentPPO): its LSTM state, kept through an episode.
        self.recurrent = hasattr(getattr(model, "policy", None), "lstm_actor")
        #: MaskablePPO: it is given the environment's action mask at every step.
        self.masked = type(model).__name__ == "MaskablePPO"
        self._memory: Any = None
        self._starting = True
        self._env: Any = None

    @property
    def play(self) -> str:
        """``deterministic`` or ``sampled``, as results record it."""
        return "deterministic" if self.deterministic else "sampled"

    def reset(self, seed: int | None = None) -> None:
        """Seed torch's sampling when acting stochastically; a recurrent policy's memory starts afresh."""
        self._memory, self._starting = None, True
        if seed is not None and not self.deterministic:
            import torch

            torch.manual_seed(seed)

    def prepare(self, env: Any) -> None:
        """Refuse an environment the model was not trained for, before any episode.

        Raises:
            UserError: when the action or observation space differs (e.g. an SP model on MP:
                7 actions against 9; a grid model on the continuous environment).
        """
        ours, theirs = self.model.action_space, env.action_space
        if (
            type(ours) is not type(theirs)
            or getattr(ours, "n", None) != getattr(theirs, "n", None)
            or getattr(ours, "shape", None) != getattr(theirs, "shape", None)
        ):
            raise UserError(
                f"{self.name}: the model has {_space_text(ours)}, this environment {_space_text(theirs)}: "
                "use a model trained on the same environment and scenario"
            )
        shape = getattr(self.model.observation_space, "shape", None)
        # SB3 stores image spaces channels-first.
        if shape is not None and sorted(shape) != sorted(env.observation_space.shape):
            raise UserError(
                f"{self.name}: the model takes observations of shape {shape}, the environment gives "
                f"{env.observation_space.shape}: use a model trained by davis-ag train"
            )
        inner = getattr(env, "unwrapped", env)
        if self.masked:
            if not callable(getattr(inner, "action_masks", None)):
                raise UserError(f"{self.name}: a MaskablePPO model needs an environment with action_masks()")
            self._env = inner
        described = inner.describe() if hasattr(inner, "describe") else {}
        check_trained_split(self.name, self.trained_on, self.split_rule, described)

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> Any:
        """The model's action for ``observation`` (a recurrent policy's memory carried on)."""
        if self.recurrent:
            starting = np.array([self._starting])
            action, self._memory = self.model.predict(
                observation, state=self._memory, episode_start=starting, deterministic=self.deterministic
            )
            self._starting = False
            return action
        if self.masked:
            masks = self._env.action_masks() if self._env is not None else None
            action, _ = self.model.predict(observation, deterministic=self.deterministic, action_masks=masks)
            return action
        action, _ = self.model.predict(observation, deterministic=self.deterministic)
        return action

    @property
    def batches(self) -> bool:
        """Whether :meth:`act_batch` can play this model: deterministic play of any model, sampled
        play of a model whose policy gives a distribution over discrete actions (A2C, PPO,
        RecurrentPPO); not MaskablePPO, whose mask is each episode's environment's."""
        return (
            hasattr(self.model.action_space, "n")
            and not self.masked
            and (self.deterministic or hasattr(self.model.policy, "get_distribution"))
        )

    def streams(self, seeds: list[int]) -> list[Any]:
        """One torch generator per episode, on the model's device, seeded as :meth:`reset` seeds
        torch's own: episode ``i`` of a batch draws what it would draw played alone. A recurrent
        policy's memories are kept per stream, so a new batch starts them afresh."""
        import torch

        self._memories: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        device = getattr(self.model, "device", torch.device("cpu"))
        return [torch.Generator(device=device).manual_seed(int(seed)) for seed in seeds]

    def act_batch(self, observations: list[np.ndarray], streams: list[Any]) -> list[int]:
        """The model's actions for many episodes' observations, from one forward pass.

        Sampled play draws each episode's action from its own stream with what SB3's
        ``predict`` does for one observation (``Categorical.sample``: a one-row
        ``torch.multinomial``), so the draws are those of :meth:`act` after ``reset(seed)``.

        Args:
            observations: One observation per episode.
            streams: The episodes' generators (:meth:`streams`), in the same order.

        Returns:
            One action index per observation.
        """
        import torch

        if self.recurrent:
            return recurrent_batch(self, observations, streams)
        if self.deterministic:
            actions, _ = self.model.predict(np.stack(observations), deterministic=True)
            return [int(a) for a in np.asarray(actions).reshape(-1)]
        policy = self.model.policy
        policy.set_training_mode(False)
        tensor, _ = policy.obs_to_tensor(np.stack(observations))
        with torch.no_grad():
            probs = policy.get_distribution(tensor).distribution.probs
            return [int(torch.multinomial(probs[i : i + 1], 1, True, generator=g)) for i, g in enumerate(streams)]


def as_policies(items: Iterable[Any], deterministic: bool = DETERMINISTIC_PLAY) -> list[Policy]:
    """Policies from what an evaluation is handed: SPEC strings (:func:`policy_from_spec`, models
    playing as ``deterministic`` says) and policy objects or callables (:func:`as_policy`)."""
    return [
        policy_from_spec(p, deterministic=deterministic) if isinstance(p, (str, os.PathLike)) else as_policy(p)
        for p in items
    ]


def _import_target(target: str, spec: str) -> Any:
    """The module or file a SPEC's left part names, imported."""
    if target.endswith(".py") or os.sep in target or "/" in target:
        path = Path(target).expanduser()
        if not path.is_file():
            raise UserError(f"--policy {spec}: no such file {path}")
        name = f"davis_ag_policy_{abs(hash(str(path.absolute())))}"
        loader_spec = importlib.util.spec_from_file_location(name, path)
        if loader_spec is None or loader_spec.loader is None:
            raise UserError(f"--policy {spec}: {path} is not a Python file")
        module = importlib.util.module_from_spec(loader_spec)
        sys.modules[name] = module
        with _import_errors(spec, str(path), keep_missing=False):
            loader_spec.loader.exec_module(module)
        return module
    try:
        with _import_errors(spec, target):
            return importlib.import_module(target)
    except ModuleNotFoundError as error:
        raise UserError(
            f"--policy {spec}: no module {error.name!r} (is it on PYTHONPATH? a file needs "
            "its path, e.g. ./my_policy.py:act)"
        ) from None


@contextmanager
def _import_errors(spec: str, where: str, keep_missing: bool = True) -> Iterator[None]:
    """A user's policy file that fails to import (a syntax error, an exception or ``sys.exit`` at
    import) is named in one line with where it failed, not a traceback from inside the loader.
    ``keep_missing`` lets a missing module through, for the caller's own message."""
    try:
        yield
    except ModuleNotFoundError as error:
        if keep_missing:
            raise
        raise UserError(f"--policy {spec}: importing {where} needs module {error.name!r}, not installed here") from None
    except SyntaxError as error:
        raise UserError(f"--policy {spec}: {error.filename or where}, line {error.lineno}: {error.msg}") from None
    except (Exception, SystemExit) as error:
        raise UserError(
            f"--policy {spec}: importing {where} raised {type(error).__name__}: {error} "
            f"(run `python {where}` to see where)"
        ) from None


def policy_from_spec(
    spec: str | os.PathLike[str], name: str | None = None, deterministic: bool = DETERMINISTIC_PLAY
) -> Policy:
    """The :class:`Policy` a SPEC names (see the module docstring).

    Args:
        spec: ``MODEL.zip``, ``module:attr`` or ``path/to/file.py:attr``.
        name: Row name (default: the algorithm for a model, the attribute's name otherwise).
        deterministic: How a model plays (ignored by other policies).

    Raises:
        UserError: for a missing file, module or attribute, or something that is not a policy.
    """
    text = str(spec).strip()
    if not text.strip(":"):
        raise UserError(f"--policy {spec!r}: empty; give MODEL.zip, module:attr or path/to/file.py:attr")
    target, colon, attr = text.rpartition(":")
    if not colon or not target or not attr or attr.endswith((".zip", ".py")) or os.sep in attr:
        if text.endswith(".py"):
            raise UserError(f"--policy {spec}: name the function or class too, e.g. {text}:my_policy")
        policy: Policy = ModelPolicy(text, deterministic=deterministic, name=name)
    else:
        module = _import_target(target, str(spec))
        try:
            thing = getattr(module, attr)
        except AttributeError:
            raise UserError(f"--policy {spec}: {target} has no {attr!r}") from None
        try:
            policy = as_policy(thing, name)
        except UserError as error:  # which --policy it was, as every other refusal of one says
            raise UserError(f"--policy {spec}: {error}") from None
    # The results record where each policy came from; a user's own policy object has no such field.
    setattr(policy, "source", text)  # noqa: B010
    return policy
