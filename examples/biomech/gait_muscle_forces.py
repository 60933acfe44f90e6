"""
Gait muscle forces: hamstrings and triceps surae over the gait cycle
====================================================================

Static optimisation of the muscles of an OpenSim model per frame of a walking trial (Silva &
Ambrósio 2003; Anderson & Pandy 2001): the joint moments τ of inverse dynamics are shared by
Hill-type muscles (Thelen 2003 curves, rigid tendon, moment arms r = −∂L/∂q of the paths) and
reserve actuators,

.. math::

    \\sum_j r_{ij}\\,(a_j A_j + P_j) + r^{opt}_i u_i = \\tau_i, \\qquad 0 \\le a_j \\le 1,

minimising either the paper's Σ (F_j/PCSA_j)³ (Crowninshield & Brand 1981) or OpenSim's Σ a_j²,
with one cvxpy problem per model solved by Clarabel (:mod:`biomech.muscle_forces`). The trial is
OpenSim's subject01 walk on gait10dof18musc (18 muscles, planar) and, second, the 3-D gait2392
model (92 muscles) with and without the passive fibre force. Where OpenSim 4.6 is installed its
static optimization on the same files is overlaid.

This script is the scene ``gait-muscle-forces``: ``mbsuite run gait-muscle-forces`` runs this very file.
"""

# %%
# Model
# -----
import numpy as np
import pandas as pd

from biomech import opensim_peer, plots
from biomech.inverse_dynamics import inverse_dynamics, load_trial, right_gait_cycle
from biomech.muscle_forces import (cycle_peak, frame_status, group_force, muscle_inputs, muscle_redundancy,
                                   reserve_optimal_forces, reserve_summary, status_summary)
from biomech.osim import read_force_set
from biomech.spatial_dynamics import spatial_inverse_dynamics
from core.paths import data_path
from core.scenes import scene_run

scene = scene_run("gait-muscle-forces")

# ---- your files here --------------------------------------------------------------------------
# the planar model and its trial: model, inverse-kinematics motion, ground reactions, reserve actuators
trial_dir = data_path("biomech", "opensim", "gait10dof18musc_subject01_walk")
model_file = trial_dir / "subject01.osim"
motion_file = trial_dir / "subject01_walk_IK.mot"
loads_file = trial_dir / "subject01_walk_grf.xml"
reserves_file = trial_dir / "gait10dof_Reserve_Actuators.xml"
# the 3-D model (gait2392) and its trial of the same subject
trial_dir_3d = data_path("biomech", "opensim", "gait2392_subject01_walk")
model_3d = trial_dir_3d / "subject01_simbody_adjusted.osim"
motion_3d = trial_dir_3d / "subject01_walk1_ik.mot"
loads_3d = trial_dir_3d / "subject01_walk1_grf.xml"
reserves_3d = trial_dir_3d / "gait2392_SO_weak_Residual_Actuators.xml"
# -----------------------------------------------------------------------------------------------

groups = {"hamstrings": ("hamstrings_r", "bifemsh_r"), "triceps surae": ("gastroc_r", "soleus_r")}
groups_3d = {"hamstrings": ("semimem_r", "semiten_r", "bifemlh_r", "bifemsh_r"),
             "triceps surae": ("med_gas_r", "lat_gas_r", "soleus_r")}
criteria = {"stress": 3.0, "activation": 2.0}  # the exponent p of sum (F/PCSA)^p or sum a^p
labels = {"stress": "sum (F/PCSA)^3 (Crowninshield & Brand; the paper)",
          "activation": "sum a^2 (OpenSim's static optimization)"}

# %%
# Run
# ---
# Inverse dynamics over the right gait cycle, muscle geometry per frame, then one optimisation per criterion.
trial = load_trial(model_file, motion_file, loads_file)
hs0, hs1 = right_gait_cycle(trial)
inputs = muscle_inputs(trial, inverse_dynamics(trial), window=(hs0, hs1))
reserves = reserve_optimal_forces(read_force_set(reserves_file, trial.osim), inputs["coordinates"])
t, muscles = inputs["time"], inputs["muscles"]
pct = (t - hs0) / (hs1 - hs0) * 100.0
sols = {crit: muscle_redundancy(inputs, reserves, criterion=crit, exponent=p) for crit, p in criteria.items()}

