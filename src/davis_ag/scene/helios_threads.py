"""One OpenMP thread for Helios's native code in the thread that grows a scene.

pyhelios3d's native library links an OpenMP runtime of its own (``pyhelios3d.libs/libgomp-*.so``,
apart from torch's), and by default starts a team of one thread per core for loops in plant growth
and Context operations too short to gain from one. On an idle 2-core machine two threads grew a
library apple no faster than one; with the other core busy (a second scene process, the crops run,
the test suite) the team's threads wait on each other and growth took 16 to 29 times as long for a
plant-library crop, 6 times for a Canopy Generator strawberry; the scene's geometry is the same byte
for byte either way (``tests/scene/test_helios_threads.py``). ``OMP_NUM_THREADS`` would limit
torch too, which reads it and would then train on one core, so the limit is set in Helios's runtime
alone, for the calling thread: OpenMP keeps the number per thread, so
:func:`davis_ag.scene.build.build_scene`, where every scene grows, calls :func:`one_helios_thread`
first.
"""

from __future__ import annotations

import ctypes
import functools
from pathlib import Path


@functools.cache
def _helios_openmp() -> tuple[ctypes.CDLL, ...]:
    """The OpenMP runtimes pyhelios3d's wheel bundles (none for a build that uses the system's)."""
    import pyhelios

    bundled = Path(pyhelios.__file__).resolve().parent.parent / "pyhelios3d.libs"
    # Opening the file the native library already loaded returns the same runtime, not a second one.
    return tuple(ctypes.CDLL(str(path)) for path in sorted(bundled.glob("libgomp*.so*")))


def one_helios_thread() -> int:
    """Run Helios's OpenMP loops on one thread from this thread on.

    Returns:
        How many of pyhelios3d's OpenMP runtimes were set (0 where it bundles none).
    """
    runtimes = _helios_openmp()
    for runtime in runtimes:
        runtime.omp_set_num_threads(1)
    return len(runtimes)


def helios_threads() -> list[int]:
    """The threads the next OpenMP team of this thread would have, per bundled runtime."""
    return [runtime.omp_get_max_threads() for runtime in _helios_openmp()]
