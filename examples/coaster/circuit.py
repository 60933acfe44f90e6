"""
Three-car train over the 4.9 km circuit
=======================================

The train of Pombo & Ambrósio (2007) — three cars, two connecting bars, six wheelsets on
path-following joints, one degree of freedom (:mod:`coaster.train`) — over the shared 4.9 km circuit
(data/coaster, 203 control points, a quintic periodic spline with a rotation-minimising frame rolled
by the file's bank): a chain lift on the ``Lift`` section, free running, a booster on ``Launch``
(without it no train released from the lift reaches the brake hill, 9.5 m higher) and brakes from
30 m before the crest of the ``Brake`` section's hill to its end. Along the track: speed, wheel
forces from the path joints' multipliers, the rider's load factors in car axes and the time above
the acceleration limits per section, both from the run's dense solution. Checks: the energy drift
of the free run without dissipation, the rank of the constraint Jacobian, the frame's quality; a
second run with rolling resistance and drag (it rolls back at the Turnaround crest, 2.3 m above the
lift's end: reported, not hidden), and a run on the bank designed from the speed,
roll = atan(v² κ/g).

This script is the scene ``coaster-circuit``: ``mbsuite run coaster-circuit`` runs this very file.
"""

# %%
# Model
# -----
# The operating settings (chain, booster and brake speeds, rolling resistance and drag, the
# integrator) are :data:`coaster.train.CIRCUIT_SETTINGS`.
import time
import warnings

import numpy as np
import pandas as pd

from coaster import plots
from coaster.frames import RotationMinimisingFrame, frame_quality_summary
from coaster.inputs import OutwardBankWarning
from coaster.rider import read_acceleration_limits
from coaster.track import check_bank, design_bank
from coaster.train import (CIRCUIT_SETTINGS as S, ChainLift, SpeedSection, Train, chain_force, circuit_frame,
                           circuit_sections, rank_table, rider_peaks, run_train, section_summary, sections_at,
                           time_above_limits_dense, wheel_force_peaks, wheel_forces)
from core.scenes import scene_run
from core.signals import GridResolutionWarning

scene = scene_run("coaster-circuit")
frame, data, centreline = circuit_frame()
sec = circuit_sections(data, centreline)
get = {r["section"]: r for _, r in sec.iterrows()}
lift, launch, brake = get["Lift"], get["Launch"], get["Brake"]
train = Train(frame, name="three-car train")
# brakes from 30 m before the crest of the brake hill (braking at its foot would stop the train on it)
Lb = np.linspace(brake["L_start [m]"], brake["L_end [m]"], 400)
L_crest = float(Lb[np.argmax(centreline.derivatives(Lb)[0][:, 2])])
sections = [SpeedSection("booster", launch["L_start [m]"], launch["L_end [m]"], S["booster_speed"],
                         S["booster_force"], gain=S["gain"], mode="booster", ramp=5.0),
            SpeedSection("brakes", L_crest - 30.0, brake["L_end [m]"], S["brake_speed"], S["brake_force"],
                         gain=S["gain"], mode="brake", ramp=5.0)]
chain = ChainLift(lift["L_start [m]"], lift["L_end [m]"], S["chain_speed"])
L_stop = centreline.length + 0.5 * lift["L_start [m]"]  # back in the station
settings = dict(method=S["method"], rtol=S["rtol"], atol=S["atol"], output_step=0.5 if scene.fast else 0.25,
                chunk=40.0, sections=sec)
lossy = train.forces(rolling=S["rolling"], drag_area=S["drag_area"], sections=sections)

# %%
# Run
# ---
# A short warm-up run first compiles (or loads) numba's kernels: the real-time factors are of the runs after it.
w0 = time.perf_counter()
warm = ChainLift(chain.L_start, chain.L_start + 2.0, chain.speed)
run_train(train, warm.L_start, warm.speed, warm.L_end + 2.0, chain=warm, forces=lossy,
          **{**settings, "output_step": 0.5})
warmup = time.perf_counter() - w0
main = run_train(train, chain.L_start, chain.speed, L_stop, chain=chain, forces=train.forces(sections=sections),
                 **settings)
lossy_run = run_train(train, chain.L_start, chain.speed, L_stop, chain=chain, forces=lossy, **settings)
# the file's bank against the turns, and the same ride on the bank designed from the main run's speed
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always", OutwardBankWarning)
    bank_check = check_bank(frame, main)
