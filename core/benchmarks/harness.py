r"""Work-precision harness: error against run time for every integrator on benchmark problems.

For a :class:`~core.benchmarks.problems.WorkPrecisionProblem` and every integrator of
:data:`core.integrators.METHODS` (or a chosen subset), :func:`run_work_precision` integrates the
problem over a grid of settings -- relative tolerances for error-controlled methods, step sizes
for fixed-step ones -- and records, per run, one row of a tidy table (:data:`COLUMNS`):

* ``error``: the problem's error measure at ``t_end`` against an independent reference
  (column ``error measure`` names it with its unit);
* ``wall time [s]``: the median over up to ``repeats`` solves (a case stops repeating once its
  solves took :data:`MAX_REPEAT_TIME` seconds in all, as :meth:`timeit.Timer.autorange` stops at
  0.2 s: a run that long is timed to well under its spread between processes) of the time spent inside the
  integrator's ``step()`` calls (``SimulationResult.meta["wall_time_s"]``, which
  :func:`core.integrators.simulate` accumulates around ``step()`` only: model building, output
  sampling by dense output, violation/energy evaluation and multipliers are not counted);
* the largest position- and velocity-level constraint violations over the output samples
  (:attr:`WorkPrecisionProblem.n_output` equally spaced times; between steps these come from
  the method's dense output, so they include its interpolation error), and the violations at
  ``t_end``, which is always a step point (what the method itself holds);
* the relative energy drift ``max_k |E(t_k) − E(t_0)| / E_ref`` for conservative problems
  (``E_ref`` = :attr:`WorkPrecisionProblem.energy_scale`, else ``|E(t_0)|``), NaN otherwise;
* the work counters ``n_steps, n_rejected, n_rhs, n_jac, n_factor, n_newton``, the final
  ``status`` and ``message``.

A run that fails (status ``"failed"``, or an exception while setting it up) stays in the table
as a row with ``status = "failed"``, the message, and ``error = NaN``; nothing is dropped.  Only
a method that cannot integrate the system at all (:meth:`Integrator.applicable` gives a reason,
e.g. a compiled integrator on a hand-written system) is left out of the problem's table.

Settings
--------
Error-controlled methods get ``rtol`` from the grid and ``atol = rtol · atol_scale`` (the
problem's :attr:`~WorkPrecisionProblem.atol_scale`).  Fixed-step methods get the step ``h [s]``
from the grid and a tight Newton tolerance ``rtol = atol = newton_tol`` (default 1e−10): with
the integrators' default 1e−6 the Newton error, not the discretisation error, limits the
accuracy at small steps (measured: generalized-α on the N = 2 chain, h = 1e−4, tip error
4.2e−6 m at 1e−6 against 4.6e−7 m at 1e−10, the second-order value).

The methods are those of the integrator registry :data:`core.integrators.METHODS`
(:func:`available_methods`), the same that :func:`core.simulation.simulate` finds.

Sweeps run through :func:`core.sweep.run_sweep`, so any :class:`concurrent.futures.Executor`
may execute them; the reference of a problem is computed once in the calling process and sent
with every case, so the deterministic columns (:data:`DETERMINISTIC_COLUMNS`: error, status,
counters, violations) do not depend on the executor.

References
----------
E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer, 1996,
Sec. IV.10 (work-precision diagrams).
M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A benchmarking system for MBS simulation
software: problem standardization and performance measurement", Multibody Syst. Dyn. 16 (2006)
179–190 (error against CPU time at precision levels).
"""

from __future__ import annotations

import dataclasses
import math
import statistics
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from .problems import _REFERENCE_CACHE, Grid, WorkPrecisionProblem, _resolve_problem

__all__ = [
    "MAX_REPEAT_TIME",
    "COLUMNS",
    "COUNTERS",
    "DETERMINISTIC_COLUMNS",
    "NOT_APPLICABLE",
    "SETTING_RTOL",
    "SETTING_STEP",
    "available_methods",
    "run_problem_set",
    "run_problems",
    "run_work_precision",
]

SETTING_RTOL = "rtol"
SETTING_STEP = "h [s]"
#: Row status of a method that cannot integrate the problem's system (dropped from the tables).
NOT_APPLICABLE = "not applicable"
#: [s] a case stops repeating once its solves took this long in all (the median of the repeats is
#: its wall time); 2 s until issue 22, whose main job needed the time
MAX_REPEAT_TIME = 0.5
COUNTERS = ("n_steps", "n_rejected", "n_rhs", "n_jac", "n_factor", "n_newton")

