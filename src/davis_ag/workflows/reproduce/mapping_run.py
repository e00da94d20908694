"""``davis-ag reproduce --config mapping``: the crops run's rows mapped by every baseline, written
to docs/mapping.md.

For each row of the configuration in turn, each stage resumable: its scenes (finished ones
skipped), their validation, then the mapping evaluation (Sweep, Rand, Greedy, the budget's bound)
at each seen fraction of :data:`SEEN_FRACTIONS`, a results file each (reused when it is one of the
same protocol and scenes), the coverage curves and, for the first row, one episode of the greedy
planner and of the sweep drawn on its segment. No learner is trained here yet (``train --task
mapping`` trains one), so a group of one scene is scored on all its scenes (``evaluation_split``);
the page says which split.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict
from pathlib import Path

from davis_ag.errors import UserError
from davis_ag.mapping.coverage import SEEN_FRACTION
from davis_ag.mapping.results import MappingResults
from davis_ag.workflows.reproduce.configs import ReproduceConfig, check_disk
from davis_ag.workflows.reproduce.groups import group_key
from davis_ag.workflows.reproduce.pages.mapping import results_name, write_mapping_md
from davis_ag.workflows.reproduce.state import RunState

#: The seen fractions every row is mapped at: the default and one either side (docs/mapping.md).
SEEN_FRACTIONS = (0.3, SEEN_FRACTION, 0.7)


def _reusable(path: Path, config: ReproduceConfig, scenes: list[str]) -> MappingResults | None:
    """An earlier evaluation of the same protocol and scenes, or None to evaluate anew."""
    from davis_ag.mapping.results import load_mapping_results

    if not path.is_file():
        return None
    try:
        results = load_mapping_results(path)
    except UserError:
        return None
    p = results.protocol
    same = (p.episodes, p.sessions, p.seed, p.scenes) == (config.episodes, config.sessions, config.seed, scenes)
    return results if same else None


def _draw_episodes(results: MappingResults, root: Path, images: Path, key: str) -> None:
    """The greedy planner's and the sweep's first episode drawn on their segment."""
    from davis_ag.figures.mapping_plots import plot_mapping_episode
    from davis_ag.mapping.env import RowMappingEnv, grid_places

    env = RowMappingEnv(root, results.protocol.scenario, split=results.protocol.split, crop=results.protocol.crop)
    for name in ("Greedy", "Sweep"):
        episode = results.policies[name].episodes[0]
        scene = [s.id for s in env.scenes].index(episode.scene)
        names = env.caches[scene].view_names
        xy, _ = grid_places(env.scenes[scene], names)
        views = [names.index(v) for v in episode.path]
        seen = episode.seen_0 + sum(episode.gains)
        plot_mapping_episode(
            env.coverage[scene],
            xy,
            episode,
            views,
            images / f"{key}-episode-{name.lower()}.png",
            title=f"{name} on {episode.scene}: {seen} of {episode.fruit} fruit seen in {len(episode.actions)} moves",
        )


def reproduce_mapping(
    config: ReproduceConfig, out: Path, results_md: Path, pairs: list[tuple[str, str]] | tuple[tuple[str, str], ...]
) -> int:
    """Generate, validate and map each row; write ``results_md`` after each.

    Returns:
        0 on success, 1 when a dataset failed validation.
    """
    from davis_ag.atomic_files import prove_writable_file, prove_writable_folder, write_or_rescue
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.mapping.evaluation import evaluate_mapping
    from davis_ag.mapping.results import mapping_table
    from davis_ag.provenance import code_version, machine_summary
    from davis_ag.scene.camera import Camera
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE, StageClock
    from davis_ag.workflows.reproduce.run import split_scene_ids, stage_recorder, validate_once
    from davis_ag.workflows.stages import evaluation_split, generate_scenes

    check_disk(config, Path(out).expanduser().absolute(), pairs)
    out = prove_writable_folder(out)
    results_md = prove_writable_file(results_md, "--results")
    root = out / "dataset"
    state_path = out / "state.json"
    state = RunState.load(state_path)
    state.config = json.loads(json.dumps(asdict(config)))
    state.save(state_path)
    clock = StageClock(out / CLOCK_FILE, code_version(), machine=machine_summary())
    record = stage_recorder(state, state_path)
    camera = Camera(*config.size)
    for scenario_name, crop_name in pairs:
        scenario, crop = config.specs(scenario_name, crop_name)
        key = group_key(scenario_name, crop_name)
        requests = [
            SceneRequest(scenario, crop, i, config.seed, camera, structures=config.structures)
            for i in range(config.scenes(scenario_name))
        ]
        print(f"== {key}: {len(requests)} scene(s) at {config.size[0]}x{config.size[1]}", flush=True)
        began = time.perf_counter()
        generate_scenes(requests, root)
        record(f"{key}: generate", time.perf_counter() - began)
        if not validate_once(root / requests[0].folder.split("/")[0], state, f"{key}: validate", clock, record):
            return 1
        split = evaluation_split(root, scenario_name, crop_name)
        scenes = split_scene_ids(root, scenario_name, split, crop_name)
        for fraction in SEEN_FRACTIONS:
            path = out / "results" / results_name(key, fraction)
            if _reusable(path, config, scenes) is None:
                began = time.perf_counter()
                results = evaluate_mapping(
                    [], root, scenario_name, split, config.sessions, config.episodes, config.seed,
                    crop=crop_name, seen_fraction=fraction,
                )  # fmt: skip
                path.parent.mkdir(parents=True, exist_ok=True)
                write_or_rescue(path, results.write, "the results")
                record(f"{key}: map at {fraction:g}", time.perf_counter() - began, f"split {split}")
                if fraction == SEEN_FRACTION:
                    print(mapping_table(results), flush=True)
        write_run_page(results_md, config, out, pairs)
        print(f"wrote {results_md}", flush=True)
    return 0


def write_run_page(
    results_md: Path, config: ReproduceConfig, out: Path, pairs: list[tuple[str, str]] | tuple[tuple[str, str], ...]
) -> None:
    """Draw the run's pictures from its results files (and, for the first row, its dataset) beside
    ``results_md`` and write the page: what ``reproduce`` and ``--rewrite-results`` both do."""
    from davis_ag.figures.mapping_plots import plot_coverage_curves
    from davis_ag.mapping.results import load_mapping_results

    images = results_md.parent / "images" / "mapping"
    images.mkdir(parents=True, exist_ok=True)
    runs: dict[str, dict[float, MappingResults]] = {}
    for scenario_name, crop_name in pairs:
        key = group_key(scenario_name, crop_name)
        found = {f: out / "results" / results_name(key, f) for f in SEEN_FRACTIONS}
        by_fraction = {f: load_mapping_results(p) for f, p in found.items() if p.is_file()}
        main = by_fraction.get(SEEN_FRACTION)
        if main is None:
            continue
        runs[key] = by_fraction
        p = main.protocol
        plot_coverage_curves(
            main, images / f"{key}-curves.png", title=f"{key}: {len(p.scenes)} scene(s), split {p.split}"
        )
        if (scenario_name, crop_name) == tuple(pairs[0]) and (out / "dataset").is_dir():
            _draw_episodes(main, out / "dataset", images, key)
    if runs:
        write_mapping_md(results_md, runs, images)
