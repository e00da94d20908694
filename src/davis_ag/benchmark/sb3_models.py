"""Saved Stable-Baselines3 and sb3-contrib models: which algorithm a zip holds, read from the zip
itself, and loading it with that algorithm.

SB3 keeps a model's constructor settings in the zip's ``data`` entry, among them the policy class
(its module and name). The policy's module names most algorithms: SB3's off-policy ones
(``stable_baselines3.dqn.policies``...) and sb3-contrib's (``sb3_contrib.qrdqn.policies``,
``sb3_contrib.common.recurrent.policies`` for RecurrentPPO, ``...maskable...`` for MaskablePPO).
A2C, PPO and TRPO share SB3's actor-critic policies; of them only PPO has a clip range and only
TRPO a conjugate-gradient step count. A policy class of any other package is an algorithm
davis-ag does not know: refused in one line, never guessed from a failed load.

sb3-contrib is an optional extra (``pip install 'davis-ag[contrib]'``); a contrib model without it
is refused in one line that says so.
"""

from __future__ import annotations

import json
import os
import zipfile
from pathlib import Path
from typing import Any

from davis_ag.errors import UserError

#: Stable-Baselines3's algorithms, by class name.
SB3_ALGORITHMS: tuple[str, ...] = ("A2C", "PPO", "DQN", "SAC", "TD3", "DDPG")
#: sb3-contrib's algorithms davis-ag plays (discrete actions: TVM-v0, RowMapping-v0; a box:
#: TVMContinuous-v0), by class name.
CONTRIB_ALGORITHMS: tuple[str, ...] = ("RecurrentPPO", "QRDQN", "TRPO", "MaskablePPO", "ARS", "TQC", "CrossQ")
#: What a policy class's module says of its algorithm, checked in this order.
_MODULE_MARKS: tuple[tuple[str, str], ...] = (
    ("sb3_contrib.common.recurrent.", "RecurrentPPO"),
    ("sb3_contrib.common.maskable.", "MaskablePPO"),
    ("sb3_contrib.qrdqn.", "QRDQN"),
    ("sb3_contrib.ars.", "ARS"),
    ("sb3_contrib.tqc.", "TQC"),
    ("sb3_contrib.crossq.", "CrossQ"),
    ("stable_baselines3.dqn.", "DQN"),
    ("stable_baselines3.sac.", "SAC"),
    ("stable_baselines3.td3.", "TD3"),
    ("stable_baselines3.ddpg.", "DDPG"),
)
#: The one line's advice when sb3-contrib is missing.
CONTRIB_INSTALL = "pip install 'davis-ag[contrib]' (sb3-contrib)"


def supported_text() -> str:
    """The algorithms davis-ag plays, for messages."""
    return f"{', '.join(SB3_ALGORITHMS)}, and with {CONTRIB_INSTALL} {', '.join(CONTRIB_ALGORITHMS)}"


def model_algorithm(path: Path) -> str:
    """The algorithm a saved model was trained with, read from its file (see the module docstring).

    Raises:
        UserError: when the file is missing, not a Stable-Baselines3 model, or of an algorithm
            davis-ag does not play.
    """
    if path.is_dir():
        raise UserError(f"{path}: a folder, not a model file; give the .zip `davis-ag train` saved")
    if not path.is_file():
        raise UserError(f"{path}: no such model file; train one with `davis-ag train`")
    try:
        with zipfile.ZipFile(path) as archive:
            data = json.loads(archive.read("data"))
        policy = data["policy_class"]
        module, name = str(policy.get("__module__", "")), str(policy.get(":type:", ""))
    except (zipfile.BadZipFile, KeyError, ValueError, AttributeError, TypeError, OSError) as error:
        raise UserError(
            f"{path}: not a Stable-Baselines3 model ({error}); give the .zip "
            "`davis-ag train` (or SB3's model.save) wrote"
        ) from None
    for mark, algorithm in _MODULE_MARKS:
        if module.startswith(mark):
            return algorithm
    if module.startswith("stable_baselines3.common."):
        if "cg_max_steps" in data:
            return "TRPO"
        return "PPO" if "clip_range" in data else "A2C"
    raise UserError(
        f"{path}: a model of policy class {module or name or 'unknown'}, of an algorithm davis-ag does not play; "
        f"it plays {supported_text()}"
    )


