"""``davis-ag evaluate --name``: the row name of the ``--policy`` just before it."""

from __future__ import annotations

from davis_ag.cli import build_parser


def _names(*policy_args: str) -> list[str | None]:
    args = build_parser().parse_args(
        ["evaluate", "--dataset", "d", "--scenario", "sp", "--out", "r.json", *policy_args]
    )
    return list(args.policy_names)


def test_a_name_goes_to_the_policy_just_before_it() -> None:
    # The names were paired by position: this named the first policy "second", silently.
    assert _names("--policy", "a.py:f", "--policy", "b.py:g", "--name", "second") == [None, "second"]
    assert _names("--policy", "a.py:f", "--name", "first", "--policy", "b.py:g") == ["first", None]


def test_model_is_a_policy_and_takes_a_name_too() -> None:
    # --model appended to the policies without a name slot: zip() then dropped the last policy.
    assert _names("--policy", "a.py:f", "--model", "b.zip", "--name", "B") == [None, "B"]
    args = build_parser().parse_args(
        ["evaluate", "--dataset", "d", "--scenario", "sp", "--out", "r.json", "--model", "a.zip", "--policy", "b.py:g"]
    )
    assert args.policy == ["a.zip", "b.py:g"] and args.policy_names == [None, None]
