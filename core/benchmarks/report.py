r"""Report of a work-precision table: fastest run per error target, diagrams and files.

:func:`fastest_to_tolerance` scores the methods as the IFToMM benchmark does (the CPU time
needed for a given precision); :func:`work_precision_figure` draws the error against the median
wall time of one problem; :func:`write_work_precision` writes the CSV, Markdown and PNG files of
every problem and the summary.  The tables come from :mod:`core.benchmarks.harness`.

Written tables (:func:`report_table`) carry their units: every numeric column has one in brackets,
except the two whose unit changes from row to row, which have a text column beside them --
``error`` with ``error unit`` (the unit of the problem's error measure, also of ``target error``)
and ``setting value`` with ``setting unit`` (``-`` for a tolerance, ``s`` for a step size).

References
----------
E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer, 1996,
Sec. IV.10 (work-precision diagrams).
M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A benchmarking system for MBS simulation
software: problem standardization and performance measurement", Multibody Syst. Dyn. 16 (2006)
179–190 (error against CPU time at precision levels).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..results import FINISHED_STATUSES, STATUS_WARNED
from .harness import COLUMNS, COUNTERS, MAX_REPEAT_TIME, SETTING_RTOL, SETTING_STEP
from .problems import PROBLEMS

__all__ = ["REPORT_COLUMNS", "fastest_to_tolerance", "report_table", "work_precision_figure",
           "work_precision_notes", "write_work_precision"]

#: Columns of the harness table renamed for the written report (units in brackets).
_RENAME = {"rtol": "rtol [-]", "atol": "atol [units of q, v]", "n repeats": "n repeats [-]",
           **{c: f"{c} [-]" for c in COUNTERS}}
#: Unit of a setting value by setting kind (``"rtol"`` or ``"h [s]"``).
_SETTING_UNITS = {SETTING_RTOL: "-", SETTING_STEP: "s"}


def _measure_unit(measure: str) -> str:
    """Unit in the trailing brackets of an error measure, ``"|tip - tip_ref| [m]"`` -> ``"m"``."""
    measure = str(measure).strip()
    if measure.endswith("]") and "[" in measure:
        return measure[measure.rindex("[") + 1:-1]
    return "-"


def report_table(df: pd.DataFrame) -> pd.DataFrame:
    """A harness or summary table as written: units in the column names or in unit columns.

    Counters and repeats get ``[-]``, ``rtol`` ``[-]`` and ``atol`` the units of the state
    it applies to; ``error unit`` (from the ``error measure``, or from the registered problem)
    follows ``error`` and ``setting unit`` follows ``setting value``.  The values are unchanged.

    Parameters
    ----------
    df : pandas.DataFrame
        Table of :func:`~core.benchmarks.harness.run_work_precision` or of
        :func:`fastest_to_tolerance`.

    Returns
    -------
    pandas.DataFrame
    """
    out = df.rename(columns=_RENAME)
    cols = list(out.columns)
    if "error" in out.columns:
        if "error measure" in out.columns:
            measures = out["error measure"]
        else:
            measures = out["problem"].map(lambda p: PROBLEMS[p].error_measure if p in PROBLEMS else "")
        at = cols.index("error measure") + 1 if "error measure" in cols else cols.index("error") + 1
        out.insert(at, "error unit", [_measure_unit(m) for m in measures])
        cols = list(out.columns)
    if "setting value" in out.columns:
        out.insert(cols.index("setting value") + 1, "setting unit",
                   [_SETTING_UNITS.get(k, "") for k in out["setting kind"]])
    out.attrs = dict(df.attrs)
    return out


#: Columns of a per-problem table as written by :func:`write_work_precision` and the scene.
REPORT_COLUMNS = list(report_table(pd.DataFrame(columns=COLUMNS)).columns)


def fastest_to_tolerance(df: pd.DataFrame, targets: Sequence[float] = (1e-2, 1e-4, 1e-6, 1e-8)) -> pd.DataFrame:
    """Per problem and error target: the fastest finished run whose error is at most the target.

    Runs "finished with warnings" count (their error is measured against the reference, whatever
    the run's own checks said); the ``status`` column shows which.

    The IFToMM benchmark scores software by the CPU time needed for a given precision
    (González et al. 2006); this is that score over all methods and settings of the table.

    Returns
    -------
    pandas.DataFrame
        Columns ``problem, target error, method, setting kind, setting value, error,
        error measure, wall time [s], status``; a target no run reached has ``method = "none"``.
    """
    out = []
    ok = df[df["status"].isin(FINISHED_STATUSES) & np.isfinite(df["error"])]
    for prob in dict.fromkeys(df["problem"]):
        sub = ok[ok["problem"] == prob]
        rows = df[df["problem"] == prob]
        measure = str(rows["error measure"].iloc[0]) if "error measure" in rows else ""
        for tgt in targets:
            hit = sub[sub["error"] <= tgt]
            if len(hit):
                best = hit.loc[hit["wall time [s]"].idxmin()]
                out.append({"problem": prob, "target error": tgt, "method": best["method"],
                            "setting kind": best["setting kind"], "setting value": best["setting value"],
                            "error": best["error"], "error measure": measure,
                            "wall time [s]": best["wall time [s]"], "status": best["status"]})
            else:
                out.append({"problem": prob, "target error": tgt, "method": "none", "setting kind": "",
                            "setting value": math.nan, "error": math.nan, "error measure": measure,
                            "wall time [s]": math.nan, "status": ""})
    return pd.DataFrame(out, columns=["problem", "target error", "method", "setting kind", "setting value",
                                      "error", "error measure", "wall time [s]", "status"])


def work_precision_figure(df: pd.DataFrame, problem: str | None = None, ax=None):
    """Log-log work-precision diagram of one problem: error against median wall time.

    One line per method (points of finished runs in order of tightening setting, drawn by
    :func:`core.plot.plot_work_precision`); failed runs -- and finished runs whose error is
    not finite -- are drawn as ``x`` markers at their wall time on a "failed" band right of
    the largest error, so they cannot be mistaken for results; runs that finished with warnings
    keep their point on the line and are circled in black.  The title names the problem, its end
    time, the settings swept and how many runs finished with warnings or failed.

    Parameters
    ----------
    df : pandas.DataFrame
        Table of :func:`~core.benchmarks.harness.run_work_precision` (or several concatenated; then
        give ``problem``).
    problem : str, optional
        Which problem to draw; required when ``df`` holds more than one.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    from ..plot import _axes, plot_work_precision

    probs = list(dict.fromkeys(df["problem"]))
    if problem is None:
        if len(probs) != 1:
            raise ValueError(f"work_precision_figure: the table holds problems {probs}; pass problem=")
        problem = probs[0]
    elif problem not in probs:
        raise ValueError(f"work_precision_figure: problem {problem!r} not in the table ({probs})")
    sub = df[df["problem"] == problem]
    good = sub[sub["status"].isin(FINISHED_STATUSES) & np.isfinite(sub["error"]) & (sub["error"] > 0)
               & (sub["wall time [s]"] > 0)]
    bad = sub.drop(good.index)
    fig, ax = _axes(ax, figsize=(7.5, 5.0))
    colours: dict[str, Any] = {}
    if len(good):
        plot_work_precision(good, "wall time [s]", "error", "method", ax=ax)
        for line in ax.get_lines():
            colours[line.get_label()] = line.get_color()
    else:
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("error")
        ax.set_ylabel("wall time [s]")
    measure = sub["error measure"].iloc[0] if len(sub) else "error"
    ax.set_xlabel(f"error: {measure}")
    ax.set_ylabel("median wall time of the solve [s]")
    if len(bad):
        x_fail = 10.0 * (float(good["error"].max()) if len(good) else 1.0)
        tmax = bad["wall time [s]"].where(bad["wall time [s]"] > 0)
        y_default = float(good["wall time [s]"].min()) if len(good) else 1e-3
        for meth, grp in bad.groupby("method", sort=False):
            y = tmax.loc[grp.index].fillna(y_default).to_numpy()
            ax.plot(np.full(len(y), x_fail), y, linestyle="none", marker="x", markersize=9,
                    color=colours.get(meth, "k"), label=f"{meth} (failed)")
        ax.axvline(x_fail / 3.0, color="0.6", linestyle=":", linewidth=1)
        ax.annotate("failed", xy=(x_fail, 1.0), xycoords=("data", "axes fraction"), ha="center", va="top",
                    fontsize=8, color="0.3")
    warned = good[good["status"] == STATUS_WARNED]
    if len(warned):
        ax.plot(warned["error"].to_numpy(), warned["wall time [s]"].to_numpy(), linestyle="none", marker="o",
                markersize=11, markerfacecolor="none", markeredgecolor="k", label="finished with warnings")
    ax.set_title(_figure_title(sub, problem, n_warned=len(warned), n_bad=len(bad)), fontsize=9)
    ax.legend(fontsize=7, ncol=2 if sub["method"].nunique() > 8 else 1, title="method", title_fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    return fig


def _t_end(sub: pd.DataFrame, problem: str) -> float:
    if sub.attrs.get("problem") == problem and sub.attrs.get("t_end") is not None:
        return float(sub.attrs["t_end"])
    if problem in PROBLEMS:
        return float(PROBLEMS[problem].t_end)
    return float(sub["t reached [s]"].max()) if "t reached [s]" in sub and len(sub) else math.nan


def _figure_title(sub: pd.DataFrame, problem: str, n_warned: int, n_bad: int) -> str:
    """``"<problem>, t_end 1 s — error at t_end vs. median wall time"`` + settings and statuses."""
    from ..plot import _num

    head = f"{problem}, t_end {_num(_t_end(sub, problem))} s — error at t_end vs. median wall time"
    swept = []
    for kind, unit in _SETTING_UNITS.items():
        vals = sub.loc[sub["setting kind"] == kind, "setting value"].dropna()
        if len(vals):
            name = kind.split(" ")[0]
            rng = (_num(vals.max()) if vals.max() == vals.min()
                   else f"{_num(vals.max())} … {_num(vals.min())}")
            swept.append(f"{name} {rng}{'' if unit == '-' else ' ' + unit}")
    counts = [f"{len(sub)} runs"]
    if n_warned:
        counts.append(f"{n_warned} finished with warnings (circled)")
    if n_bad:
        counts.append(f"{n_bad} failed or without error (x)")
    return head + "\n" + "; ".join(swept + [", ".join(counts)])


def _markdown_table(df: pd.DataFrame) -> pd.DataFrame:
    """The table with shortened messages (full text stays in the CSV)."""
    out = df.copy()
    out["message"] = out["message"].astype(str).str.slice(0, 120)
    return out


def write_work_precision(df: pd.DataFrame, out_dir: str | Path, prefix: str = "wp") -> dict[str, dict[str, Path]]:
    """Write ``<prefix>_<problem>.csv/.md/.png`` per problem and ``<prefix>_summary.csv/.md``.

    The tables are written in the form of :func:`report_table` (columns :data:`REPORT_COLUMNS`).

    Returns
    -------
    dict
        ``{problem: {"csv": path, "md": path, "png": path}, "summary": {...}}``.
    """
    from ..plot import save_figure
    from ..results import markdown_table, write_table

    out = Path(out_dir)
    written: dict[str, dict[str, Path]] = {}
    for prob in dict.fromkeys(df["problem"]):
        sub = df[df["problem"] == prob].reset_index(drop=True)
        stem = f"{prefix}_{prob}"
        table = report_table(sub)
        paths = write_table(table, out, stem)
        md = markdown_table(_markdown_table(table), floatfmt=".3g")
        paths["md"].write_text(md + "\n", encoding="utf-8")
        paths["png"] = save_figure(work_precision_figure(sub), out, stem)
        written[prob] = paths
    summary = report_table(fastest_to_tolerance(df))
    written["summary"] = write_table(summary, out, f"{prefix}_summary", floatfmt=".3g")
    return written


def work_precision_notes(problems: Sequence[str], grid: str, workers: int | None) -> str:
    """The Markdown notes of a work-precision report: how it was run and each problem's error measure.

    Parameters
    ----------
    problems : sequence of str
        Names of registered problems (:data:`~core.benchmarks.problems.PROBLEMS`).
    grid : str
        The grid the problems ran on (``"quick"``, ``"standard"``, ``"full"``).
    workers : int or None
        Worker processes the solves ran on (:func:`core.sweep.executor_workers`; None: a
        distributed executor of varying size).

    Returns
    -------
    str
        A paragraph on the grid, the workers, the wall-time measure and the tolerances, then a
        table ``problem | error measure | reference``.
    """
    who = f"{workers} worker process(es)" if workers is not None else "the workers of a distributed executor"
    lines = [(f"Grid `{grid}`; {who} (solves run concurrently when > 1, which may "
              "inflate wall times slightly). Wall time = median over the repeated solves of the time inside the "
              f"integrator steps (a case stops repeating once its solves took {MAX_REPEAT_TIME:g} s in all). Fixed-step methods: Newton tolerance rtol = atol = 1e-10; "
              "error-controlled methods: atol = rtol."),
             "", "| problem | error measure | reference |", "|---|---|---|"]
    for name in problems:
        p = PROBLEMS[name]
        lines.append(f"| {name} | {p.error_measure} | {p.reference_note} |")
    return "\n".join(lines)
