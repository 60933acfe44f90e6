"""Collect the documentation's code snippets as tests (issue 22: no snippet can go stale).

Every fenced ```python block of ``README.md`` and ``docs/**/*.md`` is one test item, run by the
pytest-markdown-docs plugin (``pytest_markdown_docs.plugin.MarkdownTextFile``): each block runs on
its own, in a fresh namespace, so it must import what it uses; output and shell listings are
fenced ``text`` / ``console`` / ``bash`` and are not run.  Only these Markdown files are collected
(``testpaths`` in pyproject.toml names them); the plugin's ``--markdown-docs`` flag, which would
also scan every docstring of the test modules, is not needed.  Snippets read data through
``core.paths.data_path(...)``, so they run from any working directory.

Run the snippets alone: ``.venv/bin/python -m pytest -q README.md docs``.
"""

from __future__ import annotations

import os
from pathlib import Path

os.environ.setdefault("MPLBACKEND", "Agg")

import pytest  # noqa: E402

_ROOT = Path(__file__).resolve().parent
_DOCS = _ROOT / "docs"
_SKIP = {"_build", "generated", "auto_examples", "_templates", "_static"}


def _is_doc_page(path: Path) -> bool:
    if path == _ROOT / "README.md":
        return True
    try:
        rel = path.relative_to(_DOCS)
    except ValueError:
        return False
    return not _SKIP.intersection(rel.parts[:-1])


def pytest_collect_file(file_path: Path, parent: pytest.Collector):
    if file_path.suffix == ".md" and _is_doc_page(file_path.resolve()):
        from pytest_markdown_docs.plugin import MarkdownTextFile

        if parent.config.option.markdowndocs:  # the plugin's own hook collects it already
            return None
        return MarkdownTextFile.from_parent(parent, path=file_path)
    return None
