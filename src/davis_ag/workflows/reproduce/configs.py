"""The sizes ``davis-ag reproduce`` runs at (``small``, ``medium``, ``paper-scale``: Table 4; ``crops``:
the plant-library crops' ladder), what each is comparable with, and the disk each needs: one owner
for docs/benchmark.md's table of them.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass, replace
from pathlib import Path

from davis_ag.benchmark.cache import OBS_SIZE
from davis_ag.scene.specs import PAPER_IMAGE_SIZE, PAPER_TABLE3, CropSpec, ScenarioSpec, crop_spec, scenario_spec
from davis_ag.workflows.reproduce.groups import (
    CROPS_PAIRS,
    MAPPING_PAIRS,
    ROBOT_PAIRS,
    SCENARIO_CROPS,
    STRUCTURE_PAIRS,
    group_key,
)

#: The learners a Table 4 run trains beside the baselines, in the order they train (``--learners``
#: chooses among them).
TABLE4_LEARNERS: tuple[str, ...] = ("a2c", "ppo")


@dataclass(frozen=True)
class ReproduceConfig:
    """One reproduction's size.

    Attributes:
        name: ``small``, ``medium``, ``paper-scale`` or ``crops``.
        size: Image width and height.
        sp_scenes, mp_scenes: Scenes of each SP group, and of each MP or row group (Table 4: SP
            strawberry and MP vine).
        mp_extent: MP grid extent (x, y) in metres; ``None`` keeps section III-B's 7 x 3 m.
        sp_timesteps, mp_timesteps: Environment steps per scenario of each learner.
        n_envs: Parallel environments of each learner.
        episodes, sessions: Evaluation protocol (200 x 3 in the paper).
        seed: Dataset, training and evaluation seed.
        learners: The algorithms trained (:data:`davis_ag.benchmark.algorithms.ALGORITHMS`), each
            with the same steps, seed, network, train split and keep rule: the paper's ``a2c``
            and, beside it, ``ppo`` with RL Baselines3 Zoo's Atari settings.
        pairs: The run's ``(scenario, crop)`` groups, in the order it takes them.
        page: The page the run writes: ``table4`` (docs/results.md), ``crops`` (docs/crops.md),
            ``mapping`` (docs/mapping.md), ``robot`` (docs/robot.md), ``structures`` (a section
            of docs/crops.md) or ``a2c-search`` (docs/a2c-search.md and
            docs/a2c-search-paper-scale.md; their candidates:
            :func:`davis_ag.workflows.reproduce.a2c_candidates.candidates_of`).
        robots: The robots each row is played with beside none (the ``robot`` run).
        split_rule: How train and test split (:mod:`davis_ag.formats.splits`): ``scenes``
            (default) or ``starts``; the learners train and everything is scored under it.
        structures: The rows' structures (:mod:`davis_ag.scene.structures`): ``none``, the bare
            rows every published run was made of, so a run made before the option resumes and
            its pages stay reproducible.
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
    learners: tuple[str, ...] = TABLE4_LEARNERS
    pairs: tuple[tuple[str, str], ...] = SCENARIO_CROPS
    page: str = "table4"
    robots: tuple[str, ...] = ()
    split_rule: str = "scenes"
    structures: str = "none"

    def scenes(self, scenario_name: str) -> int:
        """How many scenes the run makes of a scenario (``sp``; ``mp`` or ``row``)."""
        return self.sp_scenes if scenario_name == "sp" else self.mp_scenes

    def timesteps(self, scenario_name: str) -> int:
        """Environment steps each learner trains for on a scenario (``sp``; ``mp`` or ``row``)."""
        return self.sp_timesteps if scenario_name == "sp" else self.mp_timesteps

    def scenes_in_words(self) -> str:
        """What the run makes: ``10 SP strawberry and 10 MP vine scenes`` (Table 4's runs), or per
        crop for the crops run."""
        if self.page == "table4":
            return f"{self.sp_scenes} SP strawberry and {self.mp_scenes} MP vine scenes"
        if self.page == "a2c-search":
            return f"{self.sp_scenes} SP strawberry scenes"
        if self.page in ("mapping", "robot", "structures"):
            return f"{self.mp_scenes} row scene(s) of each of {len(self.pairs)} crops"
        crops = len({crop for _, crop in self.pairs})
        return f"{self.sp_scenes} SP and {self.mp_scenes} row scenes of each of {crops} crops"

    def result_key(self, scenario_name: str, crop_name: str) -> str:
        """Where ``state.json`` keeps a group's results: by scenario for Table 4's two groups (as
        runs have always kept them), by group for the crops run."""
        return scenario_name if self.page == "table4" else group_key(scenario_name, crop_name)

    def specs(self, scenario_name: str, crop_name: str) -> tuple[ScenarioSpec, CropSpec]:
        """The scenario and crop of one group of the run, the MP grid cut to :attr:`mp_extent`."""
        crop = crop_spec(crop_name)
        scenario = scenario_spec(scenario_name, crop)
        if scenario_name == "mp" and self.mp_extent:
            scenario = replace(scenario, extent=self.mp_extent)
        return scenario, crop


