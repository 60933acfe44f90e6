"""The work-precision scene: the report of ``make run`` (``mbsuite run work-precision``).

:func:`work_precision_scenes` returns the scene; :mod:`core.demo_scenes` registers it with core's
other scenes (:func:`core.scenes.register_scene`).  The scene runs a problem set of
:mod:`core.benchmarks.problems` through :func:`core.benchmarks.harness.run_problem_set` and writes
the tables, figures and summary of :mod:`core.benchmarks.report`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from .harness import run_problem_set
from .problems import PROBLEM_SETS, PROBLEMS
from .report import fastest_to_tolerance, report_table, work_precision_figure

__all__ = ["work_precision_scenes"]


def _default_jobs() -> int:
    import os

    env = os.environ.get("MBSUITE_JOBS")
    if env:
        return max(1, int(env))
    return max(1, min(2, os.cpu_count() or 1))


def _scene_notes(problems: Sequence[str], grid: str, jobs: int) -> str:
    lines = [(f"Grid `{grid}`; {jobs} worker process(es) (solves run concurrently when > 1, which may "
              "inflate wall times slightly). Wall time = median over repeats of the time inside the "
              "integrator steps. Fixed-step methods: Newton tolerance rtol = atol = 1e-10; "
              "error-controlled methods: atol = rtol."),
             "", "| problem | error measure | reference |", "|---|---|---|"]
    for name in problems:
        p = PROBLEMS[name]
        lines.append(f"| {name} | {p.error_measure} | {p.reference_note} |")
    return "\n".join(lines)


def _work_precision_scene_run(ctx) -> Any:
    from ..scenes import SceneResult

    grid = "quick" if ctx.fast else "standard"
    problems = PROBLEM_SETS[grid]
    jobs = _default_jobs()
    df = run_problem_set(problems, grid, repeats=1 if ctx.fast else 3, jobs=jobs)
    tables = {f"wp_{p}": report_table(df[df["problem"] == p].reset_index(drop=True)) for p in problems}
    tables["wp_summary"] = report_table(fastest_to_tolerance(df))
    figures = {f"wp_{p}": work_precision_figure(df, p) for p in problems}
    return SceneResult(tables=tables, figures=figures, notes=_scene_notes(problems, grid, jobs))


def work_precision_scenes() -> list:
    """Scenes of the harness (for :func:`core.scenes.register_scene`): ``work-precision``.

    ``work-precision`` runs the ``standard`` problem set on the ``standard`` grids (``--fast``:
    the ``quick`` set and grids, one repeat), on ``MBSUITE_JOBS`` (default min(2, cores))
    worker processes, and writes one table and one figure per problem plus the
    fastest-to-tolerance summary.
    """
    from ..scenes import Scene

    return [Scene(
        name="work-precision",
        title="Work-precision: error against run time for every integrator",
        description=("Every registered integrator on the benchmark problems of core_benchmarks.md (N-link "
                     "chain rigid/spatial/stiff, Andrews' squeezer, car axis, 100-s pendulum) over tolerance "
                     "or step-size grids: error against median wall time, constraint violations, energy "
                     "drift, counters and status (core.benchmarks)."),
        run=_work_precision_scene_run,
    )]
