"""The documentation site (mkdocs.yml) holds every page, and its API page names what exists.

`make docs` builds the site with ``mkdocs build --strict``, which needs MkDocs (the ``docs``
extra); these checks need only the YAML and the package, so `make test` keeps the site honest
without it: a page added to docs/ but not to the nav, or an API entry whose object was renamed
or removed, fails here first.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path
from typing import Any

import pytest
import yaml

ROOT = Path(__file__).parents[1]
CONFIG = yaml.safe_load((ROOT / "mkdocs.yml").read_text())
DOCS = ROOT / CONFIG["docs_dir"]
API_PAGE = DOCS / "api.md"


def nav_pages(entry: Any) -> list[str]:
    """Every page a nav entry (a list, a ``{title: page or list}`` mapping, or a page) names."""
    if isinstance(entry, str):
        return [entry]
    if isinstance(entry, list):
        return [page for item in entry for page in nav_pages(item)]
    if isinstance(entry, dict):
        return [page for value in entry.values() for page in nav_pages(value)]
    raise AssertionError(f"mkdocs.yml: unexpected nav entry {entry!r}")


def api_targets() -> list[str]:
    return re.findall(r"^::: ([\w.]+)\s*$", API_PAGE.read_text(), flags=re.MULTILINE)


def test_every_page_of_docs_is_in_the_nav_once() -> None:
    listed = nav_pages(CONFIG["nav"])
    assert len(listed) == len(set(listed)), "mkdocs.yml: a page is in the nav twice"
    pages = {path.relative_to(DOCS).as_posix() for path in DOCS.rglob("*.md")}
    left_out = set(CONFIG.get("not_in_nav", "").split())
    assert pages - left_out == set(listed), "mkdocs.yml's nav and the pages of docs/ differ"


def test_the_site_is_built_where_git_ignores_it() -> None:
    assert CONFIG["site_dir"].startswith("out/")
    assert "/out/" in (ROOT / ".gitignore").read_text().split()


def test_the_site_checks_every_link_and_anchor() -> None:
    assert CONFIG["validation"] == {
        "omitted_files": "warn",
        "absolute_links": "warn",
        "unrecognized_links": "warn",
        "anchors": "warn",
    }


def test_the_api_page_documents_the_public_api() -> None:
    targets = api_targets()
    assert len(targets) == len(set(targets))
    for name in ("open_dataset", "TVMEnv", "TVMContinuousEnv", "evaluate", "load_results", "policy_from_spec"):
        assert any(target.endswith(f".{name}") for target in targets), name


@pytest.mark.parametrize("target", api_targets())
def test_every_api_target_imports(target: str) -> None:
    """Each ``::: davis_ag.module.Name`` is a module and an attribute it has (mkdocstrings reads
    them statically from src/, so the object must be defined or re-exported there by name)."""
    module_name, _, attribute = target.rpartition(".")
    module = importlib.import_module(module_name)
    assert attribute in vars(module), f"{module_name} has no {attribute}"
    assert getattr(module, attribute).__doc__, f"{target} has no docstring"