#: ``small``: under an hour of stages on a 2-core CPU machine without GPU;
#: a 3 x 2 m MP grid and 10 % / 5 % of the paper's A2C steps: not comparable with Table 4.
#: ``medium``: the paper's grids (SP strawberry's 2.5 x 2.5 m, read from Table 3's 285 views, not
#: section III-B's 3 x 3 m; section III-B's 7 x 3 m MP) and protocol (300K A2C steps,
#: 3 sessions of 200 episodes) on 10 SP strawberry and 10 MP vine scenes at 640x360 (the policy
#: sees 224x224 either way; the 70/30 split leaves 3 test scenes of each), a few hours on such a
#: machine, resumable across sittings.
#: ``paper-scale``: Table 3's scene counts at 1280x720 and 300K steps of each learner, many sittings
#: on such a machine (its results page gives the hours of every stage).
#: ``crops``: every plant-library crop, 10 SP and 4 row scenes at 640x360, 20K steps of each
#: learner per group: about a night of such a machine per sitting's worth of groups, resumable
#: (docs/crops.md is its page).
#: ``mapping``: row mapping on five of the crops run's rows (apple-wall, VSP vine, capsicum, cherry
#: tomato, olive), one row scene each at 320x180 with dataset seed 5 (apple-wall's is docs/robot.md's
#: row), every baseline at three seen fractions; no learner (docs/mapping.md is its page).
#: ``robot``: the apple-wall, VSP vine and capsicum rows (docs/robot.md's reach rows: 320x180,
#: dataset seed 5), two scenes each (one trains, one tests), played without a robot and with each
#: named robot; every baseline, and A2C and PPO trained under each robot for 10K steps (half the
#: crops run's; the table sets them beside Rand and the Best fixed action).
#: ``structures``: the fruiting wall, VSP vine, capsicum and Wye vine rows of the robot run's size
#: (320x180, dataset seed 5, two scenes each), made bare and with their structures from the same
#: seeds; every baseline, and A2C and PPO for 10K steps on each (docs/crops.md's section).
#: ``a2c-search``: the ``medium`` run's SP strawberry group (10 scenes at 640x360, dataset seed 0),
#: on whose train split A2C is trained under each candidate setting set and budget beside PPO with
#: the zoo's Atari settings, every model scored on fresh train-split episodes; the test split is
#: never read (docs/a2c-search.md is its page; the candidates: ``a2c_candidates.CANDIDATES``).
#: ``a2c-search-paper-scale``: the same on the ``paper-scale`` run's SP strawberry group (86 scenes
#: at 1280x720, dataset seed 0: the Table 4 dataset, which a link at ``OUT/dataset`` shares) under
#: the ``starts`` rule, the longer budget first (docs/a2c-search-paper-scale.md; its candidates:
#: ``a2c_candidates.PAPER_SCALE_CANDIDATES``).
#: Scene counts of Table 3 (SP strawberry, MP vine), what a configuration is measured against.
PAPER_SCENES = (PAPER_TABLE3["sp", "strawberry"][0], PAPER_TABLE3["mp", "vine"][0])
CONFIGS: dict[str, ReproduceConfig] = {
    "small": ReproduceConfig(
        "small", (640, 360), sp_scenes=3, mp_scenes=2, mp_extent=(3.0, 2.0), sp_timesteps=30_000, mp_timesteps=15_000
    ),
    "medium": ReproduceConfig(
        "medium", (640, 360), sp_scenes=10, mp_scenes=10, mp_extent=None, sp_timesteps=300_000, mp_timesteps=300_000
    ),
    "paper-scale": ReproduceConfig(
        "paper-scale",
        PAPER_IMAGE_SIZE,
        sp_scenes=PAPER_SCENES[0],
        mp_scenes=PAPER_SCENES[1],
        mp_extent=None,
        sp_timesteps=300_000,
        mp_timesteps=300_000,
    ),
    "crops": ReproduceConfig(
        "crops",
        (640, 360),
        sp_scenes=10,
        mp_scenes=4,
        mp_extent=None,
        sp_timesteps=20_000,
        mp_timesteps=20_000,
        pairs=CROPS_PAIRS,
        page="crops",
    ),
    "mapping": ReproduceConfig(
        "mapping",
        (320, 180),
        sp_scenes=0,
        mp_scenes=1,
        mp_extent=None,
        sp_timesteps=0,
        mp_timesteps=0,
        seed=5,
        learners=(),
        pairs=MAPPING_PAIRS,
        page="mapping",
    ),
    "robot": ReproduceConfig(
        "robot",
        (320, 180),
        sp_scenes=0,
        mp_scenes=2,
        mp_extent=None,
        sp_timesteps=0,
        mp_timesteps=10_000,
        seed=5,
        pairs=ROBOT_PAIRS,
        page="robot",
        robots=("ur10-lift", "ur5-trolley", "panda-trolley"),
    ),
    "structures": ReproduceConfig(
        "structures",
        (320, 180),
        sp_scenes=0,
        mp_scenes=2,
        mp_extent=None,
        sp_timesteps=0,
        mp_timesteps=10_000,
        seed=5,
        pairs=STRUCTURE_PAIRS,
        page="structures",
        structures="default",
    ),
    "a2c-search": ReproduceConfig(
        "a2c-search",
        (640, 360),
        sp_scenes=10,
        mp_scenes=0,
        mp_extent=None,
        sp_timesteps=300_000,
        mp_timesteps=0,
        pairs=(("sp", "strawberry"),),
        page="a2c-search",
    ),
    "a2c-search-paper-scale": ReproduceConfig(
        "a2c-search-paper-scale",
        PAPER_IMAGE_SIZE,
        sp_scenes=PAPER_SCENES[0],
        mp_scenes=0,
        mp_extent=None,
        sp_timesteps=300_000,
        mp_timesteps=0,
        pairs=(("sp", "strawberry"),),
        page="a2c-search",
        split_rule="starts",
    ),
}

