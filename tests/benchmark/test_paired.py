"""The paired gap between two policies: its interval and per-scene gaps follow the episodes."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from davis_ag.benchmark.paired import a2c_against_best_fixed, paired_gap


def episodes(oer: list[float], scenes: list[str] | None = None) -> list[dict]:
    """Episode records as an evaluation writes them, one start per episode."""
    scenes = scenes or ["SP/000"] * len(oer)
    return [
        {"session": i % 3, "scene": s, "path": [f"{i:04d}.jpeg"], "target_fruit": i % 5, "oer_tau": v}
        for i, (v, s) in enumerate(zip(oer, scenes))
    ]


def test_a_policy_better_on_every_scene_has_an_interval_above_zero() -> None:
    rng = np.random.default_rng(1)
    base = rng.uniform(0.2, 0.5, 300)
    scenes = [f"SP/{i % 3:03d}" for i in range(300)]
    gap = paired_gap(episodes(list(base + 0.05 + rng.normal(0, 0.02, 300)), scenes), episodes(list(base), scenes))
    assert 0 < gap.low < gap.gap < gap.high < 0.1
    assert [s.scene for s in gap.per_scene] == ["SP/000", "SP/001", "SP/002"]
    assert all(s.gap > 0 and s.episodes == 100 for s in gap.per_scene)


def test_a_gap_owed_to_one_scene_shows_in_the_per_scene_gaps() -> None:
    scenes = ["SP/000"] * 50 + ["SP/001"] * 50
    gap = paired_gap(episodes([0.9] * 50 + [0.3] * 50, scenes), episodes([0.3] * 100, scenes))
    assert gap.gap == pytest.approx(0.3)
    assert [round(s.gap, 6) for s in gap.per_scene] == [0.6, 0.0]


def test_policies_that_agree_everywhere_have_a_point_interval_at_zero() -> None:
    gap = paired_gap(episodes([0.4] * 20), episodes([0.4] * 20))
    assert (gap.gap, gap.low, gap.high) == (0.0, 0.0, 0.0)


def test_episodes_that_are_not_the_same_are_refused() -> None:
    a, b = episodes([0.4, 0.5]), episodes([0.4, 0.5])
    b[1]["target_fruit"] += 1
    with pytest.raises(ValueError, match="same episodes"):
        paired_gap(a, b)
    with pytest.raises(ValueError, match="same episodes"):
        paired_gap(a, a[:1])
    with pytest.raises(ValueError, match="same episodes"):
        paired_gap([], [])


@settings(max_examples=30, deadline=None)
@given(
    st.lists(st.tuples(st.floats(0, 1), st.floats(0, 1), st.integers(0, 3)), min_size=2, max_size=60),
    st.integers(0, 2**16),
)
def test_the_gap_is_the_difference_of_means_and_lies_in_its_interval(rows: list, seed: int) -> None:
    first, second, scene = zip(*rows)
    scenes = [f"MP/{s:03d}" for s in scene]
    gap = paired_gap(episodes(list(first), scenes), episodes(list(second), scenes), seed=seed)
    assert gap.gap == pytest.approx(np.mean(first) - np.mean(second), abs=1e-12)
    assert gap.low <= gap.gap + 1e-12 and gap.gap <= gap.high + 1e-12
    assert sum(s.episodes for s in gap.per_scene) == gap.episodes == len(rows)
    # Scene gaps weighted by their episodes give back the overall gap; the same seed, the same interval.
    assert sum(s.gap * s.episodes for s in gap.per_scene) / gap.episodes == pytest.approx(gap.gap, abs=1e-9)
    again = paired_gap(episodes(list(first), scenes), episodes(list(second), scenes), seed=seed)
    assert (again.low, again.high, again.scene_low, again.scene_high) == (
        gap.low,
        gap.high,
        gap.scene_low,
        gap.scene_high,
    )
    # Resampled scenes average their gaps, so the interval over scenes lies within the scenes' own gaps.
    if len(gap.per_scene) < 2:
        assert gap.scene_low is gap.scene_high is None
    else:
        lowest, highest = min(s.gap for s in gap.per_scene), max(s.gap for s in gap.per_scene)
        assert lowest - 1e-9 <= gap.scene_low <= gap.scene_high <= highest + 1e-9


def test_a_gap_that_rests_on_one_scene_of_many_does_not_survive_resampling_the_scenes() -> None:
    # Ten scenes of 60 episodes: a gap of .3 on one scene and none on the others is sure over
    # episodes (600 of them) but not over scenes: another draw of ten scenes may leave it out.
    scenes = [f"SP/{i // 60:03d}" for i in range(600)]
    rng = np.random.default_rng(0)
    base = rng.uniform(0.2, 0.5, 600)
    better = base + np.where(np.arange(600) < 60, 0.3, 0.0) + rng.normal(0, 0.01, 600)
    gap = paired_gap(episodes(list(better), scenes), episodes(list(base), scenes))
    assert gap.low > 0  # over episodes: above zero
    assert gap.scene_low is not None and gap.scene_low <= 0.001 < gap.gap < gap.scene_high
    # The same gap spread over every scene survives either way.
    even = base + 0.03 + rng.normal(0, 0.01, 600)
    spread = paired_gap(episodes(list(even), scenes), episodes(list(base), scenes))
    assert spread.low > 0 and spread.scene_low > 0


def test_a_gap_stored_before_the_interval_over_scenes_gets_it_from_the_episodes() -> None:
    scenes = [f"SP/{i % 4:03d}" for i in range(40)]
    first, second = episodes([0.5 + i % 4 / 10 for i in range(40)], scenes), episodes([0.5] * 40, scenes)
    fresh = paired_gap(first, second)
    old = {k: v for k, v in fresh.__dict__.items() if not k.startswith("scene_")}  # as an older file kept it
    results = {
        "protocol": {"seed": 0},
        "policies": {
            "A2C": {"paired": {"Best fixed action": old}, "episodes": first},
            "Best fixed action": {"episodes": second},
        },
    }
    again = a2c_against_best_fixed(results)
    assert (again["low"], again["scene_low"], again["scene_high"]) == (fresh.low, fresh.scene_low, fresh.scene_high)
    # Without its episodes the stored gap is what there is.
    del results["policies"]["A2C"]["episodes"]
    assert a2c_against_best_fixed(results) is old
