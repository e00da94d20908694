"""Every help text reads as plain text: no Sphinx markup, no dates (a help says what is, not when)."""

from __future__ import annotations

import re

import pytest

from davis_ag import cli

MARKUP = re.compile(r"``|:(mod|func|class|meth|data|attr|exc):`")
DATE = re.compile(r"\b20\d\d-\d\d-\d\d\b")


@pytest.mark.parametrize("command", ["", *cli.COMMANDS])
def test_help_is_plain_text(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as stopped:
        cli.main([command, "--help"] if command else ["--help"])
    text = capsys.readouterr().out
    assert stopped.value.code == 0 and text.startswith("usage: davis-ag")
    assert not MARKUP.search(text), f"davis-ag {command} --help: {MARKUP.search(text).group()!r}"
    assert not DATE.search(text), f"davis-ag {command} --help: {DATE.search(text).group()!r}"


def test_plain_text_keeps_the_words() -> None:
    assert (
        cli.plain_text("``davis-ag view`` (:mod:`davis_ag.live`, :func:`~davis_ag.cli.main`)")
        == "davis-ag view (davis_ag.live, davis_ag.cli.main)"
    )
