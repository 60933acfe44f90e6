r"""Statistics of a signal taken from a run's dense record, not from its output grid.

An output grid ``t_k`` samples the motion at times the user chose; a peak, a threshold crossing or
the time spent beyond a limit read from it changes with the output step, and an event shorter
than the step (a wheel lifting for 3 ms between two outputs 50 ms apart) is not seen at all.  The
accepted steps of the integrator (``simulate(..., record_steps=True)``,
:class:`core.results.AcceptedSteps`) are where its error control held the solution to the
tolerance; the functions here take their statistics there and locate crossings between the steps.

Equations
---------
A signal x sampled at the accepted steps ``t_0 < … < t_N``.  The set where the condition holds,
``C = {t : x(t) ≤ c}`` (``side="below"``) or ``{t : x(t) ≥ c}`` (``side="above"``), is a union of
intervals ``[a_j, b_j]``; a boundary lies between a sample outside and the next one inside (or
the reverse) and is located by

* a callable ``refine(t_i, t_{i+1}) -> t*`` the caller provides (e.g. bisection on the condition
  evaluated at interpolated states of the step: the event location of an integrator), or
* linear interpolation of ``x − c`` between the two samples::

      t* = t_i + (t_{i+1} − t_i) (c − x_i) / (x_{i+1} − x_i)                              (S1)

  which is exact to ``O(h²)`` for a smooth signal; for a signal that is flat *at* the level
  inside C (a wheel load Q = 0 while lifted) it puts the boundary at the first sample inside,
  within one step ``h`` of the true one: the bracket width is reported as ``resolution [s]``.

The time beyond the level is ``Σ_j (b_j − a_j)``; the peaks are the extreme samples
``max_i x_i`` (``min_i``) with their times.  An interval is *seen by a grid* when a grid time
lies in ``[a_j, b_j]``; :func:`grid_resolution` counts those that are not.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np
import pandas as pd

from .errors import InputError

__all__ = ["GridResolutionWarning", "level_intervals", "peak", "grid_resolution", "level_summary",
           "hidden_extremes", "dense_level_intervals", "zero_crossings"]


class GridResolutionWarning(UserWarning):
    """A table reports an event (a crossing, an interval beyond a limit) that its output grid does
    not resolve: the value came from the dense record, the grid would not show it."""


def _samples(t, x, where):
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if t.ndim != 1 or x.shape != t.shape:
        raise InputError(f"{where}: t {t.shape} and x {x.shape} must be 1-D of equal length")
    if t.size and np.any(np.diff(t) <= 0):
        i = int(np.argmax(np.diff(t) <= 0))
        raise InputError(f"{where}: t must increase strictly; t[{i}] = {float(t[i])!r} s, "
                         f"t[{i + 1}] = {float(t[i + 1])!r} s")
    return t, x


def level_intervals(t, x, level=0.0, side="below", refine: Callable[[float, float], float] | None = None):
    """Intervals where ``x ≤ level`` (``side="below"``) or ``x ≥ level`` (``"above"``), Eq. (S1).

    Parameters
    ----------
    t : (n,) array_like
        Sample times [s], strictly increasing (the accepted steps of a run).
    x : (n,) array_like
        The signal there; NaN counts as outside the set.
    level : float
        The level c (the unit of x).
    side : {"below", "above"}
        Which side of the level forms the set.
    refine : callable, optional
        ``refine(t_out_or_in, t_next) -> t*`` locating a boundary inside the bracket (event
        location); without it, linear interpolation (S1).

    Returns
    -------
    DataFrame
        One row per interval: ``start [s]``, ``end [s]``, ``duration [s]``, ``open start``
        (the set holds at the first sample: the start is the record's), ``open end``,
        ``resolution [s]`` (the widest bracket of its two boundaries when not refined, else 0).
    """
    t, x = _samples(t, x, "level_intervals")
    if side not in ("below", "above"):
        raise InputError(f"level_intervals: side must be 'below' or 'above', got {side!r}")
    with np.errstate(invalid="ignore"):
        inside = (x <= level) if side == "below" else (x >= level)
    cols = ["start [s]", "end [s]", "duration [s]", "open start", "open end", "resolution [s]"]
    if not inside.any():
        return pd.DataFrame(columns=cols)

    def boundary(i):  # between samples i and i + 1, exactly one of them inside
        if refine is not None:
            return float(refine(float(t[i]), float(t[i + 1]))), 0.0
        x0, x1 = x[i], x[i + 1]
        if np.isfinite(x0) and np.isfinite(x1) and x1 != x0:
            w = float(np.clip((level - x0) / (x1 - x0), 0.0, 1.0))
        else:
            w = 1.0 if not inside[i] else 0.0
        return float(t[i] + w * (t[i + 1] - t[i])), float(t[i + 1] - t[i])

    d = np.diff(inside.astype(np.int8))
    starts = list(np.flatnonzero(d == 1))  # i outside, i + 1 inside
    ends = list(np.flatnonzero(d == -1))  # i inside, i + 1 outside
    rows = []
    open_start = bool(inside[0])
    s_iter = iter(starts)
    e_iter = iter(ends)
    while True:
        if open_start:
            a, ra = float(t[0]), 0.0
            open_start = False
            first = True
        else:
            try:
                i = next(s_iter)
            except StopIteration:
                break
            a, ra = boundary(i)
            first = False
        try:
            j = next(e_iter)
            b, rb = boundary(j)
            open_end = False
        except StopIteration:
            b, rb, open_end = float(t[-1]), 0.0, True
        rows.append({"start [s]": a, "end [s]": b, "duration [s]": max(0.0, b - a), "open start": first,
                     "open end": open_end, "resolution [s]": max(ra, rb)})
        if open_end:
            break
    return pd.DataFrame(rows, columns=cols)


def peak(t, x, kind="max"):
    """The extreme sample of ``x`` and its time: ``(value, t)``; NaN samples ignored, ``(nan, nan)``
    when there is none.  ``kind`` is ``"max"``, ``"min"`` or ``"absmax"`` (largest magnitude,
    returned with its sign)."""
    t, x = _samples(t, x, "peak")
    ok = np.isfinite(x)
    if not ok.any():
        return float("nan"), float("nan")
    if kind == "max":
        i = int(np.nanargmax(np.where(ok, x, -np.inf)))
    elif kind == "min":
        i = int(np.nanargmin(np.where(ok, x, np.inf)))
    elif kind == "absmax":
        i = int(np.nanargmax(np.where(ok, np.abs(x), -np.inf)))
    else:
        raise InputError(f"peak: kind must be 'max', 'min' or 'absmax', got {kind!r}")
    return float(x[i]), float(t[i])


def grid_resolution(intervals: pd.DataFrame, t_grid) -> np.ndarray:
    """For each interval of :func:`level_intervals`, whether an output time of ``t_grid`` lies in
    ``[start, end]`` (the grid sees it); a boolean array."""
    g = np.sort(np.asarray(t_grid, dtype=float))
    if len(intervals) == 0:
        return np.zeros(0, bool)
    a = intervals["start [s]"].to_numpy(float)
    b = intervals["end [s]"].to_numpy(float)
    k = np.searchsorted(g, a, side="left")
    return (k < g.size) & (g[np.minimum(k, g.size - 1)] <= b)


def level_summary(t, x, level=0.0, side="below", refine=None, t_grid=None, name="x", warn=True):
    """One dict summarising :func:`level_intervals`: ``first [s]`` (start of the first interval,
    NaN if none), ``count``, ``total [s]``, ``shortest [s]``, ``resolution [s]`` and, with
    ``t_grid``, ``missed by the output grid`` (intervals containing no output time).  With
    ``warn``, a missed interval issues a :class:`GridResolutionWarning` naming ``name``."""
    iv = level_intervals(t, x, level, side, refine)
    out = {"first [s]": float(iv["start [s]"].iloc[0]) if len(iv) else float("nan"), "count": int(len(iv)),
           "total [s]": float(iv["duration [s]"].sum()) if len(iv) else 0.0,
           "shortest [s]": float(iv["duration [s]"].min()) if len(iv) else float("nan"),
           "resolution [s]": float(iv["resolution [s]"].max()) if len(iv) else 0.0}
    if t_grid is not None:
        seen = grid_resolution(iv, t_grid)
        out["missed by the output grid"] = int((~seen).sum())
        if warn and out["missed by the output grid"]:
            dt = float(np.max(np.diff(np.asarray(t_grid, float)))) if np.size(t_grid) > 1 else float("nan")
            warnings.warn(f"{name}: {out['missed by the output grid']} of {len(iv)} intervals with {name} "
                          f"{'≤' if side == 'below' else '≥'} {level:g} fall between output times (output step "
                          f"{dt:.3g} s; shortest {out['shortest [s]']:.3g} s): the summary comes from the accepted "
                          "steps, a table on the output grid does not show them", GridResolutionWarning, stacklevel=2)
    return out


def _oriented(x, dxdt, level, side):
    """y = x − c (``side="above"``) or c − x (``"below"``): the set is y ≥ 0; and ẏ."""
    if side not in ("below", "above"):
        raise InputError(f"side must be 'below' or 'above', got {side!r}")
    s = 1.0 if side == "above" else -1.0
    return s * (np.asarray(x, float) - level), s * np.asarray(dxdt, float)


def hidden_extremes(t, x, dxdt, level=0.0, side="above"):
    r"""Sample intervals that may hide a pair of crossings of ``level`` (Eq. S2).

    Between two samples on the same side of the level, the signal can still cross it twice: a
    local extreme between them passes the level (a short exceedance, or a short dip back).  With
    the slopes ẏ_i, ẏ_{i+1} at both samples (y = x − c, or c − x for ``side="below"``) an
    interior extreme exists where the slope changes sign, and the two tangents bound it::

        t* = (y_{i+1} − y_i + ẏ_i t_i − ẏ_{i+1} t_{i+1}) / (ẏ_i − ẏ_{i+1}),
        y* = y_i + ẏ_i (t* − t_i)                                                         (S2)

    y* bounds the maximum from above where y is concave on the interval (a maximum between
    two samples outside the set, ẏ_i > 0 > ẏ_{i+1}) and the minimum from below where it is
    convex (a minimum between two samples inside, ẏ_i < 0 < ẏ_{i+1}).  An interval is returned
    when y* reaches the other side of the level.  Two extremes within one sample interval (a
    slope that changes sign twice) are beyond what samples and slopes can resolve.

    Parameters
    ----------
    t, x, dxdt : (n,) array_like
        Times [s], signal and its time derivative at the samples.
    level : float
    side : {"above", "below"}

    Returns
    -------
    (m,) int ndarray
        Indices i of the intervals [t_i, t_{i+1}].
    """
    t, x = _samples(t, x, "hidden_extremes")
    y, yd = _oriented(x, dxdt, level, side)
    if t.size < 2:
        return np.zeros(0, int)
    y0, y1, d0, d1, t0, t1 = y[:-1], y[1:], yd[:-1], yd[1:], t[:-1], t[1:]
    with np.errstate(divide="ignore", invalid="ignore"):
        ts = (y1 - y0 + d0 * t0 - d1 * t1) / (d0 - d1)
        ys = y0 + d0 * (np.clip(ts, t0, t1) - t0)
    peak_out = (y0 < 0) & (y1 < 0) & (d0 > 0) & (d1 < 0) & (ys >= 0)
    dip_in = (y0 >= 0) & (y1 >= 0) & (d0 < 0) & (d1 > 0) & (ys < 0)
    return np.flatnonzero(peak_out | dip_in)


def dense_level_intervals(t, x, dxdt, level, side, evaluate: Callable[[float], tuple[float, float]],
                          xtol: float, max_iter: int = 60):
    r"""Intervals where ``x ≥ level`` (``side="above"``) or ``x ≤ level`` from a dense signal.

    The samples (an output grid with the signal's slopes) only *bracket*; every boundary is
    located on the dense signal ``evaluate(t) -> (x(t), dx/dt(t))`` (a run's dense output, or a
    re-integration from the sample before):

    1. every interval of :func:`hidden_extremes` (Eq. S2) is searched for its extreme, the root
       of dx/dt bracketed by the slopes' sign change (Brent's method to ``xtol``); if the
       extreme lies on the other side of the level, it is added as a sample, so that an
       exceedance (or a dip) that lies entirely between two samples is bracketed;
    2. each sign change of y = ±(x − level) between neighbouring samples is located by a
       safeguarded Newton iteration ``t ← t − y/ẏ`` (bisection whenever the step leaves the
       bracket or does not halve it) until the step or the bracket is below ``xtol``;
    3. :func:`level_intervals` assembles the intervals from the samples and the located
       boundaries.

    Parameters
    ----------
    t, x, dxdt : (n,) array_like
        Sample times [s] (strictly increasing), signal and its time derivative there.
    level : float
    side : {"above", "below"}
    evaluate : callable
        ``evaluate(t) -> (x, dx/dt)`` at any t in [t_0, t_{n−1}].
    xtol : float
        Time tolerance [s] of the located boundaries and extremes (derive it from the run's
        rtol: a boundary is known no better than the integration error over the slope).
    max_iter : int

    Returns
    -------
    DataFrame
        :func:`level_intervals`' columns (``resolution [s]`` is ``xtol`` for located
        boundaries) plus ``peak`` (the largest value of y = ±(x − level) seen in the interval,
        back in the unit of x: ``level ± max y``, from samples, located extremes and boundary
        iterates) and ``between samples`` (no sample of the input grid lies in the interval).
    """
    import scipy.optimize as so

    t, x = _samples(t, x, "dense_level_intervals")
    s = 1.0 if side == "above" else -1.0
    y, yd = _oriented(x, dxdt, level, side)
    known = {float(a): (float(b), float(c)) for a, b, c in zip(t, y, yd)}

    def ev(tt):
        tt = float(tt)
        if tt not in known:
            xv, dv = evaluate(tt)
            known[tt] = (s * (float(xv) - level), s * float(dv))
        return known[tt]

    extra = []
    for i in hidden_extremes(t, x, dxdt, level, side):
        a, b = float(t[i]), float(t[i + 1])
        try:
            tm = so.brentq(lambda u: ev(u)[1], a, b, xtol=xtol, maxiter=max_iter)
        except ValueError:  # the slope's sign change did not survive re-evaluation
            continue
        if (ev(tm)[0] >= 0) != (y[i] >= 0):
            extra.append(float(tm))
    tt = np.array(sorted(set(map(float, t)) | set(extra)))
    yy = np.array([known[float(u)][0] for u in tt])

    def refine(a, b):
        ya, yb = ev(a)[0], ev(b)[0]
        lo, hi = (a, b) if ya < 0 else (b, a)  # y(lo) < 0 <= y(hi)
        w = float(np.clip(ya / (ya - yb), 0.0, 1.0)) if ya != yb else 0.5
        tc = a + w * (b - a)
        for _ in range(max_iter):
            yc, dc = ev(tc)
            if yc < 0:
                lo = tc
            else:
                hi = tc
            width = abs(hi - lo)
            step = -yc / dc if dc != 0 else np.inf
            tn = tc + step
            if not (min(lo, hi) < tn < max(lo, hi)) or abs(step) > 0.5 * width:
                tn = 0.5 * (lo + hi)
                step = tn - tc
            tc = tn
            if abs(step) <= xtol or width <= xtol:
                break
        return float(tc)

    iv = level_intervals(tt, yy, 0.0, "above", refine=refine)
    if len(iv):
        iv["resolution [s]"] = float(xtol)
        ks = np.array(sorted(known))
        ys = np.array([known[u][0] for u in ks])
        peaks, between = [], []
        for a, b in zip(iv["start [s]"], iv["end [s]"]):
            sel = (ks >= a) & (ks <= b)
            peaks.append(level + s * float(ys[sel].max()) if sel.any() else float(level))
            between.append(not bool(np.any((t >= a) & (t <= b))))
        iv["peak"] = peaks
        iv["between samples"] = between
    else:
        iv["peak"] = pd.Series(dtype=float)
        iv["between samples"] = pd.Series(dtype=bool)
    return iv


def zero_crossings(x, y) -> np.ndarray:
    """Where ``y`` changes sign along ``x``: the crossings located by linear interpolation between
    the samples on either side, :math:`x_i - y_i (x_{i+1} - x_i)/(y_{i+1} - y_i)`.  A sample that is
    exactly zero starts no crossing of its own (its neighbours' sign change counts once)."""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    i = np.nonzero((np.sign(y[:-1]) != np.sign(y[1:])) & (y[:-1] != 0))[0]
    return x[i] - y[i] * (x[i + 1] - x[i]) / (y[i + 1] - y[i])
