"""The seeds of per-view sensor noise: grid views by index, poses off the grid by the pose itself."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from davis_ag.seeds import derived_seed, view_noise_seed

coordinate = st.floats(-1e3, 1e3, allow_nan=False)
poses = st.tuples(coordinate, coordinate, coordinate, st.floats(-360, 360), st.floats(-90, 90))


@given(st.integers(0, 2**31), st.integers(0, 100_000), poses)
def test_a_grid_view_is_seeded_by_its_index_alone(noise_seed: int, index: int, pose: tuple) -> None:
    assert view_noise_seed(noise_seed, index, pose) == derived_seed(noise_seed, index)


@given(st.integers(0, 2**31), poses, poses)
def test_a_pose_off_the_grid_always_draws_its_own_noise(noise_seed: int, pose: tuple, other: tuple) -> None:
    seed = view_noise_seed(noise_seed, -1, pose)
    assert 0 <= seed < 2**32
    assert view_noise_seed(noise_seed, -1, [float(v) for v in pose]) == seed  # a list, read back: the same
    if max(abs(a - b) for a, b in zip(pose, other)) > 1e-5:
        assert view_noise_seed(noise_seed, -1, other) != seed


def test_minus_zero_is_zero() -> None:
    assert view_noise_seed(7, -1, (0.0, -0.0, 1.0, 0.0, -0.0)) == view_noise_seed(7, -1, (0.0, 0.0, 1.0, 0.0, 0.0))
