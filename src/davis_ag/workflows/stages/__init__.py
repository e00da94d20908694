"""Stage helpers the workflows share: generate scenes through the one runner, choose the split to
evaluate on, and run the baselines (and trained models) as Table 4 does.

``davis-ag demo``, ``davis-ag reproduce`` and the benchmarks (``davis-ag bench``) call these, so
a scene, a split or a baseline row means the same thing in each.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from davis_ag.errors import UserError
from davis_ag.generate.one_scene import SceneRequest
from davis_ag.generate.run_progress import RunOptions, default_workers
from davis_ag.generate.runner import run_dataset

if TYPE_CHECKING:
    from davis_ag.benchmark.results import EvaluationResults

#: The baselines of Table 4 plus the exact upper bound; A2C needs training (``reproduce``).
BASELINES: tuple[str, ...] = ("LRD", "UDD", "Rand", "Oracle")


def generate_scenes(
    requests: list[SceneRequest], root: Path, workers: int | None = None, progress: bool = True
) -> list[dict[str, Any]]:
    """Make the scenes not yet complete under ``root`` through the one dataset runner.

    :func:`davis_ag.generate.runner.run_dataset` locks the folder (a second run on it is
    refused), skips finished scenes, clears and redoes a crashed one, spreads scenes over worker
    processes and writes dataset.json and splits.json (the seeded 70/30 split by scene).

    Args:
        requests: The scenes wanted (one dataset seed and image size).
        root: The dataset root.
        workers: Scene processes (default: one per core as memory allows, at most one per scene).
        progress: Show progress (bars on a terminal, a line per scene otherwise).

    Returns:
        One dict per request: ``scene``, ``skipped`` and, for scenes made now, the timing
        statistics of :func:`davis_ag.generate.one_scene.generate_scene`.

    Raises:
        UserError: for an unusable root, another run on it, finished scenes made with other
            settings, or scenes that failed (the finished ones are kept).
    """
    workers = workers or max(1, min(default_workers(requests), len(requests)))
    report = run_dataset(requests, root, RunOptions(workers=workers, progress=progress))
    return [
        {"scene": r.folder, "skipped": r.folder in report.skipped, **report.stats.get(r.folder, {})} for r in requests
    ]


def evaluation_split(root: Path, scenario: str, crop: str, split_rule: str = "scenes") -> str:
    """``test`` when the dataset's split has test scenes of this scenario and crop, else ``all``.

    Args:
        root: The dataset root.
        scenario: ``sp`` or ``mp``.
        crop: Crop name.
        split_rule: The split rule (:mod:`davis_ag.formats.splits`): under ``starts`` and
            ``fruits`` the test side plays every scene, so one scene has a test split.

    Returns:
        The split to evaluate on.
    """
    from davis_ag.benchmark.splits import select_scenes
    from davis_ag.data.reader import open_dataset

    try:
        select_scenes(open_dataset(root), scenario, "test", crop, split_rule)
    except UserError:
        return "all"
    return "test"


def run_baselines(
    root: Path,
    scenario: str,
    crop: str,
    split: str,
    episodes: int,
    sessions: int,
    seed: int = 0,
    model: Path | None = None,
    learners: tuple[Path, ...] = (),
    robot: str | None = None,
    split_rule: str = "scenes",
) -> EvaluationResults:
    """Evaluate LRD, UDD, Rand, Oracle, the Best fixed action (and A2C when ``model`` is given,
    and other learners' models beside it) as in Table 4.

    A2C plays as :data:`davis_ag.benchmark.policies.DETERMINISTIC_PLAY` says (sampled); the same model
    taking its most likely action is the extra row ``A2C (deterministic)``.

    Args:
        root: The dataset root.
        scenario: ``sp`` or ``mp``.
        crop: Crop to evaluate on.
        split: ``train``, ``test`` or ``all``.
        episodes: Episodes per session.
        sessions: Sessions.
        seed: Base seed of the episodes.
        model: A trained A2C ``.zip``; adds the A2C column.
        learners: Other trained models (e.g. PPO's ``.zip``), each a row named by its algorithm,
            played as A2C is. Every policy plays the same seeded episodes with its own seeded
            randomness, so adding one leaves the other rows' numbers as they were.
        robot: The robot the camera rides on (docs/robot.md): its reach, its seconds; None: none.
        split_rule: The split rule (:mod:`davis_ag.formats.splits`).

    Returns:
        What :func:`davis_ag.benchmark.evaluation.evaluate` returns (``as_json()`` is its JSON).
    """
    from davis_ag.benchmark.evaluation import evaluate
    from davis_ag.benchmark.policies import ModelPolicy

    policies = []
    if model:
        sampled = ModelPolicy(model)
        deterministic = ModelPolicy(sampled.model, deterministic=True, name="A2C (deterministic)")
        deterministic.path = sampled.path  # one zip: one digest on both rows
        policies = [sampled, deterministic]
    policies += [ModelPolicy(path) for path in learners]
    return evaluate(
        policies,
        root,
        scenario=scenario,
        split=split,
        sessions=sessions,
        episodes=episodes,
        seed=seed,
        crop=crop,
        baselines=list(BASELINES),
        robot=robot,
        split_rule=split_rule,
    )
