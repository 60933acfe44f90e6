"""
A coaster from control points: a train over your own track, rider loads against the limits
===========================================================================================

A short open track written as a handful of control points (x, y, z in metres, a section name
each): a drop from a 25 m crest, a climbing half-circle turn of 22 m radius, a camelback hill and a
run-out.
The centreline is a quintic spline through the points, reparameterised by arc length
(:class:`coaster.track.SplineCentreline`; Pombo & Ambrósio 2007), its frame rotation-minimising
(Bishop 1975) and banked by the bank that cancels the lateral load of a point mass running on
the energy speed v(L)² = v₀² + 2 g (z₀ − z(L)): roll = atan(v² κ/g)
(:func:`coaster.track.design_bank`). The three-car train of :mod:`coaster.train` is released on
the crest at walking pace and runs free under gravity; the rider of car 1 feels the load factors
n = Cᵀ Aᵀ (a_P − g)/g in car axes (:mod:`coaster.rider`), whose peaks and time above the
acceleration limits (data/coaster/acceleration_limits.csv) are taken over the ride from the run's
dense solution (independent of the output step). Replace the control points with your own.

This script is the scene ``coaster-from-control-points``: ``mbsuite run coaster-from-control-points``
runs this very file.
"""

# %%
# Model
# -----
# Your track here: one row per control point, x forward, y left, z up (m), and its section.
import pandas as pd

from coaster import plots
from coaster.frames import RotationMinimisingFrame
from coaster.rider import read_acceleration_limits
from coaster.track import SplineCentreline, design_bank, speed_from_energy
from coaster.train import (Train, named_sections, rider_peaks, run_train, sections_at, time_above_limits_dense,
                           wheel_forces)
from core.scenes import scene_run

scene = scene_run("coaster-from-control-points")
track = pd.DataFrame([
    (0, 0, 25.5, "crest"), (12, 0, 25, "crest"), (24, 0, 24, "drop"), (36, 0, 18, "drop"), (48, 0, 9, "drop"),
    (60, 0, 4, "drop"), (70, 0, 3, "turn"), (85.6, 6.4, 4.5, "turn"), (92, 22, 6, "turn"), (85.6, 37.6, 7.5, "turn"),
    (70, 44, 9, "turn"), (58, 44, 10, "camelback"), (46, 44, 13, "camelback"), (34, 44, 14, "camelback"),
    (22, 44, 12, "camelback"), (10, 44, 9, "run-out"), (-2, 44, 8, "run-out"), (-14, 44, 8, "run-out"),
], columns=["x [m]", "y [m]", "z [m]", "section"])
L_start, speed_start = 12.0, 3.0  # the lead wheelset's arc length (m) and speed (m/s) at release

centreline = SplineCentreline(track[["x [m]", "y [m]", "z [m]"]].to_numpy(float), kind="quintic",
                              name="my track")
sections = named_sections(track["section"], centreline)
bank = design_bank(centreline, speed_from_energy(centreline, L_start, speed_start))
frame = RotationMinimisingFrame(centreline, bank=bank, bank_reference="vertical", max_step=2.0,
                                name="RMF of my track, banked for the energy speed")
train = Train(frame, name="three-car train")
limits = read_acceleration_limits()

# %%
# Run
# ---
# Free running under gravity (no rolling resistance or drag: add ``train.forces(rolling=..., drag_area=...)``)
# until the lead wheelset is 12 m before the end of the track.
run = run_train(train, L_start, speed_start, centreline.length - 12.0, forces=train.forces(),
                output_step=0.1, sections=sections)
print(run.status, run.message)

# %%
# Tables
# ------
# The ride along the track (one row a second), its sections, the rider's peak load factors and the
# time above each level of the limits table with its verdict (``sections=sections`` in both gives
# them per section, at the cost of more re-integrated states).
ride = run.table()
ride.insert(2, "section", sections_at(sections, ride["L [m]"]))
scene.table("ride", ride.iloc[::10].reset_index(drop=True))
scene.table("sections", sections)
peaks = scene.table("rider_peaks", rider_peaks(run, "car1"))
above = scene.table("time_above_limits", time_above_limits_dense(run, limits, car="car1", peaks=peaks))
above[["axis", "level [g]", "peak [g]", "time above [s]", "verdict"]]

# %%
# Figures
# -------
loads = run.rider_loads("car1", jerk=False)
title = f"coaster-from-control-points ({run.meta['method']}, rtol {run.meta['rtol']:g})"
scene.figure("speed", plots.plot_speed_and_height(run, sections, f"{title}: speed and height"))
scene.figure("load_factors", plots.plot_load_factors(loads, f"{title}: rider load factors in car axes"))
scene.figure("wheel_forces", plots.plot_wheel_forces(wheel_forces(run), f"{title}: wheel forces, track frame"))
scene.figure("track_3d", plots.plot_track_3d(frame, loads["L [m]"], loads["n_z [g]"],
                                             "vertical load factor n_z at the rider of car 1 [g]",
                                             f"{title}: track coloured by n_z", z_scale=1.0))

exceeded = above[above["verdict"] == "exceeds"]
scene.note(f"Track: quintic spline through {len(track)} control points, {centreline.length:.1f} m, banked for the "
           f"energy speed from {speed_start:g} m/s at L = {L_start:g} m. Run: {run.status} ({run.message}); top speed "
           f"{ride['speed [m/s]'].max():.1f} m/s. Rider of car 1: n_z from {peaks['n_z min [g]'].min():.2f} to "
           f"{peaks['n_z max [g]'].max():.2f} g, |n_y| up to {peaks['|n_y| max [g]'].max():.2f} g; limits exceeded: "
           + (", ".join(f"{r['axis']} {r['level [g]']:+g} g" for _, r in exceeded.iterrows())
              or "none") + " (limits: data/coaster/acceleration_limits.csv).")
scene.done()
