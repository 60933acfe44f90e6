"""Figure helpers built on matplotlib's object API.

Every helper takes an optional ``ax`` (:func:`plot_violations` a pair of axes) and returns the
:class:`matplotlib.figure.Figure` it drew on. Without ``ax`` a new ``Figure`` is created directly
(not through pyplot), so no global figure state is touched and nothing pops up;
:func:`save_figure` writes PNG files. matplotlib is imported inside the functions, so
``import core.plot`` is cheap and does not select a backend.

Rules every figure of the suite follows (``tests/core/test_report_files.py`` checks them):

* **Title.** It names what was run and how: the scene or system, the integrator and its settings
  (:func:`run_title`, e.g. ``"pendulum — radau-ggl, rtol 1e-8, atol 1e-10"``), and says when the
  run *finished with warnings* or *failed* (:data:`core.results.FINISHED_STATUSES`). Helpers that
  draw a :class:`~core.results.SimulationResult` (or a table carrying its ``attrs["meta"]``) build
  it themselves; ``title=`` overrides the subject or the whole title.
* **Axis labels** carry a unit in brackets on every axis, ``[-]`` for dimensionless ones.
* **Round-off.** A panel of a quantity that is zero up to rounding (a constraint violation, an
  energy drift, a time history that does not change) is never stretched until its rounding noise
  fills the axis. The rule (:func:`floor_at_roundoff`): the round-off level of a quantity of size
  ``scale`` is ``ROUNDOFF_FACTOR * eps * scale`` (``eps`` the double-precision machine epsilon,
  ``scale`` a characteristic length [m] or speed [m/s] of the system for constraint violations,
  by default 1 m and 1 m/s, the size of the suite's models; 1 for a relative energy drift; the
  largest value for a time history); the panel
  keeps its data unchanged but its y-range is floored -- a log axis never reaches below
  ``eps * scale``, a linear axis spans at least ten round-off levels either side -- and the band
  below the level is shaded. A panel whose values all lie within that level says so in its title:
  ``"... at round-off level (max 3.1e-16 m)"`` (or ``"exactly zero"``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
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
    "ROUNDOFF_FACTOR",
    "floor_at_roundoff",
    "plot_energy",
    "plot_time_history",
    "plot_violations",
    "plot_work_precision",
    "plot_xy_path",
    "roundoff_level",
    "run_title",
    "save_figure",
]

TIME_COLUMN = "t [s]"
#: A quantity of size ``scale`` is at round-off level when it is at most ``ROUNDOFF_FACTOR * eps * scale``.
ROUNDOFF_FACTOR = 1000.0
_EPS = float(np.finfo(float).eps)
_ROUNDOFF_COLOUR = "0.88"


def _axes(ax: Axes | None, figsize: tuple[float, float] = (6.4, 4.0)) -> tuple[Figure, Axes]:
    """Return ``(figure, axes)``: the given axes' root figure, or a new pyplot-free Figure."""
    if ax is None:
        from matplotlib.figure import Figure

        fig = Figure(figsize=figsize, layout="constrained")
        return fig, fig.add_subplot()
    return _root_figure(ax), ax


def _root_figure(ax: Axes) -> Figure:
    try:
        return ax.get_figure(root=True)  # matplotlib >= 3.10 (sub-figures)
    except TypeError:  # pragma: no cover - older matplotlib
        return ax.get_figure()


def _require_columns(df: pd.DataFrame, columns: Sequence[str], where: str) -> None:
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise ValueError(f"{where}: column(s) {missing} not in table; available: {list(df.columns)}")


# ---------------------------------------------------------------------------------------------
# titles
# ---------------------------------------------------------------------------------------------
def _num(x: float) -> str:
    """A setting as short text: ``1e-08`` -> ``1e-8``, ``1e-4`` -> ``1e-4``, ``0.001`` -> ``0.001``."""
    x = float(x)
    if x != 0 and np.isfinite(x) and not (1e-3 <= abs(x) < 1e5):
        mant, exp = f"{x:.2e}".split("e")
        return f"{mant.rstrip('0').rstrip('.')}e{int(exp)}"
    return f"{x:.3g}"


