"""A vehicle through a curve: the track, the run, and what a curving assessment reads from it.

The scenario of Pombo & Ambrósio (2008, Multibody Syst. Dyn. 19:91-114) for the ML95 metro
trailer, with the Manchester benchmark coach as the stand-in (the ML95 data are not public): a
left curve of radius 200 m with 150 mm cant between clothoid transitions (cant ramped
linearly), run at constant speed under a speed control.

* :func:`curving_track` -- straight, transition, curve, transition, straight (:data:`CURVE`);
* :func:`run_curving` -- the vehicle through it at a speed, from the quasi-static start;
* :func:`curve_window` -- the rows of a contact history at which the whole vehicle is in the full
  curve, at least 30 m from both transitions (quasi-static curving);
* :func:`lateral_equilibrium` -- the rail forces on the vehicle along the track's lateral axis
  against :math:`m\\,(a_c - g)\\cdot n` (centripetal acceleration and gravity in the canted plane);
* :func:`curving_case` -- one (creep law, speed) case with its wheel-force history, wheel events
  and the two tables, as a picklable function of the case for :func:`core.sweep.run_sweep`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["CURVE", "QUASI_STATIC_COLUMNS", "curve_window", "curving_case", "curving_track", "lateral_equilibrium",
           "run_curving"]

#: the curve: 200 m radius (left), cant 150 mm, 40 m clothoid transitions, with the straight
#: lengths before and after (m)
CURVE = dict(radius=200.0, cant=0.150, transition=40.0, curve_length=200.0, lead=60.0, tail=100.0)

#: the integrator and tolerance of the vehicle runs (README/docs, Railway vehicles: accuracy)
METHOD, RTOL = "jit-dop853", 1e-4

#: wheel quantities averaged over the full-curve window
QUASI_STATIC_COLUMNS = [
    "Q [N]", "Y [N]", "Y/Q [-]", "sum Y [N]", "flange force [N]", "dQ/Q0 [-]", "lateral displacement [m]",
    "angle of attack [rad]", "contact angle [rad]", "Nadal limit [-]", "T gamma [N]", "xi_tread [-]",
    "eta_tread [-]", "phi_tread [1/m]", "Fx_tread [N]", "Fy_tread [N]", "Fx_flange [N]", "Fy_flange [N]",
    "p_max [Pa]"]


def curving_track(curve_length=None):
    """Straight, transition, the 200 m curve (cant 150 mm), transition, straight (:data:`CURVE`;
    ``curve_length`` [m] overrides the length of the full curve)."""
    from ..track import Curve, Straight, Track, Transition

    c = CURVE
    return Track([Straight(c["lead"]), Transition(c["transition"]),
                  Curve(c["curve_length"] if curve_length is None else curve_length, c["radius"], cant=c["cant"]),
                  Transition(c["transition"]), Straight(c["tail"])])


def run_curving(law, V, T=None, definition=None, track=None, method=METHOD, rtol=RTOL, n_output_per_s=20,
                reseed_every=1, record_steps=False):
    """The vehicle (default: the Manchester coach) through the curve at constant speed ``V`` [m/s]
    under a speed control, creep law ``law`` (:data:`railway.contact.creep.VEHICLE_CREEP_LAWS`);
    ``T`` [s] defaults to the time at which the car body is 30 m past the middle of the curve.

    ``record_steps``: keep the state (and the compiled contact search state) at every accepted step
    (``result.steps``) for the wheel events and peaks of
    :func:`railway.assessment.wheel_event_statistics`; the outputs and the step sequence are the
    same either way.  Returns ``(result, vehicle)``."""
    from core.integrators import simulate

    from ..contact.creep import creep_law_for_runs
    from .vehicle import VehicleDefinition, build_vehicle

    D = definition or VehicleDefinition.manchester()
    track = track or curving_track()
    cl, cp = creep_law_for_runs(law, V)
    veh = build_vehicle(D, track, s0=35.0, speed=V, creep_law=cl, creep_params=cp, speed_control=V,
                        contact_options=dict(reseed_every=reseed_every))
    veh.preload()
    q0, v0 = veh.initial_state()
    if T is None:
        c = CURVE
        T = (c["lead"] + c["transition"] + 0.5 * c["curve_length"] + 30.0 - 35.0) / V
    res = simulate(veh.model, (0.0, T), method, q0=q0, v0=v0, rtol=rtol, atol=rtol * 1e-2,
                   n_output=int(T * n_output_per_s) + 1, record_steps=record_steps)
    return res, veh


def curve_window(H, curve_length=None):
    """Rows of a contact history at the times when every wheelset is in the full curve, at
    least 30 m from both transitions (quasi-static curving of the whole vehicle); the track of
    :func:`curving_track` with its curve ``curve_length`` long (default: :data:`CURVE`'s)."""
    c = CURVE
    length = c["curve_length"] if curve_length is None else curve_length
    lo = c["lead"] + c["transition"] + 30.0
    hi = c["lead"] + c["transition"] + length - 30.0
    g = H.groupby("t [s]")["s [m]"]
    inside = (g.min() >= lo) & (g.max() <= hi)
    return H[H["t [s]"].isin(inside.index[inside.to_numpy()])]


def lateral_equilibrium(W, track, total_mass):
    r"""Lateral equilibrium of the whole vehicle in the full curve (rows ``W`` of
    :func:`curve_window`): the rail forces on the vehicle along the track's lateral axis,
    :math:`-\overline{\sum Y}`, against :math:`m\,(a_c - g)\cdot n` with the centripetal
    acceleration :math:`a_c = V^2\kappa` towards the curve's centre in the horizontal plane, gravity
    :math:`g = (0, 0, -9.81)` m/s² and the track's lateral unit vector :math:`n` in the canted
    plane at the middle of the window.  Quasi-static when the standard deviation of the rail
    forces over the window is below 5 % of :math:`m\,(a_c - g)\cdot n`.  Returns a row dict."""
    from .vehicle import GRAVITY

    c = CURVE
    sumY = W.groupby("t [s]")["sum Y [N]"].sum() / 2.0  # sum Y is repeated on both wheels of a wheelset
    s_mid = c["lead"] + c["transition"] + 0.5 * c["curve_length"]
    fr = track.evaluate(np.array([s_mid]))
    n = fr.R[0][:, 1]
    t_h = fr.R[0][:, 0]
    centre = np.array([-t_h[1], t_h[0], 0.0]) / np.hypot(t_h[0], t_h[1])  # a left curve: the heading turned left
    V = float(W["speed [m/s]"].mean())
    a_c = V**2 / c["radius"] * centre
    need = total_mass * (a_c - np.array([0.0, 0.0, -GRAVITY])) @ n
    got = float(-sumY.mean())
    return {"mean speed [m/s]": V, "rail forces on the vehicle along the track's lateral axis [N]": got,
            "m (a_c - g) . n [N]": need, "relative difference [-]": got / need - 1.0,
            "unbalanced lateral acceleration [m/s2]": need / total_mass,
            "std of the rail forces [N]": float(sumY.std()), "quasi-static": bool(sumY.std() < 0.05 * abs(need))}


def curving_case(case):
    """One case of a curving study, ``case = dict(law=..., speed=..., T=None, vehicle_file=None)``
    (a vehicle file of :mod:`railway.vehicles.vehicle_file`; default: the Manchester coach): the run, its
    contact history at the outputs, the wheel events from every accepted step (lifts located by
    bisection, peaks refined; :func:`railway.assessment.wheel_event_statistics`), the quasi-static
    means per wheel over the full-curve window and the lateral equilibrium.  Module-level and
    returning plain data, so that :func:`core.sweep.run_sweep` can run the cases on any executor.

    Returns
    -------
    dict
        ``status``, ``message``, ``leading`` (the leading wheelset's name), ``history`` (contact
        history at the outputs, with ``dQ/Q0 [-]``), ``events`` (per wheel, with the arc length of
        the first lift-off), ``quasi_static`` (rows), ``equilibrium`` (a row or None),
        ``output_step`` [s].
    """
    from ..assessment import wheel_event_statistics
    from .vehicle import GRAVITY, VehicleDefinition
    from .wheel_rail import contact_history

    from core.inputs import check_keywords

    check_keywords(case, ("law", "speed", "T", "vehicle_file"), where="curving_case")
    law, V = case["law"], float(case["speed"])
    vehicle_file = case.get("vehicle_file")
    D = VehicleDefinition.from_toml(vehicle_file) if vehicle_file else VehicleDefinition.manchester()
    res, veh = run_curving(law, V, T=case.get("T"), definition=D, record_steps=True)
    Q0 = D.total_mass * GRAVITY / 8.0
    H = contact_history(veh.model, res)
    H["dQ/Q0 [-]"] = (Q0 - H["Q [N]"]) / Q0
    Hs = contact_history(veh.model, res, at="steps")
    ev = wheel_event_statistics(Hs, output_times=res.t, warn=False)
    s_of = {w: g for w, g in Hs.groupby("wheel", sort=False)}
    ev.insert(1, "lift-off first, s [m]", [
        float(np.interp(t0, s_of[w]["t [s]"], s_of[w]["s [m]"])) if np.isfinite(t0) else np.nan
        for w, t0 in zip(ev["wheel"], ev["lift-off first [s]"])])
    base = {"speed [m/s]": V, "creep law": law, "status": res.status}
    if res.status == "failed":
        base["message"] = res.message
    W = curve_window(H)
    quasi_static, equilibrium = [], None
    if len(W) == 0:
        quasi_static.append(dict(base, wheel="(no full-curve rows)"))
    else:
        g = W.groupby("wheel", sort=False)
        mean = g[QUASI_STATIC_COLUMNS].mean()
        mean["flange contact [-]"] = g["flange contact"].mean()
        quasi_static = [dict(base, wheel=wheel, **r.to_dict()) for wheel, r in mean.iterrows()]
        if len(np.unique(W["t [s]"])) >= 3 and res.success:
            equilibrium = {"speed [m/s]": V, "creep law": law, **lateral_equilibrium(W, veh.track, D.total_mass)}
    return dict(status=res.status, message=res.message, leading=veh.wheelsets[0], history=H, events=ev,
                quasi_static=quasi_static, equilibrium=equilibrium,
                output_step=float(np.max(np.diff(res.t))) if len(res.t) > 1 else np.nan)
