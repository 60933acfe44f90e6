r"""Ride comfort of railway passengers: frequency weightings, EN 12299 mean comfort, Sperling's W_z.

All functions take SI units (accelerations in m/s^2, frequencies in Hz, times in s) and are
vectorised over frequencies and over leading axes of signals (time along the last axis).  What
was checked against published numbers, and what could not be, is listed at the end of this
docstring; :mod:`tests.railway.test_comfort` holds the checks.

Frequency weightings
--------------------
Each weighting is an analogue filter, a product of band limiting, acceleration-velocity transition
and upward step (ISO 2631-1:1997 Annex A; the same structure in BS 6841:1987, ISO 2631-4:2001 and
ISO 8041), with s = j 2 pi f and omega_i = 2 pi f_i::

    H_h(s) = s^2 / (s^2 + omega_1 s / Q_1 + omega_1^2)                   high-pass     (W1)
    H_l(s) = omega_2^2 / (s^2 + omega_2 s / Q_2 + omega_2^2)              low-pass      (W2)
    H_t(s) = (1 + s/omega_3) / (1 + s/(Q_4 omega_4) + (s/omega_4)^2)      a-v transition (W3)
    H_s(s) = (s^2 + omega_5 s/Q_5 + omega_5^2) / (s^2 + omega_6 s/Q_6 + omega_6^2)  step (W4)
    W(s)   = K H_h(s) H_l(s) H_t(s) H_s(s)                                              (W5)

=========  ==============================  =====  =====  ====  ====  ====  ====  ====  ====  ====  =====
name       use                             f_1    f_2    f_3   f_4   Q_4   f_5   Q_5   f_6   Q_6   K
=========  ==============================  =====  =====  ====  ====  ====  ====  ====  ====  ====  =====
``Wb``     vertical z (EN 12299)           0.4    100    16    16    0.55  2.5   0.90  4.0   0.95  1.024
``Wc``     seat back x (EN 12299)          0.4    100    8     8     0.63  --    --    --    --    1
``Wd``     horizontal x, y (EN 12299)      0.4    100    2     2     0.63  --    --    --    --    1
``Wk``     vertical z (ISO 2631-1)         0.4    100    12.5  12.5  0.63  2.37  0.91  3.35  0.91  1
=========  ==============================  =====  =====  ====  ====  ====  ====  ====  ====  ====  =====

(frequencies in Hz; "--": no step, H_s = 1).  Q_1 = Q_2 = 1/sqrt(2) for all four, not the 0.71
the project notes (section 6) and ISO 2631-1/-4 print: ISO 8041 gives 1/sqrt(2) as the exact value
and states that ISO 2631-4 Table A.1 rounds it to 0.71 (ISO 8041 Table quoted in the Larson Davis
HVM200 reference manual, Table 3.1, https://manualshive.com/en/manual/larson-davis/hvm200/3698114?page=33).
The tabulated factors decide it: with 1/sqrt(2) the W_c, W_d and W_k values of ISO 2631-1 agree
to their rounding (but for three entries, below), with 0.71 a dozen bands of each miss by up to
3.9 units of the last digit (tested).  The step is written in the ISO form (W4), which tends to 1 at high frequency, so W_b
carries K = 1.024; BS 6841 normalises the step to 1 at DC and writes K = 0.4 -- the same filter,
since 0.4 (4/2.5)^2 = 1.024 (tested against the BS 6841 form written independently).

:func:`weighting_response` evaluates (W5) factor by factor in complex arithmetic;
:func:`frequency_weighting` gives the same filter as zeros, poles and gain in s (rad/s), e.g.
for ``scipy.signal.freqs_zpk`` or ``zpk2tf``.

Weighted acceleration
---------------------
:func:`weighted_acceleration` multiplies the discrete Fourier transform of the record by the
analogue response at the bin frequencies f_k = k f_s / N and transforms back::

    a_w = IDFT_N[ W(j 2 pi f_k) DFT_N[a] ],   k = 0 ... N/2 (real transforms)           (W6)

This applies the exact analogue gain and phase of (W5) to every frequency the sampled record
can carry; a digital filter from the bilinear transform would warp the frequency axis, which
matters here because the 100 Hz band limit sits at the Nyquist frequency of the usual
f_s = 200 Hz (the bilinear map omega_d = 2 arctan(omega / (2 f_s)) sends the analogue 100 Hz to
64 Hz, so H_l would cut in early), and pre-warping fixes only one frequency per section.  Frequencies above f_s/2 are absent from a sampled record, so the
band-limiting low-pass acts only up to there.  Two ways of treating the ends of a finite record:

* ``mode="periodic"`` (default): N = n, the record is one period of a periodic signal.  Exact for
  a stationary periodic signal with a whole number of periods in the record (a sine on a bin:
  relative error ~1e-14, tested).  For any other record the end joins the start with a jump or a
  kink: its response fades within seconds after the start (the slowest pole, of the 0.4 Hz
  high-pass, decays as exp(-1.78 t/s)) and its band-limited ringing (next item) reaches back from
  the end.  W(0) = 0, so the mean is removed.
* ``mode="from_rest"``: the record is padded with zeros to N >= n + 30 f_s / sigma_min (sigma_min
  the smallest decay rate abs(Re p) of the filter's poles), so that the wrapped tail is below
  exp(-30).  (W6) is then exactly the analogue filter, started at rest, applied to the
  band-limited (trigonometric) interpolation of the zero-extended samples -- what an instrument
  switched on at t = 0 would show, with two remarks.  The start-up transient decays as
  exp(-sigma_min t), as the instrument's does.  Where the record starts or ends with a jump or a
  kink (a sine cut off), the interpolation rings (Gibbs), the ringing is weighted by W near f_s/2
  and fades only algebraically, in both time directions: measured for a 16 Hz sine of amplitude 1
  cut off at the end of the record, through W_b at f_s = 200 Hz, 1e-3 in the last 0.05 s, 4e-5 at
  0.1-0.25 s and 4e-6 at 1-2 s before the end.  For a record with smooth ends (cosine tapers of
  2 s) the weighted sine equals the analogue steady state to 1e-8 once the transient has gone
  (tested to 1e-6 after 12 s).

For even N the Nyquist bin is multiplied by Re W(j pi f_s) instead of W (a real signal has a real
Nyquist component); that bin carries no power in a record sampled above twice its bandwidth, as a
measured (anti-alias filtered) or simulated record should be.

EN 12299 mean comfort, simplified method
----------------------------------------
With a_w the weighted accelerations of the floor (x and y with W_d, z with W_b), their r.m.s.
values over consecutive blocks of 5 s, and P95 the 95th percentile over the blocks of a 5 min
record (60 blocks)::

    a_i = sqrt( (1/n_b) sum_{blocks i} a_w^2 )                                           (C1)
    a_P95 = P95_i(a_i)                                                                    (C2)
    N_MV = 6 sqrt( (a_XP95^Wd)^2 + (a_YP95^Wd)^2 + (a_ZP95^Wb)^2 )                        (C3)

(EN 12299:2009, simplified method; formula and the 5 s / 5 min values as given in the project
notes, section 6 -- the standard itself was not read.)  The percentile is numpy's default
(linear interpolation between order statistics, Hyndman-Fan type 7); the standard's own
definition of P95 was not checked.  Comfort scale of N_MV, :data:`EN12299_SCALE`: N < 1 very
comfortable, 1 <= N < 2 comfortable, 2 <= N < 4 medium, 4 <= N < 5 uncomfortable, N >= 5 very
uncomfortable -- the scale as ride-comfort studies usually quote it, written here from the
project's own knowledge; a public statement of it in EN 12299 or a paper quoting it was searched
for and NOT found, so it is unverified here.

Sperling's ride index
---------------------
For one harmonic of peak acceleration a (cm/s^2) at frequency f (Hz) (Sperling 1941, as quoted
by Garg & Dukkipati 1984 and Forstberg 2000 through the project notes, section 6)::

    W_z = 0.896 (a^3 F(f) / f)^(1/10)                                                    (S1)
    F_v(f) = 0.325 f^2 (0.5 <= f < 5.9),  400/f^2 (5.9 <= f < 20),  1 (f >= 20)           (S2)
    F_h(f) = 0.8 f^2 (0.5 <= f < 5.4),    650/f^2 (5.4 <= f < 26),  1 (f >= 26)

(the quoted pieces do not join: going up in frequency F_v rises by 1.6 % at 5.9 Hz, F_h drops by
4.4 % at 5.4 Hz and rises by 4 % at 26 Hz, i.e. W_z changes by 0.16, 0.45 and 0.4 %; each break
frequency here belongs to the upper piece).
For a spectrum, the continuous form with the weighting B of the same notes::

    B_v(f) = 0.588 sqrt[ (1.911 f^2 + (0.25 f^2)^2) /
                          ((1 - 0.277 f^2)^2 + (1.563 f - 0.0368 f^3)^2) ],  B_h = 1.25 B_v  (S3)
    W_z = [ c int_{f_lo}^{f_hi} B(f)^2 G(f) df ]^(1/6.67)                                 (S4)

with G the one-sided PSD of the acceleration in (cm/s^2)^2/Hz (int G df = mean square).  The
factor c is where the two forms part: for a sine of peak a, int G df = a^2/2, and (S4) with c = 1
gives about 2^(-0.15) = 0.90 times (S1) at every frequency -- 10 % low.  It is B^2 a^2, not
B^2 a^2/2, that reproduces (S1): with c = 2 the two forms agree to 1 % from 0.8 to 5 Hz and at
8 Hz (vertical).  So :func:`sperling` uses c = 2 by default (``normalisation="peak"``:
G integrates to the sum of squared peak amplitudes), which is also what a public MATLAB
implementation does (janiex/SimulinkMatlab, Matlab/sperling.m: ``2*Pxx`` from ``pwelch``, a
one-sided PSD); ``normalisation="mean-square"`` gives the notes' literal c = 1.  The ratio
(S4)/(S1) for a sine of peak 1 m/s^2, c = 2 (from the formulas; the tests reproduce it)::

    f [Hz]      0.5    0.8    1      2      3      4      5      5.9    8      10     15     20
    vertical    0.965  1.000  1.007  1.004  1.003  1.006  0.998  0.975  1.000  0.989  0.961  0.948
    lateral     0.943  0.977  0.984  0.981  0.980  0.983  0.976  0.993  1.018  1.007  0.979  0.965

(c = 1: every entry times 2^(-0.15) = 0.901, i.e. 0.78-0.92.)

Where they disagree by more than 1-2 % (0.5 Hz, near the breaks of F, above 10 Hz) neither is
"right": (S3) is a smooth rational fit of the piecewise (S2), and (S4) sums powers (a^2) where
the harmonic sum (W_z^10 = sum W_zi^10) sums a^3.  The exponent 1/6.67 (as printed) is not
exactly 3/20, which leaves a^(-0.00015) between the forms (0.07 % at a = 1 m/s^2).  The PSD is
the periodogram of the whole record (boxcar window, mean removed): for an integral of the PSD the
periodogram is exact by Parseval's theorem (sum_k B^2 G_k df = mean square of the abs(B)-filtered
periodic record), whereas Welch's averaging only lowers the variance of G at each frequency,
which the integral does not need, and its window leaks a line into its neighbours.  Band
f_lo..f_hi = 0.5..30 Hz by default, the band of the MATLAB implementation above (not checked
against a standard).

Scales (the notes' wording, second-hand, :data:`SPERLING_COMFORT_SCALE`,
:data:`SPERLING_QUALITY_SCALE`): passenger comfort W_z = 1 just noticeable, 2 clearly noticeable,
2.5 more pronounced but not unpleasant, 3 strong, irregular, still tolerable, 3.25 very irregular,
3.5 extremely irregular, unpleasant, 4 extremely unpleasant, harmful on prolonged exposure;
vehicle ride quality W_z = 1 very good, 2 good, 3 satisfactory, 4 acceptable for running,
4.5 not acceptable for running, 5 dangerous.

What was checked, and what was not
----------------------------------
Checked (tests): W_k and W_d at the 37 one-third-octave bands 0.1-400 Hz and W_c at 30 bands
0.1-80 Hz against the ISO 2631-1:1997 Table 3/4 factors as transcribed in three public code
files that agree value for value (data/railway/iso2631_weighting_factors.csv, its header names
them), to half a unit of the printed last digit -- except W_d at 10 Hz (table 212, formula 201.7:
a misprint, see the CSV) and W_k at 1.25 Hz and 16 Hz (0.55 and 0.70 units: the table rounds the
other way).  Whether ISO 2631-1 declares the formulas or the table normative, and the table
rounded, could not be read; the tests treat the table as the formulas rounded to the printed
digits, which every other entry bears out.  W_b, W_c, W_d at 100 rad/s
against the ISO 8041 reference values quoted by a vendor page (4 digits).  W_b against the BS 6841
form (K = 0.4, step normalised at DC).  Not checked: any W_b table at the band frequencies (none
was found in public material; BS 6841 and ISO 2631-4 are paywalled); the EN 12299 text (block
length, percentile definition, comfort scale); Sperling's original paper and the two books quoted
for (S1)-(S3) and the scales.

References
----------
ISO 2631-1:1997, Mechanical vibration and shock -- Evaluation of human exposure to whole-body
vibration -- Part 1: General requirements, Annex A (W1)-(W5), Tables 3 and 4 (not read; see above).
ISO 2631-4:2001 (W_b) and BS 6841:1987 (W_b, W_c, W_d; K = 0.4 form), not read; the BS 6841
parameters as implemented in public MATLAB code (cseats/Footfall_app_data,
footfall-data-master/matlab/bs6841freqweight.m, bs6841bandlimit.m).
ISO 8041 (Human response to vibration -- Measuring instrumentation), parameter table and note on
Q_1 as quoted in the Larson Davis HVM200 Reference Manual, Table 3.1.
EN 12299:2009, Railway applications -- Ride comfort for passengers -- Measurement and evaluation
(C1)-(C3), as summarised in the project notes (shared/notes/flexible.md, section 6).
Sperling, E. (1941); Garg, V. K., Dukkipati, R. V. (1984), Dynamics of Railway Vehicle Systems,
Academic Press; Forstberg, J. (2000), Ride comfort and motion sickness in tilting trains, KTH --
(S1)-(S4) and the scales as quoted in the project notes, section 6 (second-hand).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from core.errors import InputError

__all__ = [
    "WEIGHTING_NAMES",
    "Weighting",
    "frequency_weighting",
    "weighting_response",
    "weighting_gain",
    "weighted_acceleration",
    "EN12299_SCALE",
    "en12299_scale",
    "mean_comfort",
    "sperling_correction",
    "sperling_weighting",
    "sperling_harmonic",
    "sperling",
    "SPERLING_COMFORT_SCALE",
    "SPERLING_QUALITY_SCALE",
    "sperling_scale",
    "sperling_scales",
]

_Q_BAND = 1.0 / np.sqrt(2.0)  # ISO 8041: exact value; ISO 2631-1/-4 print 0.71

#: parameters of (W1)-(W5): frequencies in Hz; f5 = f6 = None for no step (H_s = 1)
_PARAMETERS = {
    "Wb": dict(use="vertical z, EN 12299 floor and seat (ISO 2631-4, BS 6841)",
               f1=0.4, q1=_Q_BAND, f2=100.0, q2=_Q_BAND, f3=16.0, f4=16.0, q4=0.55,
               f5=2.5, q5=0.90, f6=4.0, q6=0.95, k=1.024),
    "Wc": dict(use="seat back x, EN 12299 (ISO 2631-1 Table 4)",
               f1=0.4, q1=_Q_BAND, f2=100.0, q2=_Q_BAND, f3=8.0, f4=8.0, q4=0.63,
               f5=None, q5=None, f6=None, q6=None, k=1.0),
    "Wd": dict(use="horizontal x and y, EN 12299 floor and seat (ISO 2631-1 Table 3)",
               f1=0.4, q1=_Q_BAND, f2=100.0, q2=_Q_BAND, f3=2.0, f4=2.0, q4=0.63,
               f5=None, q5=None, f6=None, q6=None, k=1.0),
    "Wk": dict(use="vertical z, ISO 2631-1 Table 3 (for comparison with W_b)",
               f1=0.4, q1=_Q_BAND, f2=100.0, q2=_Q_BAND, f3=12.5, f4=12.5, q4=0.63,
               f5=2.37, q5=0.91, f6=3.35, q6=0.91, k=1.0),
}

#: the weighting names accepted (also "W_b", "wb", "W b", ... for each)
WEIGHTING_NAMES = tuple(_PARAMETERS)


def _weighting_key(name) -> str:
    """Canonical name ("Wb") of ``name`` ("Wb", "W_b", "wb", "W b", "W-b"), else InputError."""
    if isinstance(name, str):
        key = "".join(ch for ch in name.strip().lower() if ch not in "_- ")
        for canon in _PARAMETERS:
            if key == canon.lower():
                return canon
    from core.inputs import closest

    raise InputError(f"frequency weighting {name!r} is not known; valid names: "
                     f"{', '.join(WEIGHTING_NAMES)} (also written W_b, wb, ...)"
                     f"{closest(str(name), WEIGHTING_NAMES) if isinstance(name, str) else ''}")


def _frequencies(f, where: str) -> np.ndarray:
    f = np.asarray(f, dtype=float)
    bad = ~np.isfinite(f) | (f < 0)
    if np.any(bad):
        i = tuple(int(k) for k in np.argwhere(bad)[0])
        raise InputError(f"{where}: frequency f{list(i)} = {float(f[i])!r} Hz must be finite and >= 0")
    return f


def _quadratic_roots(w: float, q: float) -> np.ndarray:
    """Roots of s^2 + w s / q + w^2 (rad/s)."""
    return np.roots([1.0, w / q, w * w])


@dataclass(frozen=True)
class Weighting:
    """One frequency weighting (W5) as an analogue filter.

    Attributes
    ----------
    name : str
        Canonical name, one of :data:`WEIGHTING_NAMES`.
    use : str
        Direction and standard it serves.
    parameters : dict
        f1..f6 (Hz), Q1..Q6, K of (W1)-(W5); f5 = f6 = None where there is no step.
    zeros, poles : ndarray, complex
        Zeros and poles in s (rad/s).
    gain : float
        Gain k of W(s) = k prod(s - z) / prod(s - p).
    """

    name: str
    use: str
    parameters: dict = field(repr=False)
    zeros: np.ndarray = field(repr=False)
    poles: np.ndarray = field(repr=False)
    gain: float

    def response(self, f):
        """Complex W(j 2 pi f) (same as :func:`weighting_response`)."""
        return weighting_response(self.name, f)

    @property
    def ba(self):
        """Numerator and denominator polynomial coefficients in s (descending powers)."""
        from scipy.signal import zpk2tf

        b, a = zpk2tf(self.zeros, self.poles, self.gain)
        return np.real(b), np.real(a)

    @property
    def slowest_decay_rate(self) -> float:
        """Smallest abs(Re p) over the poles (1/s): the start-up transient fades as exp(-rate t)."""
        return float(np.min(np.abs(self.poles.real)))


def frequency_weighting(name) -> Weighting:
    """The weighting ``name`` (W1)-(W5) as zeros, poles and gain in s (rad/s).

    Parameters
    ----------
    name : str
        "Wb", "Wc", "Wd" or "Wk" (case, "_", "-" and blanks ignored: "W_b", "wb").

    Returns
    -------
    Weighting
        With ``zeros``, ``poles``, ``gain`` (``scipy.signal`` zpk form), ``ba`` and the parameters.

    Raises
    ------
    core.errors.InputError
        An unknown name (the message lists the valid ones).

    Notes
    -----
    H_h: zeros {0, 0}, poles of s^2 + omega_1 s/Q_1 + omega_1^2, gain 1; H_l: poles of the same
    form at omega_2, gain omega_2^2; H_t: zero -omega_3, poles at omega_4, gain omega_4^2/omega_3;
    H_s: zeros at omega_5, poles at omega_6, gain 1; times K.
    """
    key = _weighting_key(name)
    p = _PARAMETERS[key]
    w = {i: 2.0 * np.pi * p[f"f{i}"] for i in (1, 2, 3, 4, 5, 6) if p[f"f{i}"] is not None}
    zeros = [0.0, 0.0, -w[3]]
    poles = [*_quadratic_roots(w[1], p["q1"]), *_quadratic_roots(w[2], p["q2"]),
             *_quadratic_roots(w[4], p["q4"])]
    gain = p["k"] * w[2] ** 2 * w[4] ** 2 / w[3]
    if 5 in w:
        zeros += list(_quadratic_roots(w[5], p["q5"]))
        poles += list(_quadratic_roots(w[6], p["q6"]))
    params = {k: v for k, v in p.items() if k != "use"}
    return Weighting(key, p["use"], params, np.asarray(zeros, dtype=complex),
                     np.asarray(poles, dtype=complex), float(gain))


def weighting_response(name, f):
    """Complex frequency response W(j 2 pi f) of the weighting ``name``, Eq. (W5).

    Parameters
    ----------
    name : str
        "Wb", "Wc", "Wd" or "Wk" (also "W_b", "wb", ...).
    f : float or array_like, any shape
        Frequencies (Hz), finite, >= 0.

    Returns
    -------
    ndarray, complex, shape of ``f``
        K H_h H_l H_t H_s evaluated factor by factor (no polynomial expansion).

    Raises
    ------
    core.errors.InputError
        Unknown weighting name; a negative or non-finite frequency (names it).
    """
    key = _weighting_key(name)
    p = _PARAMETERS[key]
    f = _frequencies(f, f"weighting {key}")
    s = 2j * np.pi * f
    w1, w2, w3, w4 = (2.0 * np.pi * p[k] for k in ("f1", "f2", "f3", "f4"))
    h = s * s / (s * s + w1 * s / p["q1"] + w1 * w1)                      # (W1)
    h = h * (w2 * w2 / (s * s + w2 * s / p["q2"] + w2 * w2))              # (W2)
    h = h * ((1.0 + s / w3) / (1.0 + s / (p["q4"] * w4) + (s / w4) ** 2))  # (W3)
    if p["f5"] is not None:                                               # (W4)
        w5, w6 = 2.0 * np.pi * p["f5"], 2.0 * np.pi * p["f6"]
        h = h * ((s * s + w5 * s / p["q5"] + w5 * w5) / (s * s + w6 * s / p["q6"] + w6 * w6))
    return p["k"] * h


def weighting_gain(name, f):
    """Gain abs(W(j 2 pi f)) of the weighting ``name`` (W5) at frequencies ``f`` (Hz).

    Vectorised over ``f`` (any shape); see :func:`weighting_response` for names and errors.
    E.g. ``weighting_gain("Wb", [1, 4, 8])`` -> approx. [0.385, 0.889, 1.025].
    """
    return np.abs(weighting_response(name, f))


def _check_fs(fs, where: str) -> float:
    try:
        fs = float(fs)
    except (TypeError, ValueError):
        raise InputError(f"{where}: sampling frequency fs = {fs!r} is not a number (Hz)") from None
    if not np.isfinite(fs) or fs <= 0.0:
        raise InputError(f"{where}: sampling frequency fs = {fs!r} Hz must be finite and > 0")
    return fs


def _signal(a, name: str, where: str, min_samples: int = 2) -> np.ndarray:
    try:
        a = np.asarray(a, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{where}: {name} is not an array of numbers") from None
    if a.ndim == 0 or a.shape[-1] < min_samples:
        raise InputError(f"{where}: {name} needs at least {min_samples} samples along its last axis "
                         f"(shape {a.shape})")
    bad = ~np.isfinite(a)
    if np.any(bad):
        i = tuple(int(k) for k in np.argwhere(bad)[0])
        raise InputError(f"{where}: {name}{list(i)} = {float(a[i])!r} is not finite "
                         "(NaN or inf in the signal)")
    return a


_MODES = ("periodic", "from_rest")


def weighted_acceleration(a, fs, name, *, mode: str = "periodic"):
    """Frequency-weighted acceleration, Eq. (W6): the record filtered by the weighting ``name``.

    Parameters
    ----------
    a : array_like, shape (..., n)
        Acceleration (m/s^2) sampled at ``fs``, time along the last axis, n >= 2.
    fs : float
        Sampling frequency (Hz), > 0.
    name : str
        "Wb", "Wc", "Wd" or "Wk" (also "W_b", "wb", ...).
    mode : {"periodic", "from_rest"}
        "periodic": the record is one period (exact for periodic stationary signals);
        "from_rest": zero-padded, i.e. the analogue filter started at rest at the first sample
        (see the module docstring for both and their end effects).

    Returns
    -------
    ndarray, shape (..., n)
        Weighted acceleration (m/s^2).

    Raises
    ------
    core.errors.InputError
        fs <= 0 or not finite, a non-finite sample (names its index), fewer than 2 samples, an
        unknown weighting or mode.
    """
    from scipy.fft import irfft, next_fast_len, rfft, rfftfreq

    where = "weighted_acceleration"
    fs = _check_fs(fs, where)
    a = _signal(a, "a", where)
    weighting = frequency_weighting(name)
    if mode not in _MODES:
        from core.inputs import closest

        raise InputError(f"{where}: mode {mode!r} is not one of {list(_MODES)}{closest(str(mode), _MODES)}")
    n = a.shape[-1]
    if mode == "periodic":
        n_fft = n
    else:
        n_pad = int(np.ceil(30.0 / weighting.slowest_decay_rate * fs))
        n_fft = next_fast_len(n + n_pad, real=True)
    spectrum = rfft(a, n=n_fft, axis=-1)
    spectrum *= weighting_response(weighting.name, rfftfreq(n_fft, d=1.0 / fs))
    return irfft(spectrum, n=n_fft, axis=-1)[..., :n]


#: EN 12299 comfort scale of N_MV: (upper bound, exclusive; reading) -- as usually quoted, not
#: verified against EN 12299 (module docstring)
EN12299_SCALE = (
    (1.0, "very comfortable"),
    (2.0, "comfortable"),
    (4.0, "medium"),
    (5.0, "uncomfortable"),
    (np.inf, "very uncomfortable"),
)


def en12299_scale(n_mv):
    """Reading of the EN 12299 comfort scale for N_MV (:data:`EN12299_SCALE`; unverified).

    Parameters
    ----------
    n_mv : float or array_like
        Comfort index N_MV (-), >= 0.

    Returns
    -------
    str or ndarray of str
        "very comfortable" (N < 1), "comfortable" (1 <= N < 2), "medium" (2 <= N < 4),
        "uncomfortable" (4 <= N < 5), "very uncomfortable" (N >= 5).
    """
    n = np.asarray(n_mv, dtype=float)
    bad = ~np.isfinite(n) | (n < 0)
    if np.any(bad):
        raise InputError(f"en12299_scale: N_MV = {float(n[bad].flat[0])!r} must be finite and >= 0")
    bounds = np.array([b for b, _ in EN12299_SCALE])
    labels = np.array([t for _, t in EN12299_SCALE], dtype=object)
    out = labels[np.searchsorted(bounds, n, side="right")]
    return out if isinstance(out, np.ndarray) else str(out)


def _block_rms(aw: np.ndarray, n_block: int, n_blocks: int) -> np.ndarray:
    """(C1): r.m.s. over consecutive blocks of n_block samples, shape (n_blocks,)."""
    x = aw[: n_block * n_blocks].reshape(n_blocks, n_block)
    return np.sqrt(np.mean(x * x, axis=1))


def mean_comfort(ax, ay, az, fs, block: float = 5.0, *, mode: str = "periodic"):
    """EN 12299 mean comfort, simplified method: N_MV of Eqs. (C1)-(C3), ready for a report.

    Parameters
    ----------
    ax, ay, az : array_like, shape (n,)
        Car-body floor accelerations (m/s^2): longitudinal x, lateral y, vertical z, sampled at
        ``fs``.  ``ax=None`` gives a lateral/vertical-only evaluation (a_XP95 taken as 0 in
        N_MV, and the result says so).
    fs : float
        Sampling frequency (Hz), > 0.
    block : float, optional
        Block length (s) of the r.m.s. values, 5 s in EN 12299; rounded to a whole number of
        samples (the result gives the length used).
    mode : {"periodic", "from_rest"}
        End treatment of the weighting filter, see :func:`weighted_acceleration`.

    Returns
    -------
    pandas.Series
        ``N_MV [-]``, ``comfort (EN 12299 scale)``, ``a_XP95 Wd [m/s2]`` (NaN without ax),
        ``a_YP95 Wd [m/s2]``, ``a_ZP95 Wb [m/s2]``, ``directions``, ``blocks used``,
        ``block [s]``, ``record [s]``, ``samples not used`` (after the last whole block),
        ``5 min record (60 blocks)`` (False for a shorter -- or longer -- record: EN 12299
        evaluates 5 min), ``filter mode``; ``.attrs["block_rms"]`` holds the block r.m.s. values
        (DataFrame, one row per block).  ``result.to_frame().to_markdown()`` pastes into a report.

    Raises
    ------
    core.errors.InputError
        fs <= 0, a non-finite sample (names the signal and index), signals of different
        lengths, block <= 0, or a record shorter than one block (says how long it is).

    Notes
    -----
    The whole record is weighted first (x, y with W_d, z with W_b), then cut into blocks; samples
    after the last whole block are not used.  A record longer than 5 min is evaluated as one
    (P95 over all its blocks); EN 12299 evaluates each 5 min -- split it for that.
    """
    where = "mean_comfort"
    fs = _check_fs(fs, where)
    try:
        block = float(block)
    except (TypeError, ValueError):
        raise InputError(f"{where}: block = {block!r} is not a number (s)") from None
    if not np.isfinite(block) or block <= 0.0:
        raise InputError(f"{where}: block = {block!r} s must be finite and > 0 (EN 12299: 5 s)")
    signals = {}
    for label, sig in (("ax", ax), ("ay", ay), ("az", az)):
        if sig is None and label == "ax":
            continue
        if sig is None:
            raise InputError(f"{where}: {label} is None; only ax may be left out "
                             "(lateral/vertical-only evaluation)")
        s = _signal(sig, label, where, min_samples=1)
        if s.ndim != 1:
            raise InputError(f"{where}: {label} must be one-dimensional (shape {s.shape})")
        signals[label] = s
    lengths = {k: v.shape[0] for k, v in signals.items()}
    if len(set(lengths.values())) > 1:
        raise InputError(f"{where}: the signals have different lengths {lengths} (samples); "
                         "they must be sampled together")
    n = next(iter(lengths.values()))
    n_block = int(round(block * fs))
    if n_block < 2:
        raise InputError(f"{where}: block = {block!r} s holds {n_block} sample(s) at fs = {fs!r} Hz; "
                         "it needs at least 2")
    if n < n_block:
        raise InputError(f"{where}: the record of {n} samples ({n / fs:.6g} s) is shorter than one "
                         f"block of {n_block / fs:.6g} s ({n_block} samples); EN 12299 evaluates "
                         "5 min (60 blocks of 5 s)")
    n_blocks = n // n_block
    names = {"ax": "Wd", "ay": "Wd", "az": "Wb"}
    rms = {k: _block_rms(weighted_acceleration(v, fs, names[k], mode=mode), n_block, n_blocks)
           for k, v in signals.items()}
    p95 = {k: float(np.percentile(v, 95.0)) for k, v in rms.items()}                  # (C2)
    n_mv = 6.0 * float(np.sqrt(sum(v * v for v in p95.values())))                      # (C3)
    if "ax" in signals:
        directions = "x, y, z"
    else:
        directions = "y, z only (lateral/vertical; no x record, a_XP95 taken as 0)"
    result = pd.Series({
        "N_MV [-]": n_mv,
        "comfort (EN 12299 scale)": en12299_scale(n_mv),
        "a_XP95 Wd [m/s2]": p95.get("ax", np.nan),
        "a_YP95 Wd [m/s2]": p95["ay"],
        "a_ZP95 Wb [m/s2]": p95["az"],
        "directions": directions,
        "blocks used": n_blocks,
        "block [s]": n_block / fs,
        "record [s]": n / fs,
        "samples not used": n - n_blocks * n_block,
        "5 min record (60 blocks)": bool(n_blocks == 60),
        "filter mode": mode,
    }, name="EN 12299 mean comfort (simplified)", dtype=object)
    table = pd.DataFrame({f"a_{k[1]}_rms [m/s2]": v for k, v in rms.items()})
    table.insert(0, "t_start [s]", np.arange(n_blocks) * n_block / fs)
    result.attrs["block_rms"] = table
    return result


_DIRECTIONS = {"vertical": "vertical", "lateral": "lateral", "horizontal": "lateral"}


def _direction(direction, where: str) -> str:
    if isinstance(direction, str) and direction.strip().lower() in _DIRECTIONS:
        return _DIRECTIONS[direction.strip().lower()]
    from core.inputs import closest

    hint = closest(direction.strip().lower(), _DIRECTIONS) if isinstance(direction, str) else ""
    raise InputError(f"{where}: direction {direction!r} is not one of ['vertical', 'lateral'] "
                     f"('horizontal' = 'lateral'){hint}")


def sperling_correction(f, direction):
    """Sperling's frequency correction F(f), Eq. (S2) (-).

    Parameters
    ----------
    f : float or array_like
        Frequency (Hz), >= 0.5 (below, (S1) is not defined).
    direction : {"vertical", "lateral"}
        "horizontal" is taken as "lateral".

    Returns
    -------
    ndarray
        F(f); each break frequency (5.9, 20 Hz vertical; 5.4, 26 Hz lateral) belongs to the upper
        piece (the quoted pieces do not join there, module docstring).
    """
    where = "sperling_correction"
    d = _direction(direction, where)
    f = _frequencies(f, where)
    if np.any(f < 0.5):
        raise InputError(f"{where}: frequency {float(f[f < 0.5].flat[0])!r} Hz is below 0.5 Hz, "
                         "where Sperling's correction F(f) is not defined")
    if d == "vertical":
        return np.where(f < 5.9, 0.325 * f * f, np.where(f < 20.0, 400.0 / (f * f), 1.0))
    return np.where(f < 5.4, 0.8 * f * f, np.where(f < 26.0, 650.0 / (f * f), 1.0))


def sperling_weighting(f, direction):
    """Sperling's spectral weighting B(f), Eq. (S3) (-): B_v, and B_h = 1.25 B_v for "lateral"."""
    d = _direction(direction, "sperling_weighting")
    f = _frequencies(f, "sperling_weighting")
    f2 = f * f
    bv = 0.588 * np.sqrt((1.911 * f2 + (0.25 * f2) ** 2)
                         / ((1.0 - 0.277 * f2) ** 2 + (1.563 * f - 0.0368 * f2 * f) ** 2))
    return bv if d == "vertical" else 1.25 * bv


