"""Every results row carries a SHA-256 of the code that played, with davis-ag's version and
commit; the leaderboard shows it and tells two rows of one name and different code apart (issue 44)."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest

from davis_ag import __version__, cli
from davis_ag.benchmark.code_digest import code_digest
from davis_ag.benchmark.policies import ModelPolicy, policy_from_spec
from davis_ag.benchmark.tvm import TVMEnv

POLICY = "def act(observation, info):\n    return {move!r}\n"


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _evaluate(sp_root: Path, spec: str, out: Path) -> dict:
    args = ["evaluate", "--dataset", str(sp_root), "--scenario", "sp", "--episodes", "4", "--sessions", "1"]
    assert cli.main([*args, "--policies", "Rand", "--policy", spec, "--out", str(out)]) == 0
    return json.loads(out.read_text())


def test_rows_carry_their_code_and_the_board_tells_two_codes_of_one_name_apart(
    sp_root: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    mine = tmp_path / "mine.py"
    mine.write_text(POLICY.format(move="up"))
    first = _evaluate(sp_root, "mine.py:act", tmp_path / "first.json")
    digest = first["policies"]["act"]["digest"]
    assert digest["sha256"] == _sha(mine) and digest["of"] == "source" and digest["file"] == "mine.py"
    assert digest["package"] == __version__ and digest["commit"]  # a git checkout: its commit
    rand = first["policies"]["Rand"]["digest"]
    assert rand["file"] == "agents.py" and rand["sha256"] != digest["sha256"]
    mine.write_text(POLICY.format(move="down"))  # one name, other code
    second = _evaluate(sp_root, "mine.py:act", tmp_path / "second.json")
    changed = second["policies"]["act"]["digest"]["sha256"]
    assert changed == _sha(mine) != digest["sha256"]
    capsys.readouterr()
    assert cli.main(["compare", "first.json", "second.json"]) == 0
    board = capsys.readouterr().out
    assert "| act | " in board and f"| act (code {changed[:8]}) | " in board
    assert f"`{digest['sha256'][:8]}`" in board and f"`{changed[:8]}`" in board
    assert board.count("| Rand |") == 1  # the same baseline, code and numbers: one row


def test_a_model_is_known_by_its_zip(sp_root: Path, tmp_path: Path, one_thread: None) -> None:
    from stable_baselines3 import A2C

    from davis_ag.benchmark.networks import ARCHITECTURES

    env = TVMEnv(sp_root, "sp", "all")
    model = A2C("CnnPolicy", env, device="cpu", policy_kwargs=dict(ARCHITECTURES["pooled"]))
    path = tmp_path / "a2c.zip"
    model.save(path)
    loaded = policy_from_spec(str(path))
    assert code_digest(loaded).model_dump(include={"sha256", "of", "file"}) == {
        "sha256": _sha(path),
        "of": "model",
        "file": "a2c.zip",
    }
    # A model handed over in memory is known by its parameters: the same weights, the same digest.
    in_memory = code_digest(ModelPolicy(loaded.model))
    assert in_memory.of == "parameters" and in_memory.sha256 == code_digest(ModelPolicy(model)).sha256
    model.policy.state_dict()["action_net.bias"].add_(1.0)
    assert code_digest(ModelPolicy(model)).sha256 != in_memory.sha256
