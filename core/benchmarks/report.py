r"""Report of a work-precision table: fastest run per error target, diagrams and files.

:func:`fastest_to_tolerance` scores the methods as the IFToMM benchmark does (the CPU time
needed for a given precision); :func:`work_precision_figure` draws the error against the median
wall time of one problem; :func:`write_work_precision` writes the CSV, Markdown and PNG files of
every problem and the summary.  The tables come from :mod:`core.benchmarks.harness`.

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

__all__ = ["fastest_to_tolerance", "work_precision_figure", "write_work_precision"]


def fastest_to_tolerance(df: pd.DataFrame, targets: Sequence[float] = (1e-2, 1e-4, 1e-6, 1e-8)) -> pd.DataFrame:
    """Per problem and error target: the fastest finished run whose error is at most the target.

    The IFToMM benchmark scores software by the CPU time needed for a given precision
    (González et al. 2006); this is that score over all methods and settings of the table.

    Returns
    -------
    pandas.DataFrame
        Columns ``problem, target error, method, setting kind, setting value, error,
        wall time [s]``; a target no run reached has ``method = "none"``.
    """
    out = []
    ok = df[(df["status"] == "finished") & np.isfinite(df["error"])]
    for prob in dict.fromkeys(df["problem"]):
        sub = ok[ok["problem"] == prob]
        for tgt in targets:
            hit = sub[sub["error"] <= tgt]
            if len(hit):
                best = hit.loc[hit["wall time [s]"].idxmin()]
                out.append({"problem": prob, "target error": tgt, "method": best["method"],
                            "setting kind": best["setting kind"], "setting value": best["setting value"],
                            "error": best["error"], "wall time [s]": best["wall time [s]"]})
            else:
                out.append({"problem": prob, "target error": tgt, "method": "none", "setting kind": "",
                            "setting value": math.nan, "error": math.nan, "wall time [s]": math.nan})
    return pd.DataFrame(out, columns=["problem", "target error", "method", "setting kind", "setting value",
                                      "error", "wall time [s]"])


def work_precision_figure(df: pd.DataFrame, problem: str | None = None, ax=None):
    """Log-log work-precision diagram of one problem: error against median wall time.

    One line per method (points of finished runs in order of tightening setting, drawn by
    :func:`core.plot.plot_work_precision`); failed runs -- and finished runs whose error is
    not finite -- are drawn as ``x`` markers at their wall time on a "failed" band right of
    the largest error, so they cannot be mistaken for results.

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
    good = sub[(sub["status"] == "finished") & np.isfinite(sub["error"]) & (sub["error"] > 0)
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
    ax.set_title(f"{problem}: error vs. run time", fontsize=10)
    ax.legend(fontsize=7, ncol=2 if sub["method"].nunique() > 8 else 1, title="method", title_fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    return fig


def _markdown_table(df: pd.DataFrame) -> pd.DataFrame:
    """The table with shortened messages (full text stays in the CSV)."""
    out = df.copy()
    out["message"] = out["message"].astype(str).str.slice(0, 120)
    return out


def write_work_precision(df: pd.DataFrame, out_dir: str | Path, prefix: str = "wp") -> dict[str, dict[str, Path]]:
    """Write ``<prefix>_<problem>.csv/.md/.png`` per problem and ``<prefix>_summary.csv/.md``.

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
        paths = write_table(sub, out, stem)
        md = markdown_table(_markdown_table(sub), floatfmt=".3g")
        paths["md"].write_text(md + "\n", encoding="utf-8")
        paths["png"] = save_figure(work_precision_figure(sub), out, stem)
        written[prob] = paths
    summary = fastest_to_tolerance(df)
    written["summary"] = write_table(summary, out, f"{prefix}_summary", floatfmt=".3g")
    return written