def run_title(meta: Mapping[str, Any], status: str | None = None, subject: str | None = None,
              message: str = "") -> str:
    """Title of a figure of one run: subject, integrator, its settings and, unless plain
    "finished", the status.

    Parameters
    ----------
    meta : mapping
        Run metadata (:func:`core.results.run_metadata`): ``system``, ``method``, ``rtol``,
        ``atol``, ``h``.
    status : str, optional
        The run's status; "finished with warnings" and "failed" are added to the title.
    subject : str, optional
        What was run (the scene, e.g. ``"double pendulum"``); default the system name.
    message : str, optional
        The run's message; its start is shown after "failed".

    Returns
    -------
    str
        E.g. ``"double pendulum — rk45-projection, rtol 1e-8, atol 1e-10"``.
    """
    subject = subject or str(meta.get("system") or "").replace("_", " ") or "run"
    settings = []
    if meta.get("h") is not None:
        settings.append(f"h {_num(meta['h'])} s")
    for key in ("rtol", "atol"):
        if meta.get(key) is not None:
            settings.append(f"{key} {_num(meta[key])}")
    method = str(meta.get("method") or "unknown integrator")
    title = f"{subject} — {', '.join([method, *settings])}"
    if status == "failed":
        short = message.strip().splitlines()[0][:80] if message.strip() else ""
        title += f" [FAILED{': ' + short if short else ''}]"
    elif status is not None and status != "finished":
        title += f" [{status}]"
    return title


def _result_title(result: SimulationResult, title: str | None) -> str:
    """``title`` if it names the integrator already, else :func:`run_title` with ``title`` as subject."""
    method = str(result.meta.get("method") or "")
    if title is not None and method and method in title:
        return title
    return run_title(result.meta, result.status, subject=title, message=result.message)


def _table_title(df: pd.DataFrame, title: str | None) -> str | None:
    meta = df.attrs.get("meta")
    if isinstance(meta, Mapping) and meta.get("method"):
        method = str(meta["method"])
        if title is not None and method in title:
            return title
        return run_title(meta, df.attrs.get("status"), subject=title)
    return title


def _set_title(ax: Axes, title: str | None, note: str | None = None) -> None:
    text = "\n".join(s for s in (title, note) if s)
    if text:
        ax.set_title(text, fontsize=9)


# ---------------------------------------------------------------------------------------------
# the round-off rule
# ---------------------------------------------------------------------------------------------
def roundoff_level(scale: float) -> float:
    """Round-off level ``ROUNDOFF_FACTOR * eps * scale`` of a quantity of size ``scale`` (1 if 0)."""
    scale = float(scale) if np.isfinite(scale) and scale > 0 else 1.0
    return ROUNDOFF_FACTOR * _EPS * scale


def floor_at_roundoff(ax: Axes, values, scale: float, what: str, unit: str = "",
                      about_zero: bool = True) -> str | None:
    """Apply the round-off rule (module docstring) to one panel already drawn on ``ax``.

    The drawn data are not changed; only the y-range is floored and the round-off band shaded.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The panel; its y scale (``"log"`` or linear) must be set already.
    values : array_like
        The values drawn on the panel (all lines together).
    scale : float
        Size of the quantity the values are errors of (see :func:`roundoff_level`).
    what : str
        Name of the quantity for the note, e.g. ``"position violation"``.
    unit : str, optional
        Unit for the note (without brackets; ``"-"`` or ``""`` for none).
    about_zero : bool, optional
        True for quantities that should be zero (violations, drifts: the level is measured from
        0); False for time histories (the level is measured from the middle of their range).

    Returns
    -------
    str or None
        The note ``"<what> at round-off level (max ...)"`` / ``"<what> exactly zero"`` if every
        value lies within the round-off level (the caller puts it into the title), else None.
    """
    y = np.asarray(values, dtype=float).ravel()
    y = y[np.isfinite(y)]
    level = roundoff_level(scale)
    floor = level / ROUNDOFF_FACTOR
    unit_text = f" {unit}" if unit and unit != "-" else ""
    band = f"round-off level ({level:.1e}{unit_text})"
    if ax.get_yscale() == "log":
        pos = y[y > 0]
        peak = float(pos.max()) if pos.size else 0.0
        ax.axhspan(floor, level, color=_ROUNDOFF_COLOUR, zorder=0, lw=0, label=band)
        ax.set_ylim(floor, max(3.0 * peak, 10.0 * level))
        ax.legend(fontsize=7)
        if peak <= level:
            return f"{what} at round-off level (max {peak:.1e}{unit_text})"
        return None
    if y.size == 0:
        centre, half, peak = 0.0, 0.0, 0.0
    elif about_zero:
        centre, half, peak = 0.0, float(np.max(np.abs(y))), float(np.max(np.abs(y)))
    else:
        lo, hi = float(y.min()), float(y.max())
        centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        peak = half
    if half < 10.0 * level:  # would be stretched over the axis: floor the range
        ax.axhspan(centre - level, centre + level, color=_ROUNDOFF_COLOUR, zorder=0, lw=0, label=band)
        span = max(1.05 * half, 10.0 * level)
        ax.set_ylim(centre - span, centre + span)
        ax.legend(fontsize=7)
    if half <= level:
        if peak == 0.0:
            return f"{what} {'exactly zero' if about_zero else 'constant'}"
        if about_zero:
            return f"{what} at round-off level (max {peak:.1e}{unit_text})"
        return f"{what} constant to round-off level (varies by {2 * half:.1e}{unit_text})"
    return None


