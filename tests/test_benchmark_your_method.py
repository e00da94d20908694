"""docs/benchmark-your-method.md works as written: its file is written, its commands run in order
(generating the small dataset they name), its Python runs, and what they print and write is what
the page says."""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import pytest

from davis_ag import cli

PAGE = Path(__file__).parents[1] / "docs" / "benchmark-your-method.md"


def blocks(text: str) -> list[tuple[str, str | None, str]]:
    """Every fenced block of the page as ``(language, file it is saved as or None, body)``, in order."""
    found = []
    for match in re.finditer(r"(?:<!-- file: (\S+) -->\n)?```(\w+)\n(.*?)```", text, re.S):
        found.append((match.group(2), match.group(1), match.group(3)))
    return found


@pytest.mark.slow
def test_the_page_runs_as_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], one_thread: None
) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.syspath_prepend(str(tmp_path))
    page = blocks(PAGE.read_text())
    assert [(lang, name) for lang, name, _ in page] == [
        ("python", "my_policy.py"),
        ("bash", None),
        ("python", None),
        ("python", None),
        ("bash", None),
        ("bash", None),
    ]
    for language, name, body in page:
        if name:
            Path(name).write_text(body)
        elif language == "bash":
            for line in body.splitlines():
                words = shlex.split(line)
                assert words[0] == "davis-ag"
                assert cli.main(words[1:]) == 0, line
        else:
            exec(compile(body, str(PAGE), "exec"), {})
    printed = capsys.readouterr().out
    heuristic = json.loads(Path("heuristic.json").read_text())["policies"]
    assert list(heuristic) == ["toward_target", "LRD", "UDD", "Rand", "Oracle", "Best fixed action"]
    assert set(heuristic["toward_target"]["paired"]) == {"Best fixed action", "Rand"}
    assert "PPO" in json.loads(Path("ppo.json").read_text())["policies"]
    assert json.loads(Path("ppo.training.json").read_text())["algorithm"] == "PPO"
    board = Path("leaderboard.md").read_text()
    for row in ("toward_target", "PPO", "Oracle", "Best fixed action"):
        assert f"| {row} |" in board
    assert "eligible starts" in board and "3 sessions x 50 episodes" in board
    assert re.search(r"[+-]\d?\.\d{3} \[[+-]\d?\.\d{3}, [+-]\d?\.\d{3}\] over 150 episodes", printed)
    # A leaderboard maintainer's check: both files replay sound on the dataset, and rank as before.
    assert "heuristic.json: sound: 900 episodes of 6 policies replayed on the dataset" in printed
    assert "ppo.json: sound: 900 episodes of 6 policies" in printed
    assert Path("rppo.zip").is_file()  # the recurrent example trained and scored its model
    verified = Path("verified.md").read_text()  # the same rows, each marked how it was checked
    assert "| Checked |" in verified and "| ours |" in verified and "| replayed |" in verified
    assert [line.split("|")[2] for line in verified.splitlines() if line.startswith("| ")] == [
        line.split("|")[2] for line in board.splitlines() if line.startswith("| ")
    ]
    # Its re-run: the rows' code plays every episode again with the same actions.
    assert "toward_target re-run sound with my_policy.py:toward_target: 150 episodes played again" in printed
    assert "PPO re-run sound with ppo.zip: 150 episodes played again" in printed
    checked = Path("rerun.md").read_text()
    assert "| re-run |" in checked and "| ours |" in checked
