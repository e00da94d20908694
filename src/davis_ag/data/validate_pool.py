"""Scenes checked in a pool of processes: one task per scene in a spawned process, the results
back in scene order, so :func:`davis_ag.data.validate.validate_dataset` reports the same for any
number of processes. Decoding the images is the cost of validating, and it scales with the cores.
"""

from __future__ import annotations

import multiprocessing
import signal
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from typing import Any, TypeVar

from davis_ag.data.reader import ANNOTATIONS, Scene

#: A pool of processes pays for its start (about a second each) from this many bytes of
#: annotations.json on (about 700 views, 20 s of checks in one process at 1280x720).
POOL_FROM_BYTES = 500_000

Result = TypeVar("Result")


@contextmanager
def in_scene_order(
    check: Callable[[Any], Result], tasks: list[Any], scenes: list[Scene], workers: int
) -> Iterator[Iterator[Result]]:
    """``check(task)`` for each scene's task, in scene order: in a pool of ``workers`` processes
    where the scenes' annotations are large enough to repay its start, else here, one by one.

    Args:
        check: A module-level function (it is sent to the pool's processes by name).
        tasks: One picklable task per scene, in the order of ``scenes``.
        scenes: The scenes, to size the work.
        workers: Processes at most.
    """
    if workers < 2 or len(scenes) < 2 or _annotation_bytes(scenes) < POOL_FROM_BYTES:
        yield (check(task) for task in tasks)
        return
    # spawn: the caller may hold threads and GL contexts (reproduce), which fork would copy.
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(min(workers, len(scenes)), mp_context=context, initializer=_ignore_ctrl_c) as pool:
        yield pool.map(check, tasks)


def _ignore_ctrl_c() -> None:
    # Ctrl-C reaches the whole process group: the parent stops the run, a worker would only
    # print a traceback.
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _annotation_bytes(scenes: list[Scene]) -> int:
    total = 0
    for scene in scenes:
        try:
            total += (scene.path / ANNOTATIONS).stat().st_size
        except OSError:  # the validation reports it
            pass
    return total
