"""
Gait inverse dynamics: hip, knee and ankle moments over the gait cycle
======================================================================

Joint moments of the right leg over the right gait cycle of a walking trial, from an OpenSim model,
its inverse-kinematics motion and the ground reactions (Silva & Ambrósio 2003; Winter 2009, ch. 5).
The Cartesian model has one planar body per segment, each OpenSim joint as three constraint
equations with its coordinates prescribed by the measured angles (low-passed at 6 Hz); core's
kinematic analysis gives positions, velocities and accelerations, core's inverse dynamics the
multipliers λ, and τ = −(∂h/∂q)ᵀ λ the generalized forces (:mod:`biomech.sagittal`). A second,
smaller model with the same joints takes its segment inertias from de Leva's (1996) Table 4
(:mod:`biomech.anthropometry`). The trial is OpenSim's subject01 walk on gait10dof18musc; where
OpenSim 4.6 is installed its inverse-dynamics tool on the same files is overlaid (Delp et al. 2007).

This script is the scene ``gait-inverse-dynamics``: ``mbsuite run gait-inverse-dynamics`` runs
this very file.
"""

# %%
# Model
# -----
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from biomech import opensim_peer
from biomech.anthropometry import anthropometric_sagittal_model, moment_differences
from biomech.inverse_dynamics import inverse_dynamics, load_trial, right_gait_cycle
from core.paths import data_path
from core.scenes import scene_run

scene = scene_run("gait-inverse-dynamics")

# ---- your files here: the model, its inverse-kinematics motion and the ground reactions -------
trial_dir = data_path("biomech", "opensim", "gait10dof18musc_subject01_walk")
model_file = trial_dir / "subject01.osim"
motion_file = trial_dir / "subject01_walk_IK.mot"
loads_file = trial_dir / "subject01_walk_grf.xml"
# ---------------------------------------------------------------------------------------------

joints = {"hip_flexion_r": "hip flexion", "knee_angle_r": "knee (angle convention: flexion negative)",
          "ankle_angle_r": "ankle dorsiflexion"}
trial = load_trial(model_file, motion_file, loads_file)
small_model = anthropometric_sagittal_model(trial.osim, table="deleva")  # 7 segments, de Leva's inertias

# %%
# Run
# ---
ours = inverse_dynamics(trial)
small = inverse_dynamics(load_trial(small_model, motion_file, loads_file))
hs0, hs1 = right_gait_cycle(trial)
mass, t = trial.body_mass, ours["time [s]"].to_numpy()
cyc = (t >= hs0 - 1e-9) & (t <= hs1 + 1e-9)
pct = (t[cyc] - hs0) / (hs1 - hs0) * 100.0
peer = None  # OpenSim's inverse-dynamics tool on the same files, when installed
if opensim_peer.available():
    peer, peer_wall = opensim_peer.run_inverse_dynamics(model_file, motion_file, loads_file, t[0], t[-1],
                                                        out_dir=scene.out_dir / "opensim")
    peer_on = {c: np.interp(t, peer["time"].to_numpy(), peer[c].to_numpy()) for c in peer.columns if c != "time"}

# %%
# Tables
# ------
# Peaks of each moment over the cycle (N m/kg), the pelvis residuals, the smaller model against
# gait10dof18musc, and the wall time.
rows, res_rows = [], []
for c in joints:
    y = ours[f"{c}_moment [N m]"].to_numpy()[cyc]
    row = {"coordinate": c}
    if peer is not None:
        d, yo = y - peer_on[f"{c}_moment"][cyc], peer_on[f"{c}_moment"][cyc]
        row |= {"rms difference [N m]": float(np.sqrt(np.mean(d**2))), "max difference [N m]": float(np.max(np.abs(d))),
                "rms difference [% of peak]": float(100 * np.sqrt(np.mean(d**2)) / np.max(np.abs(yo)))}
    i_max, i_min = int(np.argmax(y)), int(np.argmin(y))
    rows.append(row | {"max [N m/kg]": float(y[i_max] / mass), "at [% gait cycle]": float(pct[i_max]),
                       "min [N m/kg]": float(y[i_min] / mass), "at min [% gait cycle]": float(pct[i_min])})
for c, unit in (("pelvis_tx_force", "N"), ("pelvis_ty_force", "N"), ("pelvis_tilt_moment", "N m")):
    y = ours[f"{c} [{unit}]"].to_numpy()[cyc]
    r = {"residual": c, "unit": unit, "rms": float(np.sqrt(np.mean(y**2))), "max |.|": float(np.max(np.abs(y)))}
    res_rows.append(r if peer is None else r | {"rms OpenSim": float(np.sqrt(np.mean(peer_on[c][cyc] ** 2)))})
