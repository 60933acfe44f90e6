r"""What a railway engineer reads per contact and per wheel: Nadal's limit, Hertz pressure, wear
number, derailment quotient Y/Q.

All functions are vectorised (any array shapes that broadcast) and take SI units.  Acceptance
*limits* (EN 14363, UIC 518, TSI) are data, not code: the only one the project holds is the
second-hand Y/Q value in ``data/railway/assessment_limits.csv`` (:func:`assessment_limits`); no
EN 14363 numbers are hard-coded anywhere because they were not checked against the standard.

Equations
---------
Nadal's single-wheel derailment criterion (flange climbing starts when the lateral force ratio
of the climbing wheel reaches the friction-limited equilibrium on the flange of contact angle
gamma, with the friction force mu N acting fully against the climb)::

    (Y/Q)_lim = (tan gamma - mu) / (1 + mu tan gamma) = tan(gamma - arctan mu)           (A1)

Hertz's maximum pressure of an elliptical contact of semi-axes a, b under a normal force N
(the pressure is semi-ellipsoidal, p = p0 sqrt(1 - x^2/a^2 - y^2/b^2), whose integral is
(2/3) pi a b p0 = N)::

    p0 = 3 N / (2 pi a b)                                                                (A2)

Wear number (T-gamma): the work of the creep forces on the rigid creepages per unit distance
rolled, the quantity of wear and rolling-contact-fatigue damage functions::

    T_gamma = |Fx xi| + |Fy eta|            [N = J/m]                                    (A3)

The work rate of the creep forces on the rigid creepages is -V (Fx xi + Fy eta + Mz phi) with
the forces opposing the creepages; in full sliding at large creepage it is the frictional
dissipation of the patch (the elastic part of the local slip adds little): CONTACT's frictional
power for the Manchester cases equals it to 0.5 % where y >= 6.5 mm and to 3.5 % at the smallest
full-slip creepages (tested).  T_gamma is that work per metre *without the spin term* ``|Mz phi|``:
T-gamma damage functions and the usual engineering definition (the project notes, section 5)
use the two creep forces only; pass ``Mz`` and ``phi`` to add it.

Derailment quotient of a wheel (Y the lateral force of the wheel on the rail, positive towards
the field side of that rail; Q the vertical force of the wheel on the rail, positive
downwards)::

    Y/Q,   NaN where Q <= 0 (the wheel is lifted: the quotient is undefined)             (A4)

so that Y/Q > 0 on a flange-climbing wheel (the flange pushes its rail outwards).  From the
contact-frame forces (N along the rail normal n into the wheel, Fx along t, Fy along
l = n x t, the frame of :class:`railway.contact.forces.ContactForces`), the force on the wheel is
F = N n + Fx t + Fy l; summed over the contacts c of a wheel on side sigma (+1 left, -1 right)
with the track's lateral axis e_lat (to the left) and up axis e_up::

    Q = sum_c F_c . e_up,     Y = -sigma sum_c F_c . e_lat                               (A5)

Processing of time signals as a track test does (:func:`lowpass`, :func:`sliding_mean`,
:func:`wheel_force_statistics`).  A simulated wheel force carries the wheelset bouncing on its
Hertz springs (about 200 Hz on the Manchester coach); its extremes at a coarse output rate are
aliased samples of that oscillation and change from run to run with the rounding.  EN 14363 and
UIC 518 therefore assess filtered signals and percentiles, not raw maxima; as quoted second-hand
(GENSYS course notes, "Acceptance test according to UIC 518 and EN 14363",
http://gensys.se/course/UIC518_tests.html; not checked against the standard): Q low-pass 20 Hz,
the 99.85 % percentile; Y/Q and the track-shift force sum Y as sliding means over 2 m sampled every
0.5 m (after a low-pass of at least 20 Hz), the 0.15 % and 99.85 % percentiles.  With x(t)
sampled at f_s and filtered by a digital Butterworth low-pass of order n and cut-off f_c (bilinear
transform with pre-warping, scipy's ``butter``) run forwards and backwards (zero phase, the gain
squared)::

    |H(f)| = 1 / (1 + (tan(pi f / f_s) / tan(pi f_c / f_s))^(2n))                        (A6)

(1/2 at the cut-off; the same filter as :func:`biomech.kinematics.lowpass_filter`, which adds
OpenSim's padding).  The order n = 4 per pass is this project's choice: the quoted source gives
the cut-off, not the filter.  The sliding mean over a window w of distance s (x linear between
the samples)::

    x_w(s) = (1/w) int_{s - w/2}^{s + w/2} x(s') ds'                                     (A7)

which scales a harmonic of wavelength L by sin(pi w / L) / (pi w / L).  The processing
parameters are the defaults of the functions, not limits.

Events and peaks (:func:`wheel_event_statistics`) are taken from the accepted steps of the run
(``simulate(..., record_steps=True)``, ``contact_history(..., at="steps")``), not from the output
grid: wheel lift is the set where Q = 0, its boundaries located by bisection on Q > 0 inside the
step (event location); the time with Y/Q above a limit and the peaks of Q, ``|Y|``, Y/Q and the
flange force are taken over every accepted step (:mod:`core.signals`).  So they do not change
with the output step, and a lift shorter than it is found; the table says how many of the
events the output grid of the run would not show.

References
----------
Nadal, M. J. (1908). Locomotives a vapeur. Collection Encyclopedie Scientifique, Paris (A1;
quoted second-hand, not read here: formula and attribution as given by public summaries of the
"Nadal formula"; Marquis & Greif (2011), ASME JRC2011-56064, discuss its assumption F_t = mu N,
conservative at small angles of attack).
Johnson, K. L. (1985). Contact Mechanics, Cambridge University Press, sect. 4.2 (A2; Eq. H7 of
:mod:`core.contact_laws`; equation number in the book not checked here).
UIC Code 518 (2003): Y/Q <= 0.8 (quoted second-hand from D. P. Prayitno, MSc thesis, UGM,
eq. 3.9; not checked against the code).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from core.errors import DataFileError, InputError

__all__ = [
    "nadal_limit",
    "max_pressure",
    "wear_number",
    "derailment_quotient",
    "wheel_forces_track",
    "assessment_limits",
    "lowpass",
    "sliding_mean",
    "wheel_force_statistics",
    "wheel_event_statistics",
]

#: processing of the track-test quantities as quoted from EN 14363 / UIC 518 (module docstring):
#: low-pass cut-off (Hz) and order, sliding-mean window and sampling (m), percentiles (%)
CUTOFF_HZ, FILTER_ORDER = 20.0, 4
WINDOW_M, SAMPLING_M = 2.0, 0.5
PERCENTILES = (0.15, 99.85)


def _arrays(names, values):
    arrs = [np.asarray(v, dtype=float) for v in values]
    try:
        arrs = np.broadcast_arrays(*arrs)
    except ValueError:
        shapes = {n: np.shape(v) for n, v in zip(names, arrs)}
        raise InputError(f"inputs do not broadcast: {shapes}") from None
    return arrs


def _finite(name, x, where):
    bad = ~np.isfinite(x)
    if np.any(bad):
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InputError(f"{where}: {name}{list(idx)} = {float(x[idx])!r} is not finite")


def nadal_limit(contact_angle, mu):
    """Nadal's limit of the derailment quotient, Eq. (A1) of the module docstring [-].

    Parameters
    ----------
    contact_angle : float or array_like
        Flange contact angle gamma (rad), ``|gamma|`` < pi/2 (e.g. 70 deg = 1.22 rad for a new
        S1002 flank).
    mu : float or array_like
        Friction coefficient at the flange contact, >= 0.

    Returns
    -------
    ndarray
        (tan gamma - mu)/(1 + mu tan gamma) (broadcast shape); 1/mu as gamma -> 90 deg,
        tan gamma at mu = 0.

    Raises
    ------
    core.errors.InputError
        A non-finite value, ``|gamma|`` >= pi/2 or mu < 0 (names the value).

    References
    ----------
    Nadal (1908), quoted second-hand (see the module docstring).
    """
    g, m = _arrays(("contact_angle", "mu"), (contact_angle, mu))
    _finite("contact_angle", g, "Nadal limit")
    _finite("mu", m, "Nadal limit")
    if np.any(np.abs(g) >= 0.5 * np.pi):
        i = tuple(int(k) for k in np.argwhere(np.abs(g) >= 0.5 * np.pi)[0])
        raise InputError(f"Nadal limit: contact angle {float(g[i])!r} rad must lie inside "
                         "(-pi/2, pi/2); it is in radians")
    if np.any(m < 0):
        i = tuple(int(k) for k in np.argwhere(m < 0)[0])
        raise InputError(f"Nadal limit: friction coefficient mu = {float(m[i])!r} must be >= 0")
    t = np.tan(g)
    return (t - m) / (1.0 + m * t)


def max_pressure(N, a, b):
    """Hertz maximum contact pressure p0 = 3 N/(2 pi a b), Eq. (A2) [Pa].

    Parameters
    ----------
    N : float or array_like
        Normal force (N), >= 0.  Unloaded contacts (N = 0) give 0 whatever their semi-axes
        (e.g. zeros), as the creep laws do.
    a, b : float or array_like
        Semi-axes of the contact ellipse (m), > 0 where N > 0.

    Returns
    -------
    ndarray
        p0 (Pa), broadcast shape.

    Raises
    ------
    core.errors.InputError
        Non-finite input, N < 0, or a loaded contact with a <= 0 or b <= 0 (names it).

    References
    ----------
    Johnson (1985), sect. 4.2; Eq. (H7) of :mod:`core.contact_laws`.
    """
    N, a, b = _arrays(("N", "a", "b"), (N, a, b))
    for name, x in (("N", N), ("a", a), ("b", b)):
        _finite(name, x, "maximum pressure")
    if np.any(N < 0):
        i = tuple(int(k) for k in np.argwhere(N < 0)[0])
        raise InputError(f"maximum pressure: normal force N{list(i)} = {float(N[i])!r} N is negative")
    bad = (N > 0) & ((a <= 0) | (b <= 0))
    if np.any(bad):
        i = tuple(int(k) for k in np.argwhere(bad)[0])
        raise InputError(f"maximum pressure: loaded contact {list(i)} (N = {float(N[i])!r} N) needs "
                         f"semi-axes > 0, got a = {float(a[i])!r} m, b = {float(b[i])!r} m")
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(N > 0, 3.0 * N / (2.0 * np.pi * a * b), 0.0)


def wear_number(Fx, Fy, xi, eta, Mz=None, phi=None):
    """Wear number T_gamma = ``|Fx xi|`` + ``|Fy eta|``, Eq. (A3) [N = J/m].

    Parameters
    ----------
    Fx, Fy : float or array_like
        Longitudinal and lateral creep forces (N) in the contact frame.
    xi, eta : float or array_like
        Longitudinal and lateral creepages [-].
    Mz, phi : float or array_like, optional
        Spin moment (N m) and spin creepage (1/m).  Given together, ``|Mz phi|`` is added, so the
        result is the whole frictional dissipation per metre rolled (module docstring); left
        out by default, as in the usual T-gamma definition.

    Returns
    -------
    ndarray
        T_gamma (N), broadcast shape.

    Raises
    ------
    core.errors.InputError
        Non-finite input, or only one of ``Mz``, ``phi`` given.
    """
    if (Mz is None) != (phi is None):
        raise InputError("wear number: give both Mz and phi (spin term) or neither")
    names = ("Fx", "Fy", "xi", "eta") + (("Mz", "phi") if Mz is not None else ())
    vals = (Fx, Fy, xi, eta) + ((Mz, phi) if Mz is not None else ())
    arrs = _arrays(names, vals)
    for n, x in zip(names, arrs):
        _finite(n, x, "wear number")
    T = np.abs(arrs[0] * arrs[2]) + np.abs(arrs[1] * arrs[3])
    if Mz is not None:
        T = T + np.abs(arrs[4] * arrs[5])
    return T


def derailment_quotient(Y, Q):
    """Derailment quotient Y/Q of a wheel, Eq. (A4); NaN where Q <= 0 (wheel lifted) [-].

    Parameters
    ----------
    Y : float or array_like
        Lateral force of the wheel on the rail (N), positive towards the field side of that
        rail (see :func:`wheel_forces_track`).
    Q : float or array_like
        Vertical force of the wheel on the rail (N), positive downwards.

    Returns
    -------
    ndarray
        Y/Q, broadcast shape, NaN where Q <= 0.

    Raises
    ------
    core.errors.InputError
        NaN or infinite input (names it).
    """
    Y, Q = _arrays(("Y", "Q"), (Y, Q))
    _finite("Y", Y, "derailment quotient")
    _finite("Q", Q, "derailment quotient")
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(Q > 0, Y / np.where(Q > 0, Q, 1.0), np.nan)


def wheel_forces_track(N, Fx, Fy, normal, rolling_direction, side, lateral=(0.0, 1.0, 0.0),
                       up=(0.0, 0.0, 1.0)):
    """Y and Q of each wheel from its contacts' contact-frame forces, Eq. (A5).

    Parameters
    ----------
    N, Fx, Fy : (n_wheels, n_contacts) array_like
        Normal force and the creep forces along t and l = n x t of every contact candidate
        (the frame of :class:`railway.contact.forces.ContactForces`), zero for unloaded candidates.
    normal : (n_wheels, n_contacts, 3) array_like
        Rail normal into the wheel (global); ignored (may be NaN) where N = Fx = Fy = 0.
    rolling_direction : (n_wheels, 3) or (n_wheels, n_contacts, 3) array_like
        Forward axis of the wheelset (projected onto each tangent plane here, as in
        :class:`railway.contact.forces.ContactForces`).
    side : (n_wheels,) array_like
        +1 for a left wheel, -1 for a right wheel.
    lateral, up : (3,) or (n_wheels, 3) array_like
        Track lateral axis (to the left) and up axis, global.

    Returns
    -------
    Y, Q : (n_wheels,) ndarray
        Lateral force of the wheel on the rail, positive towards the field side, and vertical
        force of the wheel on the rail, positive downwards (N).
    F : (n_wheels, n_contacts, 3) ndarray
        Force of the rail on the wheel of every candidate (global, N).

    Raises
    ------
    core.errors.InputError
        Wrong shapes, a side other than +-1, a loaded contact with a non-finite normal, or a
        rolling direction parallel to a normal.
    """
    N = np.atleast_2d(np.asarray(N, dtype=float))
    Fx = np.asarray(Fx, dtype=float).reshape(N.shape)
    Fy = np.asarray(Fy, dtype=float).reshape(N.shape)
    nw, nc = N.shape
    n = np.asarray(normal, dtype=float)
    if n.shape != (nw, nc, 3):
        raise InputError(f"wheel forces: normal must have shape {(nw, nc, 3)}, got {n.shape}")
    d = np.asarray(rolling_direction, dtype=float)
    if d.shape == (nw, 3):
        d = np.broadcast_to(d[:, None, :], (nw, nc, 3))
    if d.shape != (nw, nc, 3):
        raise InputError(f"wheel forces: rolling_direction must have shape {(nw, 3)} or "
                         f"{(nw, nc, 3)}, got {d.shape}")
    sig = np.asarray(side, dtype=float).reshape(-1)
    if sig.shape != (nw,) or not np.all(np.abs(sig) == 1.0):
        raise InputError(f"wheel forces: side must be +1 (left) or -1 (right) for each of the "
                         f"{nw} wheels, got {np.asarray(side).tolist()!r}")
    loaded = (N != 0) | (Fx != 0) | (Fy != 0)
    if np.any(loaded & ~np.all(np.isfinite(n), axis=2)):
        i = tuple(int(k) for k in np.argwhere(loaded & ~np.all(np.isfinite(n), axis=2))[0])
        raise InputError(f"wheel forces: loaded contact {list(i)} has a non-finite normal")
    for name, x in (("N", N), ("Fx", Fx), ("Fy", Fy)):
        _finite(name, x, "wheel forces")
    nn = np.where(loaded[..., None], n, 0.0)
    t = d - np.sum(d * nn, axis=2)[..., None] * nn
    tn = np.linalg.norm(t, axis=2)
    if np.any(loaded & (tn < 1e-9)):
        i = tuple(int(k) for k in np.argwhere(loaded & (tn < 1e-9))[0])
        raise InputError(f"wheel forces: rolling direction parallel to the normal at contact {list(i)}")
    t = t / np.where(tn > 0, tn, 1.0)[..., None]
    l = np.cross(nn, t)
    F = N[..., None] * nn + Fx[..., None] * t + Fy[..., None] * l
    F = np.where(loaded[..., None], F, 0.0)
    lat = np.broadcast_to(np.asarray(lateral, dtype=float), (nw, 3))
    upv = np.broadcast_to(np.asarray(up, dtype=float), (nw, 3))
    Fs = F.sum(axis=1)
    Q = np.einsum("wk,wk->w", Fs, upv)
    Y = -sig * np.einsum("wk,wk->w", Fs, lat)
    return Y, Q, F


_LIMITS_FILE = ("railway", "assessment_limits.csv")


def assessment_limits():
    """Acceptance limits held as data (``data/railway/assessment_limits.csv``), with sources.

    Returns
    -------
    DataFrame
        Columns ``quantity``, ``limit [-]``, ``condition``, ``source``, ``status``.  Only
        values whose source is named; the status says whether they were checked against the
        original (none of them is).

    Raises
    ------
    core.errors.DataFileError
        The file is malformed (names it and the missing columns).
    """
    from core.paths import data_path

    path = data_path(*_LIMITS_FILE)
    df = pd.read_csv(path, comment="#")
    need = {"quantity", "limit [-]", "condition", "source", "status"}
    if not need <= set(df.columns):
        raise DataFileError(f"{path}: missing columns {sorted(need - set(df.columns))}")
    return df


def lowpass(x, fs, cutoff=CUTOFF_HZ, order=FILTER_ORDER):
    """Zero-phase Butterworth low-pass (A6) of the signal ``x`` sampled at ``fs`` Hz (along the
    last axis): scipy's ``butter`` in second-order sections run forwards and backwards
    (``sosfiltfilt``), so peaks stay where they are.

    Raises
    ------
    core.errors.InputError
        ``x`` is not finite, or the cut-off is not below the Nyquist frequency fs/2 (the signal
        cannot carry it).
    """
    from scipy.signal import butter, sosfiltfilt

    x = np.asarray(x, dtype=float)
    _finite("x", x, "lowpass")
    if not (0.0 < cutoff < 0.5 * fs):
        raise InputError(f"lowpass: cut-off {float(cutoff)!r} Hz must lie between 0 and the Nyquist frequency "
                         f"fs/2 = {0.5 * float(fs)!r} Hz")
    sos = butter(order, cutoff, btype="low", fs=fs, output="sos")
    return sosfiltfilt(sos, x, axis=-1)


def sliding_mean(s, x, window=WINDOW_M, step=SAMPLING_M):
    """Sliding mean (A7) of x over ``window`` metres of track, sampled every ``step`` metres.

    ``s`` (n,) increasing distance along the track, ``x`` (..., n) sampled at those points
    (linear in between).  Returns (centres, means): the window centres from s[0] + window/2 to
    s[-1] - window/2 in ``step`` increments and the means (..., m); NaN where x is NaN inside
    the window (a lifted wheel has no Y/Q).
    """
    s = np.asarray(s, dtype=float)
    x = np.asarray(x, dtype=float)
    if s.ndim != 1 or x.shape[-1] != s.size:
        raise InputError(f"sliding_mean: s has shape {s.shape}, x {x.shape}: need s (n,) and x (..., n)")
    if np.any(np.diff(s) <= 0.0):
        i = int(np.argmax(np.diff(s) <= 0.0))
        raise InputError(f"sliding_mean: s must increase; s[{i}] = {float(s[i])!r} m, s[{i + 1}] = {float(s[i + 1])!r} m")
    if s[-1] - s[0] < window:
        raise InputError(f"sliding_mean: {float(s[-1] - s[0])!r} m of signal is shorter than the window {window!r} m")
    centres = np.arange(s[0] + 0.5 * window, s[-1] - 0.5 * window + 1e-9 * window, step)
    # exact integral of the piecewise-linear signal: cumulative trapezoids, interpolated at the ends
    cum = np.concatenate([np.zeros(x.shape[:-1] + (1,)),
                          np.cumsum(0.5 * (x[..., 1:] + x[..., :-1]) * np.diff(s), axis=-1)], axis=-1)

    def integral(b):  # int_{s0}^{b} x ds for b inside [s0, s_end]
        j = np.clip(np.searchsorted(s, b, side="right") - 1, 0, s.size - 2)
        xb = x[..., j] + (x[..., j + 1] - x[..., j]) * (b - s[j]) / (s[j + 1] - s[j])
        return cum[..., j] + 0.5 * (x[..., j] + xb) * (b - s[j])

    return centres, (integral(centres + 0.5 * window) - integral(centres - 0.5 * window)) / window


def wheel_force_statistics(H, cutoff=CUTOFF_HZ, window=WINDOW_M, step=SAMPLING_M, percentiles=PERCENTILES):
    """Track-test statistics of simulated wheel forces (module docstring, A6-A7).

    ``H``: the long table of :func:`railway.vehicles.wheel_rail.contact_history` at a uniform output rate
    that resolves the wheelset's bounce (at least a few hundred Hz; 1 kHz in the scenes), with
    columns ``t [s]``, ``wheel``, ``wheelset``, ``s [m]``, ``Q [N]``, ``Y [N]``, ``sum Y [N]``.

    Per wheel: Q low-pass filtered at ``cutoff`` and its percentiles (``Q high [N]``, ``Q low
    [N]``), the unfiltered extremes of the samples (``Q max, unfiltered [N]``, ``Q min, unfiltered
    [N]``: extremes of this output grid, which change with its step; the peaks of the run are
    those of :func:`wheel_event_statistics`, from every accepted step), ``|Y|``
    filtered, its upper percentile (``|Y| high [N]``); Y/Q of the filtered forces as a sliding
    mean over ``window`` m, its upper percentile (``(Y/Q) 2 m high [-]``); per wheelset the same
    of the filtered sum Y, the largest magnitude of its two percentiles (``(sum Y) 2 m high
    [N]``).  Returns a DataFrame, one row per wheel.
    """
    t = np.unique(H["t [s]"].to_numpy())
    if t.size < 16:
        raise InputError(f"wheel_force_statistics: {t.size} output times; need a signal, not a few samples")
    dt = np.diff(t)
    if np.ptp(dt) > 1e-6 * dt.mean():
        raise InputError("wheel_force_statistics: the output times must be uniformly spaced "
                         f"(steps from {float(dt.min())!r} to {float(dt.max())!r} s)")
    fs = 1.0 / dt.mean()
    lo, hi = percentiles
    rows = []
    for wheel, g in H.groupby("wheel", sort=False):
        g = g.sort_values("t [s]")
        s = g["s [m]"].to_numpy()
        Q, Y, SY = (g[c].to_numpy() for c in ("Q [N]", "Y [N]", "sum Y [N]"))
        for name, x in (("Q [N]", Q), ("Y [N]", Y), ("sum Y [N]", SY)):
            bad = ~np.isfinite(x)
            if bad.any():
                k = int(np.argmax(bad))
                raise InputError(f"wheel_force_statistics: wheel {wheel!r}: {name} = {float(x[k])!r} at "
                                 f"t = {float(g['t [s]'].iloc[k])!r} s is not finite")
        Qf, Yf, SYf = lowpass(np.vstack([Q, Y, SY]), fs, cutoff)
        with np.errstate(invalid="ignore", divide="ignore"):
            yq = np.where(Qf > 0.0, Yf / Qf, np.nan)
        _, yq_w = sliding_mean(s, yq, window, step)
        _, sy_w = sliding_mean(s, SYf, window, step)
        rows.append({"wheel": wheel, "wheelset": g["wheelset"].iloc[0],
                     "Q high [N]": float(np.percentile(Qf, hi)), "Q low [N]": float(np.percentile(Qf, lo)),
                     "Q max, unfiltered [N]": float(Q.max()), "Q min, unfiltered [N]": float(Q.min()),
                     "|Y| high [N]": float(np.percentile(np.abs(Yf), hi)),
                     "(Y/Q) 2 m high [-]": float(np.nanpercentile(yq_w, hi)),
                     "(sum Y) 2 m high [N]": float(max(abs(np.percentile(sy_w, lo)), abs(np.percentile(sy_w, hi))))})
    return pd.DataFrame(rows)


def wheel_event_statistics(H, output_times=None, yq_limit=None, warn=True):
    """Wheel lift, peaks and exceedances per wheel from the dense record of a run.

    Parameters
    ----------
    H : DataFrame
        :func:`railway.vehicles.wheel_rail.contact_history` with ``at="steps"`` (every accepted step of a
        run made with ``record_steps=True``); its ``attrs["lift crossings"]`` give the located
        lift-off and touch-down times (else they are interpolated, to one step).  A table on
        the output grid is refused: its statistics would change with the output step.
    output_times : (n_t,) array_like, optional
        The output grid of the run (``result.t``): the table then counts the lifts and the
        Y/Q exceedances that fall between two output times (the grid does not show them) and,
        with ``warn``, issues a :class:`core.signals.GridResolutionWarning` naming the wheel.
    yq_limit : float, optional
        Limit of Y/Q for the time above it; default the Y/Q value of :func:`assessment_limits`.

    Returns
    -------
    DataFrame
        One row per wheel: ``lift-off first [s]`` (NaN: never lifted), ``lifts``, ``lifted
        [s]`` (total time with Q = 0), ``shortest lift [s]``, ``lift timing resolution [s]``,
        ``Q max [N]`` and ``t at Q max [s]``, ``Q min [N]``, ``|Y| max [N]``, ``Y/Q max [-]``
        and its time, ``flange force max [N]``, ``Y/Q above limit [s]`` and ``Y/Q
        exceedances`` (with ``Y/Q limit [-]``), ``accepted steps``; with ``output_times`` also
        ``lifts between outputs`` and ``Y/Q exceedances between outputs``.  ``attrs`` state the
        source.

    Raises
    ------
    core.errors.InputError
        A table not evaluated at the accepted steps, or missing columns.
    """
    from core.signals import level_summary, peak

    if H.attrs.get("at") != "steps":
        raise InputError("wheel_event_statistics: H must be a contact history at the accepted steps "
                         "(contact_history(model, result, at='steps') of a run with record_steps=True); statistics "
                         "of the output grid change with the output step")
    need = {"t [s]", "wheel", "Q [N]", "Y [N]", "Y/Q [-]", "flange force [N]"}
    if not need <= set(H.columns):
        raise InputError(f"wheel_event_statistics: H lacks the columns {sorted(need - set(H.columns))}")
    if yq_limit is None:
        lim = assessment_limits()
        yq_limit = float(lim.loc[lim["quantity"] == "Y/Q", "limit [-]"].iloc[0])
    crossings = H.attrs.get("lift crossings", {})
    tol = float(H.attrs.get("lift tolerance [s]", 0.0))
    rows = []
    for wheel, g in H.groupby("wheel", sort=False):
        g = g.sort_values("t [s]")
        t = g["t [s]"].to_numpy(float)
        Q = g["Q [N]"].to_numpy(float)
        located = crossings.get(wheel)
        refine = None
        if located is not None:
            def refine(ta, tb, located=located):  # noqa: E306 - per wheel
                return located.get(tb, tb)
        # lifted: Q = 0 exactly (the contact force of a separated wheel is zero); the level
        # 0 with side "below" includes it
        lift = level_summary(t, Q, 0.0, "below", refine, output_times, name=f"wheel {wheel!r} lift (Q = 0)",
                             warn=warn)
        yq = g["Y/Q [-]"].to_numpy(float)
        exc = level_summary(t, yq, yq_limit, "above", None, output_times, name=f"wheel {wheel!r} Y/Q",
                            warn=warn)
        refined = H.attrs.get("peaks", {}).get(wheel, {})

        def pk(col, kind, x):  # the refined peak of contact_history where it has one, else the samples'
            if col in refined and refined[col][0] == kind and t[0] <= refined[col][2] <= t[-1]:
                v_, t_ = refined[col][1:]  # (a table cut to a window keeps the refined peaks inside it)
                return (v_, t_) if np.isfinite(v_) else (float("nan"), float("nan"))
            return peak(t, x, kind)

        q_max, t_q_max = pk("Q [N]", "max", Q)
        q_min, _ = pk("Q [N]", "min", Q)
        y_max, _ = pk("Y [N]", "absmax", g["Y [N]"].to_numpy(float))
        y_max = abs(y_max)
        yq_max, t_yq = pk("Y/Q [-]", "max", yq)
        ff_max, _ = pk("flange force [N]", "max", g["flange force [N]"].to_numpy(float))
        row = {"wheel": wheel, "lift-off first [s]": lift["first [s]"], "lifts": lift["count"],
               "lifted [s]": lift["total [s]"], "shortest lift [s]": lift["shortest [s]"],
               "lift timing resolution [s]": tol if located is not None and lift["count"] else lift["resolution [s]"],
               "Q max [N]": q_max, "t at Q max [s]": t_q_max, "Q min [N]": q_min, "|Y| max [N]": y_max,
               "Y/Q max [-]": yq_max, "t at Y/Q max [s]": t_yq, "flange force max [N]": ff_max,
               "Y/Q limit [-]": float(yq_limit), "Y/Q above limit [s]": exc["total [s]"],
               "Y/Q exceedances": exc["count"], "accepted steps": int(t.size)}
        if output_times is not None:
            row["lifts between outputs"] = lift["missed by the output grid"]
            row["Y/Q exceedances between outputs"] = exc["missed by the output grid"]
        rows.append(row)
    df = pd.DataFrame(rows)
    df.attrs["source"] = ("every accepted step of the run; Q = 0 crossings located by bisection"
                          if crossings else "every accepted step of the run; crossings interpolated between steps")
    df.attrs["peaks"] = ("refined by sampling the steps around each candidate extreme" if H.attrs.get("peaks")
                         else "extreme samples at the accepted steps")
    return df
