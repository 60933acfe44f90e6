r"""Coordinate kinematics for inverse dynamics: zero-lag low-pass filtering and smooth differentiation.

The processing follows OpenSim's inverse-dynamics tool (``InverseDynamicsTool::run``), with the
filter order a parameter:

1. **Padding.** Each coordinate series of n samples is extended by p = ⌊n/2⌋ samples at each end
   by odd reflection about the end value, x₋ₖ = 2x₀ − xₖ and x_{n−1+k} = 2x_{n−1} − x_{n−1−k}
   (value and slope continue), as ``Storage::pad(getSize()/2)`` / ``Signal::Pad`` do, so the
   filter's start-up transients fall in the padding.
2. **Filtering.** A digital low-pass Butterworth filter of order N designed by the bilinear
   transform with pre-warping (``scipy.signal.butter``), run forward and backward
   (``scipy.signal.sosfiltfilt``, steady-state initial conditions): zero phase lag, and an
   amplitude response

   .. math:: |H(f)| = \left[1 + \left(\frac{\tan(\pi f/f_s)}{\tan(\pi f_c/f_s)}\right)^{2N}\right]^{-1}

   i.e. that of a 2N-th order filter, with ``|H(f_c)|`` = 1/2 (−6 dB) at the design cut-off f_c.
   **Defaults here: N = 2 per pass (4th order effective after the two passes), f_c = 6 Hz.**
   OpenSim's ``Storage::lowpassIIR`` calls ``Signal::LowpassIIR``, a *3rd-order* Butterworth IIR
   filter (bilinear, pre-warped), also run forward and backward -- 6th order effective, also
   −6 dB at the cut-off it is given (``lowpass_cutoff_frequency_for_coordinates``, 6 Hz in the
   OpenSim gait examples).  Pass ``order=3`` to reproduce OpenSim's response.  Neither applies a
   cut-off correction for the second pass.  ``cutoff=None`` skips steps 1-2 (OpenSim: a negative
   cut-off).
3. **Differentiation.** An interpolating spline of odd degree k (default 5, quintic) through the
   filtered, padded samples, with natural end conditions (derivatives (k+1)/2 … k−1 zero at the
   ends), differentiated analytically: q̇ = s'(t), q̈ = s''(t) at the original sample times.
   OpenSim fits ``GCVSplineSet(5, ...)`` with zero error variance, i.e. the natural quintic
   interpolating spline of Woltring's GCVSPL, to the same padded data.

**End effects.**  The odd reflection continues value and slope but mirrors the curvature, so near
the ends of the record q̈ is pulled towards zero (and q̇ slightly off): for a test signal with
components of 1 and 2 Hz sampled at 60 Hz, f_c = 6 Hz, the q̈ error exceeds 1 % of its amplitude
only within 0.15 s of either end (0.22 s with N = 3) and is below 0.1 % beyond 0.25 s (0.32 s),
while q̇ is off by up to 10 % at the end samples.  OpenSim's processing has the same artefact;
analyse gait cycles that lie at least a few tenths of a second inside the record.

Units are kept: with coordinates in SI (radians, metres; :func:`biomech.storage.read_storage`
converts degrees), q̇ is in rad/s or m/s and q̈ in rad/s² or m/s².  The ``attrs`` of the returned
frames carry the units and the processing settings.

References
----------
OpenSim 4.x source (github.com/opensim-org/opensim-core): ``InverseDynamicsTool.cpp`` (pad,
lowpassIIR, ``GCVSplineSet(5, ...)``), ``Signal.cpp`` (``LowpassIIR``: "3rd order lowpass IIR
Butterworth digital filter", forward and reverse; ``Pad``).
Winter D.A. (2009) Biomechanics and Motor Control of Human Movement, 4th ed., Wiley, Sec. 3.4
(Butterworth filtering of kinematic data, forward and backward passes).
Woltring H.J. (1986) Adv. Eng. Softw. 8(2):104-113 (GCVSPL).
Oppenheim A.V., Schafer R.W. (2010) Discrete-Time Signal Processing, 3rd ed., Sec. 7.2.2 (bilinear
transformation, frequency pre-warping Ω = 2/T·tan(ω/2)).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.interpolate import make_interp_spline
from scipy.signal import butter, sosfiltfilt

from core.errors import InputError

from core.inputs import parse_quantity

from .checks import check_value, checked_options, name_hint

__all__ = [
    "CoordinateKinematics",
    "butterworth_gain",
    "odd_reflection_pad",
    "lowpass_filter",
    "process_coordinates",
    "check_cutoff",
]


def butterworth_gain(frequency, cutoff: float, sample_rate: float, order: int = 2):
    r"""Amplitude response of the zero-lag (forward-backward) digital Butterworth filter.

    .. math:: G(f) = \left[1 + \left(\tan(\pi f/f_s) / \tan(\pi f_c/f_s)\right)^{2N}\right]^{-1}

    Parameters
    ----------
    frequency : float or array_like
        [Hz], below the Nyquist frequency.
    cutoff, sample_rate : float
        [Hz].
    order : int
        N, the order of each pass.
    """
    f = np.asarray(frequency, dtype=float)
    ratio = np.tan(np.pi * f / sample_rate) / np.tan(np.pi * cutoff / sample_rate)
    return 1.0 / (1.0 + ratio ** (2 * order))


def odd_reflection_pad(values: np.ndarray, pad: int) -> np.ndarray:
    """Extend ``values`` (shape (n, ...)) by ``pad`` samples at each end by odd reflection about the
    end values (value and slope continue), as OpenSim's ``Signal::Pad``."""
    x = np.asarray(values, dtype=float)
    n = x.shape[0]
    if not 0 <= pad < n:
        raise InputError(f"pad must be in [0, {n - 1}] for {n} samples, got {pad}")
    if pad == 0:
        return x.copy()
    left = 2.0 * x[0] - x[pad:0:-1]
    right = 2.0 * x[-1] - x[-2:-pad - 2:-1]
    return np.concatenate([left, x, right], axis=0)


