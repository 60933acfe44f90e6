"""Shared pytest configuration for the mbsuite test-suite.

* ``MPLBACKEND=Agg`` so no test ever opens a window (set before matplotlib is imported).
* Tests marked ``@pytest.mark.slow`` (paper reproductions) are skipped unless
  ``pytest --runslow`` is given.
"""

from __future__ import annotations

import os

os.environ.setdefault("MPLBACKEND", "Agg")

import pytest  # noqa: E402  (the environment must be set first)


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--runslow", action="store_true", default=False, help="also run tests marked slow")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if config.getoption("--runslow"):
        return
    skip_slow = pytest.mark.skip(reason="slow reproduction; run with --runslow")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip_slow)
