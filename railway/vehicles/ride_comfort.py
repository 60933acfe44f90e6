r"""Ride comfort on irregular track: floor accelerations of a rigid or flexible car body, EN 12299
mean comfort and Sperling's ride index.

* :func:`floor_accelerations` -- what accelerometers on the car-body floor read in a run: the
  specific force :math:`f_P = A_B^\mathsf{T}(\ddot r_P - g)` at floor points, in the axes of the
  body they sit on (the car body, or for a flexible car body the node frame at the station, so the
  floor follows the bending and torsion); :math:`\ddot r_P` differentiates the point velocity
  :math:`\dot r_P = \dot r_B + A_B(\bar\omega_B\times\bar s_P)` of the run's 400 Hz output by
  fourth-order central differences, :math:`(-v_{i+2} + 8v_{i+1} - 8v_{i-1} + v_{i-2})/(12h)`,
  whose relative error on a harmonic is :math:`(2\pi f h)^4/30` = 1.3e-5 at 9 Hz and 3.3e-4 at
  20 Hz (second order at the two samples of each end).  The output rate is chosen below the
  integrator's own step rate (about 1.2 kHz on this vehicle): the compiled integrators land a
  step on every output time, so a 1 kHz output would double the steps;
* :func:`ride_comfort_case` -- the vehicle at one speed over irregular straight track
  (:func:`railway.vehicles.ride.irregularities`, ORE B176 low level as quoted, a fixed seed, so
  every speed and both car bodies run over the same track): per floor point the EN 12299 mean
  comfort N_MV (:func:`railway.comfort.mean_comfort`, 5 s blocks) with its P95 components, and
  Sperling's W_z vertical and lateral (:func:`railway.comfort.sperling`); a picklable function of
  the case for :func:`core.sweep.run_sweep`;
* :data:`FLOOR_POINTS` -- the measuring points: on the floor at the car-body centre and above
  both bogie centres, on the centre line (EN 12299's floor positions, as quoted second-hand in
  :mod:`railway.comfort`), :data:`FLOOR_HEIGHT` above the rail top (assumed: the benchmark vehicle
  gives no floor height).

EN 12299 evaluates 5 min records (60 blocks); a run here is shorter and its row says how many
blocks its N_MV used.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["FLOOR_HEIGHT", "FLOOR_POINTS", "floor_accelerations", "ride_comfort_case", "flexible_definition",
           "ASSUMED_FLEXIBLE_CAR_BODY"]

#: floor height above the rail top [m] (assumed; a passenger coach's floor is about 1.1-1.3 m high)
FLOOR_HEIGHT = 1.2
#: floor points by name: (station, lateral y [m]); the station is the car-body centre or a bogie centre
FLOOR_POINTS = {"centre": ("centre", 0.0), "over bogie 1": ("over bogie 1", 0.0),
                "over bogie 2": ("over bogie 2", 0.0)}
#: the flexible car body the scene gives the Manchester coach (every value assumed: the benchmark
#: has a rigid car body): 24 m long, first vertical bending 9 Hz, torsion 12 Hz, lateral bending
#: 15 Hz, 2 % modal damping
ASSUMED_FLEXIBLE_CAR_BODY = dict(length=24.0, vertical_bending_frequency=9.0, torsion_frequency=12.0,
                                 lateral_bending_frequency=15.0, damping_ratio=0.02, elements=24)


def flexible_definition(definition, **table):
    """``definition`` with the car body made flexible by the ``[car_body.flexible]`` table
    ``table`` (:meth:`railway.vehicles.vehicle.VehicleDefinition.with_flexible_car_body`)."""
    return definition.with_flexible_car_body(**table)


def _station_x(vehicle, station):
    L_b = vehicle.definition.geometry["bogie_centre_semi_distance"]
    return {"centre": 0.0, "over bogie 1": L_b, "over bogie 2": -L_b}[station]


def floor_accelerations(vehicle, res, points=None, floor_height=FLOOR_HEIGHT, gravity=None) -> dict:
    """Specific force at floor points in body axes (module docstring).

    Parameters
    ----------
    vehicle : railway.vehicles.vehicle.Vehicle
    res : core.results.SimulationResult
        A run of ``vehicle.model`` with uniformly spaced output.
    points : dict, optional
        name -> (station, y); default :data:`FLOOR_POINTS`.
    floor_height : float
        Above the rail top [m].

    Returns
    -------
    dict
        name -> (n_t, 3) array of (x, y, z) [m/s²] in the axes of the body at the point.
    """
    from core import frames

    m = vehicle.model
    points = FLOOR_POINTS if points is None else points
    g = np.asarray(m.gravity if gravity is None else gravity, float)
    t = np.asarray(res.t)
    if len(t) < 3 or not np.allclose(np.diff(t), t[1] - t[0], rtol=1e-6):
        raise ValueError("floor_accelerations: the run needs at least 3 uniformly spaced output times")
    h_cg = vehicle.definition.geometry["car_body_cg_height"]
    out = {}
    for name, (station, y) in points.items():
        if vehicle.car_body_frames:
            body = vehicle.car_body_frames[station]
            s = np.array([0.0, y, floor_height - h_cg])
        else:
            body = vehicle.car_body
            s = np.array([_station_x(vehicle, station), y, floor_height - h_cg])
        qs, vs = m.q_slice(body), m.v_slice(body)
        A = frames.euler_to_matrix(res.q[:, qs][:, 3:7])
        vel = res.v[:, vs]
        vP = vel[:, :3] + np.einsum("nij,nj->ni", A, np.cross(vel[:, 3:6], s))
        aP = _derivative(vP, t[1] - t[0])
        out[name] = np.einsum("nji,nj->ni", A, aP - g)
    return out


def _derivative(x, h):
    """d/dt of uniformly sampled rows: fourth-order central differences inside, second order at
    the ends (module docstring)."""
    d = np.gradient(x, h, axis=0, edge_order=2)
    if len(x) >= 5:
        d[2:-2] = (-x[4:] + 8.0 * x[3:-1] - 8.0 * x[1:-3] + x[:-4]) / (12.0 * h)
    return d


def ride_comfort_case(case):
    """One run of the sweep (module-level so that process pools can run it): the coach, rigid or
    with the flexible car body ``case['flexible']`` (a ``[car_body.flexible]`` table, None for
    rigid), at ``case['speed']`` over ``case['duration']`` s of irregular straight track.

    Returns ``(rows, spectra)``: one row per floor point (N_MV and its P95 components, Sperling
    W_z vertical and lateral, weighted r.m.s., run status) and the Welch spectra of the vertical
    and lateral floor accelerations per point."""
    from scipy.signal import welch

    from core.errors import InputError
    from core.inputs import check_keywords
    from core.integrators import simulate

    from ..comfort import mean_comfort, sperling
    from ..contact.creep import creep_law_for_runs
    from ..track import Track
    from .curving import METHOD, RTOL
    from .ride import irregularities
    from .vehicle import VehicleDefinition, build_vehicle

    check_keywords(case, ("speed", "duration", "flexible", "law", "seed", "settle"), where="ride_comfort_case")
    V, T = float(case["speed"]), float(case["duration"])
    settle = float(case.get("settle", 2.0))
    law = case.get("law", "polach2000")
    D = VehicleDefinition.manchester()
    if case.get("flexible"):
        D = D.with_flexible_car_body(**case["flexible"])
    length = V * (T + settle) + 60.0
    irr = irregularities(length, seed=case.get("seed", 1))
    track = Track.straight(length, irregularities=irr)
    cl, cp = creep_law_for_runs(law, V)
    veh = build_vehicle(D, track, s0=20.0, speed=V, creep_law=cl, creep_params=cp, speed_control=V)
    veh.preload()
    q0, v0 = veh.initial_state()
    fs = 400.0
    t_end = settle + T
    res = simulate(veh.model, (0.0, t_end), METHOD, q0=q0, v0=v0, rtol=RTOL, atol=RTOL * 1e-2,
                   n_output=int(round(t_end * fs)) + 1)
    acc = floor_accelerations(veh, res)
    keep = res.t >= settle
    rows, spectra = [], {}
    body = "flexible" if case.get("flexible") else "rigid"
    for name, a in acc.items():
        ax, ay, az = (a[keep, i] for i in range(3))
        row = {"car body": body, "speed [m/s]": V, "floor point": name, "status": res.status,
               "record [s]": float(res.t[keep][-1] - res.t[keep][0]) if keep.any() else 0.0}
        try:
            N = mean_comfort(ax, ay, az, fs)
            row.update({k: N[k] for k in ("N_MV [-]", "comfort (EN 12299 scale)", "a_XP95 Wd [m/s2]",
                                          "a_YP95 Wd [m/s2]", "a_ZP95 Wb [m/s2]", "blocks used")})
            row["Wz vertical [-]"] = float(sperling(az, fs, "vertical"))
            row["Wz lateral [-]"] = float(sperling(ay, fs, "lateral"))
        except InputError as exc:  # a run that stopped before one block: keep its row, say why
            row["message"] = f"no comfort index: {exc}"
        row["vertical acceleration rms [m/s2]"] = float(np.sqrt(np.mean((az - az.mean()) ** 2))) if keep.any() else np.nan
        if res.status == "failed":
            row["message"] = (row.get("message", "") + " " + res.message).strip()
        rows.append(row)
        if keep.sum() > 256:
            f, Pz = welch(az, fs=fs, nperseg=min(4096, int(keep.sum())))
            _, Py = welch(ay, fs=fs, nperseg=min(4096, int(keep.sum())))
            spectra[name] = (f, Py, Pz)
    return rows, spectra
