"""Scenes side by side on one process pool (core.scene_scheduler): every scene is written, a
failing one fails alone, and at no moment do more processes compute than the pool has."""

from __future__ import annotations

import concurrent.futures
import multiprocessing
import time

import pandas as pd
import pytest

from core.scene_scheduler import SlotExecutor, run_scenes
from core.scenes import Scene, SceneResult
from core.sweep import executor_workers, run_sweep

WORK = 0.25  # s of "computation" per piece


def _busy(path, label):
    """Record an interval of WORK seconds in which this process computes."""
    t0 = time.time()
    time.sleep(WORK)
    with open(path, "a", encoding="utf-8") as fh:
        fh.write(f"{label} {t0!r} {time.time()!r}\n")


def _case(case):
    _busy(case["log"], f"case-{case['i']}")
    return case["i"] ** 2


def _whole(ctx):
    _busy(ctx.out_dir.parent / "intervals.txt", f"whole-{ctx.out_dir.name}")
    return SceneResult(tables={"done": pd.DataFrame({"x": [1]})})


def _sweep(ctx):
    log = ctx.out_dir.parent / "intervals.txt"
    _busy(log, f"main-{ctx.out_dir.name}")  # before the cases: this process computes
    out = run_sweep(_case, [dict(i=i, log=str(log)) for i in range(3)], executor=ctx.executor)
    _busy(log, f"main-{ctx.out_dir.name}")  # after them
    return SceneResult(tables={"squares": pd.DataFrame({"x": out, "workers": executor_workers(ctx.executor)})})


def _broken(ctx):
    raise RuntimeError("deliberate failure")


def _scenes():
    whole = [Scene(f"whole-{k}", "whole", "", _whole) for k in range(4)]
    sweeps = [Scene(f"sweep-{k}", "sweep", "", _sweep, sweeps=True) for k in range(2)]
    return [whole[0], sweeps[0], whole[1], Scene("broken", "fails", "", _broken), whole[2], sweeps[1], whole[3]]


@pytest.fixture(scope="module")
def ran(tmp_path_factory):
    out = tmp_path_factory.mktemp("side_by_side")
    scenes = _scenes()
    reported = []
    ctx = multiprocessing.get_context("fork")
    with concurrent.futures.ProcessPoolExecutor(max_workers=2, mp_context=ctx) as pool:
        outcomes = run_scenes(scenes, out, pool, 2, mode="fast", report=reported.append)
    return out, scenes, outcomes, reported


def test_every_scene_is_written_and_a_failing_one_fails_alone(ran):
    out, scenes, outcomes, reported = ran
    assert [o.name for o in outcomes] == [s.name for s in scenes]
    assert sorted(o.name for o in reported) == sorted(s.name for s in scenes)
    for o in outcomes:
        assert o.ok == (o.name != "broken"), o
        assert o.where == ("this process" if o.name.startswith("sweep") else "pool")
    assert "deliberate failure" in (out / "broken" / "error.txt").read_text()
    for k in range(2):
        table = pd.read_csv(out / f"sweep-{k}" / "squares.csv")
        assert table["x"].tolist() == [0, 1, 4] and table["workers"].iloc[0] == 2
    assert all((out / f"whole-{k}" / "done.csv").exists() for k in range(4))


def test_no_more_processes_compute_than_the_pool_has(ran):
    out = ran[0]
    spans = [tuple(map(float, line.split()[1:])) for line in (out / "intervals.txt").read_text().splitlines()]
    # 4 whole scenes, 2 sweeps of 2 main pieces and 3 cases
    assert len(spans) == 4 + 2 * (2 + 3)
    events = sorted([(a, 1) for a, _ in spans] + [(b, -1) for _, b in spans], key=lambda e: (e[0], e[1]))
    running = peak = 0
    for _, d in events:
        running += d
        peak = max(peak, running)
    assert peak <= 2
    # and the pool was used: the computing time exceeds the elapsed time (more than one at once)
    busy = sum(b - a for a, b in spans)
    elapsed = max(b for _, b in spans) - min(a for a, _ in spans)
    assert busy > 1.3 * elapsed


def test_the_sweep_scenes_executor_is_the_pools_and_reports_its_processes():
    counts = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=3) as pool:
        ex = SlotExecutor(pool, 3, counts.append)
        assert executor_workers(ex) == 3
        assert ex.submit(pow, 2, 5).result() == 32
    assert sorted(counts) == [-1, 1]


def test_a_pool_that_refuses_work_fails_the_whole_scenes_and_returns(tmp_path):
    """A broken pool (here: shut down) fails every whole scene with its reason; nothing hangs."""
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=2)
    pool.submit(int).result()
    real_submit = pool.submit
    calls = []

    def refuse_scenes(fn, *args, **kwargs):
        calls.append(fn)
        if len(calls) > 1:  # the first is the warm-up; then the pool has been "shut down"
            raise RuntimeError("cannot schedule new futures after shutdown")
        return real_submit(fn, *args, **kwargs)

    pool.submit = refuse_scenes
    scenes = [Scene(f"whole-{k}", "whole", "", _whole) for k in range(3)]
    outcomes = run_scenes(scenes, tmp_path, pool, 2)
    pool.shutdown()
    assert [o.ok for o in outcomes] == [False] * 3
    assert all("cannot schedule new futures" in o.message for o in outcomes)
