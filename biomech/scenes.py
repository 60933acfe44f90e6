"""Biomechanics scenes for ``mbsuite run``.

* ``gait-inverse-dynamics`` — joint moments of hip, knee and ankle over the right gait cycle of
  OpenSim's subject01 walking trial on the gait10dof18musc model, from core's inverse dynamics
  of the Cartesian model driven by the measured joint angles (:mod:`biomech.inverse_dynamics`);
  side by side with OpenSim 4.6's inverse-dynamics tool when it is installed.

Each scene builds only what it needs: the inverse-dynamics scene reads no muscle and builds no
optimiser.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from core.errors import InputError
from core.paths import data_path

__all__ = ["biomech_scenes", "GAIT10DOF"]


def _trial_files():
    d = data_path("biomech", "opensim", "gait10dof18musc_subject01_walk")
    return dict(model=d / "subject01.osim", motion=d / "subject01_walk_IK.mot",
                loads=d / "subject01_walk_grf.xml", reserves=d / "gait10dof_Reserve_Actuators.xml")


GAIT10DOF = _trial_files


def _fig(nrows=1, ncols=1, size=(7, 4)):
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, layout="constrained")
    return fig, fig.subplots(nrows, ncols, squeeze=False)


def right_gait_cycle(trial):
    """(start, end) of the right gait cycle: two successive right heel strikes [s]."""
    from .inverse_dynamics import gait_events

    hs, _ = gait_events(trial.loads, "calcn_r")
    if len(hs) < 2:
        raise InputError(f"{trial.settings.get('external_loads', 'the trial')}: fewer than two right heel strikes "
                         f"(calcn_r's vertical ground reaction rises through 20 N only {len(hs)} times)")
    return float(hs[0]), float(hs[1])


def _run_inverse_dynamics(ctx):
    from core.scenes import SceneResult

    from . import opensim_peer
    from .inverse_dynamics import inverse_dynamics, load_trial

    f = _trial_files()
    trial = load_trial(f["model"], f["motion"], f["loads"])
    ours = inverse_dynamics(trial)
    hs0, hs1 = right_gait_cycle(trial)
    mass = trial.body_mass
    t = ours["time [s]"].to_numpy()
    cyc = (t >= hs0 - 1e-9) & (t <= hs1 + 1e-9)
    pct = (t[cyc] - hs0) / (hs1 - hs0) * 100.0
    peer = None
    if opensim_peer.available():
        peer, peer_wall = opensim_peer.run_inverse_dynamics(f["model"], f["motion"], f["loads"], t[0], t[-1],
                                                            out_dir=ctx.out_dir / "opensim")
        peer_time = peer["time"].to_numpy()
    # the second, smaller model: segment inertias from de Leva's table, the same joints and trial
    from .anthropometry import anthropometric_sagittal_model, moment_differences

    small_model = anthropometric_sagittal_model(trial.osim, table="deleva")
    small = inverse_dynamics(load_trial(small_model, f["motion"], f["loads"]))
    small_cmp = moment_differences(ours, small, window=(hs0, hs1)).reset_index()
    joints = [("hip_flexion_r", "hip flexion"), ("knee_angle_r", "knee (angle convention: flexion negative)"),
              ("ankle_angle_r", "ankle dorsiflexion")]
    fig, ax = _fig(3, 1, size=(7, 8))
    rows = []
    for k, (c, label) in enumerate(joints):
        y = ours[f"{c}_moment [N m]"].to_numpy()
        a = ax[k, 0]
        a.plot(pct, y[cyc] / mass, lw=1.8, label="mbsuite (Cartesian core, driving constraints)")
        ys = small[f"{c}_moment [N m]"].to_numpy()
        a.plot(pct, ys[cyc] / mass, ":", lw=1.4, label="mbsuite, planar model from de Leva's tables (7 segments)")
        row = {"coordinate": c}
        if peer is not None:
            yo = np.interp(t, peer_time, peer[f"{c}_moment"].to_numpy())
            a.plot(pct, yo[cyc] / mass, "--", lw=1.2, label=f"OpenSim {opensim_peer.version().split('-')[0]} ID tool")
            d = (y - yo)[cyc]
            row.update({"rms difference [N m]": float(np.sqrt(np.mean(d**2))),
                        "max difference [N m]": float(np.max(np.abs(d))),
                        "rms difference [% of peak]": float(100 * np.sqrt(np.mean(d**2)) / np.max(np.abs(yo[cyc])))})
        i_max, i_min = int(np.argmax(y[cyc])), int(np.argmin(y[cyc]))
        row.update({"max [N m/kg]": float(y[cyc][i_max] / mass), "at [% gait cycle]": float(pct[i_max]),
                    "min [N m/kg]": float(y[cyc][i_min] / mass), "at min [% gait cycle]": float(pct[i_min])})
        rows.append(row)
        a.axhline(0, c="k", lw=0.5)
        a.set(ylabel=f"{label}\nmoment [N m/kg]")
        a.grid(True, alpha=0.3)
    ax[0, 0].legend(fontsize=8)
    ax[2, 0].set(xlabel="right gait cycle [%] (heel strike to heel strike)")
    ax[0, 0].set_title(f"gait-inverse-dynamics — gait10dof18musc, subject01 walk ({mass:.1f} kg), right leg;\n"
                       f"coordinates low-passed at 6 Hz (3rd-order Butterworth, forward and backward)", fontsize=9)
    # residuals at the pelvis over the cycle
    res_rows = []
    for c, unit in (("pelvis_tx_force", "N"), ("pelvis_ty_force", "N"), ("pelvis_tilt_moment", "N m")):
        y = ours[f"{c} [{unit}]"].to_numpy()[cyc]
        r = {"residual": c, "unit": unit, "rms": float(np.sqrt(np.mean(y**2))), "max |.|": float(np.max(np.abs(y)))}
        if peer is not None:
            yo = np.interp(t, peer_time, peer[c].to_numpy())[cyc]
            r["rms OpenSim"] = float(np.sqrt(np.mean(yo**2)))
        res_rows.append(r)
    table = pd.DataFrame(rows)
    a = ours.attrs
    wall = a["wall_time_build"] + a["wall_time_kinematics"] + a["wall_time_inverse_dynamics"]
    timing = {"frames": int(a["n_frames"]), "mbsuite wall time [s]": wall,
              "of which kinematic analysis [s]": a["wall_time_kinematics"],
              "of which inverse dynamics [s]": a["wall_time_inverse_dynamics"]}
    if peer is not None:
        timing["OpenSim wall time [s]"] = peer_wall
        timing["mbsuite / OpenSim [-]"] = wall / peer_wall
    notes = (
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
        + "The second, smaller model (dotted; biomech.anthropometry) has the same joints, trial and coordinates, "
          "one foot segment, a pin knee fitted to the model's moving knee, a lumped head-arms-trunk segment and "
          "segment masses, centres of mass and radii of gyration from de Leva (1996) Table 4 scaled to the "
          "subject's 72.6 kg (table anthropometric_model_vs_gait10dof). "
        + ("OpenSim 4.6's inverse-dynamics tool on the same files is overlaid (dashed)."
           if peer is not None else "OpenSim is not installed: no overlay (pip install 'mbsuite[peers]').")
        + "\n\nReferences: Silva & Ambrosio (2003), Mech. Based Des. Struct. Mach. 31:381-411; Delp et al. "
          "(2007), IEEE TBME 54:1940-1950; Winter (2009), Biomechanics and Motor Control of Human Movement, ch. 5.")
    return SceneResult(tables={"joint_moments_summary": table, "pelvis_residuals": pd.DataFrame(res_rows),
                               "anthropometric_model_vs_gait10dof": small_cmp,
                               "timing": pd.DataFrame([timing]),
                               "joint_moments": ours,
                               "joint_reactions": ours.attrs["joint_reactions"]},
                       figures={"joint_moments": fig}, notes=notes)


#: the paper's muscle groups of the right leg in gait10dof18musc
GROUPS = {"hamstrings": ("hamstrings_r", "bifemsh_r"), "triceps surae": ("gastroc_r", "soleus_r")}
CRITERIA = (("stress", 3.0, "sum (F/PCSA)^3 (Crowninshield & Brand; the paper)"),
            ("activation", 2.0, "sum a^2 (OpenSim's static optimization)"))


def _run_muscle_forces(ctx):
    from core.scenes import SceneResult

    from . import opensim_peer
    from .inverse_dynamics import inverse_dynamics, load_trial
    from .muscle_forces import muscle_inputs, muscle_redundancy, reserve_optimal_forces
    from .osim import read_force_set

    f = _trial_files()
    trial = load_trial(f["model"], f["motion"], f["loads"])
    moments = inverse_dynamics(trial)
    hs0, hs1 = right_gait_cycle(trial)
    inputs = muscle_inputs(trial, moments, window=(hs0, hs1))
    reserves = reserve_optimal_forces(read_force_set(f["reserves"], trial.osim), inputs["coordinates"])
    t = inputs["time"]
    pct = (t - hs0) / (hs1 - hs0) * 100.0
    sols = {}
    for crit, p, _ in CRITERIA:
        sols[crit] = muscle_redundancy(inputs, reserves, criterion=crit, exponent=p)
    peer = None
    if opensim_peer.available():
        act, frc, peer_wall = opensim_peer.run_static_optimization(
            f["model"], f["motion"], f["loads"], f["reserves"], hs0, hs1, out_dir=ctx.out_dir / "opensim")
        peer = (act, frc)
    # group figures
    figs = {}
    for gname, members in GROUPS.items():
        fig, ax = _fig(len(members) + 1, 1, size=(7, 2.6 * (len(members) + 1)))
        for k, mname in enumerate(list(members) + ["group"]):
            a = ax[k, 0]
            for (crit, p, label), ls in zip(CRITERIA, ("-", "-.")):
                df = sols[crit]
                y = (sum(df[f"F_{m} [N]"] for m in members) if mname == "group" else df[f"F_{mname} [N]"]).to_numpy()
                a.plot(pct, y, ls, lw=1.6, label=f"mbsuite, {label}")
            if peer is not None:
                tp = peer[1]["time"].to_numpy()
                yp = (sum(peer[1][m] for m in members) if mname == "group" else peer[1][mname]).to_numpy()
                a.plot((tp - hs0) / (hs1 - hs0) * 100.0, yp, "--", lw=1.1, c="k", label="OpenSim 4.6 static optimization")
            a.set(ylabel=f"{'+'.join(members) if mname == 'group' else mname}\nforce [N]")
            a.grid(True, alpha=0.3)
        ax[0, 0].legend(fontsize=7)
        ax[-1, 0].set(xlabel="right gait cycle [%]")
        ax[0, 0].set_title(f"gait-muscle-forces — {gname} group, gait10dof18musc, subject01 walk; Thelen 2003 muscles, "
                           f"rigid tendon,\nClarabel via cvxpy; reserves from gait10dof_Reserve_Actuators.xml", fontsize=9)
        figs[f"{gname.replace(' ', '_')}_forces"] = fig
    # heat map of activations (paper criterion)
    df = sols["stress"]
    names = inputs["muscles"]
    A = np.array([df[f"a_{m} [-]"].to_numpy() for m in names])
    fig, ax = _fig(size=(8, 5))
    im = ax[0, 0].imshow(A, aspect="auto", origin="upper", cmap="viridis", vmin=0.0, vmax=max(1e-3, float(A.max())),
                         extent=(pct[0], pct[-1], len(names) - 0.5, -0.5))
    ax[0, 0].set_yticks(range(len(names)), names, fontsize=7)
    ax[0, 0].set(xlabel="right gait cycle [%]",
                 title="gait-muscle-forces — activations, sum (F/PCSA)^3 criterion (gait10dof18musc, subject01)")
    ax[0, 0].title.set_fontsize(9)
    fig.colorbar(im, ax=ax[0, 0], label="activation [-]")
    figs["activation_heat_map"] = fig
    # tables
    peaks = []
    for crit, p, label in CRITERIA:
        d = sols[crit]
        for gname, members in GROUPS.items():
            y = sum(d[f"F_{m} [N]"] for m in members).to_numpy()
            i = int(np.argmax(y))
            row = {"criterion": label, "group": gname, "peak force [N]": float(y[i]), "at [% gait cycle]": float(pct[i])}
            # second peak of the triceps surae / hamstrings in the other half of the cycle
            half = pct < 50.0 if pct[i] >= 50.0 else pct >= 50.0
            j = int(np.argmax(np.where(half, y, -np.inf)))
            row.update({"other-half peak [N]": float(y[j]), "at, other half [% gait cycle]": float(pct[j])})
            if peer is not None:
                tp = peer[1]["time"].to_numpy()
                yp = np.interp(t, tp, sum(peer[1][m] for m in members).to_numpy())
                k = int(np.argmax(yp))
                row.update({"OpenSim peak [N]": float(yp[k]), "OpenSim at [% gait cycle]": float(pct[k])})
            peaks.append(row)
    status_rows = []
    for crit, p, label in CRITERIA:
        d = sols[crit]
        for i in range(len(d)):
            status_rows.append({"criterion": crit, "time [s]": float(d["time [s]"].iloc[i]),
                                "gait cycle [%]": float(pct[i]), "status": d["status"].iloc[i],
                                "max |R F + r - tau|": float(d.iloc[i][[c for c in d.columns if c.startswith("max |R F")][0]]),
                                "solve time [ms]": float(d["solve time [s]"].iloc[i] * 1e3)})
    res_rows = []
    for crit, p, label in CRITERIA:
        d = sols[crit]
        for c in [c for c in d.columns if c.startswith("reserve_")]:
            res_rows.append({"criterion": crit, "reserve": c, "unit": c[c.index("[") + 1:-1],
                             "max |.|": float(d[c].abs().max()),
                             "rms": float(np.sqrt(np.mean(d[c] ** 2)))})
    cmp_rows = []
    if peer is not None:
        tp = peer[1]["time"].to_numpy()
        for m in names:
            yp = np.interp(t, tp, peer[1][m].to_numpy())
            for crit in ("activation",):
                y = sols[crit][f"F_{m} [N]"].to_numpy()
                cmp_rows.append({"muscle": m, "criterion": "sum a^2 (both)",
                                 "rms difference [N]": float(np.sqrt(np.mean((y - yp) ** 2))),
                                 "OpenSim peak [N]": float(np.max(yp)), "mbsuite peak [N]": float(np.max(y))})
    timing = {"frames": len(t), "muscle geometry [s]": inputs["wall_time_geometry"]}
    for crit, p, label in CRITERIA:
        timing[f"static optimization, {crit} [s]"] = sols[crit].attrs["wall_time_solve"]
        timing[f"per frame, {crit} [ms]"] = 1e3 * sols[crit].attrs["wall_time_solve"] / len(t)
    if peer is not None:
        timing["OpenSim static optimization [s]"] = peer_wall
        timing["OpenSim / mbsuite (sum a^2, geometry + solve) [-]"] = peer_wall / (
            inputs["wall_time_geometry"] + sols["activation"].attrs["wall_time_solve"])
    n_bad = {crit: int((sols[crit]["status"] != "optimal").sum()) for crit, _, _ in CRITERIA}
    notes = (
        f"Muscle forces of gait10dof18musc over the right gait cycle ({hs0:.3f}-{hs1:.3f} s, {len(t)} frames) of "
        f"OpenSim's subject01 walk: per frame, the joint moments of core's inverse dynamics (scene "
        f"gait-inverse-dynamics) shared by 18 Hill-type muscles (Thelen 2003 curves, rigid tendon, passive force "
        f"included; moment arms -dL/dq of the paths with their via, conditional and moving points) and the reserve "
        f"actuators of gait10dof_Reserve_Actuators.xml (optimal force 1 N m on each joint: expensive; the pelvis "
        f"residuals FX, FY (1 N, 2 N) and MZ (1 N m) on the pelvis coordinates tx, ty, tilt, so their columns are "
        f"in N, N and N m), activations in [0, 1]; one cvxpy problem with parameters per model, solved by "
        f"Clarabel (the cubic criterion's powers as exact second-order cones through cvxpy's power atom, the default; Clarabel's native power cones with epigraph='power_cone'). Frames not 'optimal': "
        f"{', '.join(f'{k}: {v}' for k, v in n_bad.items())} (per-frame status table). The lumbar extension moment "
        f"and the pelvis residuals are carried by reserves alone (no muscle spans them in this model). "
        + ("OpenSim 4.6's static optimization (sum a^2, its Millard 2012 muscle curves, passive force left out, "
           "activation floor 0.01) is overlaid." if peer is not None else "OpenSim not installed: no overlay.")
        + "\n\nReferences: Crowninshield & Brand (1981), J. Biomech. 14:793-801; Thelen (2003), J. Biomech. Eng. "
          "125:70-77; Anderson & Pandy (2001), J. Biomech. 34:153-161; Silva & Ambrosio (2003).")
    tables = {"group_peaks": pd.DataFrame(peaks), "reserves": pd.DataFrame(res_rows),
              "frame_status": pd.DataFrame(status_rows), "timing": pd.DataFrame([timing]),
              "muscle_forces_stress": sols["stress"].drop(columns=["message"], errors="ignore"),
              "muscle_forces_activation": sols["activation"].drop(columns=["message"], errors="ignore")}
    if cmp_rows:
        tables["opensim_comparison"] = pd.DataFrame(cmp_rows)
    t3d, f3d, n3d = _gait2392_static_optimization(ctx, peer is not None)
    tables.update(t3d)
    figs.update(f3d)
    notes = notes.replace("\n\nReferences:", "\n\n" + n3d + "\n\nReferences:")
    return SceneResult(tables=tables, figures=figs, notes=notes)


#: the same groups in gait2392 (43 muscles per leg)
GROUPS_2392 = {"hamstrings": ("semimem_r", "semiten_r", "bifemlh_r", "bifemsh_r"),
               "triceps surae": ("med_gas_r", "lat_gas_r", "soleus_r")}


def _gait2392_files():
    d = data_path("biomech", "opensim", "gait2392_subject01_walk")
    return dict(model=d / "subject01_simbody_adjusted.osim", motion=d / "subject01_walk1_ik.mot",
                loads=d / "subject01_walk1_grf.xml", reserves=d / "gait2392_SO_weak_Residual_Actuators.xml")


def _gait2392_static_optimization(ctx, with_peer):
    """The 3-D gait2392 model (92 muscles) through the same pipeline: inverse dynamics in its
    coordinates (biomech.spatial_dynamics), muscle geometry, static optimisation."""
    from . import opensim_peer
    from .inverse_dynamics import load_trial
    from .muscle_forces import muscle_inputs, muscle_redundancy, reserve_optimal_forces
    from .osim import read_force_set
    from .spatial_dynamics import spatial_inverse_dynamics

    g = _gait2392_files()
    trial = load_trial(g["model"], g["motion"], g["loads"])
    moments = spatial_inverse_dynamics(trial)
    hs0, hs1 = right_gait_cycle(trial)
    inputs = muscle_inputs(trial, moments, window=(hs0, hs1))
    reserves = reserve_optimal_forces(read_force_set(g["reserves"], trial.osim), inputs["coordinates"])
    t = inputs["time"]
    pct = (t - hs0) / (hs1 - hs0) * 100.0
    runs = {}
    for crit, p, label in CRITERIA:
        for passive in (False, True):
            runs[(crit, passive)] = muscle_redundancy(inputs, reserves, criterion=crit, exponent=p, passive=passive)
    peer = None
    if with_peer:
        act, frc, wall = opensim_peer.run_static_optimization(g["model"], g["motion"], g["loads"], g["reserves"],
                                                              hs0, hs1, out_dir=ctx.out_dir / "opensim_gait2392")
        peer = frc
    fig, ax = _fig(2, 1, size=(7, 6))
    rows, status = [], []
    for k, (gname, members) in enumerate(GROUPS_2392.items()):
        a = ax[k, 0]
        for (crit, p, label), ls in zip(CRITERIA, ("-", "-.")):
            d = runs[(crit, False)]
            y = sum(d[f"F_{m} [N]"] for m in members).to_numpy()
            a.plot(pct, y, ls, lw=1.6, label=f"mbsuite, {label}")
            i = int(np.argmax(y))
            row = {"criterion": label, "group": gname, "muscles": " + ".join(members),
                   "peak force [N]": float(y[i]), "at [% gait cycle]": float(pct[i])}
            if peer is not None:
                yp = np.interp(t, peer["time"].to_numpy(), sum(peer[m] for m in members).to_numpy())
                kk = int(np.argmax(yp))
                row.update({"OpenSim peak [N]": float(yp[kk]), "OpenSim at [% gait cycle]": float(pct[kk])})
            rows.append(row)
        if peer is not None:
            tp = peer["time"].to_numpy()
            a.plot((tp - hs0) / (hs1 - hs0) * 100.0, sum(peer[m] for m in members).to_numpy(), "--", c="k", lw=1.1,
                   label="OpenSim 4.6 static optimization")
        a.set(ylabel=f"{gname} (gait2392)\nforce [N]")
        a.grid(True, alpha=0.3)
    ax[0, 0].legend(fontsize=7)
    ax[1, 0].set(xlabel="right gait cycle [%]")
    ax[0, 0].set_title("gait-muscle-forces — gait2392 (92 muscles, 3-D), subject01 walk; inverse dynamics in the "
                       "model's coordinates,\npassive fibre force left out as OpenSim does", fontsize=9)
    for (crit, passive), d in runs.items():
        counts = d["status"].value_counts().to_dict()
        res_col = [c for c in d.columns if c.startswith("max |R F")][0]
        status.append({"criterion": crit, "passive force": "included" if passive else "left out (as OpenSim)",
                       "frames": len(d), **{f"frames {k}": v for k, v in counts.items()},
                       f"largest residual {res_col[res_col.index('['):]}": float(d[res_col].max()),
                       "per frame [ms]": 1e3 * d.attrs["wall_time_solve"] / len(d)})
    infeasible = runs[("activation", True)]
    bad = infeasible["status"] != "optimal"
    note = (f"gait2392 (92 muscles; inverse dynamics in its 23 coordinates by biomech.spatial_dynamics, which equals "
            f"OpenSim's ID tool to 2e-3 N m) over the same right gait cycle, the pelvis residual actuators of "
            f"gait2392_SO_weak_Residual_Actuators.xml on the pelvis coordinates, no other reserve. With the passive "
            f"fibre force left out (OpenSim's choice) every frame is solved (table gait2392_status). With it "
            f"included, {int(bad.sum())} of {len(bad)} frames are infeasible: with a rigid tendon the stretched knee "
            f"extensors' passive force in swing exceeds what the flexors can balance (largest residual "
            f"{float(infeasible[[c for c in infeasible.columns if c.startswith('max |R F')][0]].max()):.0f} N m); "
            f"those frames keep their least-deficit solution and their status.")
    st = pd.DataFrame(status)
    fc = [c for c in st.columns if c.startswith("frames ")]
    st[fc] = st[fc].fillna(0).astype(int)
    return ({"gait2392_group_peaks": pd.DataFrame(rows), "gait2392_status": st},
            {"gait2392_groups": fig}, note)


def biomech_scenes():
    """The biomechanics scenes (entry point ``mbsuite.scenes: biomech``)."""
    from core.scenes import Scene

    return [
        Scene("gait-inverse-dynamics",
              "Gait inverse dynamics: hip, knee and ankle moments over the gait cycle (gait10dof18musc)",
              "Joint moments from measured joint angles as driving constraints on the Cartesian core "
              "(Silva & Ambrosio 2003), subject01 walking trial, side by side with OpenSim's ID tool.",
              _run_inverse_dynamics),
        Scene("gait-muscle-forces",
              "Gait muscle forces: hamstrings and triceps surae over the gait cycle, two criteria",
              "Static optimisation of the 18 muscles of gait10dof18musc per frame (cvxpy + Clarabel): the "
              "paper's sum of cubed muscle stresses and OpenSim's sum of squared activations, reserves, "
              "per-frame status; side by side with OpenSim's static optimization.", _run_muscle_forces),
    ]
