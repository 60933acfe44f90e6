"""The railway vehicle scenes of ``mbsuite run``: each one is an example script.

* ``railway-flying-wheelset`` -- ``examples/railway/flying_wheelset.py``;
* ``railway-critical-speed`` -- ``examples/railway/critical_speed.py`` on
  :mod:`railway.vehicles.critical_speed`;
* ``railway-curving`` -- ``examples/railway/vehicle_curving.py`` on :mod:`railway.vehicles.curving`;
* ``railway-irregular-track`` -- ``examples/railway/irregular_track.py`` on :mod:`railway.vehicles.ride`;
* ``railway-ride-comfort`` -- ``examples/railway/ride_comfort.py`` on :mod:`railway.vehicles.ride_comfort`
  (rigid and flexible car body, EN 12299 and Sperling).

The functions this module held before (issue 22) moved to those modules; their old names here
still resolve, with a :class:`DeprecationWarning` naming the new place.
"""

from __future__ import annotations

import importlib
import warnings

__all__ = ["vehicle_scenes"]

#: old name here -> (module, name) where it lives now
_MOVED = {
    "CREEP_LAWS": ("railway.contact.creep", "VEHICLE_CREEP_LAWS"),
    "creep_law_spec": ("railway.contact.creep", "creep_law_for_runs"),
    "METHOD": ("railway.vehicles.curving", "METHOD"),
    "RTOL": ("railway.vehicles.curving", "RTOL"),
    "CURVE": ("railway.vehicles.curving", "CURVE"),
    "curving_track": ("railway.vehicles.curving", "curving_track"),
    "run_curving": ("railway.vehicles.curving", "run_curving"),
    "curve_window": ("railway.vehicles.curving", "curve_window"),
    "linear_critical_speed": ("railway.vehicles.critical_speed", "linear_critical_speed"),
    "run_down": ("railway.vehicles.critical_speed", "run_down"),
    "HUNTING_AMPLITUDE": ("railway.vehicles.critical_speed", "HUNTING_AMPLITUDE"),
    "PSD": ("railway.vehicles.ride", "PSD"),
    "irregularities": ("railway.vehicles.ride", "irregularities"),
    "irregular_case": ("railway.vehicles.ride", "irregular_track_case"),
}


def __getattr__(name):
    if name in _MOVED:
        module, new = _MOVED[name]
        warnings.warn(f"railway.vehicle_scenes.{name} moved to {module}.{new}", DeprecationWarning, stacklevel=2)
        return getattr(importlib.import_module(module), new)
    raise AttributeError(f"module 'railway.vehicle_scenes' has no attribute {name!r}")


def vehicle_scenes():
    """The railway vehicle scenes (registered with :func:`railway.scenes.railway_scenes`)."""
    from core.scenes import example_scene

    return [
        example_scene("railway-flying-wheelset", "railway/flying_wheelset.py",
                      "Free (flying) wheelset: Klingel wavelength of a cone, S1002 limit cycle",
                      "A free wheelset released with a lateral offset: kinematic wavelength of conical wheels "
                      "against Klingel; S1002/UIC60 growth into a flange-bounded limit cycle against V/L at the "
                      "equivalent conicity (Klingel 1883; Wickens 2003, ch. 2)."),
        example_scene("railway-critical-speed", "railway/critical_speed.py",
                      "Critical speed: suspended wheelset eigenvalues vs closed form; vehicle run-down per creep law",
                      "Linear critical speed of a wheelset on springs from core's eigenvalues against the closed "
                      "form; nonlinear critical speed of the Manchester coach by a run-down from a hunting limit "
                      "cycle, each creep law, bifurcation diagram.",
                      full_adds="the bisection of 3 s constant-speed runs to 0.1 m/s for every creep law (about "
                                "eight runs each), with the difference from the fixed-cost two-rate estimate."),
        example_scene("railway-curving", "railway/vehicle_curving.py",
                      "Manchester coach through a 200 m curve at 10 and 20 m/s, every creep law",
                      "Curving of the stand-in for the ML95 metro trailer (Pombo & Ambrosio 2008): Q, Y, Y/Q, "
                      "sum Y, flange force, dQ/Q0, displacement, angle of attack, creepages, T gamma, Nadal "
                      "limit; lateral equilibrium in the full curve."),
        example_scene("railway-irregular-track", "railway/irregular_track.py",
                      "Manchester coach on irregular straight track: car-body accelerations and wheel forces",
                      "ORE B176 low-level irregularities, speed sweep through core.sweep: car-body acceleration "
                      "r.m.s. and spectra, wheel forces."),
        example_scene("railway-ride-comfort", "railway/ride_comfort.py",
                      "Ride comfort: Manchester coach with rigid and flexible car body, EN 12299 and Sperling",
                      "The same irregular track with the rigid car body and a flexible one (free-free equivalent "
                      "beam, assumed 9 Hz bending, 12 Hz torsion): floor accelerations at the centre and over the "
                      "bogies, EN 12299 mean comfort N_MV and Sperling's W_z per floor point, spectra.",
                      full_adds="the bisection (to 0.25 m/s) of the speed where the flexible car body's N_MV at the "
                                "centre first exceeds the rigid one's by 10 %."),
    ]
