"""Run scenes as Ray tasks on an existing cluster: one task per scene, retried if its worker dies.

Ray is imported only here, and this module only when ``--executor ray`` is asked for. Every
machine of the cluster needs the same Python environment (davis-ag and pyhelios3d installed) and
must see the output folder at the same path (a shared file system): each task writes its scene
there atomically, exactly as a local run does, and the driver keeps the folder's lock.
"""

from __future__ import annotations

import logging
import signal
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from davis_ag.errors import UserError
from davis_ag.generate.one_scene import SceneRequest, generate_scene
from davis_ag.generate.run_progress import (
    Progress,
    RunOptions,
    RunReport,
    record_failure,
)


class ProgressBox:
    """A tiny Ray actor collecting progress events from scene tasks until the driver takes them."""

    def __init__(self) -> None:
        self.events: list[tuple] = []

    def put(self, event: tuple) -> None:
        """Add an event."""
        self.events.append(event)

    def take(self) -> list[tuple]:
        """Every event since the last call."""
        events, self.events = self.events, []
        return events


def ray_scene(request: SceneRequest, root: str, box: Any) -> dict:
    """The body of one scene task: make the scene, reporting progress to the driver's actor.

    Args:
        request: The scene.
        root: The dataset folder, at the same path on every machine.
        box: The :class:`ProgressBox` actor handle.

    Returns:
        The scene's timing statistics.
    """
    scene = request.folder
    box.put.remote(("start", scene))
    last = [0.0]

    def on_view(done: int, total: int) -> None:
        now = time.monotonic()
        if now - last[0] > 0.25 or done == total:  # each event is a remote call: keep them few
            last[0] = now
            box.put.remote(("view", scene, done, total))

    _, stats = generate_scene(request, Path(root), on_view)
    return stats


def require_ray() -> None:
    """Refuse ``--executor ray`` where Ray is not installed, before anything is written.

    Raises:
        UserError: saying how to install it.
    """
    import importlib.util

    try:
        found = importlib.util.find_spec("ray") is not None
    except (ImportError, ValueError):  # a broken or shadowed installation
        found = False
    if not found:
        raise UserError("--executor ray needs Ray: pip install 'davis-ag[ray]' (on every machine of the cluster)")


def connect(address: str | None):
    """Import Ray and join the cluster (or start a local one when no address is given).

    Returns:
        The ``ray`` module and whether this call started Ray (and so must shut it down).

    Raises:
        UserError: when Ray is missing or the cluster cannot be reached.
    """
    try:
        import ray
    except ImportError:
        raise UserError(
            "--executor ray needs Ray: pip install 'davis-ag[ray]' (on every machine of the cluster)"
        ) from None
    if ray.is_initialized():
        return ray, False
    # ray.init puts its own SIGTERM handler (sys.exit(15)) in place of the command line's, which
    # turns a stop into Stopped: keep ours, so a stopped run says what it kept and exits 143.
    handlers = {number: signal.getsignal(number) for number in (signal.SIGTERM, signal.SIGINT)}
    try:
        # Without --address, a new local instance (as docs/generating.md says), never the cluster
        # that /tmp/ray/ray_current_cluster or RAY_ADDRESS happens to name: --address auto joins it.
        ray.init(address=address or "local", log_to_driver=False, logging_level=logging.WARNING)
    except Exception as error:  # ConnectionError, ValueError, RuntimeError depending on the address
        where = address or "a new local instance"
        reason = (str(error).splitlines() or [type(error).__name__])[0].rstrip(".")
        raise UserError(
            f"cannot start or reach Ray at {where}: {reason}; "
            "start the cluster with `ray start --head` and pass --address auto or ray://HEAD:10001"
        ) from None
    finally:
        if threading.current_thread() is threading.main_thread():
            for number, handler in handlers.items():
                if handler is not None:  # None: set outside Python, nothing to put back
                    signal.signal(number, handler)
    return ray, True


def run_on_ray(
    todo: Sequence[SceneRequest], root: Path, options: RunOptions, progress: Progress, report: RunReport
) -> None:
    """Make scenes as Ray tasks; fills ``report.made`` and ``report.failed``.

    Args:
        todo: The scenes.
        root: The dataset folder (absolute, shared by every machine).
        options: ``address``, ``cpus_per_scene`` and ``max_retries`` are used.
        progress: Bars to feed.
        report: What happened.

    Raises:
        UserError: when Ray is missing, unreachable, or no machine has ``cpus_per_scene`` CPUs.
    """
    ray, started_here = connect(options.address)
    refs: dict[Any, SceneRequest] = {}
    try:
        biggest = max((node["Resources"].get("CPU", 0) for node in ray.nodes() if node.get("Alive")), default=0)
        if biggest < options.cpus_per_scene:
            raise UserError(
                f"no machine of the Ray cluster has {options.cpus_per_scene} CPUs for a scene "
                f"(the largest has {biggest:g}): lower --cpus-per-scene"
            )
        box = ray.remote(num_cpus=0)(ProgressBox).remote()
        # Mesa reads LP_NUM_THREADS when the worker process makes its GL context: one rasteriser
        # thread per CPU the task reserved.
        task = ray.remote(ray_scene).options(
            num_cpus=options.cpus_per_scene,
            max_retries=options.max_retries,
            retry_exceptions=False,
            runtime_env={"env_vars": {"LP_NUM_THREADS": str(options.cpus_per_scene)}},
        )
        refs = {task.remote(request, str(root), box): request for request in todo}
        while refs:
            ready, _ = ray.wait(list(refs), num_returns=len(refs), timeout=0.5, fetch_local=False)
            for event in ray.get(box.take.remote()):
                progress.event(event)
            for ref in ready:
                request = refs.pop(ref)
                try:
                    stats = ray.get(ref)
                except ray.exceptions.RayTaskError as error:  # the scene itself raised
                    cause = getattr(error, "cause", None)
                    record_failure(report, progress, request, cause if isinstance(cause, Exception) else error)
                except ray.exceptions.RayError as error:  # its worker or machine died, tries used up
                    record_failure(
                        report,
                        progress,
                        request,
                        UserError(f"its Ray worker died {options.max_retries + 1} times ({type(error).__name__})"),
                    )
                else:
                    report.made.append(request.folder)
                    report.stats[request.folder] = stats
                    progress.finished(request, stats)
    except BaseException:
        for ref in refs:  # a killed task leaves only a hidden partial folder, resumed next run
            ray.cancel(ref, force=True)
        raise
    finally:
        if started_here:
            ray.shutdown()