bank_warned = [str(w.message) for w in caught if issubclass(w.category, OutwardBankWarning)]
frame2 = RotationMinimisingFrame(centreline, bank=design_bank(centreline, main), bank_reference="vertical",
                                 max_step=2.0, name="RMF of the circuit with the designed bank")
train2 = Train(frame2, name="three-car train, designed bank")
run2 = run_train(train2, chain.L_start, chain.speed, L_stop, chain=chain, forces=train2.forces(sections=sections),
                 **settings)

# %%
# Tables
# ------
# Rider loads at car 1, peaks and time above the limits per section from the dense solution.
labels = sections_at(sec, main.L[:, 0], centreline.length)
loads = main.rider_loads("car1")
loads.insert(2, "section", labels)
limits = read_acceleration_limits()
peaks = rider_peaks(main, "car1", sections=sec)
with warnings.catch_warnings(record=True) as caught:  # exceedances between two outputs: said in the notes
    warnings.simplefilter("always", GridResolutionWarning)
    above = time_above_limits_dense(main, limits, sec, car="car1", peaks=peaks)
grid_warned = [str(w.message) for w in caught if issubclass(w.category, GridResolutionWarning)]
loads2 = run2.rider_loads("car1")
bank_rows = []
for name, chk, ld, r in (("data (file's rolls)", bank_check, loads, main),
                         ("designed from the main run's speed", check_bank(frame2, main, warn=False), loads2, run2)):
    pk = rider_peaks(r, "car1").iloc[0]  # over the whole run
    bank_rows.append({"bank": name, "run status": r.status, "outward share of v2k [-]": chk.outward_share,
                      "turns banked outward": f"{chk.n_outward} of {chk.n_turns}",
                      "quasi-static |n_y| RMS at the track [g]": chk.lateral_rms_banked,
                      "rider |n_y| RMS [g]": float(np.sqrt(np.mean(ld["n_y [g]"].to_numpy() ** 2))),
                      "rider |n_y| max [g]": pk["|n_y| max [g]"],
                      "rider n_z min [g]": pk["n_z min [g]"], "rider n_z max [g]": pk["n_z max [g]"]})
drift, t_a, t_b, T_peak = main.energy_drift(launch["L_start [m]"])
speed = main.table()
speed.insert(2, "section", labels)
rank = rank_table(train, np.linspace(0.0, centreline.length, 50 if scene.fast else 200, endpoint=False))
fq, fq_summary = frame_quality_summary(frame, centreline, step=5.0 if scene.fast else 1.0)
every = max(1, int(round(1.0 / main.meta["output_step"])))  # tables of time histories: one row a second
wf = wheel_forces(main)

scene.table("runs", pd.DataFrame([{
    "run": name, "status": r.status, "message": r.message, "simulated [s]": float(r.t[-1]),
    "L1 reached [m]": float(np.max(r.L[:, 0])), "integration wall [s]": r.wall_time,
    "real-time factor": r.real_time_factor, "method": r.meta["method"], "rtol": r.meta["rtol"],
    "compilation + warm-up wall [s]": warmup if name.startswith("no") else 0.0,
} for name, r in (("no rolling resistance or drag", main), ("rolling resistance + drag", lossy_run))]))
scene.table("energy_drift", pd.DataFrame([{"section": "free running, lift end to booster", "t from [s]": t_a,
                                           "t to [s]": t_b, "max|E - E0| / T_peak": drift, "T_peak [J]": T_peak}]))
scene.table("section_peaks", section_summary(loads, peaks, wheel_force_peaks(main, sec), above))
scene.table("time_above_limits", above)
scene.table("rank_along_circuit", pd.DataFrame([{
    "positions": len(rank), "rows": int(rank["rows"].iloc[0]), "rank min": int(rank["rank"].min()),
    "rank max": int(rank["rank"].max()), "dof": ", ".join(map(str, sorted(set(rank["dof"])))),
    "sigma_min/sigma_max min": float(rank["sigma_min/sigma_max"].min())}]))
scene.table("speed", speed.iloc[::every].reset_index(drop=True))
scene.table("wheel_forces", wf.iloc[::every].reset_index(drop=True))
scene.table("rider_loads", loads.iloc[::every].reset_index(drop=True))
scene.table("chain_force", chain_force(main).iloc[::every].reset_index(drop=True))
scene.table("sections", sec)
scene.table("frame_quality_summary", fq_summary)
scene.table("bank_design", pd.DataFrame(bank_rows))
scene.table("bank_turns", bank_check.turns)
scene.table("frame_quality", fq.iloc[::10 if not scene.fast else 2].reset_index(drop=True))

