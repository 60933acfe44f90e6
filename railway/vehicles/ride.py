"""Ride on irregular track: car-body accelerations and wheel forces as a track test reads them.

* :data:`PSD` -- the ORE B176 "low level" spectrum of alignment and level irregularities;
* :func:`irregularities` -- a track's irregularities sampled from it (sum of harmonics, random
  phases, band-limited, tapered at the ends);
* :func:`irregular_track_case` -- the vehicle at one speed over irregular straight track: car-body
  acceleration r.m.s., maxima and spectra, wheel forces filtered and as percentiles (EN 14363 /
  UIC 518 processing as quoted second-hand, :mod:`railway.assessment`), and the unfiltered extremes
  and wheel lift from every accepted step; a picklable function of the case for
  :func:`core.sweep.run_sweep`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .curving import METHOD, RTOL

__all__ = ["PSD", "irregular_track_case", "irregularities"]


#: One-sided PSD of track irregularities, S(Ω) = A Ω_c² / ((Ω² + Ω_r²)(Ω² + Ω_c²)) [m² / (rad/m)]:
#: the form and "low level" parameters of ORE B176 / ERRI as quoted in the vehicle-dynamics
#: literature; NOT checked against the ORE report in this project (data/railway/README.md).
PSD = dict(A_lateral=2.119e-7, A_vertical=4.032e-7, omega_c=0.8246, omega_r=0.0206)


def irregularities(length, seed=1, wavelengths=(3.0, 70.0), dx=0.25, level=1.0):
    """Lateral and vertical irregularities (m) sampled from :data:`PSD` by a sum of harmonics
    with random phases (``np.random.default_rng(seed)``), band-limited to ``wavelengths`` (m),
    tapered to zero over 20 m at both ends."""
    from ..track import Irregularities

    rng = np.random.default_rng(seed)
    s = np.arange(0.0, length + dx / 2, dx)
    Om = np.linspace(2 * np.pi / wavelengths[1], 2 * np.pi / wavelengths[0], 400)
    dOm = Om[1] - Om[0]
    out = []
    for key in ("A_lateral", "A_vertical"):
        S = PSD[key] * PSD["omega_c"] ** 2 / ((Om**2 + PSD["omega_r"] ** 2) * (Om**2 + PSD["omega_c"] ** 2))
        amp = np.sqrt(2.0 * S * dOm) * level
        ph = rng.uniform(0, 2 * np.pi, Om.size)
        out.append(np.sum(amp[None, :] * np.cos(Om[None, :] * s[:, None] + ph[None, :]), axis=1))
    taper = np.clip(np.minimum(s, length - s) / 20.0, 0.0, 1.0)
    return Irregularities(s, out[0] * taper, out[1] * taper)


def irregular_track_case(case):
    """One speed of the sweep (module-level so that process pools can run it): the coach over
    ``case['length']`` m of irregular straight track; returns a row dict and the spectra."""
    from scipy.signal import welch

    from core.errors import InputError
    from core.integrators import simulate

    from ..assessment import wheel_event_statistics, wheel_force_statistics
    from ..contact.creep import creep_law_for_runs
    from ..track import Track
    from .vehicle import GRAVITY, VehicleDefinition, build_vehicle
    from .wheel_rail import contact_history

    from core.inputs import check_keywords

    check_keywords(case, ("speed", "length", "law", "seed"), where="irregular_track_case")
    V, length, law = case["speed"], case["length"], case.get("law", "polach2000")
    D = VehicleDefinition.manchester()
    irr = irregularities(length + 60.0, seed=case.get("seed", 1))
    track = Track.straight(length + 60.0, irregularities=irr)
    cl, cp = creep_law_for_runs(law, V)
    veh = build_vehicle(D, track, s0=20.0, speed=V, creep_law=cl, creep_params=cp, speed_control=V)
    veh.preload()
    q0, v0 = veh.initial_state()
    T = (length - 20.0) / V
    fs, fs_force = 200.0, 1000.0  # car-body accelerations; wheel forces (the ~200 Hz bounce resolved)
    sub = int(round(fs_force / fs))
    res = simulate(veh.model, (0.0, T), METHOD, q0=q0, v0=v0, rtol=RTOL, atol=RTOL * 1e-2,
                   n_output=int(T * fs) * sub + 1, record_steps=True)
    t_acc = res.t[::sub]
    Vel = res.velocities()
    acc_y = np.gradient(Vel[f"{veh.car_body}.vy [m/s]"].to_numpy()[::sub], t_acc)
    acc_z = np.gradient(Vel[f"{veh.car_body}.vz [m/s]"].to_numpy()[::sub], t_acc)
    t_skip = min(2.0, 0.25 * T)  # the start transient
    keep = t_acc >= t_skip
    f, Py = welch(acc_y[keep], fs=fs, nperseg=min(1024, int(keep.sum())))
    _, Pz = welch(acc_z[keep], fs=fs, nperseg=min(1024, int(keep.sum())))
    # wheel forces as the run applied them, at 1 kHz; filtered and as percentiles as a track test
    # evaluates them (railway.assessment.wheel_force_statistics): raw extremes of a force that
    # carries the wheelsets' bounce are samples of that oscillation, not a statistic
    H = contact_history(veh.model, res)
    H = H[H["t [s]"] >= t_skip]
    # the unfiltered extremes and wheel lift from every accepted step (railway.assessment.
    # wheel_event_statistics), not from the 1 kHz samples of the bounce
    Hs = contact_history(veh.model, res, at="steps")
    E = wheel_event_statistics(Hs[Hs["t [s]"] >= t_skip], warn=False)
    Q0 = D.total_mass * GRAVITY / 8.0
    try:
        W = wheel_force_statistics(H)
        note = ""
    except InputError as exc:  # e.g. a run that failed before a 2 m window of signal: keep its row
        cols = ["Q high [N]", "Q low [N]", "Q max, unfiltered [N]", "Q min, unfiltered [N]", "|Y| high [N]",
                "(Y/Q) 2 m high [-]", "(sum Y) 2 m high [N]"]
        W = pd.DataFrame([{c: np.nan for c in cols}])
        note = f"no wheel-force statistics: {exc}"
    row = {"speed [m/s]": V, "creep law": law, "status": res.status,
           "car body lateral acceleration rms [m/s2]": float(np.sqrt(np.mean(acc_y[keep] ** 2))),
           "car body vertical acceleration rms [m/s2]": float(np.sqrt(np.mean(acc_z[keep] ** 2))),
           "car body lateral acceleration max [m/s2]": float(np.max(np.abs(acc_y[keep]))),
           "car body vertical acceleration max [m/s2]": float(np.max(np.abs(acc_z[keep]))),
           "Q high, 20 Hz [N]": float(W["Q high [N]"].max()), "Q low, 20 Hz [N]": float(W["Q low [N]"].min()),
           "dQ/Q0 high, 20 Hz [-]": float((Q0 - W["Q low [N]"].min()) / Q0),
           "Q max, unfiltered [N]": float(E["Q max [N]"].max()),
           "Q min, unfiltered [N]": float(E["Q min [N]"].min()),
           "wheels lifted": int((E["lifts"] > 0).sum()), "lifted, longest wheel [s]": float(E["lifted [s]"].max()),
           "|Y| high, 20 Hz [N]": float(W["|Y| high [N]"].max()),
           "(Y/Q) 2 m high [-]": float(W["(Y/Q) 2 m high [-]"].max()),
           "(sum Y) 2 m high [N]": float(W["(sum Y) 2 m high [N]"].max()), "n_rhs": res.counters["n_rhs"],
           "message": "; ".join(m for m in (res.message if not res.success else "", note) if m)}
    return row, (f, Py, Pz)
