"""Small real datasets for tests: a dataset config generated with Helios, skipped where pyhelios
cannot render natively."""

from __future__ import annotations

from pathlib import Path

import pytest

from davis_ag.errors import UserError


def generate_config(folder: Path, config_text: str) -> Path:
    """Write ``config_text`` as a dataset config in ``folder`` and generate it in one process.

    Returns:
        The dataset root, ``folder / "data"``.
    """
    from davis_ag.generate.run_config import load_dataset_config
    from davis_ag.generate.run_progress import RunOptions
    from davis_ag.generate.runner import run_dataset
    from davis_ag.scene.plants import require_native_helios

    try:
        require_native_helios()
    except UserError as error:
        pytest.skip(str(error))
    config = folder / "config.yaml"
    config.write_text(config_text)
    root = folder / "data"
    run_dataset(load_dataset_config(config).requests(), root, RunOptions(workers=1, progress=False))
    return root