#: Columns of the table returned by :func:`run_work_precision`, in order.
COLUMNS = [
    "problem",
    "method",
    "setting kind",
    "setting value",
    "rtol",
    "atol",
    "error",
    "error measure",
    "wall time [s]",
    "n repeats",
    "max position violation [m]",
    "max velocity violation [m/s]",
    "final position violation [m]",
    "final velocity violation [m/s]",
    "energy drift [-]",
    *COUNTERS,
    "status",
    "message",
    "t reached [s]",
]
#: Columns that do not depend on timing or on the executor (equal serial vs parallel).
DETERMINISTIC_COLUMNS = [
    "problem", "method", "setting kind", "setting value", "rtol", "atol", "error",
    "max position violation [m]", "max velocity violation [m/s]", "final position violation [m]",
    "final velocity violation [m/s]", "energy drift [-]", *COUNTERS,
    "status", "t reached [s]",
]


# ---------------------------------------------------------------------------------------------
# methods: the integrator registry
# ---------------------------------------------------------------------------------------------


def _methods():
    """:data:`core.integrators.METHODS` (importing the package imports every integrator module)."""
    from ..integrators import METHODS

    return METHODS


def available_methods() -> list[str]:
    """Names of all registered integrators (:data:`core.integrators.METHODS`, in registry order)."""
    return list(_methods())


# ---------------------------------------------------------------------------------------------
# one run (a sweep case) -> one row
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Case:
    problem: WorkPrecisionProblem
    method: str
    kind: str
    value: float
    rtol: float
    atol: float
    h: float | None
    repeats: int
    max_repeat_time: float
    reference: Any


def _row_template(case: _Case) -> dict[str, Any]:
    row: dict[str, Any] = {c: math.nan for c in COLUMNS}
    row.update({
        "problem": case.problem.name, "method": case.method, "setting kind": case.kind,
        "setting value": case.value, "rtol": case.rtol, "atol": case.atol,
        "error measure": case.problem.error_measure, "n repeats": 0, "status": "failed", "message": "",
    })
    for c in COUNTERS:
        row[c] = 0
    return row


def _run_case(case: _Case) -> dict[str, Any]:
    """Run one (problem, method, setting) ``repeats`` times; return its table row."""
    from ..integrators import simulate

    prob = case.problem
    row = _row_template(case)
    try:
        system = prob.build_system()
    except Exception as exc:  # noqa: BLE001 - reported in the row
        row["message"] = f"building the system failed: {type(exc).__name__}: {exc}"
        return row
    reason = _methods()[case.method].applicable(system)
    if reason is not None:
        row["status"] = NOT_APPLICABLE
        row["message"] = reason
        return row
    options = dict(prob.method_options.get(case.method, {}))
    t_eval = np.linspace(0.0, prob.t_end, prob.n_output)
    walls: list[float] = []
    result = None
    for _ in range(max(1, case.repeats)):
        try:
            with np.errstate(all="ignore"):  # diverging runs overflow; they are reported, not warned about
                result = simulate(system, (0.0, prob.t_end), case.method, t_eval=t_eval, rtol=case.rtol,
                                  atol=case.atol, h=case.h, progress=False, compute_multipliers=False,
                                  **options)
        except Exception as exc:  # noqa: BLE001 - a run that cannot start is a failed row
            row["message"] = f"{type(exc).__name__}: {exc}"
            return row
        walls.append(float(result.meta["wall_time_s"]))
        if not result.success or sum(walls) >= case.max_repeat_time:
            break
    assert result is not None
    row["wall time [s]"] = statistics.median(walls)
    row["n repeats"] = len(walls)
    row["status"] = result.status
    row["message"] = result.message
    row["t reached [s]"] = float(result.meta.get("t_end_reached", result.t[-1]))
    for c in COUNTERS:
        row[c] = int(result.counters.get(c, 0))
    with np.errstate(all="ignore"):
        pv = np.asarray(result.position_violation, float)
        vv = np.asarray(result.velocity_violation, float)
        row["max position violation [m]"] = float(np.max(pv)) if pv.size else math.nan
        row["max velocity violation [m/s]"] = float(np.max(vv)) if vv.size else math.nan
        row["final position violation [m]"] = float(pv[-1]) if pv.size else math.nan
        row["final velocity violation [m/s]"] = float(vv[-1]) if vv.size else math.nan
        if prob.conservative and result.energy is not None:
            E = np.asarray(result.energy, float)
            scale = prob.energy_scale if prob.energy_scale is not None else abs(E[0])
            row["energy drift [-]"] = float(np.max(np.abs(E - E[0])) / scale) if scale > 0 else math.nan
    if result.success:
        try:
            err = prob.error(result, system=system, reference=case.reference)
        except Exception as exc:  # noqa: BLE001
            err = math.nan
            row["message"] = f"{result.message}; error measure failed: {type(exc).__name__}: {exc}"
        row["error"] = err
    return row


