"""Critical speeds: the linear one of a suspended wheelset, the nonlinear one of a vehicle.

*Linear* (:func:`linear_critical_speed`): a wheelset with conical wheels (1:40) held by a lateral
and a yaw spring to a frame driven at V, Kalker linear creep; core's ``linearize``/``eigen`` of
the multibody wheelset in the non-rotating formulation against the closed forms of
:class:`railway.vehicles.hunting.LinearWheelset` (complete, and classical two-degree-of-freedom;
Wickens 2003, ch. 2 and 6).

*Nonlinear* (:func:`nonlinear_critical_speed`): the lowest speed at which a hunting limit cycle of
the vehicle persists (Polach 2006, Vehicle Syst. Dyn. 44 Suppl.: the run-down method).  The vehicle
on straight track is released with every wheelset off centre at a speed above the critical speed,
where the flange-bounded limit cycle forms within the first second, and its speed is lowered at a
constant rate by the speed control (:func:`run_down`).  The amplitude (max ``|y|`` of the leading
wheelset over 0.5 s, :func:`hunting_envelope`) falls below :data:`HUNTING_AMPLITUDE` at a speed
that lags the fold of the limit-cycle branch, since the decay of the cycle takes time while the
speed falls.  Two ways remove the lag: a second, slower run-down and the extrapolation of the
threshold speed to zero rate (fixed cost, two run-downs), or the bisection of constant-speed runs
started from the run-down's state (:func:`hunting_persists`; its cost grows with the depth).
"""

from __future__ import annotations

import numpy as np

from .curving import METHOD, RTOL

__all__ = ["HUNTING_AMPLITUDE", "continue_run_down", "hunting_envelope", "hunting_persists",
           "hunting_threshold_speed", "linear_critical_speed", "nonlinear_critical_speed", "run_down",
           "stop_when_quiet", "zero_rate_speed"]

#: hunting: the leading wheelset's lateral amplitude (max ``|y|`` over 0.5 s) above this [m]
HUNTING_AMPLITUDE = 0.5e-3


def linear_critical_speed(k_y=3e5, k_psi=3e5, xtol=1e-3):
    """The suspended wheelset (cone 1:40, Kalker linear), like for like.

    Core's eigenvalue critical speed of the multibody wheelset (Brent's method on the real part
    of the hunting mode), the same wheelset with the terms the classical two-degree-of-freedom
    model neglects switched off (:data:`railway.vehicles.wheelset_models.TEXTBOOK`), and the closed
    forms of :class:`railway.vehicles.hunting.LinearWheelset` from the rigid contact geometry and
    Hertz: complete (every term of :data:`railway.vehicles.hunting.TERMS`) and classical (none).
    Returns a dict; ``real(V)`` is the real part of the hunting eigenvalue at speed V [1/s], and
    ``closed_form_real(V)`` that of the complete closed form."""
    from scipy.optimize import brentq

    from ..contact.two_point import conical_wheel
    from .hunting import TERMS
    from .wheelset_models import TEXTBOOK, eigen_critical_speed, hunting_mode, linear_wheelset, suspended_wheelset

    cone = conical_wheel()

    def real(V):
        return hunting_mode(suspended_wheelset(V, k_y, k_psi, wheel=cone, nominal_spin=True))[0]

    V_core = brentq(real, 20.0, 120.0, xtol=xtol)
    w_core = hunting_mode(suspended_wheelset(V_core, k_y, k_psi, wheel=cone, nominal_spin=True))[1]
    V_tb, w_tb = eigen_critical_speed(k_y, k_psi, (20.0, 120.0), wheel=cone, xtol=xtol, **TEXTBOOK)
    lw = linear_wheelset(k_y, k_psi, wheel=cone)
    V_cf, w_cf = lw.critical_speed()
    V_plain, w_plain = lw.critical_speed(**{t: False for t in TERMS})

    def closed_form_real(V):
        M, C, K = lw.matrices(V)
        Am = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
        return float(np.max(np.linalg.eigvals(Am).real))

    return dict(V_core=V_core, w_core=w_core, V_textbook=V_tb, w_textbook=w_tb, V_cf=V_cf, w_cf=w_cf,
                V_plain=V_plain, w_plain=w_plain, lam=lw.conicity, rho=lw.roll_per_lateral, f11=lw.f11,
                f22=lw.f22, l=lw.l, r0=lw.r0, k_y=k_y, k_psi=k_psi, real=real, closed_form_real=closed_form_real)


