"""``davis-ag bench --only sharing``: two trainings on one machine, as issue 59's runs go (a
search beside a Table 4 run, on 2 cores), each with torch's own thread count and each with its
share of the cores (``--torch-threads``), beside one training alone.

Each training is A2C (ours) on the paper's network, 8 environments, on the same three
single-plant strawberry scenes as the learners' table (:mod:`davis_ag.workflows.bench.training`),
in a process of its own; the processes of a row start their timed steps together (a barrier,
after torch's import and a warm-up), so each row times the cores shared the whole time. The
rows come one after the other in this bench, so their ratios to the first hold on a machine
whose absolute rates move with its load.
"""

from __future__ import annotations

import multiprocessing
import os
import queue
import time
from functools import partial
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import write_marked_section
from davis_ag.workflows.bench.report import doc_section
from davis_ag.workflows.bench.training import SEED, STEPS, training_scenes

#: How long a row may take before the bench gives up on it (a stuck process).
ROW_TIMEOUT_S = 3600


def _trainer(arch: str) -> Any:
    """``train_agent`` as every training of this bench runs it: A2C (ours), 8 environments, no
    checkpoints or snapshot scores, quiet."""
    from davis_ag.benchmark.training import train_agent

    return partial(train_agent, seed=SEED, n_envs=8, arch=arch, checkpoint_every=0, keep="last", progress=False)


def _timed_training(
    root: Path, out: Path, threads: int | None, steps: int, arch: str, barrier: Any, rates: Any
) -> None:
    """One process of a row: warm up, wait for the others, train ``steps`` steps, report the rate."""
    import torch

    if threads is not None:
        torch.set_num_threads(threads)
    train = _trainer(arch)
    train(root, "sp", total_timesteps=8, out_path=out.with_suffix(".warm.zip"))
    barrier.wait()
    started = time.perf_counter()
    train(root, "sp", total_timesteps=steps, out_path=out)
    rates.put((steps / (time.perf_counter() - started), torch.get_num_threads()))


def _row(
    root: Path, scratch: Path, name: str, processes: int, threads: int | None, steps: int, arch: str
) -> dict[str, Any]:
    """Time ``processes`` trainings at once, each with ``threads`` torch threads (None: torch's own)."""
    from davis_ag.errors import MachineError

    context = multiprocessing.get_context("spawn")
    barrier, rates = context.Barrier(processes), context.Queue()
    workers = [
        context.Process(
            target=_timed_training, args=(root, scratch / f"{name}-{i}.zip", threads, steps, arch, barrier, rates)
        )
        for i in range(processes)
    ]
    for worker in workers:
        worker.start()
    results: list[tuple[float, int]] = []
    deadline = time.monotonic() + ROW_TIMEOUT_S
    try:
        while len(results) < processes:
            try:
                results.append(rates.get(timeout=1))
            except queue.Empty:
                # A process that died (its error is on stderr) would leave the others at the barrier.
                if any(w.exitcode not in (None, 0) for w in workers) or time.monotonic() > deadline:
                    raise MachineError(
                        f"bench --only sharing: a training of the row {name!r} failed (its process printed why above)"
                    ) from None
    finally:
        for worker in workers:
            if len(results) < processes:
                worker.kill()
            worker.join()
    each = sorted(rate for rate, _ in results)
    return {
        "processes": processes,
        "torch_threads": results[0][1],
        "steps_per_second_each": [round(rate, 1) for rate in each],
        "steps_per_second": round(sum(each), 1),
    }


def sharing_speed(scratch: Path, steps: int = STEPS, arch: str = "paper", root: Path | None = None) -> dict[str, Any]:
    """One training alone, then two at once with torch's own thread count, then two at once with
    half the cores each.

    Args:
        scratch: A folder for the scenes and models.
        steps: Steps each training is timed for.
        arch: The network (tests: a small one).
        root: A dataset with SP strawberry scenes (default: the learners' table's three, made here).

    Returns:
        ``{"steps", "seed", "cpus", "rows": {row: {"processes", "torch_threads",
        "steps_per_second_each", "steps_per_second", "over_alone"}}}``; ``steps_per_second`` is the
        rows' processes together.
    """
    root = root or training_scenes(scratch / "training")
    # Builds the observation cache once, before any row (the rows' processes then only read it).
    _trainer(arch)(root, "sp", total_timesteps=8, out_path=scratch / "cache.zip")
    share = max(1, (os.cpu_count() or 1) // 2)
    rows = {
        "one training alone, torch's threads": _row(root, scratch, "alone", 1, None, steps, arch),
        "two at once, torch's threads each": _row(root, scratch, "own", 2, None, steps, arch),
        "two at once, half the cores each (--torch-threads)": _row(root, scratch, "share", 2, share, steps, arch),
    }
    alone = next(iter(rows.values()))["steps_per_second"]
    for row in rows.values():
        row["over_alone"] = round(row["steps_per_second"] / alone, 2)
    return {"steps": steps, "seed": SEED, "cpus": os.cpu_count(), "rows": rows}


def sharing_table(result: dict[str, Any], load: tuple[float, float]) -> str:
    """The rows as Markdown, with what they mean for two runs on one machine."""
    rows = result["rows"]
    lines = [
        f"A2C (ours) on the paper's network, 8 environments, {result['steps']:,} timed steps in each process "
        f"on three single-plant strawberry scenes (seed {result['seed']}); the rows one after the other, the "
        f"processes of a row started together; load average {load[0]:.2f} at the start, {load[1]:.2f} at "
        f"the end, {result['cpus']} CPUs.",
        "",
        "| how | processes | torch threads each | steps/s each | steps/s together | against one alone |",
        "|---|---|---|---|---|---|",
    ]
    for name, r in rows.items():
        each = ", ".join(str(rate) for rate in r["steps_per_second_each"])
        lines.append(
            f"| {name} | {r['processes']} | {r['torch_threads']} | {each} | **{r['steps_per_second']}** "
            f"| {r['over_alone']:.2f}x |"
        )
    own, share = list(rows.values())[1:]
    lines += [
        "",
        f"Two trainings sharing the machine train {share['steps_per_second'] / own['steps_per_second']:.2f} times "
        f"as fast together on half the cores each as on torch's own count each ({share['steps_per_second']} "
        f"steps/s against {own['steps_per_second']}).",
    ]
    return "\n".join(lines)


def write_sharing(
    result: dict[str, Any], load: tuple[float, float], doc: Path | None, gpu_machine: bool = False
) -> None:
    """Write the table into the doc's ``bench-sharing`` section (its GPU section on a GPU machine)."""
    if doc:
        write_marked_section(doc, doc_section("bench-sharing", gpu_machine), sharing_table(result, load))