# gait2392: inverse dynamics in its 23 coordinates, only the pelvis residuals as reserves
trial3 = load_trial(model_3d, motion_3d, loads_3d)
hs0_3, hs1_3 = right_gait_cycle(trial3)
inputs3 = muscle_inputs(trial3, spatial_inverse_dynamics(trial3), window=(hs0_3, hs1_3))
reserves3 = reserve_optimal_forces(read_force_set(reserves_3d, trial3.osim), inputs3["coordinates"])
pct3 = (inputs3["time"] - hs0_3) / (hs1_3 - hs0_3) * 100.0
runs3 = {(crit, passive): muscle_redundancy(inputs3, reserves3, criterion=crit, exponent=p, passive=passive)
         for crit, p in criteria.items() for passive in (False, True)}

peer = peer3 = None  # OpenSim's static optimization on the same files, when installed
if opensim_peer.available():
    _, peer, peer_wall = opensim_peer.run_static_optimization(model_file, motion_file, loads_file, reserves_file,
                                                              hs0, hs1, out_dir=scene.out_dir / "opensim")
    _, peer3, _ = opensim_peer.run_static_optimization(model_3d, motion_3d, loads_3d, reserves_3d, hs0_3, hs1_3,
                                                       out_dir=scene.out_dir / "opensim_gait2392")

# %%
# Tables
# ------
# Peak group forces, reserves and solver status per frame, timing; the same for gait2392.
def peaks_table(solutions, groups, pct, t, peer, other_half, by_group=False):
    """One row per criterion and group (``by_group``: per group and criterion, naming the muscles):
    the group's peak force over the cycle, and OpenSim's."""
    rows = []
    pairs = [(c, g) for g in groups for c in solutions] if by_group else [(c, g) for c in solutions for g in groups]
    for crit, gname in pairs:
        members = groups[gname]
        row = {"criterion": labels[crit], "group": gname} | ({"muscles": " + ".join(members)} if by_group else {})
        row |= cycle_peak(group_force(solutions[crit], members), pct, other_half=other_half)
        if peer is not None:
            yp = np.interp(t, peer["time"].to_numpy(), sum(peer[m] for m in members).to_numpy())
            row |= {"OpenSim peak [N]": float(yp.max()), "OpenSim at [% gait cycle]": float(pct[int(np.argmax(yp))])}
        rows.append(row)
    return pd.DataFrame(rows)

timing = {"frames": len(t), "muscle geometry [s]": inputs["wall_time_geometry"]}
for crit, d in sols.items():
    timing |= {f"static optimization, {crit} [s]": d.attrs["wall_time_solve"],
               f"per frame, {crit} [ms]": 1e3 * d.attrs["wall_time_solve"] / len(t)}
if peer is not None:
    timing |= {"OpenSim static optimization [s]": peer_wall, "OpenSim / mbsuite (sum a^2, geometry + solve) [-]":
               peer_wall / (inputs["wall_time_geometry"] + sols["activation"].attrs["wall_time_solve"])}
scene.table("group_peaks", peaks_table(sols, groups, pct, t, peer, other_half=True))
scene.table("reserves", reserve_summary(sols))
scene.table("frame_status", frame_status(sols, pct))
scene.table("timing", pd.DataFrame([timing]))
for crit, d in sols.items():
    scene.table(f"muscle_forces_{crit}", d.drop(columns=["message"], errors="ignore"))
if peer is not None:
    scene.table("opensim_comparison", pd.DataFrame([{
        "muscle": m, "criterion": "sum a^2 (both)",
        "rms difference [N]": float(np.sqrt(np.mean((sols["activation"][f"F_{m} [N]"].to_numpy() - yp) ** 2))),
        "OpenSim peak [N]": float(np.max(yp)), "mbsuite peak [N]": float(sols["activation"][f"F_{m} [N]"].max())}
        for m in muscles for yp in [np.interp(t, peer["time"].to_numpy(), peer[m].to_numpy())]]))
scene.table("gait2392_group_peaks", peaks_table({c: runs3[(c, False)] for c in criteria}, groups_3d, pct3,
                                                inputs3["time"], peer3, other_half=False, by_group=True))
