"""``reproduce --learners``: a Table 4 run that trains some of its learners (issue 59's runs on a
machine without the hours for PPO), recorded in the run's configuration and refused elsewhere."""

from __future__ import annotations

from pathlib import Path

import pytest

from davis_ag import cli
from davis_ag.commands.reproduce import configured
from davis_ag.workflows.reproduce.configs import CONFIGS, TABLE4_LEARNERS


def parsed(*flags: str) -> object:
    return cli.build_parser().parse_args(["reproduce", "--out", "run", *flags])


def test_the_learners_flag_chooses_which_learners_a_table4_run_trains() -> None:
    assert configured(parsed("--config", "medium")).learners == TABLE4_LEARNERS == ("a2c", "ppo")
    config = configured(parsed("--config", "medium", "--learners", "A2C", "--split-rule", "starts"))
    assert config.learners == ("a2c",) and config.split_rule == "starts"
    # Everything else is the configuration's own.
    assert config.sp_scenes == CONFIGS["medium"].sp_scenes and config.size == CONFIGS["medium"].size
    assert configured(parsed("--learners", "ppo,a2c,ppo")).learners == ("ppo", "a2c")


@pytest.mark.parametrize(
    ("flags", "said"),
    [
        (["--learners", "sac"], "unknown name 'sac': choose from a2c, ppo"),
        (["--learners", ","], "names nothing"),
        (["--config", "robot", "--learners", "a2c"], "the robot run chooses its own learners"),
    ],
)
def test_a_learner_list_that_cannot_be_run_is_refused_in_one_line_before_anything_starts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], flags: list[str], said: str
) -> None:
    out = tmp_path / "run"
    try:
        code = cli.main(["reproduce", "--out", str(out), *flags])
    except SystemExit as stop:  # argparse's own refusal of a flag's value
        code = stop.code
    assert code == 2
    err = capsys.readouterr().err
    assert said in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not out.exists()
