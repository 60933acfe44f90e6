r"""Rider loads: load factors and jerk at the rider's seat in car axes, time spent above limits.

Public API (simple signatures; the train and circuit scenes call these)::

    rider_loads(model, result, car_body, rider_point=(0, 0, 0), *, axes=None,
                coordinate=None, jerk=True, jerk_step=1e-5) -> DataFrame
        one row per output time: "t [s]", ["L [m]"], "n_x [g]", "n_y [g]", "n_z [g]",
        "jerk_x [g/s]", "jerk_y [g/s]", "jerk_z [g/s]", "v_P [m/s]"
    load_factor(model, t, q, v, car_body, rider_point=(0, 0, 0), axes=None) -> (3,) ndarray
        the same at one state
    read_acceleration_limits(path=None) -> DataFrame
        data/coaster/acceleration_limits.csv: "axis", "level [g]", "max duration [s]", "basis"
    exceedances(t, n, level) -> DataFrame
        contiguous intervals where the signal n(t) is beyond the level
    time_above_limits(loads, limits=None, sections=None) -> DataFrame
        per limit row (and per track section): peak, number of exceedances, total and longest
        time beyond the level, verdict against the allowed duration -- read from the output
        grid (moves with the output step; warns GridResolutionWarning where it cannot resolve);
        coaster.train.time_above_limits_dense(run, limits, sections) gives the same table from
        the run's dense solution

**Load factor.**  The rider sits at the body-fixed point P of the car body (ρ′ in body
coordinates, ρ = A ρ′).  With the car's centre-of-mass acceleration a = r̈, its angular
velocity ω and angular acceleration ω̇ (global; core's spatial bodies carry the body-frame
ω̄ = Aᵀω, and ω̇ = A dω̄/dt since ω̄ × ω̄ = 0)::

    a_P = a + ω̇ × ρ + ω × (ω × ρ)                        (rigid-body kinematics)
    n   = Cᵀ Aᵀ (a_P − g_vec) / g,   g = |g_vec|          (load factor in car axes, in g)

with g_vec the model's gravity and C the car axes in body coordinates (columns x forward,
y left, z up through the seat; identity when the car body is mounted that way, as the
path-following joint's default ξ′ = x, ζ′ = z on a rotation-minimising frame gives).  n is the
specific force the seat and restraints apply to the rider, per unit weight: at rest on level
track n = (0, 0, 1); in free fall (the ballistic parabola) n = 0.  The accelerations a and
dω̄/dt come from the model's equations of motion at each output state (the index-1 KKT
solution, :func:`core.dynamics.accelerations`), not from finite differences of positions.

**Jerk.**  j = dn/dt, the rate of change of the components the rider feels (car axes).  n is a
function N(t, q, v) of the state (through the KKT accelerations); along the motion
(q̇ = Z(q) v, v̇ = a)::

    j = d/dτ N(t + τ, q ⊕ τ v, v + τ a) |_{τ=0}
      ≈ [N(t + ε, q ⊕ ε v, v + ε a) − N(t − ε, q ⊕ (−ε v), v − ε a)] / (2ε)

(q ⊕ δ the model's retraction, body-frame rotation increments).  This is the exact directional
derivative of the model's acceleration map along the state's flow, evaluated by a central
difference in τ: truncation O(ε²) (any path with the same first derivative gives the same
derivative), round-off O(eps_mach ``|N|`` / ε); ε = 1e-5 s gives about 1e-10 g/s on the coaster
scenes.  It needs two extra KKT solves per output time and no filtering of sampled data.

**Limits and durations.**  ASTM F2291 and EN 13814 give acceleration limits per axis as
envelopes of level against duration.  ``data/coaster/acceleration_limits.csv`` holds such an
envelope as data (second-hand numbers, see the file's source line and data/coaster/README.md):
each row is an axis, a signed level and the longest contiguous time allowed beyond it.
:func:`time_above_limits` measures every contiguous exceedance (crossing times by linear
interpolation between output samples), not only the peaks; :func:`coaster.train.time_above_limits_dense`
locates the crossings on the run's dense solution (re-integrated states, Newton on the load
factor with its rate along the flow) and finds exceedances between two outputs.

References
----------
ASTM F2291, Standard Practice for Design of Amusement Rides and Devices (acceleration limits
by axis and duration; not read here: numbers second-hand, see the data file).
EN 13814, Fairground and amusement park machinery and structures - Safety (the European
counterpart; not read here).
Pendrill, A.-M. and Eager, D. (2020). Velocity, acceleration, jerk, snap and vibration: forces in
our bodies during a roller coaster ride. Phys. Educ. 55:065012 (load factors in the rider's
axes, jerk).
Pombo, J. and Ambrósio, J. (2007). Modelling tracks for roller coaster dynamics. Int. J. Vehicle
Design 45(4):470-500 (rider accelerations from the multibody model).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from core import frames
from core.dynamics import accelerations
from core.errors import DataFileError, InputError
from core.signals import GridResolutionWarning, hidden_extremes

__all__ = [
    "LIMITS_FILE",
    "LOAD_COLUMNS",
    "JERK_COLUMNS",
    "STANDARD_GRAVITY",
    "exceedances",
    "load_factor",
    "read_acceleration_limits",
    "rider_loads",
    "time_above_limits",
]

#: The acceleration-limit envelope shipped with the project (second-hand numbers).
LIMITS_FILE = Path(__file__).resolve().parent.parent / "data" / "coaster" / "acceleration_limits.csv"
#: Load-factor columns of :func:`rider_loads` (car axes x forward, y left, z up).
LOAD_COLUMNS = ("n_x [g]", "n_y [g]", "n_z [g]")
#: Jerk columns of :func:`rider_loads`.
JERK_COLUMNS = ("jerk_x [g/s]", "jerk_y [g/s]", "jerk_z [g/s]")
#: g used to express loads in g when the model has no gravity (m/s²).
STANDARD_GRAVITY = 9.80665
_AXES = {"x": 0, "y": 1, "z": 2}


# ---------------------------------------------------------------------------------------------
# load factors
# ---------------------------------------------------------------------------------------------
class _Rider:
    """Checked inputs and the map N(t, q, v) of the module docstring."""

    def __init__(self, model, car_body, rider_point, axes):
        if getattr(model, "space", None) is None or model.space.dim != 3:
            raise InputError("rider loads need a spatial (3-D) model")
        self.model = model
        self.k = model.body_index(car_body)  # ModelError naming an unknown body
        if self.k >= model.n_bodies:
            raise InputError(f"rider loads: car body {car_body!r} is the ground")
        rho = np.asarray(rider_point, dtype=float)
        if rho.shape != (3,) or not np.all(np.isfinite(rho)):
            raise InputError(f"rider loads: rider_point must be 3 finite numbers (m, body axes), got "
                             f"{np.asarray(rider_point).tolist()}")
        self.rho = rho
        C = np.eye(3) if axes is None else np.asarray(axes, dtype=float)
        if C.shape != (3, 3) or not np.all(np.isfinite(C)) or np.abs(C.T @ C - np.eye(3)).max() > 1e-9 \
                or np.linalg.det(C) < 0:
            raise InputError("rider loads: axes must be a proper rotation (columns: car x forward, y left, z up "
                             f"in body coordinates), got {np.asarray(axes).tolist()}")
        self.C = C
        gv = np.asarray(model.gravity, dtype=float)
        self.g_vec = gv
        self.g = float(np.linalg.norm(gv)) or STANDARD_GRAVITY
        self.qs = model.q_slice(car_body)
        self.vs = model.v_slice(car_body)

    def loads(self, t, q, v):
        """(n (3,) in car axes [g], a (n_v,), v_P (3,) [m/s]) at one state."""
        a, _ = accelerations(self.model, t, q, v)
        return self.loads_given(q, v, a)

    def loads_given(self, q, v, a):
        """As :meth:`loads` with the accelerations ``a`` (n_v,) already known."""
        qb, vb, ab = q[self.qs], v[self.vs], a[self.vs]
        A = frames.euler_to_matrix(qb[3:7])
        wb, dwb = vb[3:6], ab[3:6]
        rho = self.rho
        # body components: Aᵀ a_P = Aᵀ a + ω̄̇ × ρ′ + ω̄ × (ω̄ × ρ′)
        aP = A.T @ (ab[:3] - self.g_vec) + np.cross(dwb, rho) + np.cross(wb, np.cross(wb, rho))
        vP = vb[:3] + A @ np.cross(wb, rho)
        return self.C.T @ aP / self.g, a, vP

    def jerk(self, t, q, v, a, eps):
        """dn/dt (3,) [g/s]: central difference of N along the flow (module docstring)."""
        m = self.model
        qp, qm = m.retract(q, eps * v), m.retract(q, -eps * v)
        n_p = self.loads(t + eps, qp, v + eps * a)[0]
        n_m = self.loads(t - eps, qm, v - eps * a)[0]
        return (n_p - n_m) / (2.0 * eps)


def load_factor(model, t, q, v, car_body, rider_point=(0.0, 0.0, 0.0), axes=None):
    """Load factor n = Cᵀ Aᵀ (a_P − g_vec)/g at one state (module docstring).

    Parameters
    ----------
    model : core.model.Model
        Spatial model.
    t : float
        Time (s).
    q : (n_q,) array_like
    v : (n_v,) array_like
    car_body : str
        Body that carries the rider.
    rider_point : (3,) array_like
        ρ′, the rider's point in body coordinates (m).
    axes : (3, 3) array_like, optional
        Car axes in body coordinates (columns x forward, y left, z up); default identity.

    Returns
    -------
    (3,) ndarray
        n_x, n_y, n_z (g).
    """
    r = _Rider(model, car_body, rider_point, axes)
    return r.loads(float(t), np.asarray(q, float), np.asarray(v, float))[0]


def rider_loads(model, result, car_body, rider_point=(0.0, 0.0, 0.0), *, axes=None, coordinate=None,
                jerk=True, jerk_step=1e-5):
    """Load factors and jerk at the rider point over a run, one row per output time.

    Equations in the module docstring: n = Cᵀ Aᵀ (a_P − g_vec)/g with a_P = a + ω̇ × ρ +
    ω × (ω × ρ), accelerations from the model's equations of motion at each output state;
    jerk as the derivative of n along the state's flow.

    Parameters
    ----------
    model : core.model.Model
        The spatial model that produced ``result``.
    result : core.results.SimulationResult
        A run (``t``, ``q``, ``v``); a failed run gives rows up to where it stopped.
    car_body : str
        Name of the body that carries the rider.
    rider_point : (3,) array_like
        ρ′, the rider's point (seat) in body coordinates (m).
    axes : (3, 3) array_like, optional
        Car axes in body coordinates (columns: x forward, y left, z up through the seat);
        default identity (the body axes are the car axes).
    coordinate : str, optional
        Name of the model's arc-length coordinate; adds the column ``"L [m]"``.
    jerk : bool
        Compute the jerk columns (two more KKT solves per row).
    jerk_step : float
        ε (s) of the central difference along the flow.

    Returns
    -------
    pandas.DataFrame
        Columns ``"t [s]"``, ``"L [m]"`` (with ``coordinate``), :data:`LOAD_COLUMNS`,
        :data:`JERK_COLUMNS` (with ``jerk``), ``"v_P [m/s]"`` (speed of the rider point).
        ``attrs``: ``meta`` and ``status`` of the run, ``car_body``, ``rider_point_m``,
        ``g_m_s2`` (the g that divides), ``jerk_method``.

    Raises
    ------
    core.errors.InputError
        A planar model, an unknown body (ModelError), a bad rider point, axes or jerk_step,
        or an unknown coordinate.
    """
    r = _Rider(model, car_body, rider_point, axes)
    eps = float(jerk_step)
    if jerk and not (np.isfinite(eps) and eps > 0):
        raise InputError(f"rider_loads: jerk_step must be a positive time step (s), got {jerk_step!r}")
    T = np.asarray(result.t, float)
    Q = np.asarray(result.q, float)
    V = np.asarray(result.v, float)
    n = np.empty((T.size, 3))
    j = np.full((T.size, 3), np.nan)
    vP = np.empty(T.size)
    for i in range(T.size):
        n[i], a, vp = r.loads(T[i], Q[i], V[i])
        vP[i] = np.linalg.norm(vp)
        if jerk:
            j[i] = r.jerk(T[i], Q[i], V[i], a, eps)
    df = pd.DataFrame({"t [s]": T})
    if coordinate is not None:
        names = list(getattr(model, "extra_names", []))
        if coordinate not in names:
            raise InputError(f"rider_loads: model {model.name!r} has no coordinate {coordinate!r} (has {names})")
        iq = model.n_bodies * 7 + names.index(coordinate)
        df["L [m]"] = Q[:, iq]
    for k, c in enumerate(LOAD_COLUMNS):
        df[c] = n[:, k]
    if jerk:
        for k, c in enumerate(JERK_COLUMNS):
            df[c] = j[:, k]
    df["v_P [m/s]"] = vP
    df.attrs.update(meta=dict(getattr(result, "meta", {}) or {}), status=getattr(result, "status", None),
                    car_body=car_body, rider_point_m=r.rho.tolist(), g_m_s2=r.g,
                    jerk_method=(f"derivative of the KKT load factor along the state's flow, central difference "
                                 f"eps = {eps:g} s" if jerk else "not computed"))
    return df


# ---------------------------------------------------------------------------------------------
# limits as data
# ---------------------------------------------------------------------------------------------
_LIMIT_COLUMNS = ["axis", "level [g]", "max duration [s]", "basis"]


def read_acceleration_limits(path=None):
    """Read an acceleration-limit envelope (value against duration per axis).

    The file (CSV, ``#`` comment lines first: its source) has the columns ``axis`` (x, y or z:
    car axes), ``level [g]`` (signed, non-zero: exceeded when n > level for a positive level,
    n < level for a negative one), ``max duration [s]`` (longest contiguous time allowed beyond
    the level; 0 a peak limit; empty: none given, reported only) and ``basis`` (where the row
    comes from).

    Parameters
    ----------
    path : str or Path, optional
        Default :data:`LIMITS_FILE` (second-hand numbers after ASTM F2291, see its source line).

    Returns
    -------
    pandas.DataFrame
        The rows; ``attrs["source"]`` holds the comment lines.

    Raises
    ------
    core.errors.DataFileError
        Missing file, wrong columns, an unknown axis, a zero or non-finite level, or a negative
        duration (the message names the file and the data row).
    """
    path = Path(LIMITS_FILE if path is None else path)
    if not path.is_file():
        raise DataFileError(f"{path}: acceleration-limit file not found")
    text = path.read_text(encoding="utf-8").splitlines()
    source = [ln.lstrip("#").strip() for ln in text if ln.startswith("#")]
    df = pd.read_csv(path, comment="#", skipinitialspace=True)
    if list(df.columns) != _LIMIT_COLUMNS:
        raise DataFileError(f"{path}: columns must be {_LIMIT_COLUMNS}, got {list(df.columns)}")
    for i, row in df.iterrows():
        if row["axis"] not in _AXES:
            raise DataFileError(f"{path}: data row {i}: axis {row['axis']!r} is not x, y or z")
        lev = float(row["level [g]"])
        if not np.isfinite(lev) or lev == 0.0:
            raise DataFileError(f"{path}: data row {i}: level {row['level [g]']!r} g must be finite and non-zero")
        dur = float(row["max duration [s]"])
        if dur < 0 or dur == np.inf:
            raise DataFileError(f"{path}: data row {i}: max duration {dur!r} s must be >= 0 (or empty)")
    df["level [g]"] = df["level [g]"].astype(float)
    df["max duration [s]"] = df["max duration [s]"].astype(float)
    df.attrs["source"] = " ".join(source)
    df.attrs["path"] = str(path)
    return df


def exceedances(t, n, level):
    """Contiguous intervals where a sampled signal is beyond a level.

    Beyond means n > level for level > 0 and n < level for level < 0.  Between samples the
    signal is taken as linear, so an entry or exit time is the linear interpolation of the
    crossing (exact for piecewise-linear signals); an interval still open at the first or last
    sample is cut there (``open`` True).

    Parameters
    ----------
    t : (N,) array_like
        Strictly increasing times (s).
    n : (N,) array_like
        Signal (g).
    level : float
        Non-zero level (g).

    Returns
    -------
    pandas.DataFrame
        One row per interval: ``start [s]``, ``end [s]``, ``duration [s]``, ``peak [g]`` (the
        sample furthest beyond the level), ``open`` (bool).

    Raises
    ------
    core.errors.InputError
        Shapes differ, times not strictly increasing or not finite, level zero or not finite.
    """
    t = np.asarray(t, dtype=float).reshape(-1)
    n = np.asarray(n, dtype=float).reshape(-1)
    level = float(level)
    if t.shape != n.shape:
        raise InputError(f"exceedances: t and n differ in length ({t.size} and {n.size})")
    if not (np.isfinite(level) and level != 0.0):
        raise InputError(f"exceedances: level must be finite and non-zero, got {level!r}")
    if t.size and (not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0)):
        i = int(np.argmax(~np.isfinite(t))) if not np.all(np.isfinite(t)) else int(np.argmax(np.diff(t) <= 0)) + 1
        raise InputError(f"exceedances: times must be finite and strictly increasing; t[{i}] = {float(t[i])!r} s")
    s = np.sign(level)
    x = s * (n - level)  # > 0 beyond the level
    above = x > 0
    rows = []
    i, N = 0, t.size
    while i < N:
        if not above[i]:
            i += 1
            continue
        j = i
        while j + 1 < N and above[j + 1]:
            j += 1
        if i == 0:
            start, op = t[0], True
        else:
            start = t[i - 1] + (t[i] - t[i - 1]) * (-x[i - 1]) / (x[i] - x[i - 1])
            op = False
        if j == N - 1:
            end, op = t[-1], True
        else:
            end = t[j] + (t[j + 1] - t[j]) * x[j] / (x[j] - x[j + 1])
        seg = n[i:j + 1]
        peak = float(seg[np.argmax(s * seg)])
        rows.append({"start [s]": float(start), "end [s]": float(end), "duration [s]": float(end - start),
                     "peak [g]": peak, "open": bool(op)})
        i = j + 1
    return pd.DataFrame(rows, columns=["start [s]", "end [s]", "duration [s]", "peak [g]", "open"])


def _section_runs(labels):
    """(label, first row, last row inclusive) of contiguous runs; a run ends on the next run's
    first row, so that consecutive runs share one sample and cover the record without gaps."""
    runs = []
    start = 0
    for i in range(1, len(labels) + 1):
        if i == len(labels) or labels[i] != labels[start]:
            runs.append((labels[start], start, min(i, len(labels) - 1)))
            start = i
    return runs


def limit_verdict(count: int, longest: float, allowed: float) -> str:
    """The verdict of one limit row: ``"no duration given"`` (no allowed duration in the
    limits file), ``"exceeds"`` (an exceedance longer than allowed, or any exceedance of a peak
    limit with allowed duration 0) or ``"within"``."""
    if np.isnan(allowed):
        return "no duration given"
    if count and (longest > allowed or allowed == 0.0):
        return "exceeds"
    return "within"


def time_above_limits(loads, limits=None, sections=None, time_column="t [s]"):
    """Time spent beyond each level of an acceleration envelope, per axis and per track section,
    read from the output grid.

    **Grid-based**: the durations move with the output step (crossings interpolated linearly
    between outputs, error O(h²)) and an exceedance shorter than the output step, between two
    outputs, is missed.  When ``loads`` carries the jerk columns (:func:`rider_loads`), output
    intervals whose slopes change sign with tangents reaching the level (an extreme between the
    outputs that may pass it: :func:`core.signals.hidden_extremes`) are counted and a
    :class:`core.signals.GridResolutionWarning` is issued.  For a train run, use
    :func:`coaster.train.time_above_limits_dense` (same table, from the run's dense solution:
    independent of the output step).

    For every limit row (axis, signed level, allowed duration) and every section, the
    contiguous exceedances of the load factor (:func:`exceedances`) give the number of
    exceedances, the total and the longest time beyond the level, and the peak.  The verdict
    is ``"exceeds"`` when the longest exceedance is longer than the allowed duration (any
    exceedance of a peak limit, allowed duration 0), ``"within"`` otherwise, and ``"no
    duration given"`` for a level without one (reported, not judged).

    Sections: a section's samples are its contiguous rows plus the first row of the following
    section (runs share one sample, so the record is covered without gaps); a section that
    occurs several times (a circuit passed twice) is summed over its occurrences.

    Parameters
    ----------
    loads : pandas.DataFrame
        :func:`rider_loads` output, or any table with a time column and the columns
        ``n_x [g]``, ``n_y [g]``, ``n_z [g]`` needed by the limits.
    limits : pandas.DataFrame, optional
        :func:`read_acceleration_limits` table; default the shipped file.
    sections : None, str or array_like, optional
        None (one section "all"), the name of a text column of ``loads``, or one label per row.
    time_column : str

    Returns
    -------
    pandas.DataFrame
        One row per (section, limit row): ``section``, ``axis``, ``level [g]``,
        ``max duration [s]``, ``peak [g]`` (furthest value beyond the level in the section, NaN
        if none), ``exceedances [-]``, ``time above [s]``, ``longest [s]``,
        ``longest starts at [s]``, ``verdict``, ``basis``.

    Raises
    ------
    core.errors.InputError
        A missing column, or section labels of the wrong length.
    """
    limits = read_acceleration_limits() if limits is None else limits
    if time_column not in loads.columns:
        raise InputError(f"time_above_limits: loads has no time column {time_column!r}")
    t = loads[time_column].to_numpy(float)
    if sections is None:
        labels = np.array(["all"] * len(loads), dtype=object)
    elif isinstance(sections, str):
        if sections not in loads.columns:
            raise InputError(f"time_above_limits: loads has no section column {sections!r}")
        labels = loads[sections].astype(str).to_numpy(dtype=object)
    else:
        labels = np.asarray(sections, dtype=object).reshape(-1)
        if labels.size != len(loads):
            raise InputError(f"time_above_limits: {labels.size} section labels for {len(loads)} rows")
    runs = _section_runs(list(labels))
    order = list(dict.fromkeys(labels))
    rows = []
    hidden = 0
    for sec in order:
        for _, lim in limits.iterrows():
            col = f"n_{lim['axis']} [g]"
            if col not in loads.columns:
                raise InputError(f"time_above_limits: loads has no column {col!r} (limit axis {lim['axis']!r})")
            level, allowed = float(lim["level [g]"]), float(lim["max duration [s]"])
            n = loads[col].to_numpy(float)
            ex = [exceedances(t[a:b + 1], n[a:b + 1], level) for s_, a, b in runs if s_ == sec and b >= a]
            jc = f"jerk_{lim['axis']} [g/s]"
            if jc in loads.columns:  # outputs whose slopes say an extreme between them passes the level
                j = loads[jc].to_numpy(float)
                side = "above" if level > 0 else "below"
                hidden += sum(len(hidden_extremes(t[a:b + 1], n[a:b + 1], j[a:b + 1], level, side))
                              for s_, a, b in runs if s_ == sec and b > a)
            ex = pd.concat([e for e in ex if len(e)], ignore_index=True) if any(len(e) for e in ex) else None
            sgn = math.copysign(1.0, level)
            if ex is None:
                count, total, longest, at, peak = 0, 0.0, 0.0, np.nan, np.nan
            else:
                k = int(np.argmax(ex["duration [s]"].to_numpy()))
                count, total = len(ex), float(ex["duration [s]"].sum())
                longest, at = float(ex["duration [s]"].iloc[k]), float(ex["start [s]"].iloc[k])
                pk = ex["peak [g]"].to_numpy()
                peak = float(pk[np.argmax(sgn * pk)])
            verdict = limit_verdict(count, longest, allowed)
            rows.append({"section": sec, "axis": lim["axis"], "level [g]": level, "max duration [s]": allowed,
                         "peak [g]": peak, "exceedances [-]": count, "time above [s]": total,
                         "longest [s]": longest, "longest starts at [s]": at, "verdict": verdict,
                         "basis": lim.get("basis", "")})
    out = pd.DataFrame(rows)
    out.attrs["source"] = limits.attrs.get("source", "")
    out.attrs["method"] = "grid-based: exceedances of the output samples, crossings interpolated linearly"
    if hidden:
        warnings.warn(f"time_above_limits: {hidden} output intervals may hide an exceedance (or a dip back) between "
                      "two outputs: their slopes change sign and their tangents reach the level (core.signals."
                      "hidden_extremes); this table is read from the output grid and does not resolve them: use "
                      "coaster.train.time_above_limits_dense", GridResolutionWarning, stacklevel=2)
    return out
