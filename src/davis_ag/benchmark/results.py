"""The results file of an evaluation: a documented, versioned schema (pydantic), and the dataset's
identity that decides which results may be ranked together.

One :class:`EvaluationResults` is what :func:`davis_ag.benchmark.evaluate` returns and exactly
what ``davis-ag evaluate --out RESULTS.json`` writes (:meth:`EvaluationResults.as_json`, read back
by :func:`load_results`). docs/benchmark-your-method.md documents every field.

Versions: :data:`PROTOCOL_VERSION` changes whenever a change to the environments, the start
rule, the reward or the evaluation loop would move a number; files of different versions are
never ranked together. Files written before the version was recorded read as version 0.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any, Final, Literal, TypeVar

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from davis_ag.errors import UserError
from davis_ag.formats.scene_file import SceneFile

#: Section V-D's protocol as this code implements it (see the module docstring).
PROTOCOL_VERSION = 1
#: The ``format`` field of every results file.
FORMAT: Final = "davis-ag evaluation results"


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid")


class Metric(_Model):
    """One metric of one policy: mean and population std over sessions (Table 4's ``±``), the
    standard error of the mean over all episodes, and each session's mean."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)  # a NaN mean ranks nowhere

    mean: float
    std: float
    sem: float
    sessions: list[float]


class SceneGap(_Model):
    """A paired gap on one test scene: mean difference, episodes, distinct starts among them."""

    scene: str
    gap: float
    episodes: int
    starts: int


class PairedGap(_Model):
    """Mean OER_tau of a policy minus a baseline's on the same episodes, with the bootstrap
    interval over episodes (:mod:`davis_ag.benchmark.paired`), the gap per test scene and the
    interval over scenes (None with one scene, or in results from before it was given)."""

    gap: float
    low: float
    high: float
    episodes: int
    per_scene: list[SceneGap]
    scene_low: float | None = None
    scene_high: float | None = None

    def text(self) -> str:
        """``+.030 [+.020, +.039]``: the gap and its interval over episodes, as tables print it."""
        return f"{signed_number(self.gap)} [{signed_number(self.low)}, {signed_number(self.high)}]"

    def scenes_text(self) -> str | None:
        """``[+.016, +.048]``: the interval over scenes, as tables print it; None without one."""
        if self.scene_low is None or self.scene_high is None:
            return None
        return f"[{signed_number(self.scene_low)}, {signed_number(self.scene_high)}]"


class Episode(_Model):
    """One episode of one policy. ``path`` holds view names on the grid and poses
    ``[x, y, z, yaw, pitch]`` on the continuous environment; ``actions`` indices or arrays."""

    session: int
    oer_0: float
    oer_tau: float
    reward: float
    length: int
    scene: str
    target_fruit: int
    path: list[Any]
    actions: list[Any]
    refused: int | None = None
    seconds: float | None = None


class CodeDigest(_Model):
    """The code a policy played with (:mod:`davis_ag.benchmark.code_digest`): a SHA-256 of it,
    what was hashed, and the davis-ag that evaluated it."""

    sha256: str = Field(pattern="^[0-9a-f]{64}$")
    of: Literal["model", "parameters", "source", "name"] = Field(
        description="the model's zip, a model's parameters in memory, the policy's source file, or its name"
    )
    file: str | None = Field(default=None, description="the name of the file hashed")
    package: str = Field(description="davis-ag's version")
    commit: str | None = Field(default=None, description="davis-ag's git commit (-dirty: with changes)")

    def short(self) -> str:
        """The first 8 hex digits, as a leaderboard shows them."""
        return self.sha256[:8]


class PolicyResult(_Model):
    """One policy's row: Table 4's metrics and what else the evaluation knows of it."""

    oer_tau: Metric
    reward: Metric
    length: Metric
    oer_0: Metric
    refused: Metric | None = None
    seconds: Metric | None = None
    source: str | None = Field(default=None, description="the SPEC or baseline name it was built from")
    play: str | None = Field(default=None, description="a trained model's play: sampled or deterministic")
    action: str | None = Field(default=None, description="the action of the Best fixed action row")
    action_counts: dict[str, int] | None = None
    mean_abs_action: dict[str, float] | None = None
    exact: dict[str, float] | None = Field(default=None, description="exact expectations of an image-blind policy")
    paired: dict[str, PairedGap] = Field(default_factory=dict, description="gap to each baseline by name")
    digest: CodeDigest | None = Field(default=None, description="the code it played with (None: results from before)")
    episodes: list[Episode] | None = None


class SceneIdentity(_Model):
    """A scene of the dataset as generated: its id, seed, the code version that made it and how
    it was grown and drawn (None for scenes without our scene.json, e.g. the original download).
    The seed follows from the dataset seed alone: two datasets of one seed drawn at other sizes,
    by another renderer, with other plants, another appearance or structures differ only in ``drawn``."""

    id: str
    seed: int | None = None
    code: str | None = None
    drawn: str | None = Field(
        default=None,
        description="digest of scene.json's camera, renderer, plant generator, appearance, grid and box threshold",
    )


class DatasetIdentity(_Model):
    """Which dataset was evaluated: every scene with its seed and code version, and a short hash
    of that list (two copies of one dataset hash alike wherever they lie)."""

    fingerprint: str
    scenes: list[SceneIdentity]


class Protocol(_Model):
    """Section V-D's protocol as run: environment, scenario, split, the split's scenes and
    eligible starts, sessions x episodes, the base seed (episode ``e`` of session ``s`` resets
    with ``SeedSequence([seed, s])``'s ``e``-th state, the policy with ``SeedSequence([seed, s, 1])``'s)."""

    version: int = Field(0, ge=0, le=PROTOCOL_VERSION)
    environment: str = "davis_ag/TVM-v0"
    scenario: Literal["sp", "mp", "row"]
    crop: str | None = None
    split: str
    tau: int = Field(ge=1)
    episodes: int = Field(ge=1)
    sessions: int = Field(ge=1)
    seed: int
    scenes: list[str]
    dataset: str
    actions: list[str]
    start_rule: str | None = None
    split_rule: str | None = Field(
        default=None,
        description="scenes, starts or fruits (davis_ag.formats.splits); None: scenes, as before the rules",
    )
    starts: int | None = None
    aim: str | None = None
    robot: dict[str, str] | None = None


class MeanScore(_Model):
    """A score's mean, population std over sessions and standard error over episodes."""

    mean: float
    std: float
    sem: float


class TrainScore(_Model):
    """A learner's kept model scored on the train split, on fresh episodes of its own."""

    oer_tau: MeanScore
    sessions: int = Field(ge=1)
    episodes: int = Field(ge=1)


class TrainSplit(_Model):
    """The yardstick on the split a learner's snapshot is chosen on (train): every fixed action's
    exact expectations there, the split's eligible starts, and each learner's kept model scored
    there (``davis-ag reproduce`` adds these)."""

    split: str
    starts: int = Field(ge=0)
    fixed_actions: dict[str, dict[str, float]]
    learners: dict[str, TrainScore] | None = None


class EvaluationResults(_Model):
    """An evaluation: its protocol, the dataset's identity, the code, one row per policy."""

    format: Literal["davis-ag evaluation results"] = FORMAT
    protocol: Protocol
    dataset: DatasetIdentity | None = None
    code: str | None = None
    policies: dict[str, PolicyResult] = Field(min_length=1)
    fixed_actions: dict[str, dict[str, float]] | None = None
    train_split: TrainSplit | None = None

    def as_json(self) -> dict[str, Any]:
        """The results as the JSON file holds them (unset optional fields left out)."""
        return self.model_dump(mode="json", exclude_none=True)

    def write(self, path: str | os.PathLike[str]) -> Path:
        """Write the results as indented JSON, atomically."""
        from davis_ag.atomic_files import write_json_atomic

        return write_json_atomic(path, self.as_json(), indent=2)


def as_results(results: EvaluationResults | dict[str, Any]) -> EvaluationResults:
    """Results as the typed object, from the object or from its JSON dict."""
    return results if isinstance(results, EvaluationResults) else EvaluationResults.model_validate(results)


def load_results(path: str | os.PathLike[str], check: bool = True) -> EvaluationResults:
    """Read a results file and, unless ``check`` is False, make every summary in it again from its
    episodes (:func:`davis_ag.benchmark.summaries.check_summaries`): a reader ranks what the
    episodes say, never a number typed into the file.

    Raises:
        UserError: when the file is missing, not JSON, not an evaluation's results, or holds a
            summary its episodes do not give.
    """
    path = Path(path)
    results = read_results_file(path, EvaluationResults, "evaluation results", "davis-ag evaluate")
    if check:
        from davis_ag.benchmark.summaries import check_summaries

        check_summaries(results, str(path))
    return results


ModelT = TypeVar("ModelT", bound=BaseModel)


def read_results_file(path: Path, model: type[ModelT], what: str, writer: str) -> ModelT:
    """A results file read and checked against its schema (summaries not yet checked).

    Args:
        path: The file.
        model: Its pydantic schema.
        what: What it must hold, for the message ("evaluation results").
        writer: The command that writes such a file, for the advice.

    Raises:
        UserError: one line when it cannot be read, is not JSON or does not fit the schema.
    """
    try:
        data = json.loads(path.read_text())
    except OSError as error:
        raise UserError(f"{path}: cannot read it ({error.strerror or error})") from None
    except ValueError as error:
        raise UserError(f"{path}: not JSON ({error}); give a RESULTS.json {writer} wrote") from None
    try:
        return model.model_validate(data)
    except ValidationError as error:
        first = error.errors()[0]
        where = ".".join(str(p) for p in first["loc"])
        raise UserError(
            f"{path}: not davis-ag {what} ({where}: {first['msg']}); give a RESULTS.json {writer} wrote"
        ) from None


def scene_identity(scene_id: str, metadata: SceneFile | None) -> SceneIdentity:
    """A scene's identity from its scene.json (None: a scene without one)."""
    if metadata is None:
        return SceneIdentity(id=str(scene_id))
    code = metadata.generator.version if metadata.generator is not None else None
    drawn = {
        "camera": metadata.camera.as_written() if metadata.camera else None,
        "renderer": metadata.renderer.as_written() if metadata.renderer else None,
        "plants": metadata.plant_generator,
        "appearance": metadata.appearance,
        "grid": metadata.grid.as_written() if metadata.grid else None,
        "min_fruit_pixels": metadata.min_fruit_pixels,
        # Only where built: a scene without a structure hashes as it did before the option.
        **({"structures": metadata.structures} if metadata.structures is not None else {}),
    }
    digest = hashlib.sha256(json.dumps(drawn, sort_keys=True).encode()).hexdigest()[:16]
    return SceneIdentity(id=str(scene_id), seed=metadata.seed, code=code, drawn=digest)


def dataset_identity(scenes: list[SceneIdentity]) -> DatasetIdentity:
    """The identity of a dataset's scenes (sorted by id) and its fingerprint."""
    ordered = sorted(scenes, key=lambda s: s.id)
    # ``drawn`` only where known: the original download hashes as it did before the field.
    text = json.dumps([s.model_dump(exclude={"drawn"} if s.drawn is None else None) for s in ordered], sort_keys=True)
    return DatasetIdentity(fingerprint=hashlib.sha256(text.encode()).hexdigest()[:16], scenes=ordered)


def identify_dataset(root: str | os.PathLike[str]) -> DatasetIdentity | None:
    """The identity of the dataset at ``root`` (every scene), or None when it is not one
    (e.g. a single scene folder given to the continuous environment)."""
    from davis_ag.benchmark.splits import as_dataset

    try:
        dataset = as_dataset(root)
        return dataset_identity([scene_identity(s.id, s.metadata) for s in dataset.scenes])
    except (UserError, OSError, ValueError):
        return None


def split_text(protocol: Protocol) -> str:
    """What a number rests on, to print beside it: the split, its scenes and eligible starts."""
    scenes = protocol.scenes
    shown = ", ".join(scenes[:4]) + (f", ... ({len(scenes) - 4} more)" if len(scenes) > 4 else "")
    starts = f"; {protocol.starts} eligible starts" if protocol.starts is not None else "; starts drawn live"
    rule = f" (split rule {protocol.split_rule})" if protocol.split_rule not in (None, "scenes") else ""
    return (
        f"split {protocol.split}{rule}: {len(scenes)} {protocol.scenario.upper()} scene(s) ({shown}){starts}; "
        f"{protocol.sessions} sessions x {protocol.episodes} episodes, seed {protocol.seed}, tau={protocol.tau}"
    )


def table_number(value: float) -> str:
    """Table 4 style: three decimals, no leading zero below 1 (``.433``)."""
    text = f"{value:.3f}"
    return text[1:] if text.startswith("0.") else text.replace("-0.", "-.")


def signed_number(value: float) -> str:
    """:func:`table_number` with its sign (``+.013``, ``-.027``)."""
    return ("+" if value >= 0 else "") + table_number(value)
