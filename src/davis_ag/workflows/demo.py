"""``davis-ag demo`` orchestration (its stages are :mod:`davis_ag.workflows.stages`'s, shared with ``reproduce``).

The demo: generate a small single-plant strawberry dataset, validate it, write a 70/30 split by
scene, run the paper's baselines (LRD, UDD, Rand and the exact Oracle) on the test split, print
a Table 4 style table and write an HTML report (:mod:`davis_ag.figures.report`) a person can open,
with the paper's figures drawn for the small dataset; it ends by saying where they are and how to
open the viewer (``davis-ag view``).

Every stage is resumable: finished scenes are skipped (:func:`davis_ag.generate.output_checks.check_scene_slot`),
a crashed scene's partial folder is cleared, and the environment's observation cache is reused.
"""

from __future__ import annotations

import os
from pathlib import Path

from tqdm import tqdm

from davis_ag.atomic_files import prove_writable_folder, write_or_rescue
from davis_ag.errors import UserError
from davis_ag.formats.layout import SPLITS_FILE
from davis_ag.formats.models import check_image_size, check_seed
from davis_ag.generate.one_scene import SceneRequest
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import CropSpec, ScenarioSpec, crop_spec, scenario_spec
from davis_ag.stage_timer import Timer
from davis_ag.workflows.stages import evaluation_split, generate_scenes, run_baselines

#: Default image size of the demo: the paper's (2 scenes took 5.6 min in all on 2 CPU cores).
DEMO_SIZE: tuple[int, int] = (1280, 720)


def run_demo(
    out: Path,
    scenes: int = 2,
    size: tuple[int, int] = DEMO_SIZE,
    seed: int = 0,
    episodes: int = 200,
    sessions: int = 3,
    scenario: ScenarioSpec | None = None,
    crop: CropSpec | None = None,
) -> int:
    """The whole demo: generate, validate, split, benchmark the baselines, report.

    Defaults: 2 SP strawberry scenes (one train and one test scene under the 70/30 split by
    scene) at the paper's 1280x720, drawn by our OpenGL renderer (default look, with depth).
    Before our renderer, with Helios drawing, it took 5 min 37 s on a 2-core CPU machine.

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
    from davis_ag.benchmark.evaluation import write_json
    from davis_ag.benchmark.results_table import format_table
    from davis_ag.data.validate import validate_dataset
    from davis_ag.figures.report import write_report

    check_seed(seed, "--seed")
    size = check_image_size(size, "--size")
    if scenes < 1 or scenes > 1000:
        raise UserError(f"--scenes {scenes}: choose 1 to 1000")
    if episodes < 1 or sessions < 1:
        raise UserError("--episodes and --sessions must be at least 1")
    # Absolute at once: Helios moves the working directory as it works.
    out = prove_writable_folder(out)
    crop = crop or crop_spec("strawberry")
    scenario = scenario or scenario_spec("sp", crop)
    root = out / "dataset"
    timer = Timer()
    camera = Camera(*size)
    requests = [SceneRequest(scenario, crop, i, seed, camera) for i in range(scenes)]
    print(
        f"[1/5] generating {scenes} {scenario.name.upper()} {crop.name} scene(s) at {size[0]}x{size[1]} in {root}",
        flush=True,
    )
    with timer.stage("generate"):
        generated = generate_scenes(requests, root)
    if all(g["skipped"] for g in generated):
        timer.notes["generate"] = "all scenes reused"
    print("[2/5] validating", flush=True)
    with timer.stage("validate"):
        report = validate_dataset(
            root, on_problem=lambda p: tqdm.write(str(p)), progress=True, workers=os.cpu_count() or 1
        )
    print(report.summary(), flush=True)
    if not report.ok:
        print(f"the dataset in {root} is not sound: see the problems above", flush=True)
        return 1
    with timer.stage("split"):
        splits = root / SPLITS_FILE  # written by the runner
        split = evaluation_split(root, scenario.name, crop.name)
    print(f"[3/5] split written to {splits}; evaluating on split {split!r}", flush=True)
    print(f"[4/5] baselines: {sessions} sessions x {episodes} episodes", flush=True)
    with timer.stage("evaluate"):
        results = run_baselines(root, scenario.name, crop.name, split, episodes, sessions, seed)
    table = format_table(results)
    print(table, flush=True)
    report_dir = out / "report"
    write_or_rescue(report_dir / "results.json", lambda path: write_json(results, path), "the results")
    print("[5/5] writing the report", flush=True)
    with timer.stage("report"):
        index = write_report(
            root,
            report_dir,
            results=results.as_json(),
            validation=report.summary(),
            timer=timer,
            generated=generated,
            title="DAVIS-Ag demo",
        )
    print(f"report: {index}  (open it in a browser; total {timer.total:.0f} s)", flush=True)
    print(f"figures of the paper (PNG, SVG, numbers as JSON): {report_dir / 'figures'}", flush=True)
    print(f"drive through a scene: davis-ag view {root}  (then open http://127.0.0.1:8765/)", flush=True)
    return 0