def algorithm_class(name: str) -> Any:
    """The algorithm's class, from Stable-Baselines3 or sb3-contrib.

    Raises:
        UserError: for an unknown name, or a contrib algorithm without sb3-contrib installed.
    """
    if name in SB3_ALGORITHMS:
        import stable_baselines3

        return getattr(stable_baselines3, name)
    if name not in CONTRIB_ALGORITHMS:
        raise UserError(f"unknown algorithm {name!r}: davis-ag plays {supported_text()}")
    try:
        import sb3_contrib
    except ImportError:
        raise UserError(f"a {name} model needs sb3-contrib, which is not installed: {CONTRIB_INSTALL}") from None
    return getattr(sb3_contrib, name)


def load_model(path: str | os.PathLike[str], device: str = "cpu") -> Any:
    """A saved model of any algorithm davis-ag plays (:func:`model_algorithm`).

    Raises:
        UserError: when the file is missing, cannot be loaded, or needs sb3-contrib.
    """
    path = Path(path)
    algorithm = model_algorithm(path)
    cls = algorithm_class(algorithm)
    try:
        return cls.load(path, device=device)
    except Exception as error:
        raise UserError(
            f"{path}: a {algorithm} model that does not load ({type(error).__name__}: {error}); give the .zip "
            "`davis-ag train` (or the algorithm's model.save) wrote"
        ) from None


def recurrent_batch(policy: Any, observations: list[Any], streams: list[Any]) -> list[int]:
    """A recurrent model's actions for many episodes in one forward pass, each episode's LSTM
    state kept under its stream (:meth:`davis_ag.benchmark.policies.ModelPolicy.streams`), so an
    episode steps through what it would played alone: its memory from its own last step, started
    afresh at its first, and its draw from its own generator (a one-row multinomial, as
    ``Categorical.sample`` draws for one observation).

    Args:
        policy: The :class:`~davis_ag.benchmark.policies.ModelPolicy` of a RecurrentPPO model.
        observations: One observation per episode still playing.
        streams: Their generators, in the same order.

    Returns:
        One action index per observation.
    """
    import numpy as np
    import torch

    model = policy.model
    memories = policy._memories
    keys = [id(stream) for stream in streams]
    starting = np.array([key not in memories for key in keys], dtype=bool)
    blank = np.zeros(model.policy.lstm_hidden_state_shape, dtype=np.float32)
    hidden = np.concatenate([memories.get(key, (blank, blank))[0] for key in keys], axis=1)
    cell = np.concatenate([memories.get(key, (blank, blank))[1] for key in keys], axis=1)
    if policy.deterministic:
        actions, (hidden, cell) = model.predict(
            np.stack(observations), state=(hidden, cell), episode_start=starting, deterministic=True
        )
        chosen = [int(a) for a in np.asarray(actions).reshape(-1)]
    else:
        net = model.policy
        net.set_training_mode(False)
        tensor, _ = net.obs_to_tensor(np.stack(observations))
        device = tensor.device
        with torch.no_grad():
            states = (torch.as_tensor(hidden, device=device), torch.as_tensor(cell, device=device))
            distribution, states = net.get_distribution(
                tensor, states, torch.as_tensor(starting, device=device).float()
            )
            probs = distribution.distribution.probs
            chosen = [int(torch.multinomial(probs[i : i + 1], 1, True, generator=g)) for i, g in enumerate(streams)]
        hidden, cell = states[0].cpu().numpy(), states[1].cpu().numpy()
    for i, key in enumerate(keys):
        memories[key] = (hidden[:, i : i + 1], cell[:, i : i + 1])
    return chosen
