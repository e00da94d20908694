"""``davis-ag plot KIND``: every figure of the paper by name, from a dataset and/or evaluation
results, each written as PNG and SVG with a JSON file of the numbers it shows.

Kinds (paper figure in brackets): ``visibility`` (Fig. 2), ``altitude`` (Fig. 3), ``oer``
(Fig. 4b), ``actions`` (Fig. 4c and 5), ``episode`` (Fig. 6a-g), ``phenotypes`` (Fig. 6h-j and
a contact sheet).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import write_json_atomic
from davis_ag.data.reader import Dataset, Scene, open_dataset, read_json
from davis_ag.errors import UserError
from davis_ag.figures.canvas import FORMATS, Plotted

#: Kind -> what it draws, for ``--help`` and the report.
KINDS: dict[str, str] = {
    "visibility": "visible fruit per camera position, one panel per altitude (Fig. 2)",
    "altitude": "change in visible fruit between altitudes, and fruit newly seen higher up (Fig. 3)",
    "oer": "OER distribution over every fruit instance (Fig. 4b)",
    "actions": "action frequencies per policy and per-episode choices (Fig. 4c, Fig. 5)",
    "episode": "one episode: its views with the target boxed beside the map with the path (Fig. 6)",
    "phenotypes": "plants of the smallest and largest phenotypes side by side, a contact sheet",
}
#: Kinds that need a dataset, and those that need evaluation results.
NEEDS_DATASET = ("visibility", "altitude", "oer", "episode", "phenotypes")
NEEDS_RESULTS = ("actions",)


@dataclass
class PlotRequest:
    """What ``davis-ag plot`` was asked for; unused fields are ignored by a kind.

    Attributes:
        kind: One of :data:`KINDS`.
        out: Output path without suffix (``figures/oer`` -> ``oer.png``, ``oer.svg``, ``oer.json``).
        dataset: Dataset root, group or scene folder (the episode kind falls back to the one the
            results name).
        scene: Scene id (default: the first scene; for ``episode`` from the results).
        results: ``davis-ag evaluate``'s results JSON.
        policy: Policy of Fig. 5 / of the episode.
        episode: Index of the recorded episode to draw.
        start, actions, target: An episode to walk instead of a recorded one.
        formats: Figure formats.
    """

    kind: str
    out: Path
    dataset: Path | None = None
    scene: str | None = None
    results: Path | None = None
    policy: str | None = None
    episode: int = 0
    start: str | None = None
    actions: list[str] = field(default_factory=list)
    target: int | None = None
    formats: tuple[str, ...] = FORMATS


def _results(path: Path) -> dict[str, Any]:
    """Grid results a figure of moves can draw.

    Raises:
        UserError: for a file that is not evaluation results, holds no policy, or records the
            continuous environment's actions (numbers, not grid moves).
    """
    from davis_ag.benchmark.results import load_results
    from davis_ag.figures.benchmark_plots import policy_names

    data = read_json(path, "evaluation results")
    if not isinstance(data, dict) or not isinstance(data.get("policies"), dict):
        raise UserError(
            f'{path}: not `davis-ag evaluate` results (no "policies"); give the JSON '
            "that `davis-ag evaluate --out` wrote"
        )
    policy_names(data, str(path))
    environment = (data.get("protocol") or {}).get("environment") if isinstance(data.get("protocol"), dict) else None
    if environment not in (None, "davis_ag/TVM-v0"):
        raise UserError(
            f"{path}: results of {environment}, whose actions are numbers, not grid moves; these "
            "figures draw TVM-v0 results (evaluate without --env continuous)"
        )
    load_results(path)  # its summaries made again from its episodes: a figure draws what they say
    return data


def _scene(dataset: Dataset, scene_id: str | None) -> Scene:
    return dataset.scene(scene_id) if scene_id else dataset.scenes[0]


def _episode(request: PlotRequest) -> Plotted:
    from davis_ag.figures.episode_plots import episode_from_results, plot_episode, walk

    if request.start is not None:
        if request.dataset is None:
            raise UserError("plot episode --start needs the dataset folder")
        scene = _scene(open_dataset(request.dataset), request.scene)
        path = walk(scene, request.start, request.actions, request.target)
        return plot_episode(scene, path, request.actions, request.target, request.out, request.formats)
    if request.results is None:
        raise UserError(
            "plot episode needs --results RESULTS.json (a recorded episode) or --start "
            "VIEW --actions A,B,... (an episode to walk)"
        )
    results = _results(request.results)
    policy = request.policy or next(iter(results["policies"]))  # _results found at least one
    scene_id, path, actions, target = episode_from_results(results, policy, request.episode, str(request.results))
    root = request.dataset or Path(str(results.get("protocol", {}).get("dataset", "")))
    if not str(root):
        raise UserError(f"{request.results}: names no dataset; give the dataset folder")
    scene = open_dataset(root).scene(scene_id)
    return plot_episode(
        scene,
        path,
        actions,
        target,
        request.out,
        request.formats,
        title=f"{scene.id}, {policy} episode {request.episode}, target fruit {target}",
    )


def make_plot(request: PlotRequest) -> Plotted:
    """Draw one kind of figure and write the numbers behind it beside it (``<out>.json``).

    Args:
        request: What to draw.

    Returns:
        The paths (figures, then the JSON) and the numbers.

    Raises:
        UserError: for an unknown kind, a missing input or input the figure cannot use.
    """
    from davis_ag.figures.benchmark_plots import plot_actions, plot_oer
    from davis_ag.figures.phenotype_plots import plot_phenotypes
    from davis_ag.figures.visibility_plots import plot_altitude, plot_visibility

    kind = request.kind
    if kind not in KINDS:
        raise UserError(f"unknown figure {kind!r}: choose one of {', '.join(KINDS)}")
    if kind in NEEDS_RESULTS and request.results is None:
        raise UserError(f"plot {kind} needs --results RESULTS.json (written by `davis-ag evaluate`)")
    if kind in NEEDS_DATASET and kind != "episode" and request.dataset is None:
        raise UserError(f"plot {kind} needs the dataset folder")
    if kind == "episode":
        plotted = _episode(request)
    elif kind == "actions":
        assert request.results is not None
        plotted = plot_actions(
            _results(request.results),
            request.out,
            request.formats,
            choices_of=request.policy,
            source=str(request.results),
        )
    else:
        assert request.dataset is not None
        dataset = open_dataset(request.dataset)
        if kind == "visibility":
            plotted = plot_visibility(_scene(dataset, request.scene), request.out, request.formats)
        elif kind == "altitude":
            plotted = plot_altitude(_scene(dataset, request.scene), request.out, request.formats)
        elif kind == "oer":
            scenes = [dataset.scene(request.scene)] if request.scene else dataset.scenes
            plotted = plot_oer(scenes, request.out, request.formats)
        else:
            plotted = plot_phenotypes(
                dataset.scenes, request.out, request.formats, sheet_of=_scene(dataset, request.scene)
            )
    base = plotted.paths[0].with_suffix("")
    numbers = base.with_name(f"{base.name}.json")
    try:
        plotted.paths.append(write_json_atomic(numbers, {"kind": kind, **plotted.data}))
    except OSError as error:
        raise UserError(f"{numbers}: cannot write ({error.strerror or error}); choose another --out") from None
    return plotted


def paper_figures(
    root: Path,
    out_dir: Path,
    results: Path | None = None,
    formats: tuple[str, ...] = FORMATS,
    kinds: list[str] | None = None,
) -> dict[str, Plotted]:
    """Draw every kind a dataset (and its results) allows into ``out_dir``, named by kind.

    Kinds the data cannot give (one altitude only, no scene.json, no episodes) are left out
    with their reason instead of failing the rest.

    Args:
        root: The dataset.
        out_dir: Folder of the figures.
        results: ``davis-ag evaluate``'s results, for ``actions`` and ``episode``.
        formats: Figure formats.
        kinds: The kinds to draw (default: all of :data:`KINDS`).

    Returns:
        Kind to what was drawn; ``skipped`` (kind to reason) under the key ``"skipped"`` of
        a :class:`Plotted` with no paths.
    """
    drawn: dict[str, Plotted] = {}
    skipped: dict[str, str] = {}
    for kind in kinds or list(KINDS):
        if kind in ("actions", "episode") and results is None:
            skipped[kind] = "no evaluation results"
            continue
        request = PlotRequest(kind, out_dir / kind, dataset=root, results=results, formats=formats)
        try:
            if kind == "episode" and results is not None:
                request.policy, request.episode = _telling_episode(_results(results))
            drawn[kind] = make_plot(request)
        except UserError as error:
            skipped[kind] = str(error)
    drawn["skipped"] = Plotted([], skipped)
    return drawn


def _telling_episode(results: dict[str, Any]) -> tuple[str | None, int]:
    """The policy with the highest mean OER_tau and its episode of the largest reward: the most
    instructive episode to look at."""
    policies = results.get("policies") or {}
    scored = [(p.get("oer_tau", {}).get("mean", 0.0), n) for n, p in policies.items()]
    if not scored:
        return None, 0
    name = max(scored)[1]
    episodes = policies[name].get("episodes") or []
    rewards = [e.get("reward", 0.0) for e in episodes]
    return name, (rewards.index(max(rewards)) if rewards else 0)
