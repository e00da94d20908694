"""Helios's OpenMP runtime on one thread: the same scene, grown without a team of threads."""

from __future__ import annotations

import hashlib
import threading

import numpy as np
import pytest

from davis_ag.scene import build
from davis_ag.scene.build import build_scene
from davis_ag.scene.helios_threads import _helios_openmp, helios_threads, one_helios_thread
from davis_ag.scene.plant_geometry import primitive_vertices
from davis_ag.scene.specs import CROPS, scenario_spec


def _scene_digest(crop: str) -> str:
    """Every primitive's vertices and every fruit's primitives of the crop's scene 0, seed 3."""
    model = build_scene(scenario_spec("sp", CROPS[crop]), CROPS[crop], np.random.default_rng(3))
    digest = hashlib.sha256()
    uuids = list(model.context.getAllUUIDs())
    for vertices in primitive_vertices(model.context, uuids):
        digest.update(vertices.tobytes())
    for fruit in model.fruits:
        digest.update(np.asarray(sorted(fruit.uuids), dtype=np.int64).tobytes())
    return digest.hexdigest()


def _in_another_thread() -> list[int]:
    answer: list[list[int]] = []
    thread = threading.Thread(target=lambda: answer.append(helios_threads()))
    thread.start()
    thread.join()
    return answer[0]


def test_the_wheels_openmp_runtime_is_set_to_one_thread_for_the_calling_thread_only() -> None:
    runtimes = len(_helios_openmp())
    assert runtimes >= 1, "pyhelios3d's wheel bundles libgomp: the limit would reach nothing"
    _helios_openmp()[0].omp_set_num_threads(2)
    assert helios_threads() == [2] * runtimes
    elsewhere = _in_another_thread()
    assert one_helios_thread() == runtimes
    assert helios_threads() == [1] * runtimes
    # OpenMP keeps the number per thread: every thread that grows plants sets its own.
    assert _in_another_thread() == elsewhere


@pytest.mark.parametrize("crop", ["capsicum", "strawberry"])
def test_a_team_of_threads_grows_the_same_scene_to_the_byte(crop: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """One thread is only faster: a plant-library crop and a Canopy Generator crop come out the same
    as with a team of two threads (the parallel loops run even on a 1-core machine)."""
    one = _scene_digest(crop)

    def team_of_two() -> int:
        for runtime in _helios_openmp():
            runtime.omp_set_num_threads(2)
        return len(_helios_openmp())

    monkeypatch.setattr(build, "one_helios_thread", team_of_two)
    assert _scene_digest(crop) == one
    assert helios_threads() == [2] * len(_helios_openmp())
