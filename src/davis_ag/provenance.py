"""Which code, and which machine, made an output: the package version and, in a git checkout, the
commit; the machine's cores, CPU model and accelerator."""

from __future__ import annotations

import functools
import os
import platform
import subprocess
from pathlib import Path

from davis_ag import __version__


@functools.cache
def source_revision() -> str | None:
    """The git commit of the checkout this package runs from, with ``-dirty`` when its tracked
    files differ from that commit; None when it is not run from a git checkout (an installed wheel).
    Looked up once per process."""
    here = Path(__file__).resolve().parent
    try:
        commit = subprocess.run(
            ["git", "-C", str(here), "rev-parse", "--short=12", "HEAD"],
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
        changed = subprocess.run(
            ["git", "-C", str(here), "status", "--porcelain", "--untracked-files=no", "--", str(here)],
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return f"{commit}-dirty" if changed else commit


def code_version() -> str:
    """``__version__``, or ``__version__+<commit>[-dirty]`` in a git checkout: what to record beside an output."""
    revision = source_revision()
    return f"{__version__}+{revision}" if revision else __version__


def machine_description() -> str:
    """CPU model, core count and accelerator of this machine, with Python's and torch's versions."""
    import torch

    return f"{machine_summary()}; Python {platform.python_version()}, torch {torch.__version__}, {platform.system()} {platform.release()}"


def machine_summary() -> str:
    """This machine in a few words, for each sitting of a run's clock: cores, CPU model, accelerator
    (``2 CPU cores (Intel(R) Xeon(R) Processor), no GPU``)."""
    import torch

    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    gpu = torch.cuda.get_device_name(0) if torch.cuda.is_available() else "no GPU"
    return f"{os.cpu_count()} CPU cores ({cpu}), {gpu}"
