"""``verify --policy NAME=SPEC``: a row's code played again must give every recorded action."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from davis_ag.benchmark.evaluation import evaluate
from davis_ag.cli import main
from davis_ag.errors import UserError
from davis_ag.mapping.evaluation import evaluate_mapping
from davis_ag.workflows.stages.rerun import parse_policy_arguments
from layout_factory import write_tiny_dataset

POLICY = '''
import numpy as np

def toward(observation, info):
    """Right while the target's box lies right of centre, else left; up every third step."""
    columns = np.flatnonzero(observation[:, :, 3].any(axis=0))
    if info["steps"] % 3 == 2:
        return "up"
    return "right" if len(columns) and columns.mean() > 112 else "left"

class Drawn:
    """A sampling policy: its draws come from the seed evaluate gives it."""
    def reset(self, seed=None):
        self.rng = np.random.default_rng(seed)
    def act(self, observation, info):
        return int(self.rng.integers(6))
'''


@pytest.fixture(scope="module")
def setup(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("rerun")
    data = write_tiny_dataset(folder / "data", "sp", "strawberry", scenes=2)
    (folder / "mine.py").write_text(POLICY)
    return data, folder


def _evaluated(data: Path, folder: Path, *specs: str) -> Path:
    results = evaluate(list(specs), data, "sp", "test", sessions=2, episodes=6, baselines=["Rand", "Oracle"])
    return results.write(folder / f"results-{len(specs)}.json")


def test_a_file_policy_and_a_sampling_class_re_run_sound(
    setup: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    data, folder = setup
    mine, drawn = f"{folder}/mine.py:toward", f"{folder}/mine.py:Drawn"
    path = _evaluated(data, folder, mine, drawn)
    argv = ["verify", str(path), "--dataset", str(data), "--policy", f"toward={mine}", "--policy", f"Drawn={drawn}"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "toward re-run sound" in out and "Drawn re-run sound" in out and "12 episodes played again" in out


def test_a_row_replaced_by_the_oracles_is_refused_at_its_first_episode(
    setup: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data, folder = setup
    mine = f"{folder}/mine.py:toward"
    data_json = json.loads(_evaluated(data, folder, mine).read_text())
    forged = dict(data_json["policies"]["Oracle"])
    forged["digest"] = data_json["policies"]["toward"]["digest"]  # the name and the digest kept
    forged["source"] = data_json["policies"]["toward"]["source"]
    data_json["policies"]["toward"] = forged
    path = tmp_path / "forged.json"
    path.write_text(json.dumps(data_json))
    assert main(["verify", str(path), "--dataset", str(data)]) == 0  # the replay alone: sound
    capsys.readouterr()
    assert main(["verify", str(path), "--dataset", str(data), "--policy", f"toward={mine}"]) == 1
    out = capsys.readouterr().out
    assert "toward not re-run sound" in out and "session 0 episode" in out and "actions is" in out


def test_other_code_is_refused_by_its_digest(setup: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    data, folder = setup
    path = _evaluated(data, folder, f"{folder}/mine.py:toward")
    (folder / "other.py").write_text(POLICY + "\n# changed\n")
    assert main(["verify", str(path), "--dataset", str(data), "--policy", f"toward={folder}/other.py:toward"]) == 1
    assert "code digest is" in capsys.readouterr().out


def test_a_mapping_row_re_runs_too(
    setup: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data, folder = setup
    spec = f"{folder}/mine.py:toward"
    results = evaluate_mapping([spec], data, "sp", "all", 1, 4, 0, budget=4, baselines=["Rand"])
    path = results.write(tmp_path / "mapping.json")
    assert main(["verify", str(path), "--dataset", str(data), "--policy", f"toward={spec}"]) == 0
    assert "toward re-run sound" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("values", "message"),
    [(["mine"], "give NAME=SPEC"), (["=x.py:f"], "give NAME=SPEC"), (["a=x.py:f", "a=y.py:g"], "given twice")],
)
def test_bad_policy_arguments_are_one_line(values: list[str], message: str) -> None:
    with pytest.raises(UserError, match=message):
        parse_policy_arguments(values)


def test_an_unknown_row_and_a_missing_file_are_one_line(
    setup: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    data, folder = setup
    path = _evaluated(data, folder, f"{folder}/mine.py:toward")
    assert main(["verify", str(path), "--dataset", str(data), "--policy", "nobody=x.py:f"]) == 2
    assert "has no row 'nobody'" in capsys.readouterr().err
    assert main(["verify", str(path), "--dataset", str(data), "--policy", "toward=missing.py:toward"]) == 2
    err = capsys.readouterr().err
    assert "missing.py" in err and len(err.strip().splitlines()) == 1


def test_compare_ranks_only_rows_re_run_and_ours(setup: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    data, folder = setup
    mine, drawn = f"{folder}/mine.py:toward", f"{folder}/mine.py:Drawn"
    path = _evaluated(data, folder, mine, drawn)
    assert main(["compare", str(path), "--verify", str(data), "--policy", f"toward={mine}"]) == 0
    out = capsys.readouterr().out
    rows = {
        line.split("|")[2].strip(): line.split("|")[-2].strip()
        for line in out.splitlines()
        if line.startswith("| ") and line[2].isdigit()
    }
    assert rows["toward"] == "re-run" and rows["Oracle"] == "ours" and rows["Rand"] == "ours"
    assert "Drawn" not in rows and "Not ranked (their code was not re-run" in out and "Drawn (" in out
    assert main(["compare", str(path), "--policy", f"toward={mine}"]) == 2  # a re-run needs the dataset
    assert main(["compare", str(path), "--verify", str(data)]) == 0
    assert "| replayed |" in capsys.readouterr().out  # without code given: every row, marked replayed