# ---------------------------------------------------------------------------------------------
# the sweep
# ---------------------------------------------------------------------------------------------


def _grid_from(problem: WorkPrecisionProblem, settings) -> Grid:
    if settings is None:
        return problem.grid("standard")
    if isinstance(settings, str):
        return problem.grid(settings)
    if isinstance(settings, Grid):
        return settings
    if isinstance(settings, Mapping):
        unknown = set(settings) - {"rtol", "rtols", "h", "steps", SETTING_STEP}
        if unknown:
            raise ValueError(f"settings: unknown key(s) {sorted(unknown)}; use 'rtol' and/or 'h'")
        rt = settings.get("rtol", settings.get("rtols", ()))
        st = settings.get("h", settings.get("steps", settings.get(SETTING_STEP, ())))
        base = problem.grid("standard")
        return Grid(rtols=tuple(np.atleast_1d(rt)) if rt is not None else base.rtols,
                    steps=tuple(np.atleast_1d(st)) if st is not None else base.steps)
    raise TypeError(f"settings must be None, a grid name, a Grid or a mapping, got {type(settings).__name__}")


def _cases(problem: WorkPrecisionProblem, methods, grid: Grid, repeats: int, max_repeat_time: float,
           reference) -> list[_Case]:
    registry = _methods()
    if methods is None:
        names = grid.select(list(registry))
    else:
        names = [methods] if isinstance(methods, str) else list(methods)
        unknown = [m for m in names if m not in registry]
        if unknown:
            raise ValueError(f"unknown integrator(s) {unknown}; registered: {sorted(registry)}")
    cases = []
    for m in dict.fromkeys(names):
        cls = registry[m]
        if cls.fixed_step:
            for h in grid.steps:
                cases.append(_Case(problem, m, SETTING_STEP, h, problem.newton_tol, problem.newton_tol, h,
                                   repeats, max_repeat_time, reference))
        else:
            for rt in grid.rtols:
                cases.append(_Case(problem, m, SETTING_RTOL, rt, rt, rt * problem.atol_scale, None,
                                   repeats, max_repeat_time, reference))
    return cases


def run_work_precision(problem: str | WorkPrecisionProblem, methods: str | Sequence[str] | None = None,
                       settings: str | Grid | Mapping | None = None, repeats: int = 3,
                       executor: Executor | None = None, progress: bool = False,
                       max_repeat_time: float | None = None) -> pd.DataFrame:
    """Run ``problem`` with every method over a grid of settings; one row per (method, setting).

    Parameters
    ----------
    problem : str or WorkPrecisionProblem
        A name of :data:`~core.benchmarks.problems.PROBLEMS` or a problem object.
    methods : str or sequence of str, optional
        Integrator names; default the grid's selection among all registered integrators.
    settings : str, Grid or mapping, optional
        A grid name (``"quick"``, ``"standard"`` (default), ``"full"``), a :class:`Grid`, or
        ``{"rtol": [...], "h": [...]}`` (rtols for error-controlled, steps [s] for fixed-step
        methods).
    repeats : int
        Solves per case; the wall time is their median.  A case stops repeating once its
        solves took ``max_repeat_time`` seconds in total (column ``n repeats`` says how many ran).
    executor : concurrent.futures.Executor, optional
        Where the cases run (:func:`core.sweep.run_sweep`); None = serially in this process.
    progress : bool
        Progress bar over cases.
    max_repeat_time : float, optional
        [s], see ``repeats`` (default :data:`MAX_REPEAT_TIME`).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`COLUMNS`; ``attrs`` hold the problem's title, error measure, reference
        note and the grid.
    """
    from ..sweep import run_sweep

    prob = _resolve_problem(problem)
    if int(repeats) < 1:
        raise ValueError(f"repeats must be ≥ 1, got {repeats}")
    grid = _grid_from(prob, settings)
    max_repeat_time = MAX_REPEAT_TIME if max_repeat_time is None else float(max_repeat_time)
    if not max_repeat_time > 0:
        raise ValueError(f"max_repeat_time must be > 0 s, got {max_repeat_time}")
    cases = _cases(prob, methods, grid, int(repeats), max_repeat_time, prob.reference())
    rows = run_sweep(_run_case, cases, executor=executor, progress=progress)
    return _frame(prob, grid, rows)


