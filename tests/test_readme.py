"""The README works as written: its commands parse, its Python runs, its links lead somewhere.

The command block is parsed by the real ``davis-ag`` parser (every sub-command, flag and value as
written); running it end to end takes minutes of rendering and training, which `make demo`'s test
covers. The Python block runs on a tiny dataset in the published layout.
"""

from __future__ import annotations

import argparse
import re
import shlex
from pathlib import Path

import pytest

from davis_ag.cli import build_parser

ROOT = Path(__file__).parents[1]
README = (ROOT / "README.md").read_text()


def block(start: str, end: str = "```") -> str:
    """The text of the README's fenced block that follows ``start``."""
    after = README[README.index(start) :]
    body = after[after.index("```") + 3 :]
    return body[body.index("\n") + 1 : body.index(end)]


def test_the_readme_reads_in_five_minutes() -> None:
    assert len(README.splitlines()) < 250


def test_every_command_in_the_readme_parses_as_written() -> None:
    commands = [line for line in block("## Generate, validate, train, evaluate").splitlines() if line.strip()]
    assert [c.split()[1] for c in commands][:5] == ["generate", "validate", "preview", "train", "evaluate"]
    parser = build_parser()
    for command in commands:
        words = shlex.split(command)
        assert words[0] == "davis-ag"
        try:
            args = parser.parse_args(words[1:])
        except SystemExit as error:  # argparse refuses: a flag or value the README spells wrong
            pytest.fail(f"README: {command!r} does not parse (exit {error.code})")
        assert callable(args.func)


def spelled_variants(command: str) -> list[str]:
    """A command as written in running text, once without its optional ``[...]`` parts and once
    with each of them (each alternative of an ``a|b|c`` value)."""
    optional = re.findall(r"\[([^\]]+)\]", command)
    bare = " ".join(re.sub(r"\[[^\]]+\]", " ", command).split())
    variants = [bare]
    for part in optional:
        *flag, value = part.split()
        variants += [f"{bare} {' '.join([*flag, choice])}" for choice in value.split("|")]
    return variants


def test_every_command_in_the_readmes_text_parses_as_written() -> None:
    """`davis-ag ...` in running text: a bare sub-command name exists, a whole command parses."""
    parser = build_parser()
    spelled = [" ".join(m.split()) for m in re.findall(r"`(davis-ag [^`]+)`", README)]
    assert any("--organs" in command for command in spelled)
    commands = next(a.choices for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for command in spelled:
        words = command.split()
        assert words[1] in commands, f"README: `{command}` names no davis-ag command"
        for variant in spelled_variants(command) if len(words) > 2 else []:
            try:
                args = parser.parse_args(shlex.split(variant)[1:])
            except SystemExit as error:
                pytest.fail(f"README: {variant!r} does not parse (exit {error.code})")
            assert callable(args.func)
            if "--organs" in variant and variant.split()[1:3] == ["export", "yolo"]:
                assert args.task == "segment", "README: export yolo --organs needs --task segment"


def test_the_python_block_runs_on_a_dataset(sp_root: Path, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    (tmp_path / "data").symlink_to(sp_root, target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    code = block("## In Python")
    namespace: dict = {}
    exec(compile(code, "README.md", "exec"), namespace)
    assert namespace["observation"].shape == (224, 224, 4)


def test_every_link_in_the_readme_and_docs_leads_to_a_file() -> None:
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    for page in pages:
        for target in re.findall(r"\]\(([^)#\s]+)\)", page.read_text()):
            if "://" not in target:
                assert (page.parent / target).exists(), f"{page.name}: link to {target} leads nowhere"


@pytest.mark.slow
def test_the_preview_example_shows_fruit_boxed(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The README's preview command, as written but for the output folder, boxes fruit in every view."""
    from davis_ag import cli

    (command,) = [
        line
        for line in block("## Generate, validate, train, evaluate").splitlines()
        if line.startswith("davis-ag preview")
    ]
    words = shlex.split(command)[1:]
    words[words.index("--out") + 1] = str(tmp_path)
    assert cli.main(words) == 0
    boxed = [int(n) for n in re.findall(r": (\d+) fruit boxed", capsys.readouterr().out)]
    assert len(boxed) == len(words[words.index("--views") + 1].split(",")) and min(boxed) > 0