def _sample_rate(t: np.ndarray, label: str) -> float:
    if t.size < 2:
        raise InputError(f"{label}: need at least 2 samples, got {t.size}")
    dt = np.diff(t)
    h = float(np.median(dt))
    if not h > 0 or np.max(np.abs(dt - h)) > 1e-4 * h:
        k = int(np.argmax(np.abs(dt - h)))
        raise InputError(f"{label}: filtering needs uniformly spaced samples; interval {dt[k]:.6g} s after "
                         f"t = {t[k]:.6g} s differs from the typical {h:.6g} s (resample first)")
    return 1.0 / h


@checked_options
def lowpass_filter(values, sample_rate: float, cutoff: float = 6.0, order: int = 2, *,
                   pad: int | None = None, label: str = "signal") -> np.ndarray:
    """Zero-lag low-pass Butterworth filter (see the module docstring for the equations).

    Parameters
    ----------
    values : array_like, shape (n,) or (n, m)
        Uniformly sampled signal(s), time along axis 0.
    sample_rate : float
        f_s [Hz].
    cutoff : float
        f_c [Hz], 0 < f_c < f_s/2; the zero-lag response is 1/2 there.
    order : int
        Butterworth order N of each pass (2N effective).
    pad : int, optional
        Odd-reflection padding at each end; default ⌊n/2⌋ (OpenSim).  The returned array has the
        original length.
    label : str
        Names the signal in error messages.

    Returns
    -------
    ndarray, same shape as ``values``
    """
    x = np.asarray(values, dtype=float)
    if x.ndim not in (1, 2):
        raise InputError(f"{label}: values must be 1-D or 2-D, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise InputError(f"{label}: values contain NaN or inf")
    _check_filter(cutoff, sample_rate, order, label)
    n = x.shape[0]
    p = n // 2 if pad is None else int(pad)
    xp = odd_reflection_pad(x, p)
    sos = butter(order, cutoff, btype="low", fs=sample_rate, output="sos")
    yp = sosfiltfilt(sos, xp, axis=0, padtype=None)
    return yp[p:p + n]


def _check_filter(cutoff, sample_rate, order, label):
    if not (isinstance(order, (int, np.integer)) and not isinstance(order, bool) and 1 <= order <= 10):
        raise InputError(f"{label}: filter order must be an integer 1..10, got {order!r}")
    if isinstance(cutoff, bool) or not isinstance(cutoff, (int, float, np.integer, np.floating)):
        raise InputError(f"{label}: cut-off {cutoff!r} must be a number of Hz")
    if not (np.isfinite(cutoff) and 0 < cutoff < 0.5 * sample_rate * (1 - 1e-6)):  # margin: fs from rounded times
        raise InputError(f"{label}: cut-off {cutoff!r} Hz must lie between 0 and the Nyquist frequency "
                         f"{0.5 * sample_rate:g} Hz (half the sampling rate {sample_rate:.6g} Hz)")


def check_cutoff(cutoff: float, *, where: str = "cutoff", accept: Sequence[str] = ()) -> float:
    """Refuse a low-pass cut-off outside the plausible range of gait kinematics (2-30 Hz).

    A cut-off below 1 names the likely slip of a normalised frequency (a fraction of the Nyquist
    frequency, as ``scipy.signal.butter`` takes without ``fs``).
    """
    value = parse_quantity(cutoff, "Hz", where=where)
    hint = "a cut-off normalised by the Nyquist frequency (scipy's Wn)? give it in Hz" if 0 < value < 1 else ""
    return check_value("filter_cutoff", cutoff, where=where, accept=accept, hint=hint)


@dataclass(frozen=True, eq=False)
class CoordinateKinematics:
    """Filtered coordinates and their time derivatives at the motion's sample times.

    Attributes
    ----------
    q, qdot, qddot : pandas.DataFrame
        ``time`` [s] then one column per coordinate (SI: rad or m; per second; per second²).
        ``attrs["units"]`` names the unit of every column; ``attrs["processing"]`` the settings.
    settings : dict
        ``cutoff_hz``, ``order_per_pass``, ``effective_order``, ``spline_degree``, ``pad``,
        ``sample_rate_hz``, ``source``.
    """

    q: pd.DataFrame
    qdot: pd.DataFrame
    qddot: pd.DataFrame
    settings: dict

    @property
    def time(self) -> np.ndarray:
        return self.q["time"].to_numpy()


def _natural_bc(k: int, trailing_shape: tuple[int, ...]):
    """Natural end conditions of an odd-degree spline: derivatives (k+1)/2 … k-1 zero at both ends."""
    m = (k - 1) // 2
    cond = [(j, np.zeros(trailing_shape)) for j in range(m + 1, k)]
    return (cond, cond)


@checked_options
def process_coordinates(motion: pd.DataFrame, *, cutoff: float | None = 6.0, order: int = 2,
                        spline_degree: int = 5, columns: Sequence[str] | None = None,
                        accept: Sequence[str] = ()) -> CoordinateKinematics:
    """Filter coordinates and differentiate them as OpenSim's inverse-dynamics tool does.

    Parameters
    ----------
    motion : DataFrame
        ``time`` column [s] and coordinate columns in SI units (from
        :func:`biomech.storage.read_storage`); uniformly sampled when filtering.
    cutoff : float, str or None
        Low-pass cut-off f_c [Hz] (default 6; a string with its unit, ``"6 Hz"``, is converted);
        None: no filtering and no padding.
    order : int
        Butterworth order per pass (default 2, 4th order effective; OpenSim uses 3).
    spline_degree : {3, 5}
        Degree of the interpolating natural spline used for the derivatives (default 5, as OpenSim).
    columns : sequence of str, optional
        Coordinates to process (default: all columns but ``time``).
    accept : sequence of str
        ``["filter_cutoff"]`` lets a cut-off outside the plausible 2-30 Hz of gait kinematics
        through (``data/biomech/plausible_ranges.csv``).

    Returns
    -------
    CoordinateKinematics
        q (the filtered coordinates), q̇ and q̈ at the motion's times.

    Raises
    ------
    core.errors.InputError
        No ``time`` column, unknown columns, NaN values, non-uniform sampling (when filtering),
        a cut-off at or above the Nyquist frequency, too few samples for the spline.
    core.inputs.ImplausibleValueError
        A cut-off outside 2-30 Hz (typical for gait: 4-20 Hz), e.g. 0.06 Hz.
    """
    if "time" not in motion.columns:
        raise InputError("motion has no 'time' column")
    source = motion.attrs.get("source", "motion")
    cols = [c for c in motion.columns if c != "time"] if columns is None else list(columns)
    missing = [c for c in cols if c not in motion.columns]
    if missing:
        others = [c for c in motion.columns if c != "time"]
        raise InputError(f"{source}: columns {missing} are not in the motion{name_hint(str(missing[0]), others)}")
    if spline_degree not in (3, 5):
        raise InputError(f"spline_degree must be 3 or 5, got {spline_degree!r}")
    t = motion["time"].to_numpy(dtype=float)
    y = motion[cols].to_numpy(dtype=float)
    if not np.all(np.isfinite(y)):
        r, c = np.argwhere(~np.isfinite(y))[0]
        raise InputError(f"{source}: column {cols[c]!r} is {y[r, c]} at t = {t[r]:g} s")
    if t.size < spline_degree + 1:
        raise InputError(f"{source}: {t.size} samples; a degree-{spline_degree} spline needs at least {spline_degree + 1}")
    if np.any(np.diff(t) <= 0):
        raise InputError(f"{source}: times must increase strictly")
    fs = None
    pad = 0
    if cutoff is not None:
        written = cutoff
        cutoff = parse_quantity(cutoff, "Hz", where=f"{source}: cutoff")
        fs = _sample_rate(t, str(source))
        _check_filter(cutoff, fs, order, str(source))
        check_cutoff(written, where=f"{source}: cutoff", accept=accept)
        pad = t.size // 2
        h = 1.0 / fs
        tp = np.concatenate([t[0] - h * np.arange(pad, 0, -1), t, t[-1] + h * np.arange(1, pad + 1)])
        yp = odd_reflection_pad(y, pad)
        sos = butter(order, cutoff, btype="low", fs=fs, output="sos")
        yp = sosfiltfilt(sos, yp, axis=0, padtype=None)
    else:
        tp, yp = t, y
    spline = make_interp_spline(tp, yp, k=spline_degree, bc_type=_natural_bc(spline_degree, yp.shape[1:]), axis=0)
    q = spline(t)
    qd = spline(t, 1)
    qdd = spline(t, 2)
    in_units = motion.attrs.get("units", {})
    settings = {"cutoff_hz": cutoff, "order_per_pass": order if cutoff is not None else None,
                "effective_order": 2 * order if cutoff is not None else None, "spline_degree": spline_degree,
                "pad": pad, "sample_rate_hz": fs, "source": source}

    def frame(values, suffix):
        df = pd.DataFrame(values, columns=cols)
        df.insert(0, "time", t)
        units = {"time": "s"}
        for c in cols:
            u = in_units.get(c, "")
            units[c] = (u + suffix) if u else ""
        df.attrs.update(source=source, units=units, processing=dict(settings))
        return df

    return CoordinateKinematics(frame(q, ""), frame(qd, "/s"), frame(qdd, "/s^2"), settings)
