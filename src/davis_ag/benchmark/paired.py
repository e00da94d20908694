"""How far apart two policies are on the same episodes, and how sure that gap is.

Every policy of an evaluation plays the same episodes (:func:`davis_ag.benchmark.evaluation.episode_seeds`),
so two policies can be compared episode by episode. Table 4's ± is the standard deviation of the
three session means: it says how much another draw of sessions would move a mean, not whether
a gap between two policies would survive other starts. Here the per-episode differences of
OER_tau are resampled (a bootstrap over episodes, which are independent draws of a start and of
the policies' own randomness) for an interval on the mean gap, and the gap is also given per
test scene, since a split of a few scenes can owe its verdict to one of them.

That interval answers "would the gap hold on other starts of these scenes?". Whether it would
hold on other scenes like them is a wider question: a second interval resamples the test scenes
themselves (a cluster bootstrap: scenes drawn with replacement, each with all its episodes, the
gap their episodes' mean), so a gap that rests on a few scenes gets the wide interval it
deserves. With few test scenes that interval is coarse (it takes at least 2 and means little
below about 10); with the paper's 26 SP strawberry and 13 MP vine test scenes it is the one that
says whether a method generalises.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from davis_ag.benchmark.exact import BEST_FIXED

#: Bootstrap resamples; the interval's last digit is stable at this count.
RESAMPLES = 10_000
#: Two-sided confidence of the interval.
CONFIDENCE = 0.95
#: Below this many test scenes the interval over scenes is coarse (with 3 it is the range of the
#: scenes' own gaps), and the pages say so beside it.
FEW_SCENES = 10


@dataclass(frozen=True)
class SceneGap:
    """The mean gap on one test scene.

    Attributes:
        scene: The scene (``group/NNN``).
        gap: Mean OER_tau of the first policy minus the second's over the scene's episodes.
        episodes: Episodes played on the scene.
        starts: Distinct (start view, target fruit) pairs among them.
    """

    scene: str
    gap: float
    episodes: int
    starts: int


@dataclass(frozen=True)
class PairedGap:
    """Mean OER_tau of one policy minus another's on the same episodes.

    Attributes:
        gap: The mean of the per-episode differences.
        low, high: The :data:`CONFIDENCE` bootstrap interval (percentile) of that mean, over
            episodes.
        episodes: Episodes compared.
        per_scene: The gap on each test scene, in scene order.
        scene_low, scene_high: The :data:`CONFIDENCE` interval over scenes (:func:`scene_interval`);
            None with fewer than 2 scenes.
    """

    gap: float
    low: float
    high: float
    episodes: int
    per_scene: tuple[SceneGap, ...]
    scene_low: float | None = None
    scene_high: float | None = None


def _start(episode: dict[str, Any]) -> tuple:
    """What makes two episodes the same: session, scene, start (a view, or a pose) and target fruit."""
    start = episode["path"][0]
    return (
        episode["session"],
        episode["scene"],
        tuple(start) if isinstance(start, list) else start,
        episode["target_fruit"],
    )


def paired_gap(first: list[dict[str, Any]], second: list[dict[str, Any]], seed: int = 0) -> PairedGap:
    """Compare two policies' episode records (the ``episodes`` lists of an evaluation's JSON).

    Args:
        first, second: Each policy's episodes, in the order they were played.
        seed: Seed of the bootstrap's resampling (the evaluation's, so a page is redrawn identically).

    Returns:
        The mean gap (first minus second), its bootstrap interval and the gap per scene.

    Raises:
        ValueError: The two lists are empty or are not the same episodes.
    """
    if not first or len(first) != len(second) or any(_start(a) != _start(b) for a, b in zip(first, second)):
        raise ValueError("the two policies did not play the same episodes")
    from scipy import stats

    differences = np.array([a["oer_tau"] - b["oer_tau"] for a, b in zip(first, second)], dtype=float)
    if np.ptp(differences) == 0:  # no spread to resample: the interval is the point
        low = high = float(differences[0])
    else:  # percentile, not BCa: BCa is undefined when most differences are equal (policies that agree)
        interval = stats.bootstrap(
            (differences,),
            np.mean,
            n_resamples=RESAMPLES,
            confidence_level=CONFIDENCE,
            method="percentile",
            random_state=np.random.default_rng(seed),
        ).confidence_interval
        low, high = float(interval.low), float(interval.high)
    scenes = [a["scene"] for a in first]
    per_scene = []
    for scene in sorted(set(scenes)):
        mask = np.array([s == scene for s in scenes])
        starts = {_start(a)[2:] for a, s in zip(first, scenes) if s == scene}
        per_scene.append(SceneGap(scene, float(differences[mask].mean()), int(mask.sum()), len(starts)))
    scene_low, scene_high = scene_interval(differences, scenes, seed)
    return PairedGap(float(differences.mean()), low, high, len(differences), tuple(per_scene), scene_low, scene_high)


def scene_interval(differences: np.ndarray, scenes: list[str], seed: int = 0) -> tuple[float | None, float | None]:
    """The :data:`CONFIDENCE` percentile interval of the mean gap when the scenes themselves are
    resampled (a cluster bootstrap of :data:`RESAMPLES` draws).

    Each draw takes as many scenes as there are, with replacement, and the mean of all their
    episodes' differences, so a scene weighs by the episodes it holds, as in the mean itself.

    Args:
        differences: Per-episode differences (first policy minus second).
        scenes: Each episode's scene.
        seed: The resampling's seed.

    Returns:
        ``(low, high)``; ``(None, None)`` with fewer than 2 scenes, where there is nothing to resample.
    """
    names, index = np.unique(np.asarray(scenes), return_inverse=True)
    if len(names) < 2:
        return None, None
    sums = np.bincount(index, weights=differences)
    counts = np.bincount(index).astype(float)
    drawn = np.random.default_rng(seed).integers(0, len(names), size=(RESAMPLES, len(names)))
    means = sums[drawn].sum(axis=1) / counts[drawn].sum(axis=1)
    tail = (1 - CONFIDENCE) / 2 * 100
    low, high = np.percentile(means, [tail, 100 - tail])
    return float(low), float(high)


def a2c_against_best_fixed(results: dict[str, Any], learner: str = "A2C") -> dict[str, Any] | None:
    """:func:`paired_gap` of ``A2C`` (or another ``learner``'s row, e.g. ``PPO``) and ``Best fixed
    action`` in an evaluation's results, as JSON.

    Args:
        results: An evaluation's results (``policies`` with their ``episodes``, ``protocol``).
        learner: The row compared with the Best fixed action.

    Returns:
        The gap as a dict, or None when either policy or its episode records are missing.
    """
    policies = results.get("policies", {})
    kept = policies.get(learner, {}).get("paired", {}).get(BEST_FIXED)
    records = [policies.get(name, {}).get("episodes") for name in (learner, BEST_FIXED)]
    if kept and (not all(records) or not lacks_scene_interval(kept)):  # the evaluation's own, same seed
        return kept
    if not all(records):
        return None
    # None kept, or one written before the interval over scenes: the episodes give it again (the
    # same seed, so the interval over episodes comes out as it was).
    first, second = records
    return asdict(paired_gap(first, second, seed=int(results.get("protocol", {}).get("seed", 0))))


def lacks_scene_interval(gap: dict[str, Any]) -> bool:
    """Whether a stored gap (as JSON) is from before the interval over scenes: it has several
    scenes but no ``scene_low`` (a gap over one scene has none to give)."""
    return gap.get("scene_low") is None and len(gap.get("per_scene", [])) >= 2