def _unit(label: str) -> str:
    """``"x [m]"`` -> ``"m"``; ``""`` if the label has no unit in brackets."""
    if label.endswith("]") and "[" in label:
        return label[label.rindex("[") + 1:-1]
    return ""


def _strip_unit(label: str) -> str:
    return label[:label.rindex("[")].strip() if _unit(label) else label


# ---------------------------------------------------------------------------------------------
# the helpers
# ---------------------------------------------------------------------------------------------
def plot_time_history(
    df: pd.DataFrame,
    columns: str | Sequence[str],
    ax: Axes | None = None,
    ylabel: str | None = None,
    title: str | None = None,
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
        y-axis label with its unit; default the column name (several columns of one unit:
        ``"x, y [m]"``; of different units: the names joined).
    title : str, optional
        Title, or the subject of :func:`run_title` when ``df.attrs["meta"]`` holds a run's
        metadata (tables of :class:`~core.results.SimulationResult` do).

    Returns
    -------
    matplotlib.figure.Figure

    Notes
    -----
    A time history constant to round-off level gets the floored y-range and the note of
    :func:`floor_at_roundoff` (``about_zero=False``, scale the largest value).
    """
    cols = [columns] if isinstance(columns, str) else list(columns)
    if not cols:
        raise ValueError("plot_time_history: no columns given")
    _require_columns(df, [TIME_COLUMN, *cols], "plot_time_history")
    fig, ax = _axes(ax)
    t = df[TIME_COLUMN].to_numpy()
    values = []
    for col in cols:
        y = df[col].to_numpy(dtype=float)
        values.append(y)
        ax.plot(t, y, label=col)
    if ylabel is None:
        units = {_unit(c) for c in cols}
        ylabel = (f"{', '.join(_strip_unit(c) for c in cols)} [{units.pop()}]"
                  if len(units) == 1 and "" not in units else ", ".join(cols))
    ax.set_xlabel(TIME_COLUMN)
    ax.set_ylabel(ylabel)
    if len(cols) > 1:
        ax.legend()
    ax.grid(True, alpha=0.3)
    y = np.concatenate(values)
    finite = y[np.isfinite(y)]
    scale = float(np.max(np.abs(finite))) if finite.size else 1.0
    note = floor_at_roundoff(ax, y, scale, ", ".join(_strip_unit(c) for c in cols), _unit(ylabel),
                             about_zero=False)
    _set_title(ax, _table_title(df, title), note)
    return fig


def _violation_axes(ax) -> tuple[Figure, list[Axes], bool]:
    if ax is None:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(6.4, 5.6), layout="constrained")
        axs = list(fig.subplots(2, 1, sharex=True))
        axs[0].tick_params(labelbottom=True)
        return fig, axs, True
    try:
        axs = list(ax)
    except TypeError:
        raise ValueError("plot_violations: ax must be a pair of Axes (position, velocity panel)") from None
    if len(axs) != 2:
        raise ValueError(f"plot_violations: ax must be a pair of Axes, got {len(axs)}")
    return _root_figure(axs[0]), axs, False


def plot_violations(result: SimulationResult, ax: Sequence[Axes] | None = None,
                    title: str | None = None, scale: tuple[float, float] = (1.0, 1.0)) -> Figure:
    """Plot the position- and velocity-level constraint violations over time, one panel each.

    Each panel is logarithmic and follows the round-off rule of the module docstring: its
    y-range is floored at ``eps * scale`` with ``scale`` the system's characteristic length
    (position panel) or speed (velocity panel), the band up to ``ROUNDOFF_FACTOR * eps * scale``
    is shaded, and a panel whose violations all lie in it says "at round-off level (max ...)" in
    its title.  (The largest coordinate is no measure of the size of Φ: coordinates mix lengths
    with angles that grow without bound on a rotating body.) Exactly-zero samples cannot be shown on a log axis and are left out
    (NaN); a panel with no positive sample stays linear and says "exactly zero".

    Parameters
    ----------
    result : SimulationResult
        Run whose ``position_violation`` and ``velocity_violation`` are plotted.
    ax : pair of matplotlib.axes.Axes, optional
        Position and velocity panels; a new two-panel figure is created if None.
    title : str, optional
        Subject of :func:`run_title` (e.g. the scene), or a full title naming the integrator.
    scale : (float, float), optional
        Characteristic length [m] and speed [m/s] of the system, for the round-off level.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .results import POSITION_VIOLATION_COLUMN, VELOCITY_VIOLATION_COLUMN

    df = result.violations()
    fig, axs, own = _violation_axes(ax)
    t = df[TIME_COLUMN].to_numpy()
    scales = dict(zip((POSITION_VIOLATION_COLUMN, VELOCITY_VIOLATION_COLUMN), scale))
    head = _result_title(result, title)
    for k, (a, col) in enumerate(zip(axs, (POSITION_VIOLATION_COLUMN, VELOCITY_VIOLATION_COLUMN))):
        y = df[col].to_numpy(dtype=float)
        positive = y > 0
        a.plot(t, np.where(positive, y, np.nan), label=col, color=f"C{k}")
        if np.any(positive):
            a.set_yscale("log")
        what = _strip_unit(col)
        note = floor_at_roundoff(a, y, float(scales[col]), what, _unit(col))
        a.set_ylabel(f"max-abs {col}")
        a.grid(True, which="both", alpha=0.3)
        panel = note or f"{what} (max {np.nanmax(y):.1e} {_unit(col)})"
        _set_title(a, None if own or k else head, panel)
    for a in axs:
        a.set_xlabel(TIME_COLUMN)
    if own:
        fig.suptitle(head, fontsize=10)
    return fig


def plot_energy(result: SimulationResult, ax: Axes | None = None, title: str | None = None) -> Figure:
    """Plot the relative energy drift ``(E - E0)/|E0|`` over time.

    The drift is a relative quantity (scale 1): the y-range spans at least ten round-off levels
    (``ROUNDOFF_FACTOR * eps``) either side of zero, and a drift that stays within one says "at
    round-off level (max ...)" in the title (module docstring).

    Parameters
    ----------
    result : SimulationResult
        Run with a recorded ``energy`` (conservative systems).
    ax : matplotlib.axes.Axes, optional
    title : str, optional
        Subject of :func:`run_title` (e.g. the scene), or a full title naming the integrator.

    Returns
    -------
    matplotlib.figure.Figure
    """
    df = result.energy_table()
    fig, ax = _axes(ax)
    y = df["relative energy drift [-]"].to_numpy()
    ax.plot(df[TIME_COLUMN].to_numpy(), y)
    ax.set_xlabel(TIME_COLUMN)
    ax.set_ylabel("relative energy drift [-]")
    ax.grid(True, alpha=0.3)
    note = floor_at_roundoff(ax, y, 1.0, "energy drift", "-")
    scale = df.attrs["energy scale [J]"]
    _set_title(ax, _result_title(result, title), note or f"energy drift relative to {scale:.4g} J")
    return fig


def plot_xy_path(df: pd.DataFrame, xcol: str, ycol: str, ax: Axes | None = None,
                 title: str | None = None) -> Figure:
    """Plot a planar path ``ycol`` over ``xcol`` with equal axis scaling.

    Parameters
    ----------
    df : pandas.DataFrame
        Table holding both columns.
    xcol, ycol : str
        Column names with units, e.g. ``"tip.x [m]"`` and ``"tip.y [m]"``.
    ax : matplotlib.axes.Axes, optional
    title : str, optional
        Title, or the subject of :func:`run_title` when ``df.attrs["meta"]`` holds a run's metadata.

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
    _set_title(ax, _table_title(df, title))
    return fig


def plot_work_precision(
    df: pd.DataFrame, time_col: str, err_col: str, group_col: str, ax: Axes | None = None,
    title: str | None = None,
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
    title : str, optional
        Title (name the problem and its end time).

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
    _set_title(ax, title)
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
