"""Figure helpers built on matplotlib's object API.

Every helper takes an optional ``ax`` and returns the :class:`matplotlib.figure.Figure`
it drew on. Without ``ax`` a new ``Figure`` is created directly (not through pyplot),
so no global figure state is touched and nothing pops up; :func:`save_figure` writes
PNG files. matplotlib is imported inside the functions, so ``import core.plot`` is
cheap and does not select a backend.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .paths import output_folder, write_atomically

if TYPE_CHECKING:  # pragma: no cover - typing only
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from .results import SimulationResult

__all__ = [
    "plot_energy",
    "plot_time_history",
    "plot_violations",
    "plot_work_precision",
    "plot_xy_path",
    "save_figure",
]

TIME_COLUMN = "t [s]"


def _axes(ax: Axes | None, figsize: tuple[float, float] = (6.4, 4.0)) -> tuple[Figure, Axes]:
    """Return ``(figure, axes)``: the given axes' root figure, or a new pyplot-free Figure."""
    if ax is None:
        from matplotlib.figure import Figure

        fig = Figure(figsize=figsize, layout="constrained")
        return fig, fig.add_subplot()
    try:
        fig = ax.get_figure(root=True)  # matplotlib >= 3.10 (sub-figures)
    except TypeError:  # pragma: no cover - older matplotlib
        fig = ax.get_figure()
    return fig, ax


def _require_columns(df: pd.DataFrame, columns: Sequence[str], where: str) -> None:
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise ValueError(f"{where}: column(s) {missing} not in table; available: {list(df.columns)}")


def plot_time_history(
    df: pd.DataFrame,
    columns: str | Sequence[str],
    ax: Axes | None = None,
    ylabel: str | None = None,
) -> Figure:
    """Plot one or more columns of a time-history table against ``"t [s]"``.

    Parameters
    ----------
    df : pandas.DataFrame
        Table with a ``"t [s]"`` column (e.g. ``SimulationResult.coordinates()``).
    columns : str or sequence of str
        Column(s) to plot; each becomes one labelled line.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; a new figure is created if None.
    ylabel : str, optional
        y-axis label; defaults to the column name when a single column is plotted.

    Returns
    -------
    matplotlib.figure.Figure
    """
    cols = [columns] if isinstance(columns, str) else list(columns)
    if not cols:
        raise ValueError("plot_time_history: no columns given")
    _require_columns(df, [TIME_COLUMN, *cols], "plot_time_history")
    fig, ax = _axes(ax)
    t = df[TIME_COLUMN].to_numpy()
    for col in cols:
        ax.plot(t, df[col].to_numpy(), label=col)
    ax.set_xlabel(TIME_COLUMN)
    ax.set_ylabel(ylabel if ylabel is not None else (cols[0] if len(cols) == 1 else ""))
    if len(cols) > 1:
        ax.legend()
    ax.grid(True, alpha=0.3)
    return fig


def plot_violations(result: SimulationResult, ax: Axes | None = None) -> Figure:
    """Plot position and velocity constraint violations over time on a log scale.

    Exactly-zero samples cannot be shown on a log axis and are left out; if no sample
    is positive (an unconstrained system, or exact satisfaction) the axis stays linear
    and says so in its title.

    Parameters
    ----------
    result : SimulationResult
        Run whose ``position_violation`` and ``velocity_violation`` are plotted.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    df = result.violations()
    fig, ax = _axes(ax)
    t = df[TIME_COLUMN].to_numpy()
    any_positive = False
    for col in df.columns[1:]:
        y = df[col].to_numpy(dtype=float)
        positive = y > 0
        any_positive |= bool(np.any(positive))
        ax.plot(t, np.where(positive, y, np.nan), label=col)
    if any_positive:
        ax.set_yscale("log")
    else:
        ax.set_title("constraint violation is exactly zero")
    ax.set_xlabel(TIME_COLUMN)
    ax.set_ylabel("max-abs constraint violation")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    return fig


def plot_energy(result: SimulationResult, ax: Axes | None = None) -> Figure:
    """Plot the relative energy drift ``(E - E0)/|E0|`` over time.

    Parameters
    ----------
    result : SimulationResult
        Run with a recorded ``energy`` (conservative systems).
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    df = result.energy_table()
    fig, ax = _axes(ax)
    ax.plot(df[TIME_COLUMN].to_numpy(), df["relative energy drift [-]"].to_numpy())
    ax.set_xlabel(TIME_COLUMN)
    ax.set_ylabel("relative energy drift [-]")
    ax.grid(True, alpha=0.3)
    return fig


