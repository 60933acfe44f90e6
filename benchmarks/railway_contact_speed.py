"""Speed of the railway contact geometry: contact-geometry table and trajectory contact search.

Run: ``python benchmarks/railway_contact_speed.py``

Measures (wall time, best of several repeats, on this machine):

1. the rigid contact-geometry table of S1002/UIC60 1:40 over 401 lateral shifts (target < 1 s);
2. the contact search alone (no normal or creep forces) for the 8 wheels of a 4-wheelset
   vehicle moving at 30 m/s along a track with a clothoid, a curve with cant and lateral and
   vertical irregularities, called every 1 ms with warm starts (target < 200 us per call), with
   the default periodic global re-seeding (every 10 calls) and with warm starts only; and a cold
   (globally seeded) call for comparison.  With numba installed both the compiled Newton kernel
   and the numpy implementation are measured side by side.
"""

from __future__ import annotations

import time

import numpy as np
import pandas as pd

from railway._kernels import HAVE_NUMBA
from railway.contact_geometry import conicity_table, contact_geometry_table, flange_contact_onset
from railway.contact_search import ContactSearch, wheelset_pose
from railway.track import Curve, Irregularities, Straight, Track, Transition


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


def trajectory_poses(track, n_steps, dt=1e-3, speed=30.0, s0=250.0):
    """Poses of 4 wheelsets (bogie wheelbase 2.5 m, bogie centres 19 m apart) hunting gently."""
    offsets = np.array([0.0, 2.5, 19.0, 21.5])
    poses = []
    for k in range(n_steps):
        s = s0 + speed * k * dt + offsets
        y = 0.004 * np.sin(2 * np.pi * s / 25.0)
        yaw = 0.002 * np.cos(2 * np.pi * s / 25.0)
        r, A = wheelset_pose(track, s, y, 0.46, 0.0, yaw)
        poses.append((r, A, s))
    return poses


def bench_trajectory(track, poses, reseed_every, compiled):
    cs = ContactSearch(track, n_wheelsets=4, reseed_every=reseed_every, compiled=compiled)
    cs.search(*poses[0], warm=False)
    passes = []
    t0, c0 = time.perf_counter(), time.process_time()
    for r, A, s in poses[1:]:
        passes.append(cs.search(r, A, s).iterations)
    n = len(poses) - 1
    return (time.perf_counter() - t0) / n, (time.process_time() - c0) / n, float(np.mean(passes))


def main():
    rows = []
    shifts = np.linspace(-0.010, 0.010, 401)
    t_table, c_table, df = _best(lambda: contact_geometry_table(shifts))
    rows.append(("contact-geometry table, 401 shifts (S1002/UIC60 1:40)", t_table, c_table, "s",
                 "< 1 s"))

    track = _vehicle_track()
    poses = trajectory_poses(track, 2001)
    for compiled in ((True, False) if HAVE_NUMBA else (False,)):
        impl = "numba kernel" if compiled else "numpy"
        cs = ContactSearch(track, n_wheelsets=4, compiled=compiled)
        cs.search(*poses[0], warm=False)  # compile / warm caches
        t_cold, c_cold, _ = _best(lambda: cs.search(*poses[0], warm=False), repeats=20)
        rows.append((f"[{impl}] contact search, 8 wheels, cold call (scan, 2 seeds)",
                     t_cold * 1e6, c_cold * 1e6, "us", ""))
        for reseed in (10, 50, 10**9):
            per_call, cpu, passes = bench_trajectory(track, poses, reseed, compiled)
            what = f"re-seed every {reseed} calls" if reseed < 10**9 else "no re-seeding"
            rows.append((f"[{impl}] contact search, 8 wheels, warm-started trajectory, {what} "
                         f"(mean {passes:.2f} passes)", per_call * 1e6, cpu * 1e6, "us",
                         "< 200 us"))

    out = pd.DataFrame(rows, columns=["case", "wall", "CPU", "unit", "target"])
    print(out.to_markdown(index=False, floatfmt=".3g"))
    con = conicity_table(df, [0.002, 0.003, 0.004])
    y_f, g_f = flange_contact_onset(df)
    print()
    print(f"flange contact from {y_f * 1e3:.2f} mm, contact angle {np.degrees(g_f):.1f} deg")
    print(con.to_markdown(index=False, floatfmt=".4f"))
    print("\n(search only: normal and creep forces are not included; wall = elapsed time,")
    print(" CPU = process time, which is less sensitive to other load on the machine)")


if __name__ == "__main__":
    main()
