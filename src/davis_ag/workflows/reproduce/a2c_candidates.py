"""The ``a2c-search`` run's candidates (:mod:`davis_ag.workflows.reproduce.a2c_search`): each A2C
setting set and budget tried on the train split, the target beside them, and where the run keeps
each one's model and the train-split evaluation of them all; one owner for the run, its page and
its status."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from davis_ag.workflows.reproduce.configs import ReproduceConfig
from davis_ag.workflows.reproduce.groups import group_key

#: The page's marker (docs/a2c-search.md), and the run's only split.
MARKER = "a2c-search"
SPLIT = "train"
#: The stage that scores the candidates on the train split.
EVALUATE = "evaluate on train"


@dataclass(frozen=True)
class Candidate:
    """One setting set and budget of the search.

    Attributes:
        key: Its name in file and stage names (``a2c-zoo-atari``: ``models/a2c-zoo-atari_sp-strawberry.zip``).
        label: Its row's name without the steps (``A2C zoo-atari``).
        algo: ``a2c``, or ``ppo`` for the target.
        preset: The setting set (:data:`davis_ag.benchmark.algorithms.SETTINGS_PRESETS`; PPO's
            ``ours`` is the zoo's Atari settings, :data:`~davis_ag.benchmark.algorithms.SB3_SETTINGS`).
        source: Where its settings come from, in words.
        budget: Its steps over the run's (``sp_timesteps``, the paper's 300K).
        over: Settings over the preset's (tests: a short PPO rollout); None: none.
    """

    key: str
    label: str
    algo: str
    preset: str
    source: str
    budget: float = 1.0
    over: dict[str, Any] | None = None

    def timesteps(self, config: ReproduceConfig) -> int:
        """Environment steps it trains for in ``config``'s run."""
        return round(config.sp_timesteps * self.budget)

    def row(self, config: ReproduceConfig) -> str:
        """Its row in the evaluation and on the page (``A2C ours 300K``)."""
        return f"{self.label} {steps_text(self.timesteps(config))}"

    def settings(self) -> dict[str, Any] | None:
        """What :func:`~davis_ag.workflows.reproduce.learners.train_learner` takes: A2C's resolved
        set (with its ``n_envs`` where it carries one), PPO's settings over ours (None: ours)."""
        from davis_ag.benchmark.algorithms import resolve_settings

        if self.algo != "a2c":
            return None if self.over is None else dict(self.over)
        return {**resolve_settings(self.preset), **(self.over or {})}

    def shown_settings(self) -> dict[str, Any]:
        """Every setting it trains with over SB3's defaults, as its training record keeps them."""
        from davis_ag.workflows.reproduce.learners import learner_stamp

        stamp = learner_stamp(self.algo, 0, self.settings())
        return dict(stamp["a2c_settings" if self.algo == "a2c" else "sb3_settings"])


#: The Table 4 run's A2C and PPO, as candidates of both searches.
A2C_OURS = Candidate(
    "a2c-ours",
    "A2C ours",
    "a2c",
    "ours",
    "the Table 4 run's: SB3's A2C defaults with an entropy bonus and normalised advantages",
)
PPO_TARGET = Candidate(
    "ppo-zoo-atari",
    "PPO zoo-atari",
    "ppo",
    "ours",
    "the target, as the Table 4 run trains it: RL Baselines3 Zoo, hyperparams/ppo.yml, `atari`",
)
#: The search (docs/a2c-search.md says why each): our A2C at the paper's budget, the zoo's Atari
#: A2C, SB3's defaults, and the target (PPO as the Table 4 run trains it), in the order the run
#: takes them: the A2C rows the rule chooses among first (an hour each), so the choice is known
#: before the target's 2.7 hours. The longer budget is the paper-scale search's
#: (:data:`PAPER_SCALE_CANDIDATES`): on these 10 scenes our A2C already learns at 300K steps.
CANDIDATES: tuple[Candidate, ...] = (
    A2C_OURS,
    Candidate("a2c-zoo-atari", "A2C zoo-atari", "a2c", "zoo-atari", "RL Baselines3 Zoo, hyperparams/a2c.yml, `atari`"),
    Candidate("a2c-sb3", "A2C sb3", "a2c", "sb3", "Stable-Baselines3's A2C defaults alone"),
    PPO_TARGET,
)
#: The paper-scale search (docs/a2c-search-paper-scale.md): on the Table 4 dataset our A2C does
#: not learn at the paper's budget where PPO does, and PPO passes over each rollout four times
#: (``n_epochs``) where A2C passes once, so the longer budget (10/3 of the paper's: 1M steps) comes
#: first; then ours at the paper's budget and the target, which the Table 4 run of the same rule
#: trains identically (a run folder that holds those finished models reuses them).
PAPER_SCALE_CANDIDATES: tuple[Candidate, ...] = (
    Candidate(
        "a2c-ours-long", "A2C ours", "a2c", "ours", "the Table 4 run's, 10/3 of the paper's budget", budget=10 / 3
    ),
    A2C_OURS,
    PPO_TARGET,
)
#: Each search configuration's candidates, by its name.
SEARCHES: dict[str, tuple[Candidate, ...]] = {
    "a2c-search": CANDIDATES,
    "a2c-search-paper-scale": PAPER_SCALE_CANDIDATES,
}


def candidates_of(config: ReproduceConfig) -> tuple[Candidate, ...]:
    """The candidates a search configuration trains, in its order (:data:`SEARCHES`); the
    10-scene search's for a configuration made from it under another name (tests)."""
    return SEARCHES.get(config.name, CANDIDATES)


def steps_text(steps: int) -> str:
    """``300K``, ``1M``, ``64``: a budget as the page names it."""
    if steps >= 1_000_000 and steps % 1_000_000 == 0:
        return f"{steps // 1_000_000}M"
    return f"{steps // 1000}K" if steps >= 1000 and steps % 1000 == 0 else str(steps)


def group_of(config: ReproduceConfig) -> tuple[str, str, str]:
    """The run's one group: ``(scenario, crop, key)``."""
    scenario, crop = config.pairs[0]
    return scenario, crop, group_key(scenario, crop)


def candidate_model(out: Path, config: ReproduceConfig, candidate: Candidate) -> Path:
    """A candidate's model (``models/a2c-zoo-atari_sp-strawberry.zip``)."""
    from davis_ag.workflows.reproduce.learners import model_path

    return model_path(out, group_of(config)[2], candidate.key)


def results_path(out: Path, config: ReproduceConfig) -> Path:
    """The train-split evaluation of every finished candidate with Rand and the Best fixed action."""
    return out / "results" / f"{group_of(config)[2]}-{SPLIT}.json"