def sperling_harmonic(a_peak, f, direction):
    """Sperling's W_z of one harmonic, Eq. (S1): 0.896 (a^3 F(f)/f)^(1/10), a in cm/s^2.

    Parameters
    ----------
    a_peak : float or array_like
        Peak (amplitude) acceleration of the harmonic in m/s^2 (SI; converted to cm/s^2 inside),
        >= 0.
    f : float or array_like
        Its frequency (Hz), >= 0.5.
    direction : {"vertical", "lateral"}

    Returns
    -------
    ndarray
        W_z (-), broadcast shape of ``a_peak`` and ``f``.
    """
    where = "sperling_harmonic"
    a = np.asarray(a_peak, dtype=float)
    bad = ~np.isfinite(a) | (a < 0)
    if np.any(bad):
        raise InputError(f"{where}: peak acceleration {float(a[bad].flat[0])!r} m/s^2 must be "
                         "finite and >= 0")
    f = _frequencies(f, where)
    a_cm = 100.0 * a
    return 0.896 * (a_cm ** 3 * sperling_correction(f, direction) / f) ** 0.1


_NORMALISATIONS = {"peak": 2.0, "mean-square": 1.0}


def sperling(a, fs, direction, *, band=(0.5, 30.0), normalisation: str = "peak"):
    """Sperling's ride index W_z of an acceleration record, spectral form (S3)-(S4).

    Parameters
    ----------
    a : array_like, shape (..., n)
        Car-body acceleration (m/s^2; converted to cm/s^2 inside), time along the last axis.
    fs : float
        Sampling frequency (Hz), > 0.
    direction : {"vertical", "lateral"}
        Selects B_v or B_h ("horizontal" = "lateral").
    band : (float, float), optional
        Integration band f_lo..f_hi (Hz), 0 < f_lo < f_hi <= fs/2; default 0.5..30 Hz.
    normalisation : {"peak", "mean-square"}
        c in (S4): "peak" (c = 2, default) makes (S4) agree with the harmonic formula (S1) for a
        sine (to 1 % at 0.8-5 Hz vertical); "mean-square" (c = 1) is the literal one-sided-PSD
        reading of the notes, 10 % below (S1).  Module docstring.

    Returns
    -------
    float or ndarray, shape (...)
        W_z (-).

    Raises
    ------
    core.errors.InputError
        fs <= 0, a non-finite sample, an unknown direction or normalisation, a band outside
        (0, fs/2], or a record too short to resolve f_lo (duration < 1/f_lo).
    """
    from scipy.signal import periodogram

    where = "sperling"
    fs = _check_fs(fs, where)
    d = _direction(direction, where)
    if normalisation not in _NORMALISATIONS:
        from core.inputs import closest

        raise InputError(f"{where}: normalisation {normalisation!r} is not one of "
                         f"{list(_NORMALISATIONS)}{closest(str(normalisation), _NORMALISATIONS)}")
    try:
        lo, hi = (float(v) for v in band)
    except (TypeError, ValueError):
        raise InputError(f"{where}: band = {band!r} must be two frequencies (Hz)") from None
    if not (0.0 < lo < hi) or not np.isfinite(hi):
        raise InputError(f"{where}: band = {band!r} Hz must satisfy 0 < f_lo < f_hi")
    if hi > 0.5 * fs:
        raise InputError(f"{where}: band upper limit {hi!r} Hz is above the Nyquist frequency "
                         f"fs/2 = {0.5 * fs!r} Hz; sample faster or lower the band")
    a = _signal(a, "a", where)
    n = a.shape[-1]
    if n / fs < 1.0 / lo:
        raise InputError(f"{where}: the record of {n / fs:.6g} s cannot resolve f_lo = {lo!r} Hz "
                         f"(needs at least {1.0 / lo:.6g} s)")
    f, g = periodogram(100.0 * a, fs=fs, window="boxcar", detrend="constant",
                       scaling="density", axis=-1)                     # (cm/s^2)^2/Hz, one-sided
    keep = (f >= lo) & (f <= hi)
    b2 = sperling_weighting(f[keep], d) ** 2
    integral = np.sum(g[..., keep] * b2, axis=-1) * (fs / n)              # sum B^2 G df
    wz = (_NORMALISATIONS[normalisation] * integral) ** (1.0 / 6.67)     # (S4)
    return float(wz) if np.ndim(wz) == 0 else wz


