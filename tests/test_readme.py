"""The README works as written: its commands parse, its Python runs, its links lead somewhere.

The command block is parsed by the real ``davis-ag`` parser (every sub-command, flag and value as
written); running it end to end takes minutes of rendering and training, which `make demo`'s test
covers. The Python block runs on a tiny dataset in the published layout.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from davis_ag.cli import build_parser

ROOT = Path(__file__).parents[1]
README = (ROOT / "README.md").read_text()


def block(start: str, end: str = "```") -> str:
    """The text of the README's fenced block that follows ``start``."""
    after = README[README.index(start):]
    body = after[after.index("```") + 3:]
    return body[body.index("\n") + 1:body.index(end)]


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


def test_the_python_block_runs_on_a_dataset(sp_root: Path, monkeypatch: pytest.MonkeyPatch,
                                             tmp_path: Path) -> None:
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