def plot_xy_path(df: pd.DataFrame, xcol: str, ycol: str, ax: Axes | None = None) -> Figure:
    """Plot a planar path ``ycol`` over ``xcol`` with equal axis scaling.

    Parameters
    ----------
    df : pandas.DataFrame
        Table holding both columns.
    xcol, ycol : str
        Column names, e.g. ``"tip.x [m]"`` and ``"tip.y [m]"``.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    _require_columns(df, [xcol, ycol], "plot_xy_path")
    fig, ax = _axes(ax)
    ax.plot(df[xcol].to_numpy(), df[ycol].to_numpy())
    ax.set_xlabel(xcol)
    ax.set_ylabel(ycol)
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    return fig


def plot_work_precision(
    df: pd.DataFrame, time_col: str, err_col: str, group_col: str, ax: Axes | None = None
) -> Figure:
    """Draw a work-precision diagram: computing time over error, one line per group.

    Following Hairer and Wanner, the error is on the x axis and the work on the y
    axis, both logarithmic; points of each group (e.g. method) are joined in order of
    decreasing error, i.e. tightening tolerance.

    Parameters
    ----------
    df : pandas.DataFrame
        One row per run.
    time_col : str
        Work column, e.g. ``"wall time [s]"`` or a count of right-hand sides.
    err_col : str
        Error column (positive values).
    group_col : str
        Column whose values label the lines, e.g. ``"method"``.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure

    References
    ----------
    E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed.,
    Springer 1996, Sect. IV.10 (work-precision diagrams).
    """
    _require_columns(df, [time_col, err_col, group_col], "plot_work_precision")
    nonpositive = df[(df[time_col] <= 0) | (df[err_col] <= 0)]
    if len(nonpositive):
        raise ValueError(
            f"plot_work_precision: {len(nonpositive)} row(s) with non-positive {time_col!r} or "
            f"{err_col!r} cannot be drawn on log axes (first index {nonpositive.index[0]!r})"
        )
    fig, ax = _axes(ax)
    for group, sub in df.groupby(group_col, sort=False):
        sub = sub.sort_values(err_col, ascending=False)
        ax.plot(sub[err_col].to_numpy(), sub[time_col].to_numpy(), marker="o", label=str(group))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(err_col)
    ax.set_ylabel(time_col)
    ax.legend(title=group_col)
    ax.grid(True, which="both", alpha=0.3)
    return fig


def save_figure(fig: Figure, out_dir: str | Path, stem: str, dpi: int = 150, **savefig_kw: Any) -> Path:
    """Save a figure as ``<out_dir>/<stem>.png`` (tight bounding box).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    out_dir : str or Path
        Output folder, created if missing.
    stem : str
        File name without suffix.
    dpi : int, optional
        Resolution in dots per inch.
    **savefig_kw
        Further arguments for :meth:`matplotlib.figure.Figure.savefig`.

    Returns
    -------
    Path
        Path of the written PNG file.
    """
    from .results import _check_stem

    _check_stem(stem)
    out = output_folder(out_dir)
    path = out / f"{stem}.png"
    savefig_kw.setdefault("format", "png")  # the temporary file's name has no .png suffix
    write_atomically(path, lambda p: fig.savefig(p, dpi=dpi, bbox_inches="tight", **savefig_kw))
    return path