# %%
# Figures
# -------
run_label = f"{main.meta['method']}, rtol {main.meta['rtol']:g}"
scene.figure("speed", plots.plot_speed_and_height(main, sec, f"coaster-circuit: three-car train, chain lift, free "
                                                  f"running, booster, brakes ({run_label})"))
scene.figure("wheel_forces", plots.plot_wheel_forces(wf, "coaster-circuit: wheel forces from the path joints' "
                                                     f"multipliers, track frame ({run_label})"))
scene.figure("load_factors", plots.plot_load_factors(loads, "coaster-circuit: rider load factors in car axes "
                                                     f"({run_label})"))
scene.figure("circuit_3d", plots.plot_track_3d(
    frame, np.mod(loads["L [m]"].to_numpy(), centreline.length), loads["n_z [g]"],
    "vertical load factor n_z at the rider of car 1 [g]",
    f"coaster-circuit: track coloured by the rider's vertical load factor ({run_label})"))
closure = fq_summary["frame closure max |R(length) - R(0)| [-]"].iloc[0]
scene.figure("frame_quality", plots.plot_frame_quality(
    fq, "coaster-circuit: rotation-minimising frame with bank along the circuit (quintic spline, samples every "
        f"{fq_summary['step [m]'].iloc[0]:g} m; closure {closure:.1e})"))

p = train.p
scene.note(
    f"Train: {p.n_cars} cars, {p.n_cars - 1} bars, {p.n_wheelsets} wheelsets (11 bodies, 72 coordinates, "
    f"71 constraint rows, 1 DOF; total mass {p.total_mass:.0f} kg). Chain lift on the Lift section at "
    f"{S['chain_speed']} m/s (it descends 10.7 m: the chain holds the train back, see "
    f"chain_force), booster on Launch to {S['booster_speed']} m/s, brakes on Brake to "
    f"{S['brake_speed']} m/s. Main run: {main.status} ({main.message}); simulated "
    f"{main.t[-1]:.1f} s in {main.wall_time:.1f} s of integration (real-time factor "
    f"{main.real_time_factor:.1f}, after a warm-up run that compiled the kernels in {warmup:.1f} s). "
    f"Peak load factors and wheel forces per section from the outputs, the section boundaries and re-integrated "
    f"states around each extreme (coaster.train.rider_peaks, wheel_force_peaks: independent of the output step). "
    f"Energy drift over the free-running section without dissipation: "
    f"{drift:.2e} of the peak kinetic energy. With rolling resistance c_rr = {S['rolling']} and "
    f"c_d A = {S['drag_area']} m^2: {lossy_run.status} ({lossy_run.message}). "
    f"Rider loads at the rider point of car 1 {p.rider_point} m (coaster.rider); limits from "
    f"{limits['basis'].iloc[0] if 'basis' in limits else 'data/coaster/acceleration_limits.csv'}. "
    f"Time above the limits (table time_above_limits) from the run's dense solution, independent of the output "
    f"step (coaster.train.time_above_limits_dense: each crossing of a level located on re-integrated states by "
    f"Newton to {above.attrs['xtol_s']:.1g} s, extremes between two outputs searched; column 'between outputs' "
    f"counts the exceedances no output falls in)" + (f"; GridResolutionWarning: {grid_warned[0]}" if grid_warned
                                                    else "") + ". "
    f"The station rows of the data carry 40-55 deg rolls (kept as given). Track: quintic periodic spline "
    f"through the 203 control points, rotation-minimising frame with the file's rolls relative to the "
    f"vertical (coaster.frames). Bank check (coaster.track.check_bank, weighted by v^2 kappa with the main run's "
    f"speed): {100 * bank_check.outward_share:.0f} % of the lateral demand is on outward bank "
    f"({bank_check.n_outward} of {bank_check.n_turns} turns)" + (f"; OutwardBankWarning: {bank_warned[0]}"
                                                                   if bank_warned else "") + ". With the bank designed "
    f"from the run's speed (coaster.track.design_bank, roll = atan(v^2 kappa / g)) the rider's |n_y| RMS is "
    f"{bank_rows[1]['rider |n_y| RMS [g]']:.3g} g against {bank_rows[0]['rider |n_y| RMS [g]']:.3g} g "
    f"(table bank_design).")
scene.done()
