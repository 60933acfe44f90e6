r"""Checked inputs of the biomech domain: plausible ranges, unit slips in trials, option names.

Every physical input a user gives the biomech functions -- a model file's masses and muscle
parameters, a trial's translations, centre of pressure and ground reactions, a body mass, a
filter cut-off, a time window, keyword arguments -- is checked once, where it enters (the reading
function or the public function), against the documented plausible ranges of
``data/biomech/plausible_ranges.csv`` (:class:`core.inputs.RangeTable`).  A value outside is
refused with one line naming the file (and line or column), the value, the range and the likely
slip::

    subject01_walk_IK.mot: column 'pelvis_ty' reaches 1046 m, outside the plausible range -0.5 m ... 2.5 m
    of the pelvis vertical translation (pelvis_ty): the values look like mm (1046 mm = 1.046 m) ...

A deliberate outlier passes with ``accept=[quantity, ...]`` of the reading function.

Heuristics over whole columns (a file's header cannot be trusted, the numbers can):

* **Angles in the wrong unit** (:func:`angle_unit_slip`).  A human joint angle in gait stays
  within ±π rad.  With ``inDegrees=no`` an angle column that reaches beyond 2π or spans more than
  2π is degrees (the RRA pitfall).  With ``inDegrees=yes``, if *every* angle column stays within
  ±π "degrees" (:data:`RADIANS_AS_DEGREES_REACH`) while the largest span among them is at least
  :data:`RADIANS_AS_DEGREES_MIN_SPAN` = 0.8 (46° if the values are radians, 0.8° if they were
  degrees), the values are radians: a walking knee alone spans about 60-75° (1.05-1.3 rad).  A
  quiet-standing trial written in degrees whose every angle stays within ±3.14° and sways by at
  least 0.8° would be a false alarm: ``check_degrees="warn"`` or ``"off"`` for such a file.
* **Lengths in mm or cm**: translation coordinates, the pelvis height and the centre of pressure
  are checked by their largest magnitude; the message names the unit in which the numbers as
  written would be plausible (``values look like mm``).
* **Ground reactions in body weights or N/kg**: the largest force of a force file below 50 N.
* **Time in ms or frames**: a sampling rate outside 10 Hz ... 20 kHz.

References
----------
Winter D.A. (2009) Biomechanics and Motor Control of Human Movement, 4th ed., Wiley (Table 4.1,
Sec. 3.4.4, ch. 5); Delp S.L. et al. (1990) IEEE TBME 37:757-767; Ward S.R. et al. (2009) Clin.
Orthop. Relat. Res. 467:1074-1082 (muscle architecture); de Leva P. (1996) J. Biomech. 29:1223.
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Iterable, Sequence

import numpy as np

from core.errors import DataFileError, DataRangeError, InputError
from core.inputs import ImplausibleValueError, RangeTable, checked_options, closest

__all__ = [
    "RANGES",
    "ranges",
    "ImplausibleDataError",
    "SamplingRateWarning",
    "RADIANS_AS_DEGREES_REACH",
    "RADIANS_AS_DEGREES_MIN_SPAN",
    "DEGREES_AS_RADIANS_REACH",
    "checked_options",
    "check_value",
    "check_column_magnitude",
    "angle_unit_slip",
    "nan_gaps",
    "check_window",
    "name_hint",
    "warn_sampling",
]

#: with inDegrees=no: an angle column reaching or spanning more than this [rad] is degrees
DEGREES_AS_RADIANS_REACH = 2.0 * math.pi
#: with inDegrees=yes: every angle column within ± this ["deg"] ...
RADIANS_AS_DEGREES_REACH = math.pi
#: ... and the largest span at least this: the values are radians (0.8 rad = 46 deg of motion)
RADIANS_AS_DEGREES_MIN_SPAN = 0.8


class ImplausibleDataError(ImplausibleValueError, DataFileError):
    """A value read from a data file lies outside its plausible range (both an
    :class:`core.inputs.ImplausibleValueError` and a :class:`core.errors.DataFileError`)."""


class SamplingRateWarning(UserWarning):
    """The kinematics and the force data are sampled at rates that do not go together."""


@functools.cache
def ranges() -> RangeTable:
    """The biomech range table (read once per process)."""
    from core.paths import data_path

    return RangeTable.from_csv(data_path("biomech", "plausible_ranges.csv"))


class _Lazy:
    def __getattr__(self, name):
        return getattr(ranges(), name)

    def __getitem__(self, key):
        return ranges()[key]

    def __contains__(self, key):
        return key in ranges()

    def __iter__(self):
        return iter(ranges())


#: the biomech :class:`core.inputs.RangeTable` (read on first use)
RANGES = _Lazy()

_LENGTH_SLIPS = ("mm", "cm")


def _fmt(x: float) -> str:
    x = float(x)
    if x == 0 or 1e-4 <= abs(x) < 1e7:
        return f"{x:.6g}"
    return f"{x:.4g}"


def _accepting(accept) -> set[str]:
    if accept is None:
        return set()
    if isinstance(accept, str):
        return {accept}
    return set(accept)


def check_value(quantity: str, value, *, where: str, accept=(), unit: str | None = None, hint: str = ""):
    """:meth:`RangeTable.check`; out of range, ``hint`` replaces the generic unit slip (or is appended)."""
    try:
        return ranges().check(quantity, value, where=where, accept=_accepting(accept), unit=unit)
    except ImplausibleValueError as exc:
        if not hint:
            raise
        msg = str(exc)
        tail = f" (to use it deliberately, accept={quantity!r})"
        if msg.endswith(tail):
            msg = msg[: -len(tail)]
        if exc.suggestion and msg.endswith(f": {exc.suggestion}"):
            msg = f"{msg[: -len(exc.suggestion) - 2]}: {hint}"  # the hint replaces the generic unit slip
        else:
            msg = f"{msg}; {hint}"
        raise ImplausibleValueError(f"{msg}{tail}", exc.quantity, exc.value, exc.suggestion) from None


def _slip_unit(quantity: str, value: float, units: Sequence[str]) -> tuple[str, float] | None:
    """The first of ``units`` in which ``value`` (as written) lies in the range, with the SI value."""
    from core.inputs import unit_registry

    r = ranges()[quantity]
    ureg = unit_registry()
    for u in units:
        f = float(ureg.Quantity(1.0, u).to(r.unit).magnitude)
        if r.contains(value * f):
            return u, value * f
    return None


def check_column_magnitude(quantity: str, values, *, where: str, column: str, accept=(),
                           slips: Sequence[str] = _LENGTH_SLIPS, error=ImplausibleDataError, what: str = "",
                           typical: tuple[float, float] | None = None):
    """Refuse a column whose largest magnitude (and smallest signed value) leaves the range.

    The message names the column, the value, the range and, when the numbers as written would be
    plausible in one of ``slips``, says "the values look like <unit>".  With ``typical`` (SI
    bounds), the slip that brings the column's median inside them is preferred (1046 is mm for a
    pelvis height of 1.046 m, 104.6 is cm).
    """
    if quantity in _accepting(accept):
        return
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return
    r = ranges()[quantity]
    k = int(np.argmax(np.abs(v)))
    worst = float(v[k])
    if r.contains(worst) and r.contains(float(v.min())) and r.contains(float(v.max())):
        return
    if not r.contains(worst):
        bad = worst
    else:
        bad = float(v.min()) if not r.contains(float(v.min())) else float(v.max())
    slip = _slip_unit(quantity, bad, slips)
    if typical is not None:
        med = float(np.median(v))
        for u in slips:
            hit = _slip_unit(quantity, bad, (u,))
            scaled = _slip_unit(quantity, med, (u,)) if hit else None
            if hit and scaled and typical[0] <= scaled[1] <= typical[1]:
                slip = hit
                break
    label = what or r.label
    msg = (f"{where}: column {column!r} reaches {_fmt(bad)} {_unit(r.unit)}, outside the plausible range "
           f"{r.describe()} of the {label}")
    if slip:
        u, si = slip
        msg += f": the values look like {u} ({_fmt(bad)} {u} = {_fmt(si)} {_unit(r.unit)}); write them in {_unit(r.unit)}"
    else:
        msg += f" ({r.rationale})"
    msg += f" (to use it deliberately, accept={quantity!r})"
    raise error(msg, quantity, bad, slip[0] if slip else "")


def _unit(u: str) -> str:
    return u.replace("*", " ").replace("^2", "²")


# ---------------------------------------------------------------------------------------------
# angles
# ---------------------------------------------------------------------------------------------
def angle_unit_slip(columns: dict[str, np.ndarray], in_degrees: bool | None) -> str:
    """Describe an implausible angle unit, or return "" (see the module docstring).

    Parameters
    ----------
    columns : dict
        Angle column name → values as written in the file.
    in_degrees : bool or None
        The file's flag (None: no flag, taken as radians).
    """
    stats = {}
    for col, v in columns.items():
        f = np.asarray(v, float)
        f = f[np.isfinite(f)]
        if f.size:
            stats[col] = (float(np.max(np.abs(f))), float(np.ptp(f)))
    if not stats:
        return ""
    if in_degrees:
        reach = max(s[0] for s in stats.values())
        col, (_, span) = max(stats.items(), key=lambda kv: kv[1][1])
        if reach <= RADIANS_AS_DEGREES_REACH and span >= RADIANS_AS_DEGREES_MIN_SPAN:
            return (f"the header has inDegrees=yes, but every angle column stays within ±π (largest |value| "
                    f"{reach:.4g}; {col!r} spans {span:.4g}, i.e. {math.degrees(span):.3g} deg if radians, a walking "
                    f"motion, but only {span:.3g} deg if degrees): the values look like radians; correct the header "
                    f"to inDegrees=no")
        return ""
    flag = "inDegrees=no" if in_degrees is False else "no inDegrees flag (taken as no)"
    for col, (reach, span) in stats.items():
        if reach > DEGREES_AS_RADIANS_REACH or span > DEGREES_AS_RADIANS_REACH:
            return (f"the header has {flag}, but angle column {col!r} reaches {reach:.4g} and spans {span:.4g} "
                    f"'rad' (more than 2π): the values look like degrees; correct the header to inDegrees=yes")
    return ""


# ---------------------------------------------------------------------------------------------
# gaps, windows, names
# ---------------------------------------------------------------------------------------------
def nan_gaps(t: np.ndarray, values: np.ndarray, columns: Sequence[str]) -> str:
    """A description of the first NaN gap ("" if none): column, number of samples, time range."""
    bad = ~np.isfinite(values)
    if not bad.any():
        return ""
    j = int(np.flatnonzero(bad.any(axis=0))[0])
    rows = np.flatnonzero(bad[:, j])
    start = int(rows[0])
    end = start
    while end + 1 < len(t) and bad[end + 1, j]:
        end += 1
    n_total = int(bad.sum())
    others = sorted({columns[k] for k in np.flatnonzero(bad.any(axis=0))} - {columns[j]})
    more = f"; {n_total} missing values in all" + (f", also in {others[:5]}" if others else "") \
        if n_total > end - start + 1 else ""
    return (f"column {columns[j]!r} has a gap of {end - start + 1} missing (NaN) value{'s' if end > start else ''} "
            f"at t = {t[start]:g} ... {t[end]:g} s{more}")


def check_window(window, t_lo: float, t_hi: float, *, where: str, tol: float = 1e-9) -> tuple[float, float]:
    """Refuse a time window that is not an increasing pair of times inside ``[t_lo, t_hi]``.

    The message names the data's range, and a window that fits when read as per cent of the gait
    cycle or as milliseconds says so.
    """
    try:
        lo, hi = (float(x) for x in window)
    except (TypeError, ValueError):
        raise InputError(f"{where}: window {window!r} must be two times (start, end) in seconds") from None
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise InputError(f"{where}: window ({lo:g}, {hi:g}) s must be finite")
    if not hi > lo:
        raise InputError(f"{where}: window ({lo:g}, {hi:g}) s must have start < end")
    if lo >= t_lo - tol and hi <= t_hi + tol:
        return lo, hi
    hint = ""
    if 0 <= lo < hi <= 100 and hi > t_hi + 1 and hi - lo >= 5:
        hint = (": it looks like per cent of the gait cycle; give the window in seconds (e.g. two successive "
                "heel strikes from biomech.inverse_dynamics.gait_events)")
    elif hi >= 10 and lo / 1000 >= t_lo - tol and hi / 1000 <= t_hi + tol:
        hint = f": it looks like milliseconds ({lo / 1000:g}, {hi / 1000:g}) s?"
    raise DataRangeError(f"{where}: window ({lo:g}, {hi:g}) s is outside the data's time range {t_lo:g} ... {t_hi:g} s"
                         f"{hint}")


def name_hint(name: str, candidates: Iterable[str]) -> str:
    """``"; did you mean 'x'?"`` (case-insensitive first, then difflib), or ""."""
    cands = list(candidates)
    low = {c.lower(): c for c in cands}
    if str(name).lower() in low:
        return f"; did you mean {low[str(name).lower()]!r}?"
    return closest(name, cands)


def warn_sampling(message: str) -> None:
    """Warn with a :class:`SamplingRateWarning` (attributed to the caller's caller)."""
    warnings.warn(message, SamplingRateWarning, stacklevel=3)

