"""generate --executor ray on a cluster of two nodes on 127.0.0.1, one worker killed mid-scene: the
run ends sound (issue 33, build item 7). Skipped where Ray is not installed.

The cluster is Ray's own ``ray.cluster_utils.Cluster`` (a head node and a second node, the
processes ``ray start --head`` and ``ray start --address`` make), in a child process that shuts
down exactly the processes it started. ``RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0`` keeps every Ray
address on the loopback interface.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytest.importorskip("ray")

DRIVER = textwrap.dedent("""
    import os, signal, sys, threading, time
    from pathlib import Path

    from ray.cluster_utils import Cluster

    from davis_ag.generate.run_config import parse_dataset_config
    from davis_ag.generate.run_progress import RunOptions
    from davis_ag.generate.runner import run_dataset

    root = Path(sys.argv[1])
    config = parse_dataset_config(
        "seed: 3\\nimage_size: 64x48\\ngrid: {extent: [3.0, 3.0], step: 1.5, altitude_levels: [0]}\\n"
        "groups:\\n  - {scenario: sp, crop: strawberry, scenes: 2}\\n", "tiny")

    def scene_workers():
        for pid in filter(str.isdigit, os.listdir("/proc")):
            try:
                with open(f"/proc/{pid}/cmdline", "rb") as handle:
                    if handle.read().startswith(b"ray::ray_scene"):
                        yield int(pid)
            except OSError:
                continue

    def kill_one_mid_scene():
        # Once some scene has written a view into its hidden partial folder, kill a scene worker.
        while not list(root.glob("*/.*.partial/images/*.jpeg")):
            time.sleep(0.05)
        victim = next(scene_workers(), None)
        if victim is not None:
            os.kill(victim, signal.SIGKILL)
            print("killed", victim, flush=True)

    cluster = Cluster(initialize_head=True, head_node_args={"num_cpus": 1, "include_dashboard": False})
    try:
        cluster.add_node(num_cpus=1)
        cluster.wait_for_nodes()
        assert cluster.address.startswith("127.0.0.1:"), cluster.address
        threading.Thread(target=kill_one_mid_scene, daemon=True).start()
        report = run_dataset(config.requests(), root, RunOptions(executor="ray", address=cluster.address,
                                                                 progress=False))
        print("made", sorted(report.made), flush=True)
    finally:
        cluster.shutdown()
""")


@pytest.mark.slow
def test_a_worker_killed_mid_scene_on_a_two_node_cluster(tmp_path: Path) -> None:
    from davis_ag.data.validate import validate_dataset

    root = tmp_path / "data"
    env = {**os.environ, "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER": "0", "RAY_USAGE_STATS_ENABLED": "0"}
    done = subprocess.run(
        [sys.executable, "-c", DRIVER, str(root)], capture_output=True, text=True, env=env, timeout=300, check=False
    )
    assert done.returncode == 0, done.stdout + done.stderr[-3000:]
    assert "killed" in done.stdout, done.stdout
    assert "made ['Single-Strawberry/000', 'Single-Strawberry/001']" in done.stdout
    report = validate_dataset(root)
    assert report.ok and report.scenes == 2 and report.views == 14
    assert not list(root.rglob(".*.partial")) and (root / "splits.json").is_file()
