"""The ``davis-ag reproduce`` workflow: the paper's Table 4 (section VI) end to end, at a size that fits.

Stages (each resumable: finished scenes are skipped, a trained model's zip and an evaluation's
JSON are reused): SP strawberry data, its validation and split, A2C on SP, the SP benchmark,
then the same for MP vine; ``--results`` (Markdown) is rewritten after every benchmark, so a
run cut short still leaves what it measured.
"""

from __future__ import annotations

import json
import os
import platform
import sys
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import write_json_atomic


@dataclass(frozen=True)
class ReproduceConfig:
    """One reproduction's size.

    Attributes:
        name: ``small``, ``medium`` or ``paper-scale``.
        size: Image width and height.
        sp_scenes, mp_scenes: SP strawberry and MP vine scenes.
        mp_extent: MP grid extent (x, y) in metres; ``None`` keeps Table 2's 7 x 3 m.
        sp_timesteps, mp_timesteps: A2C environment steps per scenario.
        n_envs: A2C parallel environments.
        episodes, sessions: Evaluation protocol (200 x 3 in the paper).
        seed: Dataset, training and evaluation seed.
    """

    name: str
    size: tuple[int, int]
    sp_scenes: int
    mp_scenes: int
    mp_extent: tuple[float, float] | None
    sp_timesteps: int
    mp_timesteps: int
    n_envs: int = 8
    episodes: int = 200
    sessions: int = 3
    seed: int = 0


#: ``small``: 43 min of stages measured on a 2-core CPU machine without GPU (docs/results.md);
#: a 3 x 2 m MP grid and 10 % / 5 % of the paper's A2C steps: not comparable with Table 4.
#: ``medium``: the paper's grids (Table 2: 3 x 3 m SP, 7 x 3 m MP) and protocol (300K A2C steps,
#: 3 sessions of 200 episodes) on 10 SP strawberry and 4 MP vine scenes at 640x360 (the policy
#: sees 224x224 either way), a few hours on such a machine, resumable across sittings.
#: ``paper-scale``: Table 3's scene counts at 1280x720 and 300K A2C steps (days on such a machine).
CONFIGS: dict[str, ReproduceConfig] = {
    "small": ReproduceConfig("small", (640, 360), sp_scenes=3, mp_scenes=2, mp_extent=(3.0, 2.0),
                             sp_timesteps=30_000, mp_timesteps=15_000),
    "medium": ReproduceConfig("medium", (640, 360), sp_scenes=10, mp_scenes=4, mp_extent=None,
                              sp_timesteps=300_000, mp_timesteps=300_000),
    "paper-scale": ReproduceConfig("paper-scale", (1280, 720), sp_scenes=86, mp_scenes=44,
                                   mp_extent=None, sp_timesteps=300_000, mp_timesteps=300_000),
}

#: Table 4 of the paper: scenario -> metric -> policy -> value.
PAPER_TABLE4: dict[str, dict[str, dict[str, float]]] = {
    "sp": {"oer_tau": {"A2C": .520, "LRD": .433, "UDD": .371, "Rand": .438},
           "reward": {"A2C": .052, "LRD": .026, "UDD": .008, "Rand": .027},
           "length": {"A2C": 2.987, "LRD": 2.157, "UDD": 2.137, "Rand": 2.652}},
    "mp": {"oer_tau": {"A2C": .369, "LRD": .316, "UDD": .313, "Rand": .340},
           "reward": {"A2C": .020, "LRD": .006, "UDD": .004, "Rand": .012},
           "length": {"A2C": 5.000, "LRD": 2.558, "UDD": 2.683, "Rand": 4.163}},
}
#: The scenario and crop pairs of Table 4.
SCENARIO_CROPS: tuple[tuple[str, str], ...] = (("sp", "strawberry"), ("mp", "vine"))


def load_state(path: Path) -> dict[str, Any]:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return {}


