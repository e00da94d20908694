"""Every random stream of davis-ag, and how each follows from the one seed recorded with an output.

Streams are NumPy ``SeedSequence`` keys, so two streams never share draws however many each takes:

- a scene: ``[dataset seed, scenario's index, crop's index, scene index]`` gives the scene's own
  seed (:func:`davis_ag.generate.one_scene.scene_seed`), which scene.json records; the plants, the
  Helios seeds, the sun and the slip draw from ``default_rng(scene seed)`` in a fixed order;
  a PlantArchitecture model's load seeds Helios from a child of that generator (``spawn``),
  which leaves those draws as they were;
- a scene's random appearance: ``[scene seed, APPEARANCE_STREAM]``;
- a group's train/test split: ``[split seed, scenario's index, crop's index, SPLIT_STREAM]``;
- a group's split of its episode starts (``--split-rule starts``) and of its target fruits
  (``--split-rule fruits``): ``[split seed, scenario's index, crop's index, START_SPLIT_STREAM]``
  and ``[..., FRUIT_SPLIT_STREAM]`` (:mod:`davis_ag.formats.splits`);
- our renderer's per-view noise: ``[lighting's noise seed, view index]`` for a grid view, and
  ``[lighting's noise seed, OFF_GRID_STREAM, digest of the pose]`` for a pose off the grid (a live
  scene's free camera): the same pose always gets the same noise (:func:`view_noise_seed`);
- evaluation session ``s``: ``[seed, s]`` for the environment's resets and ``[seed, s, AGENT_STREAM]``
  for the agent's own draws (:mod:`davis_ag.benchmark.evaluation`);
- a training run's environment ``i``: ``[seed, TRAIN_ENV_STREAM, i]`` (:func:`training_env_seed`;
  runs begun before it, and their resumptions, seed ``seed + i`` as SB3 does, under which
  environment 1 of seed 0 replays environment 0 of seed 1); the learner itself is seeded with
  the run's seed (SB3: torch, NumPy, Python); a sitting resumed from the checkpoint at step ``k``
  seeds all of these from ``[seed, TRAIN_RESUME_STREAM, k]`` instead (:func:`resumed_training_seed`),
  so it does not replay the first sitting's episodes and draws; the snapshot scoring plays fixed episodes
  (:data:`davis_ag.benchmark.selection.SELECT_SEED`) under a forked torch state;
- a robot's reach of a scene (:mod:`davis_ag.robot.reach`): the IK's random restarts on the
  base line of side ``s`` (0 south, 1 north) draw from ``[scene seed, REACH_STREAM, s]``;
- a row scene's cover crop (:mod:`davis_ag.scene.cover`): ``[scene seed, COVER_STREAM]``, apart
  from the scene's own generator, so its plants, sun and cameras are those of a scene without;
- the paired bootstrap: ``default_rng(seed)`` of the evaluation (:mod:`davis_ag.benchmark.paired`);
  the transfer experiment's split ``k``: ``seed + k``, its appearance shift: ``[seed, image]``.

Known coincidences, kept because changing them would change datasets already made: NumPy's
``SeedSequence`` ignores trailing zeros and a key is a prefix of longer ones only in name, so a few
keys meet: scene 001's key ``[dataset seed, scenario, crop, 1]`` is the split's, view 2's noise
key is the appearance's, view 0's is ``default_rng(scene seed)``'s and session 0's resets are the
bootstrap's. Each pair feeds different generators or hashes (a scene seed is one word of its
sequence, the split draws a permutation; the noise is hashed again in the shaders), so no draw is
shared; a new stream must not add to them.

A new stream takes a new number here, never an old one.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence

import numpy as np

#: The split's stream after the group's keys.
SPLIT_STREAM = 1
#: A scene's random appearance, after the scene seed.
APPEARANCE_STREAM = 2
#: An evaluation session's agent draws, after ``[seed, session]``.
AGENT_STREAM = 1
#: Noise of a pose off the grid, after the noise seed; larger than any grid's view index.
OFF_GRID_STREAM = 2**32 - 1
#: A training run's environments, after its seed (then the environment's index); beyond any
#: evaluation session's number, whose keys ``[seed, session, ...]`` share the first place.
TRAIN_ENV_STREAM = 2**32 - 2
#: A training sitting resumed from a checkpoint, after the run's seed (then the step it resumes at).
TRAIN_RESUME_STREAM = 2**32 - 3
#: A robot's IK restarts over a scene's views, after the scene seed (then the base line's side).
REACH_STREAM = 2**32 - 4
#: A group's split of its episode starts, after the group's keys; beyond any scene index, whose
#: keys ``[dataset seed, scenario, crop, scene]`` share the first places.
START_SPLIT_STREAM = 2**32 - 5
#: A group's split of its target fruits, after the group's keys (as :data:`START_SPLIT_STREAM`).
FRUIT_SPLIT_STREAM = 2**32 - 6
#: A row scene's cover crop (spots, turns, its prototypes' Helios seeds), after the scene seed.
COVER_STREAM = 2**32 - 7


def derived_seed(*keys: int) -> int:
    """A 32-bit seed for the stream named by ``keys`` (what Helios, Gymnasium and SB3 take)."""
    return int(np.random.SeedSequence(list(keys)).generate_state(1, dtype=np.uint32)[0])


def stream_rng(*keys: int) -> np.random.Generator:
    """A generator for the stream named by ``keys``."""
    return np.random.default_rng(np.random.SeedSequence(list(keys)))


def view_noise_seed(noise_seed: int, index: int, pose: Sequence[float]) -> int:
    """The seed of one view's sensor noise.

    Args:
        noise_seed: The lighting's noise seed (the scene seed).
        index: The view's index in its grid; negative for a pose off the grid.
        pose: x, y, z, yaw, pitch: what names a pose off the grid (rounded to a micrometre and a
            microdegree, so a pose read back from a file draws the same noise).
    """
    if index >= 0:
        return derived_seed(noise_seed, index)
    rounded = np.round(np.asarray(pose, dtype=np.float64), 6) + 0.0  # + 0.0: -0.0 and 0.0 alike
    digest = int.from_bytes(hashlib.sha256(rounded.tobytes()).digest()[:8], "little")
    return derived_seed(noise_seed, OFF_GRID_STREAM, digest)


def resumed_training_seed(seed: int, step: int) -> int:
    """The seed of a training sitting of a run of ``seed`` resumed at ``step`` (``[seed,
    TRAIN_RESUME_STREAM, step]``): the learner's and, through it, its environments'."""
    return derived_seed(seed, TRAIN_RESUME_STREAM, step)


def training_env_seed(seed: int, index: int) -> int:
    """The seed of environment ``index`` of a training run of ``seed`` (``[seed, TRAIN_ENV_STREAM, index]``)."""
    return derived_seed(seed, TRAIN_ENV_STREAM, index)
