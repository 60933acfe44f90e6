"""``benchmarks/regression_ab.py`` refuses bad arguments by name, and its timed cases refuse a run
that did not finish (a failed run must never be reported as a fast one).  Nothing is timed here."""

from __future__ import annotations

import importlib.util
import types
from pathlib import Path

import pytest

_SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "regression_ab.py"


@pytest.fixture(scope="module")
def ab():
    spec = importlib.util.spec_from_file_location("regression_ab", _SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_rounds_below_one_refused(ab, capsys):
    with pytest.raises(SystemExit):
        ab.main(["--old", str(_SCRIPT.parents[1]), "--rounds", "0"])
    assert "--rounds must be >= 1, got 0" in capsys.readouterr().err


def test_old_that_is_not_a_checkout_refused(ab, tmp_path, capsys):
    with pytest.raises(SystemExit):
        ab.main(["--old", str(tmp_path), "--rounds", "1"])
    err = capsys.readouterr().err
    assert str(tmp_path) in err and "not a checkout of mbsuite" in err


def test_timed_cases_refuse_an_unfinished_run(ab):
    """The cases' ``best`` (in the script run per round) raises on a run whose status is not
    ``"finished"`` instead of returning its time."""
    ns: dict = {}
    src = ab.CASES
    start = src.index("def best(")
    end = src.index("\nm8, s8 = ")
    exec(compile("import time\n" + src[start:end], "regression_ab.CASES", "exec"), ns)
    done = types.SimpleNamespace(status="finished", message="")
    failed = types.SimpleNamespace(status="failed", message="Newton failed at t = 0.3 s")
    assert ns["best"](lambda: done, 2) >= 0.0
    with pytest.raises(RuntimeError, match="status 'failed': Newton failed at t = 0.3 s"):
        ns["best"](lambda: failed, 2)
