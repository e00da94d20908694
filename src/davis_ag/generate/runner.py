"""Make a whole dataset: lock the folder, skip finished scenes, run the rest, write splits.json.

A run is safe to kill at any moment and to start again with the same command:

- scenes are written atomically (:mod:`davis_ag.generate.scene_writer`), so a scene folder is whole or absent;
  finished scenes are skipped (:func:`davis_ag.generate.output_checks.check_scene_slot`) and what a killed run
  left of a scene (its hidden ``.NNN.partial`` folder) is resumed: the views it wrote are kept and
  only the rest are drawn, unless the request or the code changed, when it is cleared and redone;
- every scene is fully determined by its seed, so a resumed or redone scene equals the one an
  uninterrupted run writes;
- ``dataset.json`` (seed, image size, each group's grid) is written before any scene and checked
  on every later run, so one folder never mixes scenes made with different settings; temporary
  files a kill left beside it are removed under the lock;
- ``splits.json`` is written last, atomically, from the scenes on disk, so it is the same whether
  the dataset was made in one go or resumed (:mod:`davis_ag.generate.dataset_files`);
- ``<out>/.davis_ag.lock`` is held (``fcntl.flock``) for the whole run: a second run on the same
  folder stops at once with the first one's PID. The kernel drops the lock when its holder dies.

Scenes run one after the other in this process (``workers=1``), on a pool of local processes
(:mod:`davis_ag.generate.pool_executor`), or as Ray tasks on a cluster (:mod:`davis_ag.generate.ray_executor`);
see docs/performance.md for the measurements behind :func:`~davis_ag.generate.run_progress.default_workers`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from pathlib import Path

from davis_ag.atomic_files import PROBE_PREFIX, write_json_atomic
from davis_ag.errors import MachineError, UserError
from davis_ag.formats.layout import LOCK_FILE, ROOT_FILES
from davis_ag.formats.outputs import OutputLock
from davis_ag.generate.dataset_files import (
    DATASET_FILE,
    SPLITS_FILE,
    complete_scenes,
    dataset_settings,
    reconcile_settings,
    write_splits,
)
from davis_ag.generate.one_scene import SceneRequest, generate_scene
from davis_ag.generate.output_checks import check_drawn_like_the_rest, check_output_root, check_scene_slot
from davis_ag.generate.run_progress import (  # noqa: F401
    DEFAULT_MAX_RETRIES,
    Progress,
    RunOptions,
    RunReport,
    count_views,
    record_failure,
)
from davis_ag.scene.plants import require_native_helios
from davis_ag.scene.specs import parse_group_name

#: What :mod:`davis_ag.atomic_files` leaves if killed mid-write (``.NAME.tmp``, then renamed).
TEMPORARY_FILES = (f".{DATASET_FILE}.tmp", f".{SPLITS_FILE}.tmp")


# ---------------------------------------------------------------------------------------------
# The lock


class DatasetLock(OutputLock):
    """The output rule's lock (:class:`davis_ag.formats.outputs.OutputLock`) on
    ``<root>/.davis_ag.lock``, holding the owner's PID.

    Args:
        root: The dataset folder (must exist).
    """

    def __init__(self, root: Path) -> None:
        # The file stays (the folder's layout lists it; older runs kept it too).
        super().__init__(Path(root) / LOCK_FILE, "generated", remove=False)


# ---------------------------------------------------------------------------------------------
# Running


def run_dataset(requests: Sequence[SceneRequest], root: Path, options: RunOptions | None = None) -> RunReport:
    """Make every requested scene that is not complete yet, then write splits.json.

    Args:
        requests: The scenes (see :meth:`davis_ag.generate.run_config.DatasetConfig.requests`).
        root: The dataset folder; created if missing.
        options: Workers and executor (default: :class:`RunOptions`).

    Returns:
        The run's report (:class:`RunReport`).

    Raises:
        UserError: for an unusable folder, another run holding it, settings that differ from the
            scenes already there, or scenes that failed (the others are complete and kept).
    """
    if not requests:
        raise UserError("no scenes to make")
    options = options or RunOptions()
    if options.executor != "ray":  # Ray's drivers draw nothing; its workers check for themselves
        require_native_helios()  # before any scene, not as each scene's failure
    else:  # before the folder or dataset.json is made
        from davis_ag.generate.ray_executor import require_ray

        require_ray()
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
        if todo:  # scenes outside this run's list (--first, --only, another group) count too
            check_drawn_like_the_rest(root, todo[0], complete_scenes(root))
        write_json_atomic(root / DATASET_FILE, settings)
        progress = Progress(todo, options.progress)
        if report.skipped:
            progress.write(f"{len(report.skipped)} of {len(requests)} scenes already complete in {root}: skipped")
        try:
            if todo and options.executor == "ray":
                from davis_ag.generate.ray_executor import run_on_ray

                run_on_ray(todo, root, options, progress, report)
            elif todo and min(options.workers, len(todo)) <= 1:
                # One scene (or --workers 1): draw here, Mesa spreading each frame over every core.
                _run_here(todo, root, progress, report)
            elif todo:
                from davis_ag.generate.pool_executor import run_on_pool

                # No more processes than scenes, so the cores go to Mesa threads instead.
                pool = dataclasses.replace(options, workers=min(options.workers, len(todo)))
                run_on_pool(todo, root, pool, progress, report)
        finally:
            progress.close()
        # A scene made where this machine cannot see it (Ray workers without the shared folder
        # --out must be) would be left out of splits.json while the run said it was made.
        unseen = sorted(set(report.made) - set(complete_scenes(root)))
        if unseen:
            raise UserError(
                f"{len(unseen)} scene(s) were made where {root} cannot see them ({unseen[0]}, ...): "
                "--out must be a folder every Ray worker shares with this machine"
            )
        if report.failed:
            first, message = next(iter(report.failed.items()))
            # Exit status 1 when the machine failed every one of them (a full disk), 2 otherwise.
            kind = MachineError if set(report.failed) <= report.machine_failed else UserError
            raise kind(
                f"{len(report.failed)} of {len(todo)} scenes failed ({first}: {message}); the others "
                "are complete: run the same command again to retry the failed ones"
            )
        report.splits = write_splits(root, settings["seed"])
    return report


def _precheck(root: Path) -> None:
    """Refuse a folder we could damage before creating anything in it; our own temporary files,
    which a killed run may have left, are cleared later under the lock."""
    if root.is_dir() and not any(
        p.name not in ROOT_FILES
        and p.name not in TEMPORARY_FILES
        and not p.name.startswith(PROBE_PREFIX)
        and not (p.is_dir() and parse_group_name(p.name))
        for p in root.iterdir()
    ):
        return
    check_output_root(root)


def _run_here(todo: Sequence[SceneRequest], root: Path, progress: Progress, report: RunReport) -> None:
    """Scenes one after another in this process (Mesa spreads each draw over every core)."""
    for request in todo:
        progress.event(("start", request.folder))

        def on_view(done: int, total: int, scene: str = request.folder) -> None:
            progress.event(("view", scene, done, total))

        try:
            _, stats = generate_scene(request, root, on_view)
        except Exception as error:  # one bad scene must not stop the others
            record_failure(report, progress, request, error)
            continue
        report.made.append(request.folder)
        report.stats[request.folder] = stats
        progress.finished(request, stats)