def _frame(prob: WorkPrecisionProblem, grid: Grid, rows: list[dict]) -> pd.DataFrame:
    # methods that cannot integrate this system at all (Integrator.applicable) are left out of the table
    df = pd.DataFrame([r for r in rows if r["status"] != NOT_APPLICABLE], columns=COLUMNS)
    for c in (*COUNTERS, "n repeats"):
        df[c] = df[c].astype(int)
    df.attrs.update(problem=prob.name, title=prob.title, error_measure=prob.error_measure,
                    reference=prob.reference_note, t_end=prob.t_end, grid=dataclasses.asdict(grid))
    return df


def run_problems(problems: Iterable[str | WorkPrecisionProblem], **kwargs) -> pd.DataFrame:
    """:func:`run_work_precision` for several problems, concatenated into one tidy table."""
    frames = [run_work_precision(p, **kwargs) for p in problems]
    if not frames:
        return pd.DataFrame(columns=COLUMNS)
    return pd.concat(frames, ignore_index=True)


# ---------------------------------------------------------------------------------------------
# several problems as one sweep
# ---------------------------------------------------------------------------------------------


def _reference_of(problem: WorkPrecisionProblem) -> Any:
    return problem.reference_fn()


def run_problem_set(problems: Sequence[str], grid: str, methods=None, repeats: int = 3, jobs: int = 1,
                    progress: bool = False, report: Callable[[str], None] | None = None,
                    max_repeat_time: float | None = None, executor: Executor | None = None) -> pd.DataFrame:
    """Run several problems as one sweep (so a process pool stays busy across problems).

    Used by ``mbsuite bench`` and the ``work-precision`` scene: ``grid`` names the grid of every
    problem, and ``report(text)`` receives progress lines.  The references and the cases run on
    ``executor`` when one is given (:func:`core.sweep.run_sweep`; it is not shut down, and
    ``jobs`` must then stay 1), else on a process pool of ``jobs`` processes that lives for the
    call (``jobs = 1``: serially in this process).  Returns the concatenated tables of
    :func:`run_work_precision`.
    """
    from concurrent.futures import ProcessPoolExecutor

    from ..sweep import run_sweep

    if executor is not None and jobs != 1:
        raise ValueError(f"run_problem_set: give an executor or jobs={jobs}, not both")
    own_pool = ProcessPoolExecutor(max_workers=jobs) if executor is None and jobs > 1 else None
    executor = executor if executor is not None else own_pool
    where = f"{jobs} process(es)" if executor is None or own_pool is not None else "the given executor"
    budget = MAX_REPEAT_TIME if max_repeat_time is None else float(max_repeat_time)
    if not budget > 0:
        raise ValueError(f"max_repeat_time must be > 0 s, got {max_repeat_time}")
    probs = [_resolve_problem(name) for name in problems]
    try:
        if report is not None:
            report(f"computing the references of {len(probs)} problem(s)")
        missing = [p for p in probs if p not in _REFERENCE_CACHE]
        for p, ref in zip(missing, run_sweep(_reference_of, missing, executor=executor)):
            _REFERENCE_CACHE[p] = ref
        plan = []
        all_cases: list[_Case] = []
        for prob in probs:
            g = prob.grid(grid)
            cases = _cases(prob, methods, g, repeats, budget, prob.reference())
            plan.append((prob, g, len(all_cases), len(cases)))
            all_cases += cases
        if report is not None:
            report(f"{len(all_cases)} runs of {len(plan)} problem(s) on {where}")
        rows = run_sweep(_run_case, all_cases, executor=executor, progress=progress)
    finally:
        if own_pool is not None:
            own_pool.shutdown()
    frames = []
    for prob, g, start, n in plan:
        df = _frame(prob, g, rows[start:start + n])
        if report is not None:
            n_failed = int((df["status"] == "failed").sum())
            n_warned = int((df["status"] == "finished with warnings").sum())
            report(f"{prob.name}: {n} runs, {n_failed} failed, {n_warned} finished with warnings")
        frames.append(df)
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=COLUMNS)
