"""
Bodies on analytic tracks against closed forms
==============================================

A body runs through the path-following joint of Pombo & Ambrósio (2003) — the arc length L as an
extra coordinate — on six analytic tracks, and each run is compared with its closed form
(:mod:`coaster.analytic_scene` lists them; g = 9.81 m/s², gravity along −z):

* a rigid car on a helix in its Frenet frame: L̈ = −m g sin α/(m + J_zz/h²), F·n = m κ L̇²;
* a bead in a vertical loop: v² = v_b² − 2gR(1 − cos φ), N = m(v²/R + g cos φ), the time to the
  top (2R/v_b) F(π/2, k) with k² = 4gR/v_b² (Byrd & Friedman 1971), N_bottom − N_top = 6 m g;
* a rigid car on a banked circle (30° and the perfect bank tan β = v²/(g R)), the rider 1 m up;
* a bead on a clothoid (κ = L/a: n_y = v² κ/g, jerk_y = v³/(a g)) and on an S-curve;
* a bead on the ballistic parabola of its own free flight: zero multipliers, a weightless rider.

Each comparison passes when ``|error|`` ≤ K · rtol · scale with K = 1e3 and rtol = 1e-10 of
``dop853-projection``. Finally the Frenet frame is set against the rotation-minimising frame
(Bishop 1975) where Frenet breaks: on a straight (κ = 0) and at the S-curve's inflection.

This script is the scene ``coaster-analytic``: ``mbsuite run coaster-analytic`` runs this very file.
"""

# %%
# Model
# -----
# The tracks, bodies and closed forms of every case are those of :func:`coaster.analytic_scene.analytic_cases`;
# the rider's acceleration limits are the shipped table.
import numpy as np
from matplotlib.figure import Figure

from coaster.analytic_scene import K_TOL, METHOD, RTOL, SCENE, analytic_cases
from coaster.rider import read_acceleration_limits
from core.plot import run_title
from core.scenes import scene_run

scene = scene_run("coaster-analytic")
limits = read_acceleration_limits()

# %%
# Run
# ---
comparison, runs, panels, frames_table, extras = analytic_cases(fast=scene.fast)

# %%
# Tables
# ------
# One row per compared quantity at its sample of largest error, one row per run, the frames where
# Frenet breaks, and the loop's rider loads with their time above the limits.
scene.table("comparison", comparison)
scene.table("runs", runs)
scene.table("frames_where_frenet_breaks", frames_table)
scene.table("loop_rider_loads", extras["loop_loads"])
scene.table("loop_time_above_limits", extras["loop_limits"])
comparison

# %%
# Figures
# -------
# Five runs against their closed forms, and the banked circle's load factors against the bank angle.
fig = Figure(figsize=(11, 10), layout="constrained")
ax = fig.subplots(3, 2, squeeze=False).ravel()
for a, p in zip(ax, panels):
    a.plot(p["x"], p["exact"], "-", lw=2.5, color="0.75", label="closed form")
    a.plot(p["x"], p["sim"], "--", lw=1.2, color="C0", label="simulated")
    a.set(xlabel=p["xlabel"], ylabel=p["ylabel"])
    a.set_title(p["title"], fontsize=8)
    a.grid(True, alpha=0.3)
    a.legend(fontsize=7)
a = ax[len(panels)]
q = extras["bank_points"][0][3]
bank = np.radians(np.linspace(0.0, 60.0, 121))
a.plot(np.degrees(bank), q * np.cos(bank) - np.sin(bank), "-", color="C1", label="n_y closed form")
a.plot(np.degrees(bank), q * np.sin(bank) + np.cos(bank), "-", color="C2", label="n_z closed form")
for beta, ny, nz, _ in extras["bank_points"]:
    a.plot([beta, beta], [ny, nz], "o", color="k", ms=5)
a.plot([], [], "o", color="k", label="simulated (30 deg; perfect bank)")
a.set(xlabel="bank angle β [deg]", ylabel="load factor at the track [g]")
a.set_title(f"banked circle R 30 m, 20 m/s (q = {q:.3f}): load factors against the bank", fontsize=8)
a.grid(True, alpha=0.3)
a.legend(fontsize=7)
title = run_title({"method": METHOD, "rtol": RTOL, "atol": RTOL}, subject=f"{SCENE} scene")
fig.suptitle(title + "\nbodies on analytic tracks against their closed forms", fontsize=10)
scene.figure("closed_forms", fig)

# %%
# On the S-curve the Frenet frame flips by π at the inflection; the rotation-minimising frame turns
# by ``|ω|`` ΔL between neighbouring samples.
fig = Figure(figsize=(8, 4.5), layout="constrained")
a = fig.subplots()
for name, fq in extras["frame_curves"].items():
    a.semilogy(fq["L_m"], fq["rotation_step_rad"], lw=1.2, label=name)
fq = next(iter(extras["frame_curves"].values()))
a.semilogy(fq["L_m"], fq["expected_step_rad"], ":", color="k", lw=1.0, label="|ω| ΔL (expected)")
a.set(xlabel="L [m]", ylabel="rotation between neighbouring samples [rad]")
a.grid(True, which="both", alpha=0.3)
a.legend(fontsize=8)
a.set_title(f"{SCENE} scene: frames on the S-curve (clothoid through κ = 0 at L = 30 m);\n"
            "Frenet flips by π at the inflection, the rotation-minimising frame turns smoothly", fontsize=9)
scene.figure("frames_s_curve", fig)

n_fail = int((~comparison["pass"]).sum())
scene.note(f"Integrator {METHOD}, rtol = atol = {RTOL:g}; a comparison passes when |error| <= {K_TOL:g} x rtol x "
           f"scale (see `comparison`): {len(comparison) - n_fail} of {len(comparison)} pass, largest error/tolerance "
           f"{comparison['error/tolerance'].max():.3g}.  Closed forms from notes/coaster.md; loads in car axes "
           "(x forward, y left, z up) from `coaster.rider.rider_loads`, jerk as the derivative of the load factor "
           "along the state's flow.\n\nThe loop's time above the acceleration limits uses "
           f"`data/coaster/acceleration_limits.csv` ({limits.attrs['source'][:160]}...).")
scene.done()