def reproduce(config: ReproduceConfig, out: Path, results_md: Path,
              pairs: list[tuple[str, str]] | tuple[tuple[str, str], ...] = SCENARIO_CROPS) -> int:
    """Generate, validate, split, train and benchmark each scenario; write ``results_md``.

    Args:
        config: The size of the run.
        out: Work folder (``dataset``, ``models``, ``results``, ``state.json``).
        results_md: The Markdown file to (re)write.
        pairs: ``(scenario, crop)`` pairs to run.

    Returns:
        0 on success, 1 when a dataset failed validation.
    """
    from davis_ag.atomic_files import prove_writable_file, prove_writable_folder, write_or_rescue
    from davis_ag.benchmark.evaluation import format_table, plot_results, write_json
    from davis_ag.benchmark.training import train_a2c
    from davis_ag.data.validate import validate_dataset
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.scene.camera import Camera
    from davis_ag.scene.specs import crop_spec, scenario_spec
    from davis_ag.workflows.demo import evaluation_split, generate_scenes, run_baselines

    out = prove_writable_folder(out)  # absolute at once: Helios moves the working directory
    results_md = prove_writable_file(results_md, "--results")
    root = out / "dataset"
    state_path = out / "state.json"
    state = load_state(state_path)
    if state.get("config") and state["config"] != json.loads(json.dumps(asdict(config))):
        print(f"note: {out} was started with another configuration; finished stages are reused "
              "only where their files match", flush=True)
    state["config"] = asdict(config)
    state.setdefault("stages", {})
    state.setdefault("results", {})

    def record(stage: str, seconds: float, note: str = "") -> None:
        state["stages"][stage] = {"seconds": round(seconds, 1), "note": note}
        write_json_atomic(state_path, state, indent=2)

    camera = Camera(*config.size)
    for scenario_name, crop_name in pairs:
        crop = crop_spec(crop_name)
        scenario = scenario_spec(scenario_name, crop)
        if scenario_name == "mp" and config.mp_extent:
            scenario = replace(scenario, extent=tuple(config.mp_extent))
        n = config.sp_scenes if scenario_name == "sp" else config.mp_scenes
        key = f"{scenario_name}-{crop_name}"
        requests = [SceneRequest(scenario, crop, i, config.seed, camera) for i in range(n)]
        print(f"== {key}: {n} scene(s) at {config.size[0]}x{config.size[1]}", flush=True)
        generated = generate_scenes(requests, root)  # also writes splits.json
        # Per-scene times survive resumed runs, so the stage time covers every scene it used.
        scene_log = state.setdefault("scenes", {})
        for g in generated:
            if not g["skipped"]:
                scene_log[g["scene"]] = {"seconds": round(g["total_s"], 1), "views": g["views"],
                                         "s_per_view": round(g["views_s"] / g["views"], 3)}
        timed = [scene_log[r.folder] for r in requests if r.folder in scene_log]
        if timed:
            views = sum(t["views"] for t in timed)
            missing = len(requests) - len(timed)
            record(f"{key}: generate", sum(t["seconds"] for t in timed),
                   f"{len(timed)} scene(s), {views} views, "
                   f"{sum(t['s_per_view'] * t['views'] for t in timed) / views:.2f} s per view"
                   + (f"; {missing} scene(s) made earlier, not timed" if missing else ""))
        start = time.perf_counter()
        group = root / requests[0].folder.split("/")[0]
        report = validate_dataset(group)
        print(report.summary(), flush=True)
        record(f"{key}: validate", time.perf_counter() - start, report.summary())
        if not report.ok:
            for problem in report.problems[:20]:
                print(problem, flush=True)
            return 1
        split = evaluation_split(root, scenario_name, crop_name)
        model = out / "models" / f"a2c_{key}.zip"
        timesteps = config.sp_timesteps if scenario_name == "sp" else config.mp_timesteps
        stamp = out / "models" / f"a2c_{key}.json"
        if not model.is_file() or load_state(stamp).get("timesteps") != timesteps:
            print(f"training A2C (the paper's network) on {key} train split for {timesteps} steps", flush=True)
            start = time.perf_counter()
            train_a2c(root, scenario_name, total_timesteps=timesteps, seed=config.seed,
                      out_path=model, n_envs=config.n_envs, crop=crop_name, device="cpu",
                      callback=_progress_callback(timesteps, key))
            seconds = time.perf_counter() - start
            write_json_atomic(stamp, {"timesteps": timesteps, "seconds": seconds})
            record(f"{key}: train A2C", seconds,
                   f"{timesteps} steps, {timesteps / seconds:.1f} steps/s (incl. cache build)")
        print(f"benchmark on split {split!r}: {config.sessions} x {config.episodes} episodes", flush=True)
        results_json = out / "results" / f"{key}.json"
        results = _reusable_results(results_json, model, split, config)
        if results is None:
            start = time.perf_counter()
            results = run_baselines(root, scenario_name, crop_name, split, config.episodes,
                                    config.sessions, config.seed, model=model)
            write_or_rescue(results_json, lambda path: write_json(results, path), "the results")
            plot_results(results, results_json.with_suffix(".png"))
            record(f"{key}: evaluate", time.perf_counter() - start, f"split {split}")
        else:
            print(f"reusing {results_json}", flush=True)
        print(format_table(results), flush=True)
        state["results"][scenario_name] = _summary(results)
        record(f"{key}: evaluate", state["stages"][f"{key}: evaluate"]["seconds"],
               state["stages"][f"{key}: evaluate"]["note"])
        write_results_md(results_md, config, state, out)
        print(f"wrote {results_md}", flush=True)
    return 0


