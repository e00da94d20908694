"""The wall time of a long run's stages, summed over the sittings that worked on them.

A ``paper-scale`` run spans many sittings, and each one ends when its session is stopped: a stage's
time known only at its end would be lost with every sitting that did not reach it. The clock
therefore writes its file (``OUT/clock.json``) every minute while a stage runs, so a killed sitting
still counts up to its last minute, and its sittings add up to the stage's wall time, the time
redone after a kill included.
"""

from __future__ import annotations

import json
import re
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import write_json_atomic

#: The clock's file in a run's work folder.
CLOCK_FILE = "clock.json"
#: Seconds between the clock's writes while a stage runs: what a killed sitting may go uncounted.
WRITE_EVERY_S = 60.0


class Sitting:
    """One sitting's work on a stage; :meth:`discard` it when the stage found nothing to do."""

    def __init__(self) -> None:
        self.discarded = False

    def discard(self) -> None:
        """Leave this sitting out of the stage's time (everything it would do was done before)."""
        self.discarded = True


class StageClock:
    """Per stage, the wall seconds of every sitting that worked on it, kept in one JSON file."""

    def __init__(self, path: Path, code: str, every_s: float = WRITE_EVERY_S, machine: str | None = None) -> None:
        """Args:
        path: The clock's file (``OUT/clock.json``); its earlier sittings are kept.
        code: The code version this sitting runs, recorded with each of its sittings.
        every_s: Seconds between writes while a stage runs.
        machine: Where this sitting runs (``2 CPU cores (AMD EPYC), no GPU``), recorded with each of its
            sittings, so a run whose stages ran on several machines says which ran where.
        """
        self.path = Path(path)
        self.code = code
        self.every_s = every_s
        self.machine = machine
        stages = _read(self.path)
        if stages is None:
            # Unreadable: kept aside, never overwritten, and the stages timed from here on.
            kept = self.path.with_name(self.path.name + ".unreadable")
            self.path.replace(kept)
            print(f"note: {self.path} could not be read; kept as {kept}, stages timed from now on", flush=True)
        self.stages: dict[str, list[dict[str, Any]]] = stages or {}
        self._lock = threading.Lock()

    @contextmanager
    def timing(self, stage: str) -> Iterator[Sitting]:
        """Time the body as one sitting of ``stage``; the file is rewritten every ``every_s`` seconds
        and at the end, and the sitting is dropped if the body discards it."""
        sitting = Sitting()
        entry = {"started": datetime.now(timezone.utc).isoformat(timespec="seconds"), "seconds": 0.0, "code": self.code}
        if self.machine:
            entry["machine"] = self.machine
        start = time.perf_counter()
        done = threading.Event()

        def tick() -> None:
            while not done.wait(self.every_s):
                self._write(stage, entry, time.perf_counter() - start, keep=True)

        ticker = threading.Thread(target=tick, name=f"clock {stage}", daemon=True)
        ticker.start()
        try:
            yield sitting
        finally:
            done.set()
            ticker.join()
            self._write(stage, entry, time.perf_counter() - start, keep=not sitting.discarded)

    def _write(self, stage: str, entry: dict[str, Any], seconds: float, keep: bool) -> None:
        with self._lock:
            entry["seconds"] = round(seconds, 1)
            sittings = self.stages.setdefault(stage, [])
            if keep and not any(s is entry for s in sittings):
                sittings.append(entry)
            elif not keep:
                sittings[:] = [s for s in sittings if s is not entry]
            if not sittings:  # a stage no sitting worked on is not listed
                del self.stages[stage]
            write_json_atomic(self.path, {"stages": self.stages}, indent=2)

    def seconds(self, stage: str) -> float:
        """The stage's wall seconds over every sitting so far (0 when none worked on it)."""
        return round(sum(s["seconds"] for s in self.stages.get(stage, [])), 1)

    def sittings(self, stage: str) -> int:
        """How many sittings worked on the stage."""
        return len(self.stages.get(stage, []))

    def started(self, stage: str) -> float | None:
        """When the stage's first timed sitting began (POSIX seconds), or None."""
        sittings = self.stages.get(stage, [])
        return datetime.fromisoformat(sittings[0]["started"]).timestamp() if sittings else None


