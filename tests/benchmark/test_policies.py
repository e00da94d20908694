"""The policy protocol and SPECs: a function, a class, a file, a module, SB3 zips of every algorithm."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from davis_ag.benchmark import TVMEnv, evaluate
from davis_ag.benchmark.evaluation import evaluate_policies
from davis_ag.benchmark.exact import start_expectations
from davis_ag.benchmark.policies import ModelPolicy, Policy, policy_from_spec
from davis_ag.benchmark.sb3_models import model_algorithm
from davis_ag.errors import UserError

POLICY_FILE = """
import numpy as np

def always_down(observation, info):
    return "down"

class Wiggle:
    name = "Wiggle"
    def reset(self, seed=None):
        self.rng = np.random.default_rng(seed)
    def act(self, observation, info):
        return int(self.rng.integers(2))

class NoReset:
    def act(self, observation, info):
        return 0

class NeedsArgs:
    def __init__(self, size):
        self.size = size
    def reset(self, seed=None):
        pass
    def act(self, observation, info):
        return 0
"""


@pytest.fixture()
def policy_file(tmp_path: Path) -> Path:
    path = tmp_path / "my_policies.py"
    path.write_text(POLICY_FILE)
    return path


def test_every_spec_form_plays(sp_root: Path, policy_file: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(policy_file.parent))
    monkeypatch.delitem(sys.modules, "my_policies", raising=False)
    policies = [
        policy_from_spec(f"{policy_file}:always_down"),
        policy_from_spec("my_policies:Wiggle"),
        policy_from_spec(f"{policy_file}:always_down", name="mine"),
    ]
    assert [p.name for p in policies] == ["always_down", "Wiggle", "mine"]
    assert all(isinstance(p, Policy) for p in policies)
    results = evaluate(policies, sp_root, scenario="sp", split="all", sessions=1, episodes=6, baselines=["Rand"])
    rows = results.policies
    assert list(rows) == ["always_down", "Wiggle", "mine", "Rand", "Best fixed action"]
    assert rows["always_down"].action_counts["down"] == sum(e.length for e in rows["always_down"].episodes)
    assert set(rows["Wiggle"].action_counts) >= {"forward", "backward"}
    assert rows["always_down"].source == f"{policy_file}:always_down"
    assert set(rows["Wiggle"].paired) == {"Rand", "Best fixed action"} and set(rows["Rand"].paired) == {
        "Best fixed action"
    }


@pytest.mark.parametrize(
    "spec, message",
    [
        ("nowhere.py:act", "no such file"),
        ("no_such_module_here:act", "no module"),
        ("{file}:missing", "has no 'missing'"),
        ("{file}", "name the function or class too"),
        ("/nonexistent/model.zip", "no such model file"),
        ("{file}:NoReset", r"^--policy .*:NoReset: NoReset has act but no reset\(seed\) method"),
        ("{file}:NeedsArgs", r"^--policy .*:NeedsArgs: class NeedsArgs cannot be made without arguments"),
    ],
)
def test_bad_specs_get_one_line(spec: str, message: str, policy_file: Path) -> None:
    with pytest.raises(UserError, match=message) as error:
        policy_from_spec(spec.format(file=policy_file))
    assert "\n" not in str(error.value)


def test_an_action_that_does_not_fit_is_one_line(sp_root: Path) -> None:
    with pytest.raises(UserError, match="policy shout: invalid action 'shout'"):
        evaluate_policies(TVMEnv(sp_root, "sp", "all"), [_named(lambda o, i: "shout", "shout")], episodes=1, sessions=1)
    with pytest.raises(UserError, match="invalid action 99"):
        evaluate_policies(TVMEnv(sp_root, "sp", "all"), [_named(lambda o, i: 99, "far")], episodes=1, sessions=1)


def _named(function, name):
    from davis_ag.benchmark.policies import FunctionPolicy

    return FunctionPolicy(function, name)


def test_a_policy_that_always_plays_one_move_scores_its_exact_oer(sp_root: Path) -> None:
    """Every episode of "always down" ends exactly where the exact computation says its start ends
    (:func:`davis_ag.benchmark.exact.start_expectations` with probability 1 on ``down``)."""
    env = TVMEnv(sp_root, "sp", "all")
    results = evaluate_policies(env, [_named(lambda o, i: "down", "down")], episodes=40, sessions=2, keep_episodes=True)
    exact = start_expectations(env, np.eye(len(env.action_names))[env.action_names.index("down")])
    rows = {}
    for row, (scene, box) in enumerate(env.starts.tolist()):
        cache = env.caches[scene]
        rows[
            (env.scenes[scene].id, cache.view_names[cache.box_view[box]], int(cache.fruit_ids[cache.box_fruit[box]]))
        ] = row
    episodes = results.policies["down"].episodes
    expected = [exact["oer_tau"][rows[(e.scene, e.path[0], e.target_fruit)]] for e in episodes]
    assert [e.oer_tau for e in episodes] == pytest.approx(expected, abs=1e-6)
    assert results.policies["down"].oer_tau.mean == pytest.approx(np.mean(expected), abs=1e-6)


def test_saved_models_name_their_algorithm(sp_root: Path, tmp_path: Path, one_thread: None) -> None:
    """A PPO zip is read as PPO (not as the A2C it would also load as), a DQN as DQN; a model of
    another scenario is refused before any episode."""
    from stable_baselines3 import A2C, DQN, PPO

    from davis_ag.benchmark.networks import ARCHITECTURES

    env = TVMEnv(sp_root, "sp", "all")
    for algorithm, extra in ((A2C, {}), (PPO, {"n_steps": 16, "batch_size": 8}), (DQN, {"buffer_size": 100})):
        model = algorithm("CnnPolicy", env, device="cpu", policy_kwargs=dict(ARCHITECTURES["pooled"]), **extra)
        path = tmp_path / f"{algorithm.__name__.lower()}.zip"
        model.save(path)
        assert model_algorithm(path) == algorithm.__name__
        policy = policy_from_spec(str(path))
        assert isinstance(policy, ModelPolicy) and policy.name == algorithm.__name__
    results = evaluate_policies(env, [policy], episodes=3, sessions=1)
    assert results.policies["DQN"].play == "deterministic"  # its greedy action, whatever the default play
    (tmp_path / "junk.zip").write_bytes(b"not a zip")
    with pytest.raises(UserError, match="not a Stable-Baselines3 model"):
        policy_from_spec(str(tmp_path / "junk.zip"))


def test_a_policy_that_fails_is_one_line_naming_where(sp_root: Path) -> None:
    def broken(observation, info):
        return {}["missing"]

    with pytest.raises(
        UserError, match=r"policy broken: act failed with KeyError: 'missing' \(at .*test_policies.py:\d+\)"
    ):
        evaluate_policies(TVMEnv(sp_root, "sp", "all"), [_named(broken, "broken")], episodes=1, sessions=1)


@pytest.mark.parametrize(
    "source, message",
    [
        ("def act(observation, info)\n    return 0\n", r"broken\.py, line 1: "),
        ("raise RuntimeError('no GPU here')\n", r"importing .*broken\.py raised RuntimeError: no GPU here"),
        ("import sys\nsys.exit(3)\n", r"importing .*broken\.py raised SystemExit: 3"),
        ("import a_package_nobody_installed\n", r"needs module 'a_package_nobody_installed', not installed"),
        ("x = 1\x00\n", r"broken\.py"),
    ],
)
def test_a_policy_file_that_fails_to_import_is_one_line(source: str, message: str, tmp_path: Path) -> None:
    """A syntax error, an exception or sys.exit at import came out as a traceback (or a silent exit)."""
    broken = tmp_path / "broken.py"
    broken.write_text(source)
    with pytest.raises(UserError, match=message) as error:
        policy_from_spec(f"{broken}:act")
    assert "\n" not in str(error.value)


@pytest.mark.parametrize("spec, message", [("", "empty"), (":", "empty"), ("{folder}", "a folder, not a model file")])
def test_an_empty_spec_or_a_folder_says_so(spec: str, message: str, tmp_path: Path) -> None:
    with pytest.raises(UserError, match=message):
        policy_from_spec(spec.format(folder=tmp_path))