#: Sperling's passenger comfort scale (W_z, feeling), the notes' wording, second-hand
SPERLING_COMFORT_SCALE = (
    (1.0, "just noticeable"),
    (2.0, "clearly noticeable"),
    (2.5, "more pronounced but not unpleasant"),
    (3.0, "strong, irregular, but still tolerable"),
    (3.25, "very irregular"),
    (3.5, "extremely irregular, unpleasant"),
    (4.0, "extremely unpleasant, harmful on prolonged exposure"),
)

#: Sperling's vehicle ride quality scale (W_z, rating), the notes' wording, second-hand
SPERLING_QUALITY_SCALE = (
    (1.0, "very good"),
    (2.0, "good"),
    (3.0, "satisfactory"),
    (4.0, "acceptable for running"),
    (4.5, "not acceptable for running"),
    (5.0, "dangerous"),
)

_SPERLING_SCALES = {"comfort": SPERLING_COMFORT_SCALE, "quality": SPERLING_QUALITY_SCALE}


def _sperling_reading(wz: float, levels) -> str:
    values = [v for v, _ in levels]
    for v, text in levels:
        if np.isclose(wz, v, rtol=0.0, atol=1e-12):
            return f"{v:g} ({text})"
    i = int(np.searchsorted(values, wz))
    if i == 0:
        return f"below {values[0]:g} ({levels[0][1]})"
    if i == len(values):
        return f"above {values[-1]:g} ({levels[-1][1]})"
    return (f"between {values[i - 1]:g} ({levels[i - 1][1]}) and {values[i]:g} ({levels[i][1]})")


