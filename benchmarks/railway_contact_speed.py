"""Speed of the railway contact geometry and of the wheel-rail contact call of a vehicle.

Run: ``python benchmarks/railway_contact_speed.py``

Measures, on this machine, both the CPU time of the process (``time.process_time``, less
sensitive to other load on the machine) and the elapsed wall time (``time.perf_counter``):

1. the rigid contact-geometry table of S1002/UIC60 1:40 over 401 lateral shifts (target < 1 s);
2. the contact call for the 8 wheels of a 4-wheelset vehicle moving at 30 m/s along a track with
   a clothoid, a curve with cant and lateral and vertical irregularities, called every 1 ms of
   travel with warm starts (target < 200 us per call on average):

   * search only (four-condition contact search, :class:`railway.contact.search.ContactSearch`);
   * search + forces: the same search followed by :class:`railway.contact.forces.ContactForces` --
     Hertz normal force from the penetration with Lankarani-Nikravesh damping, creepages from
     the wheelset velocities, and the creep law (Kalker linear and Polach 2000), for all 8
     wheels (both tread and flange candidates);

   with global re-seeding every 10, 20 and 50 calls and without re-seeding, and a cold call.
   With numba installed the compiled kernels and the numpy implementations are measured side
   by side (the numpy forces use the reference modules core.contact_laws, railway.contact.creepage, railway.contact.creep).
"""

from __future__ import annotations

import time

import numpy as np
import pandas as pd

from railway.contact.search.kernels import HAVE_NUMBA
from railway.contact.geometry import conicity_table, contact_geometry_table, flange_contact_onset
from railway.contact.search import ContactSearch, wheelset_pose
from railway.contact.forces import ContactForces
from railway.track import Curve, Irregularities, Straight, Track, Transition

R0 = 0.46
SPEED = 30.0
DT = 1e-3


def _best(fn, repeats=3):
    """Best wall time and best CPU time (process_time) over repeats, and the last result."""
    best, best_cpu = np.inf, np.inf
    out = None
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        best = min(best, time.perf_counter() - t0)
        best_cpu = min(best_cpu, time.process_time() - c0)
    return best, best_cpu, out


def _vehicle_track():
    rng = np.random.default_rng(1)
    s = np.arange(0.0, 1000.0, 0.25)
    taper = np.clip(np.minimum(s, 1000.0 - s) / 20.0, 0.0, 1.0)
    lat = 1e-3 * taper * np.convolve(rng.normal(size=s.size), np.ones(20) / 20, mode="same")
    ver = 1e-3 * taper * np.convolve(rng.normal(size=s.size), np.ones(20) / 20, mode="same")
    return Track([Straight(200.0), Transition(100.0), Curve(400.0, 1200.0, 0.08),
                  Transition(100.0), Straight(200.0)], irregularities=Irregularities(s, lat, ver))


def trajectory_poses(track, n_steps, dt=DT, speed=SPEED, s0=250.0, sink=3e-4):
    """Poses and velocities of 4 wheelsets (bogie wheelbase 2.5 m, bogie centres 19 m apart).

    The wheelsets hunt gently (4 mm, 25 m wavelength) and sit ``sink`` below the rigid rolling
    height so that the treads carry load.  Velocities: centre by central differences of the
    positions, angular velocity = rolling spin V/r0 about the axle plus the yaw rate.
    Returns a list of (r, A, s, v, omega).
    """
    offsets = np.array([0.0, 2.5, 19.0, 21.5])

    def pose(k):
        s = s0 + speed * k * dt + offsets
        y = 0.004 * np.sin(2 * np.pi * s / 25.0)
        yaw = 0.002 * np.cos(2 * np.pi * s / 25.0)
        r, A = wheelset_pose(track, s, y, R0 - sink, 0.0, yaw)
        return r, A, s, yaw

    out = []
    prev = pose(-1)
    cur = pose(0)
    for k in range(n_steps):
        nxt = pose(k + 1)
        v = (nxt[0] - prev[0]) / (2 * dt)
        yaw_rate = (nxt[3] - prev[3]) / (2 * dt)
        omega = cur[1][:, :, 1] * (speed / R0) + cur[1][:, :, 2] * yaw_rate[:, None]
        out.append((cur[0], cur[1], cur[2], v, omega))
        prev, cur = cur, nxt
    return out