def _reusable_results(path: Path, model: Path, split: str, config: ReproduceConfig) -> dict[str, Any] | None:
    """An earlier evaluation of the same model and protocol, or ``None`` to evaluate anew."""
    results = load_state(path)
    protocol = results.get("protocol", {})
    try:
        fresh = path.stat().st_mtime >= model.stat().st_mtime
    except OSError:
        return None
    same = (protocol.get("split") == split and protocol.get("episodes") == config.episodes
            and protocol.get("sessions") == config.sessions and protocol.get("seed") == config.seed)
    return results if fresh and same and "A2C" in results.get("policies", {}) else None


def _summary(results: dict[str, Any]) -> dict[str, Any]:
    """The part of the evaluation results that results.md needs."""
    return {"protocol": results["protocol"],
            "policies": {name: {k: {"mean": v["mean"], "std": v["std"]} for k, v in stats.items()
                                if isinstance(v, dict) and "mean" in v}
                         for name, stats in results["policies"].items()}}


def _progress_callback(total: int, label: str) -> Any:
    """An SB3 callback drawing a tqdm bar over environment steps."""
    from stable_baselines3.common.callbacks import BaseCallback
    from tqdm import tqdm

    class Progress(BaseCallback):
        # A bar on a terminal; in a log (not a terminal), a line a minute instead of a redrawn bar.
        def _on_training_start(self) -> None:
            self.bar = tqdm(total=total, desc=f"A2C {label}", unit="step", mininterval=5, disable=None)
            self.steps, self.last = 0, time.monotonic()

        def _on_step(self) -> bool:
            self.bar.update(self.training_env.num_envs)
            self.steps += self.training_env.num_envs
            if self.bar.disable and time.monotonic() - self.last >= 60:
                self.last = time.monotonic()
                print(f"A2C {label}: {self.steps} of {total} steps", file=sys.stderr, flush=True)
            return True

        def _on_training_end(self) -> None:
            self.bar.close()

    return Progress()


def machine_description() -> str:
    """CPU model, core count, memory and accelerator of this machine, one line."""
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
    return (f"{os.cpu_count()} CPU cores ({cpu}), {gpu}; Python {platform.python_version()}, "
            f"torch {torch.__version__}, {platform.system()} {platform.release()}")


def _cell(value: float | None) -> str:
    if value is None:
        return "–"
    text = f"{value:.3f}"
    return text[1:] if text.startswith("0.") else text


def _notes(config: ReproduceConfig, state: dict[str, Any], out: Path | None) -> list[str]:
    """Plain statements of where this run differs from the paper's, from what it measured."""
    notes = []
    for key, scenario in (("sp-strawberry", "sp"), ("mp-vine", "mp")):
        stamp = load_state(out / "models" / f"a2c_{key}.json") if out else {}
        steps, seconds = stamp.get("timesteps"), stamp.get("seconds")
        if steps and seconds:
            rate = steps / seconds
            notes.append(f"A2C on {key} trained for {steps:,} environment steps, "
                         f"{steps / 300_000:.1%} of the paper's 300K: {rate:.1f} steps/s with "
                         f"the paper's network on this CPU (cache build included), so 300K would take about "
                         f"{300_000 / rate / 3600:.1f} h per scenario here. The A2C column is "
                         "therefore an under-trained agent, not the paper's.")
        result = state.get("results", {}).get(scenario)
        if result:
            protocol = result["protocol"]
            scenes = protocol.get("scenes", [])
            if protocol["split"] == "all":
                notes.append(f"{key}: only {len(scenes)} scene(s), so no test scene exists; the "
                             "benchmark ran on split `all`, i.e. on the scene(s) A2C trained on "
                             "(in-sample for A2C; the heuristics and the Oracle do not learn).")
            else:
                notes.append(f"{key}: evaluated on the test split, {len(scenes)} scene(s): "
                             f"{', '.join(scenes)} (70/30 split by scene, seeded).")
    for scenario, result in state.get("results", {}).items():
        lengths = {n: p.get("length", {}).get("mean") for n, p in result["policies"].items()}
        if lengths.get("LRD") is not None and lengths.get("LRD") == lengths.get("UDD"):
            notes.append(f"{scenario.upper()}: LRD and UDD have the same episode lengths because every "
                         "policy plays the same seeded episodes with the same agent seeds, and both "
                         "draw `done` with probability 1/3 at each step (common random numbers).")
    notes.append("Stage times are wall times; a resumed run keeps each scene's own time. Other "
                 "work may share the machine, so rates (e.g. A2C steps/s) can vary between stages.")
    notes.append("Oracle is not in the paper: it plays the best reachable final OER within tau "
                 "steps from the environment's tables, an upper bound for any policy.")
    notes.append("Episode starts follow section V-C: a boxed target with OER < 0.4 and at least the "
                 "crop's pixel threshold; reward max(OER_end - OER_0, 0)^2 at the end.")
    return notes


