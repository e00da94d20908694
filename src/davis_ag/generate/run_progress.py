"""What a dataset run reports as it goes: its options, its outcome, progress bars and failures.

Shared by the runner and its executors (local pool, Ray), which receive these objects from the
runner and never import it.
"""

from __future__ import annotations

import os
import sys
import time
import traceback
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

import numpy as np
from tqdm import tqdm

from davis_ag.errors import MachineError, UserError
from davis_ag.generate.one_scene import SceneRequest
from davis_ag.scene.scene_size import MEMORY_SHARE, scene_bytes
from davis_ag.scene.specs import CropSpec, ScenarioSpec
from davis_ag.scene.view_grid import build_view_grid

#: Memory one scene process may need at most (a multi-plant vine scene), bytes.
WORKER_MEMORY = 3 * 2**30
#: How often a scene whose worker process died is tried again.
DEFAULT_MAX_RETRIES = 2


def default_workers(requests: Sequence[SceneRequest] = ()) -> int:
    """Scene processes for this machine: one per core, as far as memory allows.

    Measured on 2 cores (docs/performance.md): two processes drawing with one Mesa thread each
    made 1.90 views/s, one process with two Mesa threads 1.61 (llvmpipe's threads leave part of
    each frame serial), and plant growth, single-threaded, only overlaps across processes.

    Args:
        requests: The scenes to make: where the largest needs more than :data:`WORKER_MEMORY`
            (:func:`davis_ag.scene.scene_size.scene_bytes`; a cherry-tomato row peaks near 18 GB),
            only as many processes as fit the share of memory one scene may take.
    """
    cores = os.cpu_count() or 1
    try:
        memory = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError):
        return cores
    largest = max((scene_bytes(r.scenario, r.crop) for r in requests), default=0)
    if largest > WORKER_MEMORY:  # a large scene: its processes share what one scene may take
        return max(1, min(cores, int(MEMORY_SHARE * memory) // largest))
    return max(1, min(cores, memory // WORKER_MEMORY))


@dataclass(frozen=True)
class RunOptions:
    """How to run the scenes.

    Attributes:
        workers: Local scene processes; 1 draws in this process.
        executor: ``local`` (this machine) or ``ray`` (an existing Ray cluster).
        address: Ray cluster address (``auto``, ``ray://head:10001``); None starts or finds one.
        cpus_per_scene: Ray only: CPUs each scene task reserves, also its Mesa thread count.
        max_retries: Tries after the first for a scene whose worker process died.
        progress: Show progress bars and one line per finished scene.
    """

    workers: int = field(default_factory=lambda: default_workers())
    executor: str = "local"
    address: str | None = None
    cpus_per_scene: int = 1
    max_retries: int = DEFAULT_MAX_RETRIES
    progress: bool = True


@dataclass
class RunReport:
    """What a run did.

    Attributes:
        root: The dataset folder.
        made: Scene ids made by this run.
        skipped: Scene ids that were already complete.
        failed: Scene id to error message.
        machine_failed: The failed scenes whose failure was the machine's (a full disk, a lost mount).
        splits: splits.json, when written.
        stats: Scene id to the timing statistics of each scene made by this run.
    """

    root: Path
    made: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)
    machine_failed: set[str] = field(default_factory=set)
    splits: Path | None = None
    stats: dict[str, dict] = field(default_factory=dict)


# ---------------------------------------------------------------------------------------------
# Progress


@cache
def count_views(scenario: ScenarioSpec, crop: CropSpec) -> int:
    """Views of every scene of a scenario and crop (exclusion uses the nominal grid, not slip)."""
    from davis_ag.scene.specs import plant_centres

    grid = build_view_grid(
        scenario, crop, plant_centres(scenario, crop), crop.plant_height / 2, np.random.default_rng(0)
    )
    return len(grid.viewpoints)


#: Seconds between progress lines when stderr is not a terminal (a log file, CI).
LOG_INTERVAL_S = 60.0


class Progress:
    """A scenes bar and a views bar (with the time left), fed by events from any executor.

    Events are tuples ``("start", scene_id[, pid])`` and ``("view", scene_id, done, total)``. When
    stderr is not a terminal there are no bars (a bar redrawn per view floods a log): a line per
    finished scene, and one every :data:`LOG_INTERVAL_S` seconds with the views done and the
    time left.

    Args:
        todo: The scenes to make.
        enabled: False hides the bars and the per-scene lines.
    """

    def __init__(self, todo: Sequence[SceneRequest], enabled: bool) -> None:
        self.enabled = enabled
        total_views = sum(count_views(r.scenario, r.crop) for r in todo)
        self._log = enabled and not _is_terminal(sys.stderr)
        self._total_views = total_views
        self._done_views = 0
        self._started = self._last_line = time.monotonic()
        self._finished = 0
        disable = None if enabled else True  # None: no bars when stderr is not a terminal
        self.scenes = tqdm(
            total=len(todo), desc="scenes", unit="scene", position=0, disable=disable, dynamic_ncols=True
        )
        # The time left comes from this bar: views are the unit of work, scenes vary tenfold.
        self.views = tqdm(
            total=total_views,
            desc="views",
            unit="view",
            position=1,
            disable=disable,
            dynamic_ncols=True,
            smoothing=0.05,
        )
        self._counted: dict[str, int] = {}

    def event(self, event: tuple) -> None:
        """Apply one event."""
        kind, scene = event[0], event[1]
        if kind == "start":  # a scene (re)starts: views a dead try counted no longer count
            lost = self._counted.pop(scene, 0)
            self.views.update(-lost)
            self._done_views -= lost
            self._counted[scene] = 0
        elif kind == "view":
            done = int(event[2])
            self.views.update(done - self._counted.get(scene, 0))
            self._done_views += done - self._counted.get(scene, 0)
            self._counted[scene] = done
            if self._log and time.monotonic() - self._last_line >= LOG_INTERVAL_S:
                self._log_line()

    def _log_line(self) -> None:
        """One line with the views done and the time left (instead of a bar, in logs)."""
        now = time.monotonic()
        self._last_line = now
        done, total = self._done_views, max(self._total_views, 1)
        # Until a scene is finished the rate misses the plant growth of later scenes (or is all
        # growth): no estimate rather than a wild one.
        left = (now - self._started) * (total - done) / done if done > 0 and self._finished else None
        eta = f"{left / 60:.0f} min left" if left is not None else "time left known after the first scene"
        self.write(f"{done} of {total} views ({100 * done / total:.0f} %), {eta}")

    def finished(self, request: SceneRequest, stats: dict) -> None:
        """A scene is complete."""
        self.scenes.update(1)
        self._finished += 1
        self.write(
            f"{request.folder}: {stats['views']} views, grown in {stats['grow_s']:.1f} s, "
            f"{stats['views_s'] / max(stats['views'], 1):.3f} s per view"
        )

    def write(self, line: str, always: bool = False) -> None:
        """A line above the bars (``always``: even when progress is off)."""
        if self.enabled or always:
            tqdm.write(line, file=sys.stderr)

    def close(self) -> None:
        """Remove the bars."""
        self.views.close()
        self.scenes.close()


def _is_terminal(stream: object) -> bool:
    isatty = getattr(stream, "isatty", None)
    try:
        return bool(isatty and isatty())
    except (OSError, ValueError):  # a closed stream
        return False


def record_failure(report: RunReport, progress: Progress, request: SceneRequest, error: BaseException) -> None:
    """Note a failed scene; a traceback is shown for anything but a UserError or an OSError (a full
    disk, a lost mount: the machine, not a bug), which get one line."""
    message = str(error) if isinstance(error, UserError) else f"{type(error).__name__}: {error}"
    report.failed[request.folder] = message
    if isinstance(error, (OSError, MachineError)):
        report.machine_failed.add(request.folder)
    if not isinstance(error, (UserError, OSError)):
        progress.write("".join(traceback.format_exception(error)).rstrip(), always=True)
    progress.write(f"{request.folder}: failed: {message}", always=True)