def bench_trajectory(track, poses, reseed_every, compiled, forces=None):
    """Mean wall and CPU time per call along the trajectory (after a cold first call)."""
    cs = ContactSearch(track, n_wheelsets=4, reseed_every=reseed_every, compiled=compiled)
    r, A, s, v, w = poses[0]
    res = cs.search(r, A, s, warm=False)
    if forces is not None:
        forces(res, r, A, v, w)  # compile / warm caches
    passes = []
    n_contact = 0
    t0, c0 = time.perf_counter(), time.process_time()
    if forces is None:
        for r, A, s, v, w in poses[1:]:
            res = cs.search(r, A, s)
            passes.append(res.iterations)
    else:
        for r, A, s, v, w in poses[1:]:
            res = cs.search(r, A, s)
            f = forces(res, r, A, v, w)
            passes.append(res.iterations)
            n_contact += int(np.count_nonzero(f["N"]))
    wall = time.perf_counter() - t0
    cpu = time.process_time() - c0
    n = len(poses) - 1
    return wall / n, cpu / n, float(np.mean(passes)), n_contact / n


def main():
    rows = []
    shifts = np.linspace(-0.010, 0.010, 401)
    t_table, c_table, df = _best(lambda: contact_geometry_table(shifts))
    rows.append(("contact-geometry table, 401 shifts (S1002/UIC60 1:40)", t_table, c_table, "s",
                 "< 1 s"))

    track = _vehicle_track()
    poses = trajectory_poses(track, 2001)
    for compiled in ((True, False) if HAVE_NUMBA else (False,)):
        impl = "numba" if compiled else "numpy"
        cs = ContactSearch(track, n_wheelsets=4, compiled=compiled)
        cs.search(*poses[0][:3], warm=False)  # compile / warm caches
        t_cold, c_cold, _ = _best(lambda: cs.search(*poses[0][:3], warm=False), repeats=20)
        rows.append((f"[{impl}] search only, 8 wheels, cold call (scan, 2 seeds)",
                     t_cold * 1e6, c_cold * 1e6, "us", ""))
        reseeds = (10, 20, 50, 10**9) if compiled else (10, 10**9)
        models = ("kalker_linear", "polach2000")
        for reseed in reseeds:
            what = f"re-seed every {reseed}" if reseed < 10**9 else "no re-seeding"
            wall, cpu, passes, _ = bench_trajectory(track, poses, reseed, compiled)
            rows.append((f"[{impl}] search only, warm trajectory, {what} ({passes:.2f} passes)",
                         wall * 1e6, cpu * 1e6, "us", "< 200 us"))
            for model in models:
                fc = ContactForces(creep_model=model, compiled=compiled)
                wall, cpu, passes, nc = bench_trajectory(track, poses, reseed, compiled, fc)
                rows.append((f"[{impl}] search + forces ({model}), warm trajectory, {what} "
                             f"({nc:.1f} loaded contacts)", wall * 1e6, cpu * 1e6, "us", "< 200 us"))

    out = pd.DataFrame(rows, columns=["case", "wall", "CPU", "unit", "target"])
    from _calibration import calibrate, header_lines

    cal = calibrate()
    scale = out["unit"].map({"s": 1.0, "us": 1e-6})
    out.insert(2, "wall / calibration [-]", out["wall"] * scale / cal)
    print("\n".join(header_lines(cal)))
    print(out.to_markdown(index=False, floatfmt=".3g"))
    con = conicity_table(df, [0.002, 0.003, 0.004])
    y_f, g_f = flange_contact_onset(df)
    print()
    print(f"flange contact from {y_f * 1e3:.2f} mm, contact angle {np.degrees(g_f):.1f} deg")
    print(con.to_markdown(index=False, floatfmt=".4f"))
    print("\n(wall = elapsed time, CPU = process time of this process; on a loaded machine the")
    print(" wall time includes waiting for a core. Forces = Hertz + Lankarani-Nikravesh normal")
    print(" force, creepages and the creep law for all 8 wheels, after the search.)")


if __name__ == "__main__":
    main()
