r"""Running many scenes on one local process pool, side by side, without oversubscribing it.

``mbsuite run --all`` runs twenty scenes.  Six of them are sweeps: their cases (creep laws,
speeds, integrators) run on the pool through :func:`core.sweep.run_sweep`, and between the
sweeps the scene's own process computes alone (linear analyses, tables, figures).  The other
fourteen are one process's work each.  Run one after another, a single-process scene leaves every
core but one idle, and so does a sweep between its cases.

The rule
--------
With ``W`` pool processes (one per core by default) and the scenes split into sweep scenes
(:attr:`core.scenes.Scene.sweeps`) and whole scenes:

* the sweep scenes run one after another in this process, their cases on the pool (their own
  order: the listing's);
* the whole scenes run on the pool, each in one worker process, whenever a processor is free:

  .. math::

      n_\text{whole} < W - \min(n_\text{cases}, W) - b

  where :math:`n_\text{whole}` counts the whole scenes running, :math:`n_\text{cases}` the sweep
  cases submitted and not finished, and :math:`b = 1` while this process may compute (from the
  first sweep scene to the end of the last, whenever no case is in flight), else 0.  A sweep
  scene waits for its cases (:func:`core.sweep.run_sweep` does); between them and between the
  scenes it computes.

So at no moment do more than ``W`` processes compute, and a timing that a scene reports (the
work-precision report's run times, the coaster's real-time factor) is that of a process with a
processor to itself, as in a serial run.  A whole scene is never interrupted: a sweep that starts
while one runs has one processor fewer until it ends.

Order of the whole scenes: longest first by their wall time in an earlier run's ``run.json`` in
the output folder (a long scene started last would leave the other processors idle at the end),
otherwise the listing's.

A failed scene fails alone (``error.txt`` in its folder, :func:`core.scenes.run_scene`); the others
go on.  Interrupted (Ctrl-C), the whole scenes not yet started are not started.
"""

from __future__ import annotations

import concurrent.futures
import json
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from .scenes import Scene, SceneError, run_scene

__all__ = ["SceneOutcome", "SlotExecutor", "run_scenes"]


@dataclass(frozen=True)
class SceneOutcome:
    """How one scene of :func:`run_scenes` ended: ``ok``; its tables and figures; its wall time
    (s); where it ran (``"this process"`` or ``"pool"``); the error message of a failed scene."""

    name: str
    ok: bool
    tables: int = 0
    figures: int = 0
    wall_time_s: float = 0.0
    where: str = "this process"
    message: str = ""


def _quiet(iterable, **_kwargs):
    return iterable


def _run_whole_scene(scene: Scene | str, out_dir: str, mode: str) -> SceneOutcome:
    """A whole scene in a pool process: the scene itself, or its name where it does not pickle
    (an example scene's ``run`` is a closure), looked up in the pool process's registry."""
    from .scenes import all_scenes

    start = time.perf_counter()
    name = scene if isinstance(scene, str) else scene.name
    if isinstance(scene, str):
        scene = all_scenes().get(name)
    if scene is None:
        return SceneOutcome(name, False, where="pool", message=f"scene {name!r} is not registered in the pool process")
    try:
        result = run_scene(scene, out_dir, mode=mode, progress=_quiet, executor=None, workers=1)
    except SceneError as exc:
        return SceneOutcome(name, False, wall_time_s=time.perf_counter() - start, where="pool", message=str(exc))
    return SceneOutcome(name, True, len(result.tables), len(result.figures), time.perf_counter() - start, "pool")


class SlotExecutor(concurrent.futures.Executor):
    """The executor the sweep scenes see: the pool's ``submit``, counting the cases in flight for
    the rule of the module docstring.  ``max_workers``: the pool's processes."""

    def __init__(self, pool: concurrent.futures.Executor, max_workers: int, changed: Callable[[int], None]):
        self._pool = pool
        self.max_workers = int(max_workers)
        self._changed = changed

    def submit(self, fn, /, *args, **kwargs):
        """The pool's ``submit(fn, ...)``, counted in flight until the future is done."""
        self._changed(+1)
        try:
            future = self._pool.submit(fn, *args, **kwargs)
        except BaseException:
            self._changed(-1)
            raise
        future.add_done_callback(lambda _f: self._changed(-1))
        return future

    def shutdown(self, wait=True, *, cancel_futures=False):
        """Nothing: the pool belongs to the caller of :func:`run_scenes`."""
        return None