def write_results_md(path: Path, config: ReproduceConfig, state: dict[str, Any],
                     out: Path | None = None) -> Path:
    """Write the Markdown results: our Table 4 beside the paper's, the setup and the timings.

    Args:
        path: The Markdown file.
        config: The run's configuration.
        state: ``results`` (per scenario) and ``stages`` (seconds and notes).
        out: The work folder, for the training records (``models/*.json``).

    Returns:
        ``path``.
    """
    from davis_ag.atomic_files import write_text_atomic
    from davis_ag.scene.specs import crop_spec, scenario_spec
    from davis_ag.scene.view_grid import views_per_scene

    titles = {"sp": "SP strawberry", "mp": "MP vine"}
    strawberry = crop_spec("strawberry")
    sp_views = views_per_scene(scenario_spec("sp", strawberry), strawberry)
    mp_grid = (f"{config.mp_extent[0]:g} x {config.mp_extent[1]:g} m around the middle vine"
               if config.mp_extent else "Table 2's 7 x 3 m")
    lines = [
        "# Table 4 reproduction",
        "",
        "Written by `davis-ag reproduce` (`make reproduce`). Every number in the *ours* columns "
        "was measured by the run described here; the *paper* columns are Table 4 of the paper.",
        "",
        f"- **Configuration** `{config.name}`: {config.sp_scenes} SP strawberry scene(s) (Table 3's "
        f"grid, {sp_views} views each) and {config.mp_scenes} MP vine scene(s) (grid {mp_grid}, 0.5 m "
        f"step, 12 headings, 2 altitudes) at {config.size[0]}x{config.size[1]}, dataset seed "
        f"{config.seed}; box thresholds scaled by image area; A2C (SB3 defaults, the paper's "
        f"network of section V-B, {config.n_envs} environments) for {config.sp_timesteps:,} (SP) and "
        f"{config.mp_timesteps:,} (MP) environment steps; evaluation {config.sessions} sessions x "
        f"{config.episodes} episodes, seed {config.seed}, A2C deterministic.",
        "- **Paper**: 86 SP strawberry and 44 MP vine scenes at 1280x720 (Table 3), A2C for 300K "
        "steps, 3 sessions x 200 episodes on the test split.",
        f"- **Machine**: {machine_description()}.",
        "",
    ]
    for scenario in ("sp", "mp"):
        lines.append(f"## {titles[scenario]}")
        lines.append("")
        result = state.get("results", {}).get(scenario)
        if not result:
            lines += ["Not run (yet): the run stopped before this benchmark.", ""]
            continue
        protocol, policies = result["protocol"], result["policies"]
        lines.append(f"Split `{protocol['split']}` ({len(protocol.get('scenes', []))} scene(s)), "
                     f"tau = {protocol['tau']}; ours: mean ± std over {protocol['sessions']} "
                     f"sessions of {protocol['episodes']} episodes.")
        lines.append("")
        lines.append("| Policy | OER_tau ours | OER_tau paper | Cum. reward ours | Cum. reward paper "
                     "| Ep. length ours | Ep. length paper |")
        lines.append("|---|---|---|---|---|---|---|")
        for name in ("A2C", "LRD", "UDD", "Rand", "Oracle"):
            if name not in policies:
                continue
            cells = [name]
            for metric in ("oer_tau", "reward", "length"):
                stat = policies[name][metric]
                cells.append(f"{_cell(stat['mean'])} ± {_cell(stat['std'])}")
                cells.append(_cell(PAPER_TABLE4[scenario][metric].get(name)))
            lines.append("| " + " | ".join(cells) + " |")
        if "oer_0" in policies.get("LRD", {}):
            lines += ["", f"Mean start OER (OER_0) of these episodes: "
                          f"{_cell(policies['LRD']['oer_0']['mean'])}."]
        lines.append("")
    lines += ["## Notes", ""] + [f"- {note}" for note in _notes(config, state, out)] + [""]
    lines += ["## Wall time per stage", "", "| Stage | Seconds | Note |", "|---|---|---|"]
    total = 0.0
    for stage, entry in state.get("stages", {}).items():
        total += entry["seconds"]
        lines.append(f"| {stage} | {entry['seconds']:.0f} | {entry['note']} |")
    lines += [f"| total | {total:.0f} | |", ""]
    return write_text_atomic(path, "\n".join(lines) + "\n")
