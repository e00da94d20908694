"""Make a whole dataset: lock the folder, skip finished scenes, run the rest, write splits.json.

A run is safe to kill at any moment and to start again with the same command:

- scenes are written atomically (:mod:`davis_ag.writer`), so a scene folder is whole or absent;
  finished scenes are skipped (:func:`davis_ag.generate.check_scene_slot`) and what a killed run
  left of a scene (its hidden ``.NNN.partial`` folder) is removed before the scene is redone;
- every scene is fully determined by its seed, so a redone scene equals the one that was lost;
- ``dataset.json`` (seed, image size, each group's grid) is written before any scene and checked
  on every later run, so one folder never mixes scenes made with different settings; temporary
  files a kill left beside it are removed under the lock;
- ``splits.json`` is written last, atomically, from the scenes on disk, so it is the same whether
  the dataset was made in one go or resumed (:mod:`davis_ag.dataset_files`);
- ``<out>/.davis_ag.lock`` is held (``fcntl.flock``) for the whole run: a second run on the same
  folder stops at once with the first one's PID. The kernel drops the lock when its holder dies.

Scenes run one after the other in this process (``workers=1``), on a pool of local processes
(:mod:`davis_ag.pool_executor`), or as Ray tasks on a cluster (:mod:`davis_ag.ray_executor`);
see docs/performance.md for the measurements behind :func:`default_workers`.
"""

from __future__ import annotations

import fcntl
import os
import sys
import traceback
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any, Sequence

import numpy as np
from tqdm import tqdm

from davis_ag.config import CropSpec, ScenarioSpec, parse_group_name
from davis_ag.dataset_files import DATASET_FILE, SPLITS_FILE, dataset_settings, reconcile_settings, write_splits
from davis_ag.errors import UserError
from davis_ag.plants import require_native_helios
from davis_ag.generate import (
    ROOT_EXTRAS,
    SceneRequest,
    check_output_root,
    check_scene_slot,
    generate_scene,
    remove_stale_partial,
)
from davis_ag.view_grid import build_view_grid
from davis_ag.writer import write_json