def stop_when_quiet(veh, quiet=1.0):
    """A ``stop_when`` for :func:`core.integrators.simulate`: True once the leading wheelset, after
    hunting, has stayed within ±:data:`HUNTING_AMPLITUDE` of the track centre for ``quiet`` [s].
    Below the fold of the limit-cycle branch the centred running is stable (the Hopf bifurcation of
    the hunting mode is subcritical), so the run-down has nothing more to show."""
    i = veh.model.coordinate_names.index(f"{veh.wheelsets[0]}.y [m]")
    last_hunting = [None]

    def stop(t, q, v):
        if abs(q[i]) > HUNTING_AMPLITUDE:
            last_hunting[0] = t
        return last_hunting[0] is not None and t - last_hunting[0] >= quiet

    return stop


def run_down(law, V0=90.0, V1=40.0, rate=2.0, kick=0.008, definition=None, n_output_per_s=100,
             reseed_every=1, stop_quiet=None):
    """A speed run-down of the vehicle (default: the Manchester coach) on straight S1002 / UIC60
    track from a hunting limit cycle: the car body is pulled at V(t) = V0 - rate t [m/s] (speed
    control), all wheelsets start ``kick`` [m] off centre.  With ``stop_quiet`` [s] the run ends
    once the hunting has stopped for that long (:func:`stop_when_quiet`).  Returns
    ``(result, vehicle)``."""
    from core.drivers import polynomial
    from core.integrators import simulate

    from ..contact.creep import creep_law_for_runs
    from ..track import Track
    from .vehicle import VehicleDefinition, build_vehicle

    D = definition or VehicleDefinition.manchester()
    T = (V0 - V1) / rate
    track = Track.straight(V0 * T + 100.0)
    cl, cp = creep_law_for_runs(law, 0.5 * (V0 + V1))
    veh = build_vehicle(D, track, s0=30.0, speed=V0, creep_law=cl, creep_params=cp,
                        speed_control=polynomial([V0, -rate]), contact_options=dict(reseed_every=reseed_every))
    veh.preload()
    q0, v0 = veh.initial_state(wheelset_lateral=[kick] * 4)
    res = simulate(veh.model, (0.0, T), METHOD, q0=q0, v0=v0, rtol=RTOL, atol=RTOL * 1e-2,
                   n_output=int(T * n_output_per_s) + 1,
                   stop_when=None if stop_quiet is None else stop_when_quiet(veh, stop_quiet))
    return res, veh


def continue_run_down(law, res, veh, V0, rate0, V_start, V_end, rate, n_output_per_s=100, stop_quiet=None):
    """A second run-down of the vehicle of a :func:`run_down` (``res``, ``veh``, its start speed
    ``V0`` and rate ``rate0``), continued from its state at the speed ``V_start`` [m/s] down to
    ``V_end`` at the rate ``rate`` [m/s²]: V(t) = V_start - rate (t - t_start); ``stop_quiet`` as in
    :func:`run_down`.  Returns ``(result, speed at its output times)``."""
    from core.drivers import polynomial
    from core.integrators import simulate

    from ..contact.creep import creep_law_for_runs
    from .vehicle import build_vehicle

    k = int(np.argmin(np.abs((V0 - rate0 * res.t) - V_start)))
    t0, V_start = float(res.t[k]), float(V0 - rate0 * res.t[k])
    cl, cp = creep_law_for_runs(law, 0.5 * (V_start + V_end))
    veh2 = build_vehicle(veh.definition, veh.track, s0=veh.s0, speed=V_start, creep_law=cl, creep_params=cp,
                         speed_control=polynomial([V_start + rate * t0, -rate]))
    T = (V_start - V_end) / rate
    r = simulate(veh2.model, (t0, t0 + T), METHOD, q0=res.q[k], v0=res.v[k], rtol=RTOL, atol=RTOL * 1e-2,
                 n_output=int(T * n_output_per_s) + 1,
                 stop_when=None if stop_quiet is None else stop_when_quiet(veh2, stop_quiet))
    return r, V_start - rate * (r.t - t0)


def hunting_envelope(res, veh, V0, rate, window=0.5):
    """Limit-cycle amplitude of the leading wheelset (max ``|y|`` over a sliding ``window`` [s]) against
    the prescribed speed of a :func:`run_down`: ``(V, amplitude)`` [m/s, m] per output time."""
    t = res.t
    y = np.abs(res.coordinates()[f"{veh.wheelsets[0]}.y [m]"].to_numpy())
    n = max(1, int(round(window / (t[1] - t[0]))))
    amp = np.array([y[max(0, k - n):k + 1].max() for k in range(len(t))])
    return V0 - rate * t, amp