#: Bytes one 1280x720 view writes (JPEG 0.36 MB, depth 0.07 MB, masks and classes), measured on
#: canopy-plant scenes; other sizes scale it by their pixel count, and once scenes exist their
#: own mean is used instead.
BYTES_PER_VIEW_720P = 0.46e6
#: Bytes one view takes in the observation cache (224 x 224 x 4 uint8, :mod:`davis_ag.benchmark.cache`).
CACHE_BYTES_PER_VIEW = OBS_SIZE * OBS_SIZE * 4
#: Room left free beyond the estimate, for models, results and the estimate's error.
DISK_MARGIN = 1.1

#: Marker of docs/benchmark.md's table of the configurations (:func:`configurations_table`).
CONFIGS_MARKER = "reproduce-configs"


def beside_table4(config: ReproduceConfig) -> str:
    """What a configuration's numbers can be read beside in Table 4.

    Returns:
        ``Table 3's scenes and images``; for the paper's grids, protocol and steps on fewer scenes
        or smaller images, how it differs; else ``not comparable: a smoke test of every stage``.
    """
    scenes = (config.sp_scenes, config.mp_scenes)
    if scenes == PAPER_SCENES and config.size == PAPER_IMAGE_SIZE:
        return "Table 3's scenes and images"
    if config.mp_extent is None and (config.sp_timesteps, config.mp_timesteps) == (300_000, 300_000):
        return (
            f"grids, protocol and training as the paper's; {sum(scenes)} scenes instead of "
            f"{sum(PAPER_SCENES)}, {config.size[0]}x{config.size[1]} images"
        )
    return "not comparable: a smoke test of every stage"


