r"""Hill-type muscles after Thelen (2003) with a rigid tendon, as static optimisation uses them.

A musculotendon unit is a contractile fibre (active element in parallel with a passive elastic
element) in series with a tendon.  With a *rigid* tendon the fibre state follows from the path
length and its rate alone, and the tendon force is linear in activation: this is the muscle
model of OpenSim's static optimisation (``use_muscle_physiology = true``) and the one this
module provides.

Curves (normalised fibre length :math:`\tilde l = l_M / l_{opt}`, normalised fibre velocity
:math:`\tilde v = v_M / (v_{max} l_{opt})`, lengthening positive, :math:`v_{max}` in optimal
lengths per second)::

    active force-length   f_L(l~)  = exp(-(l~ - 1)^2 / gamma)                          Thelen Eq. 3
    passive force-length  f_PE(l~) = (exp(k_PE (l~ - 1)/eps0) - 1) / (exp(k_PE) - 1),  l~ > 1
                                   = 0,                                              l~ <= 1   Eq. 2
    force-velocity        f_V(v~)  = Eq. 6-7 solved for F~/(a f_L) at a given v~     (see below)

Geometry (constant-height, "fixed-width" pennation; rigid tendon of length l_TS)::

    l_M sin(alpha) = l_opt sin(alpha0) = h            (parallelogram height, constant)
    l_M cos(alpha) = l_MT - l_TS                      (fibre length along the tendon)
    =>  l_M = sqrt(h^2 + (l_MT - l_TS)^2),   v_M = v_MT cos(alpha)

and what static optimisation needs per frame, force *along the tendon*::

    F_j = A_j a_j + P_j,   A_j = F0_j f_L f_V cos(alpha_j)   [N per unit activation]
                           P_j = F0_j f_PE cos(alpha_j)       [N]

Force-velocity inverted
-----------------------
Thelen's Eq. 6 gives the fibre velocity for a fibre force :math:`\tilde F = a f_L f_V`
(normalised by F0)::

    v~ = (0.25 + 0.75 a) (F~ - a f_L) / b                                               (Eq. 6)
    b  = a f_L + F~ / A_f                                  if F~ <= a f_L  (shortening)   (Eq. 7)
    b  = (2 + 2/A_f) (a f_L F_len - F~) / (F_len - 1)      if F~ >  a f_L  (lengthening)

Both branches are homogeneous of degree zero in (F~, a f_L), so f_V = F~/(a f_L) depends on v~
and a only, and solving for it is closed-form (k = 0.25 + 0.75 a, c = (2 + 2/A_f)/(F_len - 1))::

    f_V = (k + v~) / (k - v~/A_f)                 -k <= v~ <= 0   (Hill hyperbola, f_V(-k) = 0)
    f_V = (k + c F_len v~) / (k + c v~)           v~ > 0          (rises to the plateau F_len)
    f_V = 0                                       v~ < -k         (no pushing; OpenSim extrapolates
                                                                   linearly to negative values)

The curve is continuous at v~ = 0 (f_V = 1) but its slope jumps from (1 + 1/A_f)/k to
2 (1 + 1/A_f)/k: Thelen's lengthening branch is twice as steep at the isometric point.  OpenSim's
``calcfvInv`` solves the same equations by Newton iteration and, above
``fv_linear_extrap_threshold`` (0.95) x F_len, continues the lengthening branch linearly in F~
instead of letting it approach F_len; set :attr:`ThelenMuscleSet.fv_linear_extrap_threshold` to
reproduce that (default None: the plain hyperbola with its plateau F_len).  The gait2392 model
file does not set the property, so OpenSim runs it with 0.95.  OpenSim's static
optimisation evaluates the active force with activation 1 (``calcInextensibleTendonActiveFiberForce
(s, 1.0)``), i.e. k = 1, so that force is linear in activation; :meth:`ThelenMuscleSet.rigid_tendon_forces`
does the same.

Minimum fibre length
--------------------
A fibre may not shorten below ``l_min = max(h / sin(alpha_max), 0.01 l_opt)`` (alpha_max =
``maximum_pennation_angle``, OpenSim's default acos 0.1 = 84.3 deg; the 1 % floor, OpenSim's for
unpennated fibres, also keeps a barely pennated fibre away from zero length).  A path so short that
``l_MT - l_TS < sqrt(l_min^2 - h^2)`` clamps the fibre at l_min (at the pennation angle
asin(h / l_min), <= alpha_max) with zero velocity; it produces no active force (as in OpenSim's
``calcInextensibleTendonActiveFiberForce``) and is flagged in :attr:`FiberKinematics.clamped`.
The clamped state joins the unclamped one continuously in length and angle.

References
----------
.. [1] D. G. Thelen, "Adjustment of muscle mechanics model parameters to simulate dynamic
   contractions in older adults", J. Biomech. Eng. 125 (2003) 70-77, Eqs. 2, 3, 6 and 7.
.. [2] F. E. Zajac, "Muscle and tendon: properties, models, scaling, and application to
   biomechanics and motor control", Crit. Rev. Biomed. Eng. 17 (1989) 359-411 (constant-thickness
   pennation, rigid tendon).
.. [3] M. Millard, T. Uchida, A. Seth, S. L. Delp, "Flexing computational muscle: modeling and
   simulation of musculotendon dynamics", J. Biomech. Eng. 135 (2013) 021005 (fixed-width
   pennation model, rigid-tendon model).
.. [4] opensim-core, ``OpenSim/Actuators/Thelen2003Muscle.cpp`` (``calcfal``, ``calcfpe``,
   ``calcdlceN``, ``calcfvInv``, ``calcInextensibleTendonActiveFiberForce``) and
   ``MuscleFixedWidthPennationModel.cpp``; read to learn the conventions, not copied.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import NamedTuple

import numpy as np

from core.errors import InputError, ModelError

__all__ = [
    "OPENSIM_PROPERTY_NAMES",
    "FiberKinematics",
    "RigidTendonForces",
    "ThelenMuscleSet",
    "active_force_length",
    "passive_force_length",
    "force_velocity",
    "normalized_fiber_velocity",
]

#: Default maximum pennation angle of OpenSim's fixed-width pennation model, acos(0.1) [rad].
DEFAULT_MAXIMUM_PENNATION_ANGLE = float(np.arccos(0.1))

#: Field of :class:`ThelenMuscleSet` for each property name of an OpenSim ``Thelen2003Muscle``
#: (for the model-file readers).
OPENSIM_PROPERTY_NAMES: dict[str, str] = {
    "max_isometric_force": "max_isometric_force",
    "optimal_fiber_length": "optimal_fiber_length",
    "tendon_slack_length": "tendon_slack_length",
    "pennation_angle_at_optimal": "pennation_angle_at_optimal",
    "max_contraction_velocity": "max_contraction_velocity",
    "KshapeActive": "kshape_active",
    "KshapePassive": "kshape_passive",
    "FmaxMuscleStrain": "fmax_muscle_strain",
    "Af": "af",
    "Flen": "flen",
    "fv_linear_extrap_threshold": "fv_linear_extrap_threshold",
    "maximum_pennation_angle": "maximum_pennation_angle",
}


# --------------------------------------------------------------------------------------------
# Curves
# --------------------------------------------------------------------------------------------


def active_force_length(norm_fiber_length, kshape_active=0.5):
    r"""Active force-length multiplier, Thelen (2003) Eq. 3.

    .. math:: f_L(\tilde l) = \exp\!\left(-(\tilde l - 1)^2 / \gamma\right)

    A Gaussian with its peak 1 at the optimal length, symmetric about it, falling to 1/e at
    :math:`\tilde l = 1 \pm \sqrt{\gamma}`.

    Parameters
    ----------
    norm_fiber_length : array_like, shape (...)
        Fibre length over optimal fibre length [-].
    kshape_active : float or array_like, broadcastable to (...)
        Shape factor :math:`\gamma` (OpenSim ``KshapeActive``): 0.45 in the paper, 0.5 in
        OpenSim's gait2392 and gait10dof18musc models.

    Returns
    -------
    ndarray, shape (...)
        :math:`f_L \in (0, 1]`.
    """
    lt = np.asarray(norm_fiber_length, float)
    return np.exp(-((lt - 1.0) ** 2) / np.asarray(kshape_active, float))


def passive_force_length(norm_fiber_length, kshape_passive=4.0, fmax_muscle_strain=0.6):
    r"""Passive force-length multiplier, Thelen (2003) Eq. 2 in the form of OpenSim's Thelen2003Muscle.

    .. math::
        f_{PE}(\tilde l) = \frac{\exp\left(k^{PE} (\tilde l - 1)/\varepsilon_0^M\right) - 1}
                                {\exp(k^{PE}) - 1}  \quad (\tilde l > 1), \qquad
        f_{PE} = 0 \quad (\tilde l \le 1)

    so that :math:`f_{PE}(1) = 0` and :math:`f_{PE}(1 + \varepsilon_0^M) = 1`.  The paper's
    expression would be slightly negative below the optimal length (down to
    :math:`-1/(e^{k^{PE}} - 1) = -0.019` for k = 4); like OpenSim (``calcfpe``), the fibre is
    slack there and the multiplier is 0.  The curve is continuous at :math:`\tilde l = 1`, its slope
    jumps from 0 to :math:`k^{PE} / (\varepsilon_0^M (e^{k^{PE}} - 1))` (0.12 for the defaults).

    Parameters
    ----------
    norm_fiber_length : array_like, shape (...)
        Fibre length over optimal fibre length [-].
    kshape_passive : float or array_like
        Exponential shape factor :math:`k^{PE}` (OpenSim ``KshapePassive``; 4 in gait2392, 5 in the
        paper and OpenSim's class default).
    fmax_muscle_strain : float or array_like
        Passive fibre strain :math:`\varepsilon_0^M` at which the passive force equals F0
        (OpenSim ``FmaxMuscleStrain``; 0.6).

    Returns
    -------
    ndarray, shape (...)
        :math:`f_{PE} \ge 0`.
    """
    lt = np.asarray(norm_fiber_length, float)
    k = np.asarray(kshape_passive, float)
    e0 = np.asarray(fmax_muscle_strain, float)
    stretch = np.maximum(lt - 1.0, 0.0)
    return np.expm1(k * stretch / e0) / np.expm1(k)


def _fv_constants(activation, af, flen):
    k = 0.25 + 0.75 * np.asarray(activation, float)
    af = np.asarray(af, float)
    flen = np.asarray(flen, float)
    c = (2.0 + 2.0 / af) / (flen - 1.0)
    return k, af, flen, c


def force_velocity(norm_fiber_velocity, activation=1.0, af=0.3, flen=1.8, fv_linear_extrap_threshold=None):
    r"""Force-velocity multiplier: Thelen (2003) Eqs. 6-7 solved for :math:`f_V` at a given velocity.

    With :math:`k = 0.25 + 0.75 a` and :math:`c = (2 + 2/A_f)/(F_{len} - 1)`:

    .. math::
        f_V = \begin{cases}
            0 & \tilde v < -k \\
            \dfrac{k + \tilde v}{k - \tilde v / A_f} & -k \le \tilde v \le 0 \\
            \dfrac{k + c F_{len} \tilde v}{k + c \tilde v} & \tilde v > 0
        \end{cases}

    (derivation in the module docstring).  :math:`f_V(0) = 1`, :math:`f_V(-k) = 0` (at a = 1:
    zero force at the maximum shortening velocity), :math:`f_V \to F_{len}` for fast lengthening.
    Continuous and non-decreasing everywhere; the slope at 0 jumps by a factor 2.

    If ``fv_linear_extrap_threshold`` = θ is given (OpenSim's property of that name, 0.95 there),
    the lengthening branch is continued by its tangent above :math:`f_V^* = θ F_{len}`, i.e. at
    :math:`\tilde v > \tilde v^* = k (f_V^* - 1) / (c (F_{len} - f_V^*))`:
    :math:`f_V = f_V^* + c (F_{len} - f_V^*)^2 / (k (F_{len} - 1)) \, (\tilde v - \tilde v^*)`, as
    OpenSim's ``calcdlceN`` does; f_V then exceeds F_len at high lengthening speeds.

    Parameters
    ----------
    norm_fiber_velocity : array_like, shape (...)
        :math:`\tilde v = v_M / (v_{max} l_{opt})` [-], lengthening positive.
    activation : float or array_like
        Activation a in Eq. 6 (it scales the maximum shortening velocity by k).  Static
        optimisation uses a = 1, as OpenSim does, so that the force is linear in activation.
    af : float or array_like
        Force-velocity shape factor :math:`A_f` (OpenSim ``Af``; 0.3 in gait2392, 0.25 in the paper).
    flen : float or array_like
        Maximum normalised lengthening force :math:`F_{len} > 1` (OpenSim ``Flen``; 1.8).
    fv_linear_extrap_threshold : float or None
        θ with :math:`1/F_{len} < θ < 1`; None (default) keeps the hyperbola.

    Returns
    -------
    ndarray, shape (...)
        :math:`f_V \ge 0`.
    """
    v = np.asarray(norm_fiber_velocity, float)
    k, af, flen, c = _fv_constants(activation, af, flen)
    vc = np.minimum(v, 0.0)  # shortening branch argument; its denominator k - vc/af >= k > 0
    ve = np.maximum(v, 0.0)  # lengthening branch argument; its denominator k + c ve >= k > 0
    shortening = np.maximum(k + vc, 0.0) / (k - vc / af)
    lengthening = (k + c * flen * ve) / (k + c * ve)
    fv = np.where(v <= 0.0, shortening, lengthening)
    if fv_linear_extrap_threshold is not None:
        theta = float(fv_linear_extrap_threshold)
        fv_star = theta * flen
        v_star = k * (fv_star - 1.0) / (c * (flen - fv_star))
        slope = c * (flen - fv_star) ** 2 / (k * (flen - 1.0))
        fv = np.where(v > v_star, fv_star + slope * (v - v_star), fv)
    return fv


def normalized_fiber_velocity(force_velocity_multiplier, activation=1.0, af=0.3, flen=1.8):
    r"""Thelen (2003) Eqs. 6-7 as written: normalised fibre velocity for a force-velocity multiplier.

    .. math::
        \tilde v = k \frac{\tilde F - a f_L}{b}, \quad \tilde F = a f_L f_V, \quad
        b = \begin{cases} a f_L + \tilde F / A_f & f_V \le 1 \\
                          (2 + 2/A_f)(a f_L F_{len} - \tilde F)/(F_{len} - 1) & f_V > 1 \end{cases}

    which, divided through by :math:`a f_L`, depends on :math:`f_V` only.  The inverse of
    :func:`force_velocity` (without extrapolation) on :math:`0 \le f_V < F_{len}`.

    Parameters
    ----------
    force_velocity_multiplier : array_like, shape (...)
        :math:`f_V` with :math:`0 \le f_V < F_{len}`.
    activation, af, flen : float or array_like
        As in :func:`force_velocity`.

    Returns
    -------
    ndarray, shape (...)
        :math:`\tilde v` [-], lengthening positive.
    """
    fv = np.asarray(force_velocity_multiplier, float)
    k, af, flen, _ = _fv_constants(activation, af, flen)
    if np.any(fv < 0) or np.any(fv >= flen):
        raise InputError(f"normalized_fiber_velocity: multipliers must lie in [0, Flen={flen}), got "
                         f"min {fv.min()}, max {fv.max()}")
    b_short = 1.0 + fv / af  # b / (a f_L)
    b_long = (2.0 + 2.0 / af) * (flen - fv) / (flen - 1.0)
    b = np.where(fv <= 1.0, b_short, b_long)
    return k * (fv - 1.0) / b


# --------------------------------------------------------------------------------------------
# Parameters and per-frame quantities
# --------------------------------------------------------------------------------------------


class FiberKinematics(NamedTuple):
    """Fibre state of rigid-tendon musculotendon units; every array has shape (..., n_muscles)."""

    fiber_length: np.ndarray
    """l_M [m]."""
    fiber_velocity: np.ndarray
    """v_M [m/s], lengthening positive."""
    pennation_angle: np.ndarray
    """alpha [rad]."""
    cos_pennation: np.ndarray
    """cos(alpha) [-]."""
    norm_fiber_length: np.ndarray
    """l_M / l_opt [-]."""
    norm_fiber_velocity: np.ndarray
    """v_M / (v_max l_opt) [-]."""
    clamped: np.ndarray
    """bool: the path is too short for the fibre (l_MT - l_TS < sqrt(l_min^2 - h^2)); fibre held at
    l_min with zero velocity and no active force."""


class RigidTendonForces(NamedTuple):
    """What static optimisation needs per frame; every array has shape (..., n_muscles)."""

    active_force_per_activation: np.ndarray
    """A = F0 f_L f_V cos(alpha) [N]: tendon force per unit activation (0 where clamped)."""
    passive_force: np.ndarray
    """P = F0 f_PE cos(alpha) [N]: passive tendon force."""
    active_force_length: np.ndarray
    """f_L [-]."""
    passive_force_length: np.ndarray
    """f_PE [-]."""
    force_velocity: np.ndarray
    """f_V at activation 1 [-]."""
    kinematics: FiberKinematics
    """The fibre state the forces were computed from."""


def _as_param(value, n: int, label: str) -> np.ndarray:
    arr = np.asarray(value, float)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise ModelError(f"ThelenMuscleSet: {label} must be a scalar or have shape ({n},) (one per muscle), "
                         f"got shape {arr.shape}")
    arr = arr.copy()
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class ThelenMuscleSet:
    r"""Parameters of n Thelen (2003) muscles, as arrays over muscles (immutable, picklable).

    Scalars are broadcast to every muscle.  The curves and the geometry are stated in the module
    docstring; :meth:`fiber_kinematics` and :meth:`rigid_tendon_forces` evaluate them for all
    muscles and any number of frames in one vectorised call.

    Parameters
    ----------
    names : sequence of str, length n_muscles
        Unique muscle names (they name the muscle in every error message).
    max_isometric_force : array_like, shape (n_muscles,)
        F0 [N], > 0.
    optimal_fiber_length : array_like, shape (n_muscles,)
        l_opt [m], > 0.
    tendon_slack_length : array_like, shape (n_muscles,)
        l_TS [m], >= 0.
    pennation_angle_at_optimal : array_like, shape (n_muscles,)
        alpha0 [rad], 0 <= alpha0 < maximum_pennation_angle.
    max_contraction_velocity : float or array_like, shape (n_muscles,)
        v_max [optimal fibre lengths per second], > 0 (10 in OpenSim's gait models).
    kshape_active : float or array_like
        gamma of Eq. 3 (OpenSim ``KshapeActive``), default 0.5 as in gait2392 (paper 0.45).
    kshape_passive : float or array_like
        k_PE of Eq. 2 (``KshapePassive``), default 4.
    fmax_muscle_strain : float or array_like
        eps0_M of Eq. 2 (``FmaxMuscleStrain``), default 0.6.
    af : float or array_like
        A_f of Eq. 7 (``Af``), default 0.3.
    flen : float or array_like
        F_len of Eq. 7 (``Flen``), > 1, default 1.8.
    fv_linear_extrap_threshold : float or None
        OpenSim's linear continuation of the lengthening branch above this fraction of F_len
        (0.95 in OpenSim); None (default) keeps Thelen's hyperbola (see :func:`force_velocity`).
    maximum_pennation_angle : float or array_like
        alpha_max [rad] of the fixed-width pennation model, default acos(0.1).

    Raises
    ------
    core.errors.ModelError
        A parameter out of range or of the wrong shape; the message names the muscle.

    Notes
    -----
    OpenSim's XML property names map to these fields through :data:`OPENSIM_PROPERTY_NAMES`.
    The defaults are those of OpenSim's gait2392 / gait10dof18musc models; the class defaults of
    OpenSim's ``Thelen2003Muscle`` (version 4) differ (KshapeActive 0.45, KshapePassive 5,
    Af 0.25, Flen 1.4).
    """

    names: tuple[str, ...]
    max_isometric_force: np.ndarray
    optimal_fiber_length: np.ndarray
    tendon_slack_length: np.ndarray
    pennation_angle_at_optimal: np.ndarray
    max_contraction_velocity: np.ndarray = field(default=10.0)  # type: ignore[assignment]
    kshape_active: np.ndarray = field(default=0.5)  # type: ignore[assignment]
    kshape_passive: np.ndarray = field(default=4.0)  # type: ignore[assignment]
    fmax_muscle_strain: np.ndarray = field(default=0.6)  # type: ignore[assignment]
    af: np.ndarray = field(default=0.3)  # type: ignore[assignment]
    flen: np.ndarray = field(default=1.8)  # type: ignore[assignment]
    fv_linear_extrap_threshold: float | None = None
    maximum_pennation_angle: np.ndarray = field(default=DEFAULT_MAXIMUM_PENNATION_ANGLE)  # type: ignore[assignment]

    def __post_init__(self):
        names = tuple(str(s) for s in self.names)
        n = len(names)
        if n == 0:
            raise ModelError("ThelenMuscleSet: no muscles given")
        seen: set[str] = set()
        for name in names:
            if name in seen:
                raise ModelError(f"ThelenMuscleSet: duplicate muscle name {name!r}")
            seen.add(name)
        object.__setattr__(self, "names", names)
        for f in fields(self):
            if f.name in ("names", "fv_linear_extrap_threshold"):
                continue
            object.__setattr__(self, f.name, _as_param(getattr(self, f.name), n, f.name))

        def check(label: str, bad: np.ndarray, rule: str):
            if np.any(bad):
                j = int(np.flatnonzero(bad)[0])
                raise ModelError(f"muscle {names[j]!r}: {label} = {getattr(self, label)[j]!r} must be {rule}")

        for label in ("max_isometric_force", "optimal_fiber_length", "max_contraction_velocity",
                      "kshape_active", "kshape_passive", "fmax_muscle_strain", "af"):
            val = getattr(self, label)
            check(label, ~(np.isfinite(val) & (val > 0)), "finite and > 0")
        check("tendon_slack_length", ~(np.isfinite(self.tendon_slack_length) & (self.tendon_slack_length >= 0)),
              "finite and >= 0")
        check("flen", ~(np.isfinite(self.flen) & (self.flen > 1)), "finite and > 1")
        check("maximum_pennation_angle",
              ~((self.maximum_pennation_angle > 0) & (self.maximum_pennation_angle < np.pi / 2)),
              "in (0, pi/2) rad")
        a0 = self.pennation_angle_at_optimal
        check("pennation_angle_at_optimal", ~((a0 >= 0) & (a0 < self.maximum_pennation_angle)),
              "in [0, maximum_pennation_angle) rad (radians, not degrees)")
        thr = self.fv_linear_extrap_threshold
        if thr is not None:
            thr = float(thr)
            bad = ~((thr * self.flen > 1.0) & (thr < 1.0))
            check("flen", bad, f"such that 1/Flen < fv_linear_extrap_threshold = {thr} < 1")
            object.__setattr__(self, "fv_linear_extrap_threshold", thr)

    @classmethod
    def from_muscles(cls, muscles, **overrides) -> ThelenMuscleSet:
        """Collect the parameters of muscle records into one set.

        Parameters
        ----------
        muscles : iterable
            Objects with attributes ``name``, ``max_isometric_force``, ``optimal_fiber_length``,
            ``tendon_slack_length``, ``pennation_angle_at_optimal`` and, optionally, the other
            fields of this class (e.g. the muscles of a model-file reader).  A missing attribute or
            None takes this class's default (the gait2392 value).
        **overrides
            Field values for all muscles (scalars or arrays), e.g. ``kshape_active=0.45``.

        Returns
        -------
        ThelenMuscleSet
        """
        from core.inputs import check_keywords

        check_keywords(overrides, [f.name for f in fields(cls) if f.name != "names"],
                       where="ThelenMuscleSet.from_muscles()")
        items = list(muscles)
        kwargs: dict[str, object] = {"names": [str(m.name) for m in items]}
        for f in fields(cls):
            if f.name in ("names", "fv_linear_extrap_threshold") or f.name in overrides:
                continue
            values = [getattr(m, f.name, None) for m in items]
            if f.name in ("max_isometric_force", "optimal_fiber_length", "tendon_slack_length",
                          "pennation_angle_at_optimal"):
                missing = [m.name for m, v in zip(items, values) if v is None]
                if missing:
                    raise ModelError(f"muscle {missing[0]!r}: no {f.name}")
            else:
                values = [f.default if v is None else v for v in values]
            kwargs[f.name] = values
        kwargs.update(overrides)
        return cls(**kwargs)

    # ---- sizes and derived constants ------------------------------------------------------

    @property
    def n_muscles(self) -> int:
        """Number of muscles."""
        return len(self.names)

    def __len__(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        """Position of the muscle ``name`` (raises :class:`core.errors.InputError` if unknown)."""
        try:
            return self.names.index(name)
        except ValueError:
            raise InputError(f"no muscle named {name!r}; muscles are {list(self.names)}") from None

    @property
    def parallelogram_height(self) -> np.ndarray:
        """h = l_opt sin(alpha0) [m], shape (n_muscles,): the constant fibre height."""
        return self.optimal_fiber_length * np.sin(self.pennation_angle_at_optimal)

    @property
    def minimum_fiber_length(self) -> np.ndarray:
        """l_min = max(h / sin(alpha_max), 0.01 l_opt) [m], shape (n_muscles,)."""
        return np.maximum(self.parallelogram_height / np.sin(self.maximum_pennation_angle),
                          0.01 * self.optimal_fiber_length)

    # ---- per-frame quantities ----------------------------------------------------------------

    def _frames(self, value, label: str) -> np.ndarray:
        arr = np.asarray(value, float)
        if arr.ndim == 0 or arr.shape[-1] != self.n_muscles:
            raise InputError(f"{label} must have shape (..., {self.n_muscles}) (last axis over muscles "
                             f"{list(self.names)[:3]}...), got shape {arr.shape}")
        bad = ~np.isfinite(arr)
        if np.any(bad):
            idx = np.argwhere(bad)[0]
            raise InputError(f"{label}: non-finite value {arr[tuple(idx)]} for muscle {self.names[idx[-1]]!r}"
                             + (f" at frame index {tuple(int(i) for i in idx[:-1])}" if arr.ndim > 1 else ""))
        return arr

    def fiber_kinematics(self, musculotendon_length, musculotendon_velocity) -> FiberKinematics:
        r"""Fibre length, velocity and pennation of rigid-tendon units with constant-height pennation.

        .. math::
            x = l_{MT} - l_{TS}, \quad l_M = \sqrt{h^2 + x^2}, \quad
            \sin\alpha = h / l_M, \quad \cos\alpha = x / l_M, \quad v_M = v_{MT} \cos\alpha

        (differentiate :math:`l_M^2 = h^2 + x^2` with :math:`\dot x = v_{MT}`, tendon rigid).
        Where :math:`x < \sqrt{l_{min}^2 - h^2}` the fibre is clamped at :math:`l_{min}` with zero
        velocity (module docstring).

        Parameters
        ----------
        musculotendon_length : array_like, shape (..., n_muscles)
            Path length l_MT [m].
        musculotendon_velocity : array_like, shape (..., n_muscles)
            Its rate v_MT [m/s], lengthening positive.

        Returns
        -------
        FiberKinematics
            Arrays of shape (..., n_muscles).

        Raises
        ------
        core.errors.InputError
            Wrong last axis or a non-finite value (names the muscle and the frame).
        """
        l_mt = self._frames(musculotendon_length, "musculotendon_length")
        v_mt = self._frames(musculotendon_velocity, "musculotendon_velocity")
        l_mt, v_mt = np.broadcast_arrays(l_mt, v_mt)
        h = self.parallelogram_height
        x_min = np.sqrt(self.minimum_fiber_length ** 2 - h * h)
        x = l_mt - self.tendon_slack_length
        clamped = x < x_min
        x_ok = np.maximum(x, x_min)
        l_m = np.sqrt(h * h + x_ok * x_ok)
        cos_a = x_ok / l_m
        alpha = np.arctan2(h, x_ok)
        v_m = np.where(clamped, 0.0, v_mt * cos_a)
        lopt = self.optimal_fiber_length
        return FiberKinematics(
            fiber_length=l_m,
            fiber_velocity=v_m,
            pennation_angle=alpha,
            cos_pennation=cos_a,
            norm_fiber_length=l_m / lopt,
            norm_fiber_velocity=v_m / (self.max_contraction_velocity * lopt),
            clamped=clamped,
        )

    def rigid_tendon_forces(self, musculotendon_length, musculotendon_velocity, *,
                            use_muscle_physiology: bool = True) -> RigidTendonForces:
        r"""Active force per unit activation and passive force along the tendon, per muscle and frame.

        .. math::
            A_j = F_{0,j} \, f_L(\tilde l_j) \, f_V(\tilde v_j; a = 1) \cos\alpha_j, \qquad
            P_j = F_{0,j} \, f_{PE}(\tilde l_j) \cos\alpha_j

        so the tendon force is :math:`F_j = A_j a_j + P_j`, linear in the activation (f_V at
        a = 1, as OpenSim's static optimisation).  Clamped fibres (module docstring) have A = 0.

        Parameters
        ----------
        musculotendon_length, musculotendon_velocity : array_like, shape (..., n_muscles)
            Path length [m] and its rate [m/s].
        use_muscle_physiology : bool
            False reproduces OpenSim's ``use_muscle_physiology = false``: A = F0 and P = 0
            (no force-length, force-velocity or pennation effects).

        Returns
        -------
        RigidTendonForces
            Arrays of shape (..., n_muscles) [N and -].
        """
        kin = self.fiber_kinematics(musculotendon_length, musculotendon_velocity)
        f_l = active_force_length(kin.norm_fiber_length, self.kshape_active)
        f_pe = passive_force_length(kin.norm_fiber_length, self.kshape_passive, self.fmax_muscle_strain)
        f_v = force_velocity(kin.norm_fiber_velocity, 1.0, self.af, self.flen, self.fv_linear_extrap_threshold)
        f0 = self.max_isometric_force
        if use_muscle_physiology:
            active = np.where(kin.clamped, 0.0, f0 * f_l * f_v * kin.cos_pennation)
            passive = f0 * f_pe * kin.cos_pennation
        else:
            active = np.broadcast_to(f0, kin.fiber_length.shape).copy()
            passive = np.zeros_like(kin.fiber_length)
        return RigidTendonForces(active, passive, f_l, f_pe, f_v, kin)
