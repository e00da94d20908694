"""Run scenes on a pool of local processes, each making whole scenes with one share of the cores.

Processes rather than Mesa threads: on the 2-core machines measured (docs/performance.md) two
processes drawing with one llvmpipe thread each made 1.90 views/s against 1.61 for one process
with two threads, and plant growth, which is single-threaded, only overlaps across processes.
Each process sets LP_NUM_THREADS to its share of the cores before Mesa starts, and dies with the
run (Linux), so a killed run leaves no process writing into the dataset.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import multiprocessing
import os
import signal
import sys
import time
from collections.abc import Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Any

from davis_ag.errors import UserError, stops_held
from davis_ag.generate.one_scene import SceneRequest, generate_scene
from davis_ag.generate.run_progress import (
    Progress,
    RunOptions,
    RunReport,
    record_failure,
)


def mesa_threads(workers: int) -> int | None:
    """LP_NUM_THREADS for each of ``workers`` processes: the cores shared out (one each with the
    default workers), or None to keep what the user set."""
    if "LP_NUM_THREADS" in os.environ:
        return None
    return max(1, (os.cpu_count() or 1) // workers)


def run_on_pool(
    todo: Sequence[SceneRequest], root: Path, options: RunOptions, progress: Progress, report: RunReport
) -> None:
    """Scenes on a pool of ``options.workers`` processes, each making whole scenes.

    Args:
        todo: The scenes.
        root: The dataset folder.
        options: ``workers`` and ``max_retries`` are used.
        progress: Bars to feed.
        report: Filled with the scenes made and failed.

    A scene whose process died (the pool breaks) is tried again on a fresh pool, up to
    ``options.max_retries`` times; scenes that were only queued, or whose process the pool ended
    because another one died, do not count a try.
    """
    # spawn, not fork: a forked child would share the parent's state of native libraries.
    context = multiprocessing.get_context("spawn")
    tries: dict[str, int] = {}
    pending = list(todo)
    while pending:
        started: dict[str, int | None] = {}  # scene -> the pid of the process drawing it
        culprits: set[int] | None = None  # processes that died on their own, once the pool broke
        # A fresh queue per pool: a process killed while writing may leave a queue's lock held.
        events = context.Queue()
        pool = ProcessPoolExecutor(
            options.workers,
            mp_context=context,
            initializer=_init_worker,
            initargs=(events, mesa_threads(options.workers), os.getpid()),
        )
        try:
            # A stop mid-spawn would cut a child's start short (its traceback on stderr): it waits
            # until the children are started, then ends them below like any stop.
            with stops_held():
                futures = {pool.submit(_pool_scene, request, str(root)): request for request in pending}
            pending = []
            while futures:
                done, _ = wait(futures, timeout=0.25, return_when=FIRST_COMPLETED)
                _drain(events, progress, started)
                for future in done:
                    request = futures.pop(future)
                    try:
                        stats = future.result()
                    except BrokenProcessPool as error:
                        if culprits is None:
                            culprits = _died_on_their_own(pool)
                        pid = started.get(request.folder)
                        if request.folder not in started or (culprits and pid not in culprits):
                            # Only queued, or ended by the pool because a sibling died: no try spent.
                            pending.append(request)
                        elif tries.setdefault(request.folder, 0) < options.max_retries:
                            tries[request.folder] += 1
                            progress.write(f"{request.folder}: its worker process died; trying again")
                            pending.append(request)
                        else:
                            record_failure(
                                report,
                                progress,
                                request,
                                UserError(f"its worker process died {options.max_retries + 1} times ({error})"),
                            )
                    except Exception as error:
                        record_failure(report, progress, request, error)
                    else:
                        report.made.append(request.folder)
                        report.stats[request.folder] = stats
                        progress.finished(request, stats)
            _drain(events, progress, started)
        except BaseException:
            # Ctrl-C or a bug here: stop the scenes now rather than wait for them (what they
            # leave is a hidden partial folder, resumed by the next run).
            for process in list(getattr(pool, "_processes", {}).values()):
                process.kill()
            raise
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
            events.close()  # its feeder thread and semaphores go with it: no leaked-resource warning
            events.join_thread()


def _drain(events: Any, progress: Progress, started: dict[str, int | None]) -> None:
    while True:
        try:
            event = events.get_nowait()
        except Exception:  # queue.Empty, or the queue of a dead pool
            return
        if event[0] == "start":
            started[event[1]] = event[2] if len(event) > 2 else None
        progress.event(event)


def _died_on_their_own(pool: ProcessPoolExecutor) -> set[int]:
    """The pids of a broken pool's processes that ended by themselves (killed for memory, a
    crash), not by the SIGTERM the pool then sends every other worker: only their scenes spend
    a try. Empty when none can be told apart (every scene running then spends one, as before)."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    for process in processes:
        process.join(5)
    return {
        process.pid
        for process in processes
        if process.pid is not None and process.exitcode not in (None, -signal.SIGTERM)
    }


_EVENTS: Any = None


def _init_worker(events: Any, lp_threads: int | None, parent: int) -> None:
    """Set up a pool process: its event queue, Mesa's thread count, and death with its parent."""
    global _EVENTS
    _EVENTS = events
    # Ctrl-C reaches the whole process group: the parent decides, the workers would only print
    # tracebacks.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if lp_threads is not None:  # read by llvmpipe when the first GL context is made, later
        os.environ["LP_NUM_THREADS"] = str(lp_threads)
    die_with_parent(parent)


def die_with_parent(parent: int) -> None:
    """Ask Linux to kill this process when its parent dies (a killed run leaves no orphan writing
    into the dataset); elsewhere, do nothing."""
    if not sys.platform.startswith("linux"):
        return
    libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
    pr_set_pdeathsig = 1
    libc.prctl(pr_set_pdeathsig, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:  # the parent died before the request was made
        os._exit(1)


def _pool_scene(request: SceneRequest, root: str) -> dict:
    """Make one scene in a pool process, reporting progress on the event queue."""
    scene = request.folder
    _EVENTS.put(("start", scene, os.getpid()))
    last = [0.0]

    def on_view(done: int, total: int) -> None:
        now = time.monotonic()
        if now - last[0] > 0.1 or done == total:  # a few events a second are plenty for a bar
            last[0] = now
            _EVENTS.put(("view", scene, done, total))

    _, stats = generate_scene(request, Path(root), on_view)
    return stats