scene.table("gait2392_status", status_summary(runs3))

# %%
# Figures
# -------
peer_pct = None if peer is None else (peer["time"].to_numpy() - hs0) / (hs1 - hs0) * 100.0
for gname, members in groups.items():
    scene.figure(f"{gname.replace(' ', '_')}_forces", plots.plot_muscle_group(
        pct, sols, labels, members, f"gait-muscle-forces — {gname} group, gait10dof18musc, subject01 walk; Thelen "
        "2003 muscles, rigid tendon,\nClarabel via cvxpy; reserves from gait10dof_Reserve_Actuators.xml",
        peer=peer, peer_pct=peer_pct))
scene.figure("activation_heat_map", plots.plot_activation_heat_map(
    pct, sols["stress"], muscles,
    "gait-muscle-forces — activations, sum (F/PCSA)^3 criterion (gait10dof18musc, subject01)"))
scene.figure("gait2392_groups", plots.plot_group_totals(
    pct3, {c: runs3[(c, False)] for c in criteria}, labels, groups_3d,
    "gait-muscle-forces — gait2392 (92 muscles, 3-D), subject01 walk; inverse dynamics in the model's "
    "coordinates,\npassive fibre force left out as OpenSim does", model="gait2392", peer=peer3,
    peer_pct=None if peer3 is None else (peer3["time"].to_numpy() - hs0_3) / (hs1_3 - hs0_3) * 100.0))

n_bad = {crit: int((d["status"] != "optimal").sum()) for crit, d in sols.items()}
infeasible = runs3[("activation", True)]
bad = infeasible["status"] != "optimal"
scene.note(
    f"Muscle forces of gait10dof18musc over the right gait cycle ({hs0:.3f}-{hs1:.3f} s, {len(t)} frames) of "
    f"OpenSim's subject01 walk: per frame, the joint moments of core's inverse dynamics (scene "
    f"gait-inverse-dynamics) shared by 18 Hill-type muscles (Thelen 2003 curves, rigid tendon, passive force "
    f"included; moment arms -dL/dq of the paths with their via, conditional and moving points) and the reserve "
    f"actuators of gait10dof_Reserve_Actuators.xml (optimal force 1 N m on each joint: expensive; the pelvis "
    f"residuals FX, FY (1 N, 2 N) and MZ (1 N m) on the pelvis coordinates tx, ty, tilt, so their columns are "
    f"in N, N and N m), activations in [0, 1]; one cvxpy problem with parameters per model, solved by "
    f"Clarabel (the cubic criterion's powers as exact second-order cones through cvxpy's power atom, the default; "
    f"Clarabel's native power cones with epigraph='power_cone'). Frames not 'optimal': "
    f"{', '.join(f'{k}: {v}' for k, v in n_bad.items())} (per-frame status table). The lumbar extension moment "
    f"and the pelvis residuals are carried by reserves alone (no muscle spans them in this model). "
    + ("OpenSim 4.6's static optimization (sum a^2, its Millard 2012 muscle curves, passive force left out, "
       "activation floor 0.01) is overlaid." if peer is not None else "OpenSim not installed: no overlay.")
    + f"\n\ngait2392 (92 muscles; inverse dynamics in its 23 coordinates by biomech.spatial_dynamics, which equals "
    f"OpenSim's ID tool to 2e-3 N m) over the same right gait cycle, the pelvis residual actuators of "
    f"gait2392_SO_weak_Residual_Actuators.xml on the pelvis coordinates, no other reserve. With the passive "
    f"fibre force left out (OpenSim's choice) every frame is solved (table gait2392_status). With it "
    f"included, {int(bad.sum())} of {len(bad)} frames are infeasible: with a rigid tendon the stretched knee "
    f"extensors' passive force in swing exceeds what the flexors can balance (largest residual "
    f"{float(infeasible[[c for c in infeasible.columns if c.startswith('max |R F')][0]].max()):.0f} N m); "
    f"those frames keep their least-deficit solution and their status."
    + "\n\nReferences: Crowninshield & Brand (1981), J. Biomech. 14:793-801; Thelen (2003), J. Biomech. Eng. "
      "125:70-77; Anderson & Pandy (2001), J. Biomech. 34:153-161; Silva & Ambrosio (2003).")
scene.done()
