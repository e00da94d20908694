"""``davis-ag demo`` orchestration, and the stage helpers ``davis-ag reproduce`` shares.

The demo: generate a small single-plant strawberry dataset, validate it, write a 70/30 split by
scene, run the paper's baselines (LRD, UDD, Rand and the exact Oracle) on the test split, print
a Table 4 style table and write an HTML report (:mod:`davis_ag.figures.report`) a person can open.

Every stage is resumable: finished scenes are skipped (:func:`davis_ag.generate.one_scene.check_scene_slot`),
a crashed scene's partial folder is cleared, and the environment's observation cache is reused.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from tqdm import tqdm

from davis_ag.atomic_files import write_text_atomic
from davis_ag.errors import UserError
from davis_ag.generate.one_scene import (
    SceneRequest,
    check_output_root,
    check_scene_slot,
    generate_scene,
    remove_stale_partial,
)
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import CropSpec, ScenarioSpec, crop_spec, scenario_spec
from davis_ag.stage_timer import Timer

#: The baselines of Table 4 plus the exact upper bound; A2C needs training (``reproduce``).
BASELINES: tuple[str, ...] = ("LRD", "UDD", "Rand", "Oracle")
#: Default image size of the demo: the paper's (2 scenes took 5.6 min in all on 2 CPU cores).
DEMO_SIZE: tuple[int, int] = (1280, 720)


def generate_scenes(requests: list[SceneRequest], root: Path, label: str = "scenes") -> list[dict[str, Any]]:
    """Generate the scenes not yet complete under ``root``, with progress bars.

    Args:
        requests: The scenes wanted.
        root: The dataset root (checked with :func:`check_output_root`).
        label: Name of the progress bar.

    Returns:
        One dict per request: ``scene``, ``skipped`` and, for generated scenes, the timing
        statistics of :func:`davis_ag.generate.one_scene.generate_scene`.

    Raises:
        UserError: for an unusable root or a finished scene made with other settings.
    """
    check_output_root(root)
    root.mkdir(parents=True, exist_ok=True)
    done = {r.folder: check_scene_slot(root, r) for r in requests}
    for request in (r for r in requests if done[r.folder]):
        _check_image_size(root / request.folder, request.camera)
    todo = [r for r in requests if not done[r.folder]]
    results = [{"scene": r.folder, "skipped": True} for r in requests if done[r.folder]]
    if results:
        tqdm.write(f"{len(results)} of {len(requests)} {label} already complete in {root}: skipped")
    with tqdm(total=len(todo), desc=label, unit="scene", position=0) as scenes_bar, \
         tqdm(desc="views", unit="view", position=1, leave=False) as views_bar:
        for request in todo:
            remove_stale_partial(root, request)
            views_bar.reset()
            views_bar.set_description(f"views {request.folder}")

            def on_view(count: int, total: int) -> None:
                views_bar.total = total
                views_bar.update(1)

            scene_dir, stats = generate_scene(request, root, on_view)
            scenes_bar.update(1)
            tqdm.write(f"{scene_dir}: {stats['views']} views, grown in {stats['grow_s']:.1f} s, "
                       f"{stats['views_s'] / max(stats['views'], 1):.3f} s per view")
            results.append({"scene": request.folder, "skipped": False, **stats})
    return results


def _check_image_size(scene_dir: Path, camera: Camera) -> None:
    """Refuse to reuse a finished scene drawn at another image size.

    Raises:
        UserError: when the scene's scene.json names another width or height.
    """
    try:
        drawn = json.loads((scene_dir / "scene.json").read_text())["camera"]
        size = (int(drawn["width"]), int(drawn["height"]))
    except (OSError, ValueError, KeyError, TypeError):
        return
    if size != (camera.width, camera.height):
        raise UserError(f"{scene_dir} was drawn at {size[0]}x{size[1]}, not {camera.width}x"
                        f"{camera.height}: use the same --size or another --out")


def write_splits(root: Path, seed: int = 0) -> Path:
    """Write ``root/splits.json``: the 70/30 split by scene of every group.

    Uses :func:`davis_ag.generate.runner.write_splits` (the split ``davis-ag generate`` writes: seeded,
    at least one scene on each side when a group has two or more, a group of one scene is
    train only) when that module is present; otherwise the same rule with
    :func:`davis_ag.benchmark.splits.fallback_split`.

    Args:
        root: The dataset root.
        seed: The dataset seed (seeds the runner's split).

    Returns:
        The path of splits.json.
    """
    try:
        from davis_ag.generate.one_scene import runner
    except ImportError:  # an older checkout without the runner: use the fallback below
        runner = None  # type: ignore[assignment]
    writer = getattr(runner, "write_splits", None)
    if callable(writer):
        written = writer(root, seed)
        if isinstance(written, (str, os.PathLike)) and Path(written).is_file():
            return Path(written)
    from davis_ag.benchmark.splits import SPLIT_SEED, fallback_split
    from davis_ag.data.reader import open_dataset

    groups: dict[str, list[str]] = {}
    for scene in open_dataset(root).scenes:
        groups.setdefault(scene.id.split("/")[0], []).append(scene.id)
    train: list[str] = []
    test: list[str] = []
    for ids in groups.values():
        split = fallback_split(ids)
        train += split["train"]
        test += split["test"]
    path = root / "splits.json"
    write_text_atomic(path, json.dumps({"seed": SPLIT_SEED, "train": sorted(train),
                                        "test": sorted(test)}, indent=2))
    return path


def evaluation_split(root: Path, scenario: str, crop: str) -> str:
    """``test`` when the dataset's split has test scenes of this scenario and crop, else ``all``.

    Args:
        root: The dataset root.
        scenario: ``sp`` or ``mp``.
        crop: Crop name.

    Returns:
        The split to evaluate on.
    """
    from davis_ag.benchmark.splits import select_scenes
    from davis_ag.data.reader import open_dataset

    try:
        select_scenes(open_dataset(root), scenario, "test", crop)
    except UserError:
        return "all"
    return "test"


def run_baselines(root: Path, scenario: str, crop: str, split: str, episodes: int, sessions: int,
                  seed: int = 0, model: Path | None = None) -> dict[str, Any]:
    """Evaluate LRD, UDD, Rand, Oracle (and A2C when ``model`` is given) as in Table 4.

    Args:
        root: The dataset root.
        scenario: ``sp`` or ``mp``.
        crop: Crop to evaluate on.
        split: ``train``, ``test`` or ``all``.
        episodes: Episodes per session.
        sessions: Sessions.
        seed: Base seed of the episodes.
        model: A trained A2C ``.zip``; adds the A2C column.

    Returns:
        What :func:`davis_ag.benchmark.evaluation.evaluate_agents` returns.
    """
    from davis_ag.benchmark import TVMEnv
    from davis_ag.benchmark.agents import build_agents
    from davis_ag.benchmark.evaluation import evaluate_agents

    names = list(BASELINES) + (["A2C"] if model else [])
    agents = build_agents(names, model=model)
    env = TVMEnv(root, scenario=scenario, split=split, crop=crop)
    results = evaluate_agents(env, agents, episodes=episodes, sessions=sessions, seed=seed)
    results["protocol"]["crop"] = crop
    env.close()
    return results


def run_demo(out: Path, scenes: int = 2, size: tuple[int, int] = DEMO_SIZE, seed: int = 0,
             episodes: int = 200, sessions: int = 3, scenario: ScenarioSpec | None = None,
             crop: CropSpec | None = None) -> int:
    """The whole demo: generate, validate, split, benchmark the baselines, report.

    Defaults: 2 SP strawberry scenes (one train and one test scene under the 70/30 split by
    scene) at the paper's 1280x720. Measured on a 2-core CPU machine without GPU: 5 min 37 s in
    all (0.44-0.47 s per view, 704 views); at 640x360, 4 min 29 s. Helios' draw time is set by
    the geometry (~180K primitives per strawberry scene) more than by the pixel count.

    Args:
        out: Output folder: ``out/dataset`` and ``out/report``.
        scenes: Scenes to generate (2 gives one train and one test scene).
        size: Image width and height.
        seed: Dataset seed.
        episodes: Episodes per evaluation session.
        sessions: Evaluation sessions.
        scenario: Scenario spec (default: the paper's SP); tests pass a reduced grid.
        crop: Crop spec (default: strawberry).

    Returns:
        0 when the dataset is sound and the report was written, 1 when validation failed.

    Raises:
        UserError: for bad arguments or an unusable output folder.
    """
    from davis_ag.benchmark.evaluation import format_table, write_json
    from davis_ag.data.validate import validate_dataset
    from davis_ag.figures.report import write_report

    if scenes < 1 or scenes > 1000:
        raise UserError(f"--scenes {scenes}: choose 1 to 1000")
    if episodes < 1 or sessions < 1:
        raise UserError("--episodes and --sessions must be at least 1")
    if seed < 0:
        raise UserError(f"--seed {seed} is negative: use a whole number from 0")
    out = Path(out).expanduser().absolute()  # Helios moves the working directory as it works
    crop = crop or crop_spec("strawberry")
    scenario = scenario or scenario_spec("sp", crop)
    if out.exists() and not out.is_dir():
        raise UserError(f"{out} is a file, not a folder: choose another --out")
    root = out / "dataset"
    timer = Timer()
    camera = Camera(*size)
    requests = [SceneRequest(scenario, crop, i, seed, camera) for i in range(scenes)]
    print(f"[1/5] generating {scenes} {scenario.name.upper()} {crop.name} scene(s) at "
          f"{size[0]}x{size[1]} in {root}", flush=True)
    with timer.stage("generate"):
        generated = generate_scenes(requests, root)
    if all(g["skipped"] for g in generated):
        timer.notes["generate"] = "all scenes reused"
    print("[2/5] validating", flush=True)
    with timer.stage("validate"):
        report = validate_dataset(root, on_problem=lambda p: tqdm.write(str(p)), progress=True)
    print(report.summary(), flush=True)
    if not report.ok:
        print(f"the dataset in {root} is not sound: see the problems above", flush=True)
        return 1
    with timer.stage("split"):
        splits = write_splits(root, seed)
        split = evaluation_split(root, scenario.name, crop.name)
    print(f"[3/5] split written to {splits}; evaluating on split {split!r}", flush=True)
    print(f"[4/5] baselines: {sessions} sessions x {episodes} episodes", flush=True)
    with timer.stage("evaluate"):
        results = run_baselines(root, scenario.name, crop.name, split, episodes, sessions, seed)
    table = format_table(results)
    print(table, flush=True)
    report_dir = out / "report"
    write_json(results, report_dir / "results.json")
    print("[5/5] writing the report", flush=True)
    with timer.stage("report"):
        index = write_report(root, report_dir, results=results, validation=report.summary(),
                             timer=timer, generated=generated, title="DAVIS-Ag demo")
    print(f"report: {index}  (open it in a browser; total {timer.total:.0f} s)", flush=True)
    return 0