def machines(sittings: list[dict[str, Any]]) -> str:
    """Where a stage's sittings ran, each machine once in order (``2 CPU cores (AMD EPYC), no GPU``), with
    the sittings that recorded less counted apart; ``-`` without sittings.

    A sitting from before the clock named the CPU model (``2 CPU cores, no GPU``) is counted with
    those that recorded no machine when the same machine with its model is listed: it adds nothing
    the fuller name does not say, and may have run elsewhere.
    """
    named = list(dict.fromkeys(s["machine"] for s in sittings if s.get("machine")))
    fuller = {_without_model(m) for m in named if _without_model(m) != m}
    listed = [m for m in named if m not in fuller]
    less = sum(1 for s in sittings if not s.get("machine") or s["machine"] in fuller)
    if less:
        listed.append(f"{less} sitting(s) with no machine or CPU model recorded")
    return "; ".join(listed) or "-"


def _without_model(machine: str) -> str:
    """``2 CPU cores (Intel Xeon), no GPU`` as a sitting recorded it before the CPU model was named."""
    return re.sub(r"^(\d+ CPU cores) \((?:[^()]|\([^()]*\))*\)", r"\1", machine)


def scene_seconds(timing: dict[str, Any]) -> float:
    """A scene's own time from its ``scene.json`` ``timing_s``: growing, then drawing and labelling."""
    return float(timing.get("grow", 0.0)) + float(timing.get("draw_and_label", 0.0))


def generation_seconds(root: Path, scenes: list[str], clock: StageClock, stage: str) -> tuple[float, str]:
    """A generate stage's wall seconds and note: the clock's sittings, plus the scenes finished
    before the clock first timed this stage (a run begun before the clock existed), from the
    time each scene's ``scene.json`` records spread over the scene processes that ran at once.

    Args:
        root: The dataset root.
        scenes: The stage's scene folders.
        clock: The run's clock.
        stage: The stage's name on the clock.

    Returns:
        ``(seconds, note)``; the note says which part was on the clock and which was not.
    """
    from davis_ag.formats.layout import SCENE_METADATA
    from davis_ag.generate.run_progress import default_workers

    began = clock.started(stage)
    views = 0
    earlier: list[float] = []
    for scene in scenes:
        path = root / scene / SCENE_METADATA
        try:
            metadata = json.loads(path.read_text())
        except (OSError, ValueError):
            continue
        views += len(metadata.get("views", []))
        if began is None or path.stat().st_mtime < began:
            earlier.append(scene_seconds(metadata.get("timing_s", {})))
    workers = max(1, min(default_workers(), len(scenes)))
    seconds = clock.seconds(stage) + sum(earlier) / workers
    note = f"{len(scenes)} scene(s), {views:,} views; {clock.sittings(stage)} sitting(s) on the clock"
    if earlier:
        note += (
            f", {len(earlier)} scene(s) made before it: their scene.json times "
            f"({sum(earlier) / 3600:.2f} h) over {workers} scene processes"
        )
    return seconds, note


def read_clock(path: Path) -> dict[str, list[dict[str, Any]]]:
    """The sittings per stage of a clock file; none for a missing or unreadable one (a run from
    before the clock, or a file damaged by hand: its stages are then timed from here on)."""
    return _read(Path(path)) or {}


def _read(path: Path) -> dict[str, list[dict[str, Any]]] | None:
    """The clock file's stages; {} when there is no file, None when it cannot be read as a clock."""
    if not path.is_file():
        return {}
    try:
        stages = json.loads(path.read_text()).get("stages", {})
    except (OSError, ValueError, AttributeError):
        return None
    if not isinstance(stages, dict):
        return None
    return {k: v for k, v in stages.items() if isinstance(v, list)}