def hunting_persists(law, res, veh, V_test, V0, rate, T_check=3.0):
    """Does the hunting limit cycle persist at the constant speed ``V_test`` [m/s]?  The run starts
    from the :func:`run_down` state at ``V_test`` and lasts ``T_check`` [s]; the cycle persists when
    the leading wheelset's amplitude over the last second is at least 0.8 times that over the first
    and above :data:`HUNTING_AMPLITUDE`.  Returns ``(persists, result)``."""
    from core.integrators import simulate

    from ..contact.creep import creep_law_for_runs
    from .vehicle import build_vehicle

    k = int(np.argmin(np.abs((V0 - rate * res.t) - V_test)))
    cl, cp = creep_law_for_runs(law, V_test)
    veh2 = build_vehicle(veh.definition, veh.track, s0=veh.s0, speed=V_test, creep_law=cl, creep_params=cp,
                         speed_control=V_test)
    r = simulate(veh2.model, (res.t[k], res.t[k] + T_check), METHOD, q0=res.q[k], v0=res.v[k], rtol=RTOL,
                 atol=RTOL * 1e-2, n_output=int(T_check * 100) + 1)
    y = np.abs(r.coordinates()[f"{veh.wheelsets[0]}.y [m]"].to_numpy())
    n1 = len(y) // T_check if T_check >= 1 else len(y) // 2
    first, last = y[: int(n1)].max(), y[-int(n1):].max()
    return bool(r.success and last >= 0.8 * first and last > HUNTING_AMPLITUDE), r