a = ours.attrs
wall = a["wall_time_build"] + a["wall_time_kinematics"] + a["wall_time_inverse_dynamics"]
timing = {"frames": int(a["n_frames"]), "mbsuite wall time [s]": wall,
          "of which kinematic analysis [s]": a["wall_time_kinematics"],
          "of which inverse dynamics [s]": a["wall_time_inverse_dynamics"]}
if peer is not None:
    timing |= {"OpenSim wall time [s]": peer_wall, "mbsuite / OpenSim [-]": wall / peer_wall}
scene.table("joint_moments_summary", pd.DataFrame(rows))
scene.table("pelvis_residuals", pd.DataFrame(res_rows))
scene.table("anthropometric_model_vs_gait10dof", moment_differences(ours, small, window=(hs0, hs1)).reset_index())
scene.table("timing", pd.DataFrame([timing]))
scene.table("joint_moments", ours)
scene.table("joint_reactions", ours.attrs["joint_reactions"])

# %%
# Figures
# -------
fig = Figure(figsize=(7, 8), layout="constrained")
ax = fig.subplots(3, 1, squeeze=False)[:, 0]
for k, (c, label) in enumerate(joints.items()):
    ax[k].plot(pct, ours[f"{c}_moment [N m]"].to_numpy()[cyc] / mass, lw=1.8,
               label="mbsuite (Cartesian core, driving constraints)")
    ax[k].plot(pct, small[f"{c}_moment [N m]"].to_numpy()[cyc] / mass, ":", lw=1.4,
               label="mbsuite, planar model from de Leva's tables (7 segments)")
    if peer is not None:
        ax[k].plot(pct, peer_on[f"{c}_moment"][cyc] / mass, "--", lw=1.2,
                   label=f"OpenSim {opensim_peer.version().split('-')[0]} ID tool")
    ax[k].axhline(0, c="k", lw=0.5)
    ax[k].set(ylabel=f"{label}\nmoment [N m/kg]")
    ax[k].grid(True, alpha=0.3)
ax[0].legend(fontsize=8)
ax[2].set(xlabel="right gait cycle [%] (heel strike to heel strike)")
ax[0].set_title(f"gait-inverse-dynamics — gait10dof18musc, subject01 walk ({mass:.1f} kg), right leg;\n"
                f"coordinates low-passed at 6 Hz (3rd-order Butterworth, forward and backward)", fontsize=9)
scene.figure("joint_moments", fig)

scene.note(
    f"Joint moments of the right leg over the right gait cycle ({hs0:.3f}-{hs1:.3f} s, heel strikes from the "
    f"vertical ground reaction force through 20 N) of OpenSim's subject01 walking trial on gait10dof18musc "
    f"({mass:.1f} kg), normalised by body mass. The Cartesian model has one planar body per segment "
    f"(absolute coordinates of its centre of mass), each OpenSim joint as three constraint equations "
    f"with its coordinates prescribed by the measured angles (the knee's translations are the model's "
    f"splines of its angle); core's kinematic analysis gives positions, velocities and accelerations, "
    f"core's inverse dynamics the multipliers, and tau = -(dh/dq)^T lambda the generalized forces "
    f"(biomech.sagittal). Largest constraint-force residual of the driven mechanism: "
    f"{a['max_residual']:.1e}. Pelvis residuals (the trial is not dynamically consistent; OpenSim's RRA "
    f"would reduce them): see residuals table. "
    "The second, smaller model (dotted; biomech.anthropometry) has the same joints, trial and coordinates, "
    "one foot segment, a pin knee fitted to the model's moving knee, a lumped head-arms-trunk segment and "
    "segment masses, centres of mass and radii of gyration from de Leva (1996) Table 4 scaled to the "
    "subject's 72.6 kg (table anthropometric_model_vs_gait10dof). "
    + ("OpenSim 4.6's inverse-dynamics tool on the same files is overlaid (dashed)."
       if peer is not None else "OpenSim is not installed: no overlay (pip install 'mbsuite[peers]').")
    + "\n\nReferences: Silva & Ambrosio (2003), Mech. Based Des. Struct. Mach. 31:381-411; Delp et al. "
      "(2007), IEEE TBME 54:1940-1950; Winter (2009), Biomechanics and Motor Control of Human Movement, ch. 5.")
scene.done()
