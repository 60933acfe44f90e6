"""
Ride on irregular track
=======================

The Manchester benchmark coach on straight track whose centreline carries lateral (alignment) and
vertical (level) irregularities sampled from the ORE B176 low-level spectrum
:math:`S(\\Omega) = A\\,\\Omega_c^2 / ((\\Omega^2 + \\Omega_r^2)(\\Omega^2 + \\Omega_c^2))` (form and
parameters as quoted in the vehicle-dynamics literature, not checked against the ORE report;
harmonics with random phases, seed 1, wavelengths 3-70 m, tapered over 20 m at the ends), at
20, 30 and 40 m/s with Polach 2000:

* car-body accelerations at the centre of mass (200 Hz output) after a 2 s start transient:
  r.m.s., maxima and Welch spectra;
* wheel forces at 1 kHz (the wheelsets bounce on the Hertz springs at about 200 Hz) as a track
  test evaluates them (EN 14363 / UIC 518 processing as quoted second-hand,
  :mod:`railway.assessment`): Q low-passed at 20 Hz with its 99.85 % and 0.15 % percentiles, ``|Y|``
  at 20 Hz, Y/Q and ΣY as 2 m sliding means;
* the unfiltered extremes of Q and wheel lift from every accepted step of the run.

The speeds run as a sweep (:func:`core.sweep.run_sweep`) on every local core; any executor gives
the same table. For your own track, pass your :class:`railway.Irregularities` (measured, or from
:func:`railway.vehicles.ride.irregularities` with your spectrum level) to
:meth:`railway.Track.straight`. This script is the scene ``railway-irregular-track``.
"""

# %%
# Run
# ---
import pandas as pd
from matplotlib.figure import Figure

from core.scenes import scene_run
from core.sweep import run_sweep
from railway.tables import display_units
from railway.vehicles.ride import METHOD, RTOL, irregular_track_case

scene = scene_run("railway-irregular-track")
speeds = (30.0,) if scene.fast else (20.0, 30.0, 40.0)
length = 120.0 if scene.fast else 320.0  # m of irregular track
cases = [dict(speed=V, length=length, law="polach2000", seed=1) for V in speeds]
out = run_sweep(irregular_track_case, cases, executor=scene.executor)

# %%
# Table
# -----
table = scene.table("irregular_track", display_units(pd.DataFrame([row for row, _ in out])))
table

# %%
# Car-body acceleration spectra
# -----------------------------
fig = Figure(figsize=(7.5, 6), layout="constrained")
ax = fig.subplots(2, 1)
for row, (f, Py, Pz) in out:
    ax[0].semilogy(f, Py, lw=1, label=f"{row['speed [m/s]']:g} m/s")
    ax[1].semilogy(f, Pz, lw=1, label=f"{row['speed [m/s]']:g} m/s")
ax[0].set(ylabel="lateral PSD [(m/s2)^2/Hz]",
          title=f"railway-irregular-track — Manchester coach on straight track with ORE B176 low-level "
                f"irregularities (wavelengths 3-70 m), Polach 2000, {METHOD} rtol {RTOL:g}\ncar-body "
                f"acceleration spectra at the centre of mass (Welch)")
ax[0].title.set_fontsize(9)
ax[1].set(xlabel="frequency [Hz]", ylabel="vertical PSD [(m/s2)^2/Hz]")
for a in ax:
    a.set_xlim(0, 30)
    a.grid(True, alpha=0.3)
    a.legend(fontsize=8)
scene.figure("carbody_acceleration_spectra", fig)

scene.note(
    f"The coach on {length:g} m of straight track whose centreline carries lateral (alignment) and vertical "
    f"(level) irregularities sampled from the ORE B176 low-level spectrum (form and parameters as quoted in the "
    f"literature, not checked against the ORE report; harmonics with random phases, seed 1, wavelengths 3-70 m, "
    f"tapered over 20 m at the ends), at {', '.join(f'{v:g}' for v in speeds)} m/s, Polach 2000. The speed sweep "
    f"runs through core.sweep.run_sweep (on every local core by default; `mbsuite run ... --workers 1` runs it "
    f"serially and `--dask ADDRESS` on a cluster, with the same table: tests/railway/test_vehicle_scenes.py). "
    f"Car-body accelerations from the centre-of-mass velocities (200 Hz output) after a 2 s start transient. "
    f"Wheel forces at 1 kHz (the wheelsets bounce on the Hertz springs at about 200 Hz), those the run applied "
    f"(railway.vehicles.wheel_rail.contact_history evaluates them with the contact search state the run had), "
    f"evaluated as a track test does (EN 14363 / UIC 518 processing as quoted second-hand, railway.assessment): "
    f"Q low-pass 20 Hz, its 99.85 % ('high') and 0.15 % ('low') percentiles over the wheels; |Y| at 20 Hz, "
    f"99.85 %; Y/Q and sum Y as 2 m sliding means every 0.5 m, 99.85 %. The unfiltered extremes of Q and the "
    f"wheel lift (Q = 0) are taken from every accepted step of the run (railway.assessment.wheel_event_statistics), "
    f"not from the 1 kHz outputs; the extremes are peaks of the bounce and change from run to run with the "
    f"rounding (docs, Railway vehicles).")
scene.done()