def hunting_threshold_speed(V, amplitude):
    """The lowest speed of a run-down at which the leading wheelset still hunts (amplitude above
    :data:`HUNTING_AMPLITUDE`); NaN unless it hunts over the first tenth of the run and not over
    all of it."""
    hunting = np.asarray(amplitude) > HUNTING_AMPLITUDE
    if not hunting[: max(1, len(hunting) // 10)].all() or hunting.all():
        return np.nan
    return float(np.asarray(V)[np.nonzero(hunting)[0].max()])


def zero_rate_speed(rates, speeds):
    r"""The threshold speeds ``speeds`` [m/s] of run-downs at ``rates`` [m/s²], extrapolated to
    zero rate along the straight line through the two slowest: with a lag proportional to the
    rate, :math:`V(r) = V_{nc} - c\,r`, it returns :math:`V_{nc}` exactly.  NaN if either is."""
    (r1, V1), (r2, V2) = sorted(zip(map(float, rates), map(float, speeds)))[:2]
    if not (np.isfinite(V1) and np.isfinite(V2)) or r1 == r2:
        return np.nan
    return V1 + (V1 - V2) * r1 / (r2 - r1)


def nonlinear_critical_speed(case):
    r"""The nonlinear critical speed of the vehicle for one creep law, ``case = dict(law=..., V0=90,
    V1=40, rate=2, bisect=False, two_rate=True, stop_quiet=1)`` [m/s, m/s², s]: every run-down ends
    ``stop_quiet`` seconds after the hunting has stopped (:func:`stop_when_quiet`; None: at ``V1``).  Module-level and returning
    plain data, for :func:`core.sweep.run_sweep`.

    1. *Run-down* (:func:`run_down`) from ``V0`` to ``V1`` at ``rate``: the threshold speed
       :math:`V_f` (:func:`hunting_threshold_speed`) lags the fold of the limit-cycle branch.
    2. *Two rates* (``two_rate``): two slower run-downs, at :math:`r/2` and :math:`r/4`, each
       continued from the first one's state 4.5 m/s above :math:`V_f` (on the branch; 9 m/s above
       if it is not hunting there) down to :math:`V_f`, give :math:`V_{r/2}` and :math:`V_{r/4}`.
       With a lag proportional to the rate -- measured for the Manchester coach with Polach 2000:
       1.95 and 0.99 m/s below the bisected speed at 1 and 0.5 m/s² --, the threshold speed
       extrapolated to zero rate is :math:`V_{nc} = V_{r/4} + (V_{r/4} - V_{r/2})`.  Its cost is
       fixed, three run-downs; ``benchmarks/railway_critical_speed.py`` checks it against 3.
    3. *Bisection* (``bisect``): 3 s constant-speed runs from the run-down's state
       (:func:`hunting_persists`) bisect the lowest speed at which the cycle persists to 0.1 m/s;
       the bracket reaches 4 m/s above :math:`V_f` (widened upwards until hunting persists at its
       top).  Its cost grows with the depth (about eight runs).

    Returns
    -------
    dict
        ``row`` (creep law, status, outcome -- why there is no critical speed, if there is none --,
        message, run-down estimate, the two-rate and the bisected speed where computed, the
        nonlinear critical speed -- the bisected one where computed, else the two-rate one --,
        bracket, constant-speed runs, amplitude at 1.1 V_nc, wall times) and ``curve``
        (speed, amplitude, status) of the run-down.
    """
    import time

    from core.inputs import check_keywords

    check_keywords(case, ("law", "V0", "V1", "rate", "two_rate", "bisect", "stop_quiet"),
                   where="nonlinear_critical_speed case")
    law = case["law"]
    V0, V1, rate = case.get("V0", 90.0), case.get("V1", 40.0), case.get("rate", 2.0)
    start = time.perf_counter()
    quiet = case.get("stop_quiet", 1.0)
    res, veh = run_down(law, V0=V0, V1=V1, rate=rate, stop_quiet=quiet)
    Vt, amp = hunting_envelope(res, veh, V0, rate)
    row = {"creep law": law, "status": res.status, "outcome": "", "message": "" if res.status == "finished" else res.message,
           "run-down wall time [s]": time.perf_counter() - start}
    V_f = hunting_threshold_speed(Vt, amp) if res.success else np.nan
    row["run-down estimate [m/s]"] = V_f
    if not np.isfinite(V_f):
        hunting = amp > HUNTING_AMPLITUDE
        row["nonlinear critical speed [m/s]"] = np.nan
        row["outcome"] = ("run failed" if not res.success else "hunting over the whole run-down"
                          if hunting.all() else f"no limit cycle at {V0:g} m/s")
        return dict(row=row, curve=(Vt, amp, res.status))
    V_nc = np.nan
    notes = []
    if case.get("two_rate", True):
        start = time.perf_counter()
        speeds = []
        for slow in (2.0, 4.0):  # rate / 2 and rate / 4, each from the first run's state on the branch
            V_s = np.nan
            for above in (4.5, 9.0):
                V_start = min(V_f + above, V0 - 1.0)
                r2, V2 = continue_run_down(law, res, veh, V0, rate, V_start, V_f, rate / slow, stop_quiet=quiet)
                V_s = (hunting_threshold_speed(V2, hunting_envelope(r2, veh, V2[0], rate / slow)[1])
                       if r2.success else np.nan)
                if not r2.success:  # a failed run says why, and no speed is extrapolated from it
                    notes.append(f"run-down at {rate / slow:g} m/s2 from {V_start:.2f} m/s failed: {r2.message}")
                    break
                if np.isfinite(V_s) or V_start >= V0 - 1.0:
                    break
            if r2.success and not np.isfinite(V_s):
                notes.append(f"run-down at {rate / slow:g} m/s2 from {V_start:.2f} m/s: no threshold speed (not "
                             f"hunting at its start, or hunting to its end)")
            row[f"run-down estimate at {rate / slow:g} m/s2 [m/s]"] = V_s
            speeds.append(V_s)
        V_nc = zero_rate_speed((rate / 2.0, rate / 4.0), speeds)
        row["two-rate critical speed [m/s]"] = V_nc
        row["slow run-downs wall time [s]"] = time.perf_counter() - start
    if case.get("bisect", False):
        start = time.perf_counter()
        V_lo, V_hi = V_f - 1.0, min(V_f + 4.0, V0 - 1.0)
        n_runs = 0
        failed = []  # a constant-speed run that fails decides nothing: the bisection stops there

        def persists(V):
            ok, r = hunting_persists(law, res, veh, V, V0, rate)
            if not r.success:
                failed.append(f"constant-speed run at {V:.3f} m/s failed: {r.message}")
            return ok

        while not (top_ok := persists(V_hi)) and not failed and V_hi < V0 - 1.0:
            V_lo, V_hi = V_hi, min(V_hi + 4.0, V0 - 1.0)
            n_runs += 1
        n_runs += 1
        while top_ok and not failed and V_hi - V_lo > 0.1:
            Vm = 0.5 * (V_hi + V_lo)
            ok = persists(Vm)
            V_hi, V_lo = (Vm, V_lo) if ok else (V_hi, Vm)
            n_runs += 1
        V_b = 0.5 * (V_hi + V_lo) if top_ok and not failed else np.nan
        notes += failed
        row["bisected critical speed [m/s]"] = V_b
        row["bracket [m/s]"] = ("bisection stopped by a failed run" if failed else f"{V_lo:.3f} .. {V_hi:.3f}"
                                if top_ok else f"no persisting limit cycle below {V0 - 1.0:g} m/s")
        row["constant-speed runs"] = n_runs
        row["bisection wall time [s]"] = time.perf_counter() - start
        if np.isfinite(V_nc):
            row["two-rate minus bisected [m/s]"] = V_nc - V_b
        V_nc = V_b
    row["nonlinear critical speed [m/s]"] = V_nc
    if notes:
        row["outcome"] = "; ".join(notes)
    if np.isfinite(V_nc):
        row["amplitude at 1.1 V_nc [m]"] = float(np.interp(1.1 * V_nc, Vt[::-1], amp[::-1]))
    return dict(row=row, curve=(Vt, amp, res.status))