def configurations_table() -> str:
    """docs/benchmark.md's table of :data:`CONFIGS`, written from them so the page follows the code.

    Returns:
        A Markdown table: scenes, grid, image size, learners, their steps and disk space of each
        configuration.
    """
    rows = [
        "| configuration | SP strawberry | MP vine | images | learners | steps each (SP / MP) "
        "| disk (views and caches) | beside Table 4 |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for config in (c for c in CONFIGS.values() if c.page == "table4"):
        grid = (
            f"{config.mp_extent[0]:g} x {config.mp_extent[1]:g} m grid"
            if config.mp_extent
            else "the paper's 7 x 3 m grid"
        )
        rows.append(
            f"| `{config.name}` | {config.sp_scenes} scenes | {config.mp_scenes} scenes, {grid} | "
            f"{config.size[0]}x{config.size[1]} | {', '.join(a.upper() for a in config.learners)} "
            f"| {config.sp_timesteps // 1000}K / "
            f"{config.mp_timesteps // 1000}K | {disk_needed(config) / 1e9:.1f} GB "
            f"| {beside_table4(config)} |"
        )
    return "\n".join(rows)


def disk_needed(
    config: ReproduceConfig,
    root: Path | None = None,
    pairs: list[tuple[str, str]] | tuple[tuple[str, str], ...] = SCENARIO_CROPS,
) -> int:
    """Bytes the run still has to write under its dataset ``root``: the scenes not yet complete
    and the observation caches not yet built.

    Args:
        config: The size of the run.
        root: The dataset root (``OUT/dataset``); what is complete there is not counted. None
            for a run not started.
        pairs: ``(scenario, crop)`` pairs to run.

    Returns:
        An estimate in bytes, the measured per-view size of finished scenes where there are some.
    """
    from davis_ag.benchmark.cache import CACHE_FOLDER
    from davis_ag.generate.dataset_files import complete_scenes
    from davis_ag.scene.specs import group_name
    from davis_ag.scene.view_grid import views_per_scene

    root = root or Path("/nonexistent")
    done = set(complete_scenes(root))
    written = [p for scene in done for p in (root / scene).rglob("*") if p.is_file()]
    done_views = sum(1 for p in written if p.suffix == ".jpeg")
    width, height = config.size
    per_view = (
        sum(p.stat().st_size for p in written) / done_views
        if done_views
        else BYTES_PER_VIEW_720P * width * height / (1280 * 720)
    )
    needed = 0.0
    for scenario_name, crop_name in pairs:
        scenario, crop = config.specs(scenario_name, crop_name)
        views = views_per_scene(scenario, crop)
        n = config.scenes(scenario_name)
        group = group_name(scenario, crop)
        cache_folders = [f"{group}/{p.name}" for p in (root / CACHE_FOLDER / group).glob("*")]
        made = sum(_among_first(folder, group, n) for folder in done)
        cached = sum(_among_first(folder, group, n) for folder in cache_folders)
        needed += views * (per_view * (n - made) + CACHE_BYTES_PER_VIEW * (n - cached))
    return int(needed)


def _among_first(folder: str, group: str, n: int) -> bool:
    """Whether a scene folder is one of a run's ``n`` scenes of ``group`` (``GROUP/000`` to ``n - 1``)."""
    name, _, index = folder.partition("/")
    return name == group and index.isascii() and index.isdigit() and int(index) < n


def check_disk(
    config: ReproduceConfig, out: Path, pairs: list[tuple[str, str]] | tuple[tuple[str, str], ...] = SCENARIO_CROPS
) -> None:
    """Refuse, before anything is written, a run whose files the disk under ``out`` cannot hold.

    Raises:
        UserError: when the free space is below :func:`disk_needed` with a 10 % margin.
    """
    from davis_ag.errors import UserError

    needed = disk_needed(config, out / "dataset", pairs) * DISK_MARGIN
    free = free_bytes(out)
    if free < needed:
        raise UserError(
            f"reproduce --config {config.name} needs about {needed / 1e9:.1f} GB more under {out} "
            f"and the disk has {free / 1e9:.1f} GB free: free space, or pass --out on a larger disk"
        )


def free_bytes(out: Path) -> int:
    """Free bytes on the disk that holds ``out``'s dataset (a linked dataset: the link's disk), or
    ``out``'s nearest existing parent for a run not started."""
    probe = next(p for p in (out / "dataset", out, *out.parents) if p.exists())
    return shutil.disk_usage(probe).free


def disk_line(config: ReproduceConfig, out: Path) -> str:
    """For ``--status``: what each group still has to write under ``out/dataset`` (with the margin
    :func:`check_disk` asks) beside the free space, and which groups do not fit, so a long run's
    next sitting (or its ``--only`` half) is planned before it is refused."""
    root = out / "dataset"
    needs = {group_key(s, c): disk_needed(config, root, [(s, c)]) * DISK_MARGIN for s, c in config.pairs}
    free = free_bytes(out)
    line = "Disk, still to write under the dataset (scenes and observation caches not yet made, 10 % margin): "
    line += ", ".join(f"{key} {need / 1e9:.1f} GB" for key, need in needs.items())
    line += f"; {free / 1e9:.1f} GB free there"
    if sum(needs.values()) <= free:
        return line + "."
    over = [key for key, need in needs.items() if need > free]
    if over:
        return line + f": {', '.join(over)} cannot fit; free space, or move the run to a larger disk."
    return line + ": not all at once; run a group at a time (`--only`), or free space."