def _picklable(scene: Scene) -> Scene | str:
    import pickle

    try:
        pickle.dumps(scene)
    except Exception:  # a closure, a lambda: the pool process finds the scene by its name
        return scene.name
    return scene


def _earlier_wall_time(out_dir: Path, name: str) -> float:
    try:
        return float(json.loads((out_dir / name / "run.json").read_text(encoding="utf-8"))["wall_time_s"])
    except (OSError, ValueError, KeyError, TypeError):
        return -1.0


def run_scenes(
    scenes: Sequence[Scene],
    out_dir: str | Path,
    pool: concurrent.futures.Executor,
    workers: int,
    mode: str = "default",
    progress: Callable = _quiet,
    report: Callable[[SceneOutcome], None] = lambda outcome: None,
) -> list[SceneOutcome]:
    """Run ``scenes`` into ``out_dir`` on ``pool`` (``workers`` processes) by the rule of the
    module docstring.

    Parameters
    ----------
    scenes : sequence of Scene
    out_dir : str or Path
        Parent output folder (each scene writes its own sub-folder).
    pool : concurrent.futures.Executor
        A local process pool of ``workers`` processes (its processes run the whole scenes by
        name, so the scenes must be registered there too: :func:`core.scenes.all_scenes`).
    workers : int
    mode : str
        ``"fast"``, ``"default"`` or ``"full"``.
    progress : callable
        Progress wrapper for the sweep scenes (``ctx.progress``); the whole scenes run quiet.
    report : callable
        Called with each :class:`SceneOutcome` as the scene ends (from a pool thread for the
        whole scenes).

    Returns
    -------
    list of SceneOutcome
        In the order of ``scenes``.
    """
    out_dir = Path(out_dir)
    sweeps = [s for s in scenes if s.sweeps]
    whole = sorted((s for s in scenes if not s.sweeps), key=lambda s: -_earlier_wall_time(out_dir, s.name))
    cond = threading.Condition()
    state = {"cases": 0, "whole": 0, "main": False, "stop": False}
    outcomes: dict[str, SceneOutcome] = {}
    pending = list(whole)

    def free() -> int:
        return workers - state["whole"] - min(state["cases"], workers) - (1 if state["main"] and not state["cases"] else 0)

    def changed(d: int) -> None:
        with cond:
            state["cases"] += d
            cond.notify_all()

    def whole_done(future: concurrent.futures.Future, name: str) -> None:
        try:
            outcome = future.result()
        except BaseException as exc:  # the pool process died, or the task was cancelled
            outcome = SceneOutcome(name, False, where="pool", message=f"{type(exc).__name__}: {exc}")
        outcomes[name] = outcome
        report(outcome)
        with cond:
            state["whole"] -= 1
            cond.notify_all()

    def feed() -> None:
        while True:
            with cond:
                while pending and not state["stop"] and free() <= 0:
                    cond.wait()
                if state["stop"] or not pending:
                    return
                scene = pending.pop(0)
                state["whole"] += 1
            try:
                future = pool.submit(_run_whole_scene, _picklable(scene), str(out_dir), mode)
            except BaseException as exc:  # a broken or shut-down pool: the scene fails, named
                future = concurrent.futures.Future()
                future.set_exception(exc)
            future.add_done_callback(lambda f, n=scene.name: whole_done(f, n))

    # the pool's processes start before the feeder thread does: a process forked while another
    # thread holds a lock inherits the lock held
    pool.submit(int).result()
    feeder = threading.Thread(target=feed, name="mbsuite-scene-feeder", daemon=True)
    slots = SlotExecutor(pool, workers, changed)
    state["main"] = bool(sweeps)  # from the first sweep scene to the end of the last
    try:
        feeder.start()
        for scene in sweeps:
            start = time.perf_counter()
            try:
                result = run_scene(scene, out_dir, mode=mode, progress=progress, executor=slots, workers=workers)
                outcome = SceneOutcome(scene.name, True, len(result.tables), len(result.figures),
                                       time.perf_counter() - start)
            except SceneError as exc:
                outcome = SceneOutcome(scene.name, False, wall_time_s=time.perf_counter() - start, message=str(exc))
            outcomes[scene.name] = outcome
            report(outcome)
        with cond:
            state["main"] = False
            cond.notify_all()
        feeder.join()
        with cond:
            while state["whole"] > 0:
                cond.wait()
    except BaseException:
        with cond:
            state["stop"] = True
            cond.notify_all()
        raise
    return [outcomes[s.name] for s in scenes if s.name in outcomes]