LOCK_FILE = ".davis_ag.lock"
#: What writer.write_json leaves if killed mid-write (it writes ``.NAME.tmp``, then renames).
TEMPORARY_FILES = (f".{DATASET_FILE}.tmp", f".{SPLITS_FILE}.tmp")
#: Memory one scene process may need at most (a multi-plant vine scene), bytes.
WORKER_MEMORY = 3 * 2**30
#: How often a scene whose worker process died is tried again.
DEFAULT_MAX_RETRIES = 2


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
        splits: splits.json, when written.
    """

    root: Path
    made: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)
    splits: Path | None = None


def default_workers() -> int:
    """Scene processes for this machine: one per core, as far as memory allows.

    Measured on 2 cores (docs/performance.md): two processes drawing with one Mesa thread each
    made 1.90 views/s, one process with two Mesa threads 1.61 (llvmpipe's threads leave part of
    each frame serial), and plant growth, single-threaded, only overlaps across processes.
    """
    cores = os.cpu_count() or 1
    try:
        memory = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError):
        return cores
    return max(1, min(cores, memory // WORKER_MEMORY))


# ---------------------------------------------------------------------------------------------
# The lock


class DatasetLock:
    """An exclusive, non-blocking ``flock`` on ``<root>/.davis_ag.lock`` holding the owner's PID.

    Args:
        root: The dataset folder (must exist).
    """

    def __init__(self, root: Path) -> None:
        self.path = Path(root) / LOCK_FILE
        self._fd: int | None = None

    def __enter__(self) -> "DatasetLock":
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "unknown"
            os.close(fd)
            raise UserError(f"{self.path.parent} is being generated by another davis-ag run (PID {holder}): "
                            "wait for it to end or choose another --out") from None
        except OSError as error:
            os.close(fd)
            raise UserError(f"cannot lock {self.path} ({error.strerror}): use a local folder for --out") from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        self._fd = fd
        return self

    def __exit__(self, *exc: object) -> None:
        # The file stays: deleting it would let a waiting run lock a file no longer linked.
        if self._fd is not None:
            os.close(self._fd)  # closing the only descriptor releases the flock
            self._fd = None


# ---------------------------------------------------------------------------------------------
# Progress


@lru_cache(maxsize=None)
def count_views(scenario: ScenarioSpec, crop: CropSpec) -> int:
    """Views of every scene of a scenario and crop (exclusion uses the nominal grid, not slip)."""
    from davis_ag.config import plant_centres

    grid = build_view_grid(scenario, crop, plant_centres(scenario, crop), crop.plant_height / 2,
                           np.random.default_rng(0))
    return len(grid.viewpoints)


class Progress:
    """A scenes bar and a views bar (with the time left), fed by events from any executor.

    Events are tuples ``("start", scene_id)`` and ``("view", scene_id, done, total)``.

    Args:
        todo: The scenes to make.
        enabled: False hides the bars and the per-scene lines.
    """

    def __init__(self, todo: Sequence[SceneRequest], enabled: bool) -> None:
        self.enabled = enabled
        total_views = sum(count_views(r.scenario, r.crop) for r in todo)
        disable = None if enabled else True  # None: no bars when stderr is not a terminal
        self.scenes = tqdm(total=len(todo), desc="scenes", unit="scene", position=0, disable=disable,
                           dynamic_ncols=True)
        # The time left comes from this bar: views are the unit of work, scenes vary tenfold.
        self.views = tqdm(total=total_views, desc="views", unit="view", position=1, disable=disable,
                          dynamic_ncols=True, smoothing=0.05)
        self._counted: dict[str, int] = {}

    def event(self, event: tuple) -> None:
        """Apply one event."""
        kind, scene = event[0], event[1]
        if kind == "start":  # a scene (re)starts: views a dead try counted no longer count
            self.views.update(-self._counted.pop(scene, 0))
            self._counted[scene] = 0
        elif kind == "view":
            done = int(event[2])
            self.views.update(done - self._counted.get(scene, 0))
            self._counted[scene] = done

    def finished(self, request: SceneRequest, stats: dict) -> None:
        """A scene is complete."""
        self.scenes.update(1)
        self.write(f"{request.folder}: {stats['views']} views, grown in {stats['grow_s']:.1f} s, "
                   f"{stats['views_s'] / max(stats['views'], 1):.3f} s per view")

    def write(self, line: str, always: bool = False) -> None:
        """A line above the bars (``always``: even when progress is off)."""
        if self.enabled or always:
            tqdm.write(line, file=sys.stderr)

    def close(self) -> None:
        """Remove the bars."""
        self.views.close()
        self.scenes.close()


# ---------------------------------------------------------------------------------------------
# Running


def run_dataset(requests: Sequence[SceneRequest], root: Path, options: RunOptions | None = None) -> RunReport:
    """Make every requested scene that is not complete yet, then write splits.json.

    Args:
        requests: The scenes (see :meth:`davis_ag.dataset_config.DatasetConfig.requests`).
        root: The dataset folder; created if missing.
        options: Workers and executor (default: :class:`RunOptions`).

    Returns:
        The :class:`RunReport`.

    Raises:
        UserError: for an unusable folder, another run holding it, settings that differ from the
            scenes already there, or scenes that failed (the others are complete and kept).
    """
    if not requests:
        raise UserError("no scenes to make")
    options = options or RunOptions()
    if options.executor != "ray":  # Ray's drivers draw nothing; its workers check for themselves
        require_native_helios()  # before any scene, not as each scene's failure
    root = Path(root).expanduser().absolute()
    _precheck(root)
    root.mkdir(parents=True, exist_ok=True)
    report = RunReport(root)
    with DatasetLock(root):
        for name in TEMPORARY_FILES:  # left by a run killed while writing them
            (root / name).unlink(missing_ok=True)
        check_output_root(root)
        settings = reconcile_settings(root, dataset_settings(requests))
        todo = []
        for request in requests:
            if check_scene_slot(root, request):
                report.skipped.append(request.folder)
            else:
                todo.append(request)
        write_json(root / DATASET_FILE, settings)
        for request in todo:
            remove_stale_partial(root, request)
        progress = Progress(todo, options.progress)
        if report.skipped:
            progress.write(f"{len(report.skipped)} of {len(requests)} scenes already complete in {root}: skipped")
        try:
            if todo and options.executor == "ray":
                from davis_ag.ray_executor import run_on_ray

                run_on_ray(todo, root, options, progress, report)
            elif todo and options.workers <= 1:
                _run_here(todo, root, progress, report)
            elif todo:
                from davis_ag.pool_executor import run_on_pool

                run_on_pool(todo, root, options, progress, report)
        finally:
            progress.close()
        if report.failed:
            first, message = next(iter(report.failed.items()))
            raise UserError(f"{len(report.failed)} of {len(todo)} scenes failed ({first}: {message}); the others "
                            "are complete: run the same command again to retry the failed ones")
        report.splits = write_splits(root, settings["seed"])
    return report


def _precheck(root: Path) -> None:
    """Refuse a folder we could damage before creating anything in it; our own temporary files,
    which a killed run may have left, are cleared later under the lock."""
    if root.is_dir() and not any(p.name not in ROOT_EXTRAS and p.name not in TEMPORARY_FILES
                                 and not (p.is_dir() and parse_group_name(p.name)) for p in root.iterdir()):
        return
    check_output_root(root)


def record_failure(report: RunReport, progress: Progress, request: SceneRequest, error: BaseException) -> None:
    """Note a failed scene; a traceback is shown for anything but a UserError (a bug, not bad input)."""
    message = str(error) if isinstance(error, UserError) else f"{type(error).__name__}: {error}"
    report.failed[request.folder] = message
    if not isinstance(error, UserError):
        progress.write("".join(traceback.format_exception(error)).rstrip(), always=True)
    progress.write(f"{request.folder}: failed: {message}", always=True)


def _run_here(todo: Sequence[SceneRequest], root: Path, progress: Progress, report: RunReport) -> None:
    """Scenes one after another in this process (Mesa spreads each draw over every core)."""
    for request in todo:
        progress.event(("start", request.folder))
        try:
            _, stats = generate_scene(request, root, lambda done, total, scene=request.folder:
                                      progress.event(("view", scene, done, total)))
        except Exception as error:  # one bad scene must not stop the others
            record_failure(report, progress, request, error)
            continue
        report.made.append(request.folder)
        progress.finished(request, stats)