def sperling_scale(wz, scale: str = "comfort"):
    """Where W_z falls on Sperling's scale (:data:`SPERLING_COMFORT_SCALE` or ``"quality"``).

    The scales name points, not intervals, so the reading names the point(s): ``"2 (clearly
    noticeable)"`` on a point, ``"between 2 (...) and 2.5 (...)"`` between two, ``"below 1
    (...)"`` / ``"above 4 (...)"`` outside.  Returns a str, or an object array for array input.
    """
    if scale not in _SPERLING_SCALES:
        from core.inputs import closest

        raise InputError(f"sperling_scale: scale {scale!r} is not one of {list(_SPERLING_SCALES)}"
                         f"{closest(str(scale), _SPERLING_SCALES)}")
    w = np.asarray(wz, dtype=float)
    bad = ~np.isfinite(w) | (w < 0)
    if np.any(bad):
        raise InputError(f"sperling_scale: W_z = {float(w[bad].flat[0])!r} must be finite and >= 0")
    levels = _SPERLING_SCALES[scale]
    if w.ndim == 0:
        return _sperling_reading(float(w), levels)
    out = np.empty(w.shape, dtype=object)
    for idx, v in np.ndenumerate(w):
        out[idx] = _sperling_reading(float(v), levels)
    return out


def sperling_scales() -> pd.DataFrame:
    """Both Sperling scales as one table (columns ``scale``, ``W_z [-]``, ``reading``)."""
    rows = [(name, v, text) for name, levels in _SPERLING_SCALES.items() for v, text in levels]
    return pd.DataFrame(rows, columns=["scale", "W_z [-]", "reading"])
