"""Fixtures shared across test folders: tiny datasets in the published layout, made without Helios."""

from __future__ import annotations

import os

# One thread per process for OpenMP and BLAS (torch, numpy, Helios), set before any of them loads
# and inherited by the commands tests start: `make test` runs a pytest worker per core, and thread
# pools of two processes spinning on the same cores made a 2 s training test take 53 s.
for _variable in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import settings

from layout_factory import write_tiny_dataset


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The files that hold a ``slow`` test first, each file's tests kept together and in order.

    ``make test``'s workers take files whole (``--dist loadfile``) in collection order: the heavy
    files came last (tests/workflows), and the worker that drew the last of them ran on alone
    while the other stood idle (a 2-core run kept its cores 86 % busy).
    """
    slow_files = {item.path for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: item.path not in slow_files)  # stable: the order within each group stays


@pytest.fixture(scope="module")
def sp_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two single-plant strawberry scenes (splits.json: 000 train, 001 test)."""
    return write_tiny_dataset(tmp_path_factory.mktemp("sp"), "sp", "strawberry", scenes=2)


@pytest.fixture(scope="module")
def mp_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two multi-plant strawberry scenes."""
    return write_tiny_dataset(tmp_path_factory.mktemp("mp"), "mp", "strawberry", scenes=2)


@pytest.fixture()
def one_thread() -> Iterator[None]:
    """Torch on one thread for the test. Tiny tensors on shared cores: torch's thread pool spins
    and runs several times slower than one thread."""
    import torch

    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(threads)


# Hypothesis fails an example that takes over 200 ms: on a busy 2-core CI machine a descheduled
# process or a first lazy import trips that, which says nothing about the code under test.
settings.register_profile("shared-cores", deadline=None)
settings.load_profile("shared-cores")
