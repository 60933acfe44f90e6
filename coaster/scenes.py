r"""Roller-coaster scenes for ``mbsuite run`` (entry point ``mbsuite.scenes: coaster``).

* ``coaster-analytic`` — bodies on analytic tracks against closed forms
  (:mod:`coaster.analytic_scene`).
* ``coaster-circuit`` — the three-car train of Pombo & Ambrósio (:mod:`coaster.train`) over the
  shared 4.9 km circuit: chain lift on the ``Lift`` section, free running, a booster on the
  ``Launch`` section (the data's name; without it no train released from the lift reaches the
  brake hill, 9.5 m higher), brakes over the crest of the ``Brake`` section's hill to its end; speed, wheel forces and rider load
  factors (:mod:`coaster.rider`) along the track, a 3-D figure of the track coloured by the
  vertical load factor, peaks and time above the limits per section (both from the run's dense
  solution, independent of the output step), the energy drift of the
  free-running section, and a second run with rolling resistance and drag whose outcome (it
  rolls back at the Turnaround crest, 2.3 m above the lift's end) is reported, not hidden.

Run settings of the circuit (all stated in the scene's notes): compiled DOP853 with coordinate
projection, rtol = atol = 1e-8, output every 0.25 s (0.5 s with ``--fast``).
"""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np
import pandas as pd

__all__ = ["coaster_scenes", "circuit_scene", "run_coaster_circuit", "CIRCUIT_SETTINGS"]

#: Operating settings of the circuit scene (SI units).
CIRCUIT_SETTINGS = dict(
    chain_speed=8.0,          # m/s on the Lift section
    booster_speed=22.0,       # m/s target of the Launch section (linear synchronous motors)
    booster_force=40.0e3,     # N
    brake_speed=6.0,          # m/s target of the Brake section
    brake_force=30.0e3,       # N
    gain=2.0e4,               # N s/m of both speed controls
    rolling=0.0025,           # c_rr of the dissipative run
    drag_area=1.2,            # c_d A (m²) of the dissipative run
    rtol=1e-8,
    atol=1e-8,
    method="jit-dop853-projection",
)


def _sections_at(sec, L, period):
    x = np.mod(L, period)
    out = np.empty(len(x), dtype=object)
    for _, row in sec.iterrows():
        out[(x >= row["L_start [m]"]) & (x < row["L_end [m]"])] = row["section"]
    return out


def _circuit_runs(fast):
    from .train import ChainLift, SpeedSection, Train, circuit_frame, circuit_sections, run_train

    S = CIRCUIT_SETTINGS
    fr, data, cl = circuit_frame()
    sec = circuit_sections(data, cl)
    get = {r["section"]: r for _, r in sec.iterrows() if r["section"] != "Station"}
    lift, launch, brake = get["Lift"], get["Launch"], get["Brake"]
    tr = Train(fr, name="three-car train")
    # brakes from 30 m before the crest of the brake hill to the section's end (braking at the
    # foot of the hill would stop the train on it)
    Lb = np.linspace(brake["L_start [m]"], brake["L_end [m]"], 400)
    L_crest = float(Lb[np.argmax(cl.derivatives(Lb)[0][:, 2])])
    sections = [SpeedSection("booster", launch["L_start [m]"], launch["L_end [m]"], S["booster_speed"],
                             S["booster_force"], gain=S["gain"], mode="booster", ramp=5.0),
                SpeedSection("brakes", L_crest - 30.0, brake["L_end [m]"], S["brake_speed"], S["brake_force"],
                             gain=S["gain"], mode="brake", ramp=5.0)]
    chain = ChainLift(lift["L_start [m]"], lift["L_end [m]"], S["chain_speed"])
    L_stop = cl.length + 0.5 * lift["L_start [m]"]       # back in the station
    dt = 0.5 if fast else 0.25
    kw = dict(method=S["method"], rtol=S["rtol"], atol=S["atol"], output_step=dt, chunk=40.0, sections=sec)
    # warm-up: the first run of a process compiles (or loads) numba's kernels; the real-time
    # factors below are of the runs after it, the warm-up's wall time is reported on its own
    w0 = time.perf_counter()
    warm = ChainLift(chain.L_start, chain.L_start + 2.0, chain.speed)
    run_train(tr, warm.L_start, warm.speed, warm.L_end + 2.0, chain=warm,
              forces=tr.forces(rolling=S["rolling"], drag_area=S["drag_area"], sections=sections),
              **{**kw, "output_step": 0.5})
    warmup = time.perf_counter() - w0
    main = run_train(tr, chain.L_start, chain.speed, L_stop, chain=chain, forces=tr.forces(sections=sections), **kw)
    lossy = run_train(tr, chain.L_start, chain.speed, L_stop, chain=chain,
                      forces=tr.forces(rolling=S["rolling"], drag_area=S["drag_area"], sections=sections), **kw)
    return tr, fr, cl, sec, main, lossy, warmup, (chain, sections, L_stop, kw)


def _bank_study(fr, cl, main, setup):
    """The circuit's bank against its turns (coaster.track.check_bank, the warning recorded) and
    a run of the same ride on the bank designed from the main run's speed (design_bank)."""
    import warnings

    from .frames import RotationMinimisingFrame
    from .inputs import OutwardBankWarning
    from .track import check_bank, design_bank
    from .train import Train, run_train

    chain, sections, L_stop, kw = setup
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", OutwardBankWarning)
        chk = check_bank(fr, main)
    warned = [str(w.message) for w in caught if issubclass(w.category, OutwardBankWarning)]
    bank = design_bank(cl, main)
    fr2 = RotationMinimisingFrame(cl, bank=bank, bank_reference="vertical", max_step=2.0,
                                  name="RMF of the circuit with the designed bank")
    tr2 = Train(fr2, name="three-car train, designed bank")
    run2 = run_train(tr2, chain.L_start, chain.speed, L_stop, chain=chain, forces=tr2.forces(sections=sections), **kw)
    chk2 = check_bank(fr2, main, warn=False)
    return chk, chk2, warned, bank, run2


def _rider(run, car="car1"):
    """coaster.rider.rider_loads over every phase of a TrainRun (one row per output time)."""
    from .rider import rider_loads

    parts = []
    for k, model in enumerate(run.models):
        sel = np.flatnonzero(run.phase == k)
        if not len(sel):
            continue
        res = SimpleNamespace(t=run.t[sel], q=run.q[sel], v=run.v[sel], meta=run.meta, status=run.status)
        parts.append(rider_loads(model, res, car, run.train.p.rider_point, coordinate="L1"))
    return pd.concat(parts, ignore_index=True)


def _energy_drift(run, sec):
    """max|E − E0| / T_peak over the free running before the booster (no dissipation there)."""
    launch = float(sec.loc[sec["section"] == "Launch", "L_start [m]"].iloc[0])
    E = run.energy()
    sel = (run.phase == len(run.models) - 1) & (run.L[:, 0] < launch)
    Me = run.train.p.total_mass + run.train.p.n_wheelsets * run.train.p.wheel_spin_mass
    T_peak = 0.5 * Me * float(np.max(run.Ldot[sel, 0]) ** 2)
    Es = E[sel]
    return float(np.max(np.abs(Es - Es[0])) / T_peak), float(run.t[sel][0]), float(run.t[sel][-1]), T_peak


def _peaks_table(loads, wf_peaks, labels, limits_table, peaks):
    """Per section: duration, peak load factors and wheel forces (independent of the output step:
    coaster.train.rider_peaks, wheel_force_peaks)."""
    rows = []
    t = loads["t [s]"].to_numpy()
    pk = peaks.set_index("section")
    wk = wf_peaks.set_index("section")
    for name in dict.fromkeys(labels):
        m = labels == name
        dur = float(np.sum(np.diff(t)[m[:-1]]))
        p, w = pk.loc[name], wk.loc[name]
        rows.append({
            "section": name, "time in section [s]": dur,
            "n_z max [g]": p["n_z max [g]"], "n_z min [g]": p["n_z min [g]"],
            "|n_y| max [g]": p["|n_y| max [g]"], "n_x max [g]": p["n_x max [g]"],
            "n_x min [g]": p["n_x min [g]"],
            "|jerk_z| max [g/s]": loads["jerk_z [g/s]"][m].abs().max(),
            "F_b max [kN]": w["F_b max [kN]"], "F_b min [kN]": w["F_b min [kN]"], "|F_n| max [kN]": w["|F_n| max [kN]"],
            "limits exceeded": ", ".join(
                f"{r['axis']} {r['level [g]']:+g} g" for _, r in limits_table[(limits_table["section"] == name)
                                                                              & (limits_table["verdict"] == "exceeds")]
                .iterrows()) or "none",
        })
    return pd.DataFrame(rows)


def _figures(tr, fr, cl, sec, main, loads, wf):
    from matplotlib.collections import LineCollection  # noqa: F401  (2-D fallback not used)
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    figs = {}
    run_label = f"{main.meta['method']}, rtol {main.meta['rtol']:g}"
    L = main.L[:, 0]
    tab = main.table()
    # speed and height
    fig = Figure(figsize=(10, 6.5))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    ax1.plot(L, tab["speed [m/s]"], color="C0")
    ax1.set_ylabel("speed along the track [m/s]")
    ax2.plot(L, tab["z [m]"], color="C2")
    ax2.set_ylabel("height of ws1 [m]")
    ax2.set_xlabel("arc length of the lead wheelset L1 [m]")
    for ax in (ax1, ax2):
        for _, r in sec.iterrows():
            ax.axvspan(r["L_start [m]"], r["L_end [m]"], alpha=0.06 if r.name % 2 else 0.0, color="k")
        ax.grid(alpha=0.3)
    for _, r in sec.iterrows():
        ax1.text(0.5 * (r["L_start [m]"] + r["L_end [m]"]), ax1.get_ylim()[1] * 0.95, r["section"], ha="center",
                 va="top", fontsize=7)
    ax1.set_title(f"coaster-circuit: three-car train, chain lift, free running, booster, brakes ({run_label})")
    figs["speed"] = fig
    # wheel forces
    fig = Figure(figsize=(10, 6.5))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    for ws in ("ws1", "ws6"):
        ax1.plot(wf[f"{ws} L [m]"], wf[f"{ws} F_b [N]"] / 1e3, label=ws)
        ax2.plot(wf[f"{ws} L [m]"], wf[f"{ws} F_n [N]"] / 1e3, label=ws)
    ax1.set_ylabel("F_b, along the track's up axis [kN]")
    ax2.set_ylabel("F_n, lateral [kN]")
    ax2.set_xlabel("arc length of the wheelset [m]")
    for ax in (ax1, ax2):
        ax.legend()
        ax.grid(alpha=0.3)
    ax1.set_title(f"coaster-circuit: wheel forces from the path joints' multipliers, track frame ({run_label})")
    figs["wheel_forces"] = fig
    # load factors
    fig = Figure(figsize=(10, 5))
    ax = fig.subplots()
    for c in ("n_x [g]", "n_y [g]", "n_z [g]"):
        ax.plot(loads["L [m]"], loads[c], label=c)
    ax.set_xlabel("arc length L1 [m]")
    ax.set_ylabel("load factor at the rider of car 1 [g]")
    ax.set_title(f"coaster-circuit: rider load factors in car axes ({run_label})")
    ax.grid(alpha=0.3)
    ax.legend()
    figs["load_factors"] = fig
    # 3-D track coloured by n_z
    fig = Figure(figsize=(10, 8))
    ax = fig.add_subplot(projection="3d")
    Lq = np.mod(loads["L [m]"].to_numpy(), cl.length)
    P = fr.evaluate(Lq).position
    seg = np.stack([P[:-1], P[1:]], axis=1)
    nz = loads["n_z [g]"].to_numpy()
    lc = Line3DCollection(seg, cmap="coolwarm", linewidths=3)
    lc.set_array(0.5 * (nz[:-1] + nz[1:]))
    ax.add_collection(lc)
    for a, lo, hi in ((ax.set_xlim, P[:, 0].min(), P[:, 0].max()), (ax.set_ylim, P[:, 1].min(), P[:, 1].max()),
                      (ax.set_zlim, P[:, 2].min(), P[:, 2].max())):
        a(lo, hi)
    ax.set_box_aspect((np.ptp(P[:, 0]), np.ptp(P[:, 1]), 5 * np.ptp(P[:, 2])))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m] (×5)")
    fig.colorbar(lc, ax=ax, shrink=0.6, pad=0.12, label="vertical load factor n_z at the rider of car 1 [g]")
    ax.set_title(f"coaster-circuit: track coloured by the rider's vertical load factor ({run_label})")
    figs["circuit_3d"] = fig
    return figs


def _frame_quality(fr, cl, step=1.0):
    """Frame quality along the circuit (coaster.frames.frame_quality every ``step`` m): the
    samples with units in the column names, a summary and a figure."""
    from matplotlib.figure import Figure

    from .frames import frame_quality

    q = frame_quality(fr, cl, L=np.arange(0.0, cl.length, step))
    q = q.rename(columns={"L_m": "L [m]", "orthonormality": "max |R^T R - I| [-]", "tangent_error": "|t - g'| [-]",
                          "position_error_m": "|r - g| [m]", "R_jump": "max |R_i - R_i-1| [-]",
                          "rotation_step_rad": "rotation step [rad]", "expected_step_rad": "|omega| dL [rad]",
                          "curvature_1_m": "curvature [1/m]", "torsion_1_m": "torsion [1/m]",
                          "twist_1_m": "twist omega.t [1/m]"})
    ratio = (q["rotation step [rad]"] / q["|omega| dL [rad]"]).replace([np.inf, -np.inf], np.nan)
    end = fr.evaluate(np.array([0.0, cl.length]))
    closure = float(np.max(np.abs(end.R[0] - end.R[1])))
    summary = pd.DataFrame([{
        "samples [-]": len(q), "step [m]": step,
        "max |R^T R - I| [-]": q["max |R^T R - I| [-]"].max(), "max |t - g'| [-]": q["|t - g'| [-]"].max(),
        "max |r - g| [m]": q["|r - g| [m]"].max(),
        "max rotation step [rad]": q["rotation step [rad]"].max(),
        "max rotation step / (|omega| dL) [-]": ratio.max(),
        "frame closure max |R(length) - R(0)| [-]": closure,
        "max curvature [1/m]": q["curvature [1/m]"].max(),
        "max |torsion| [1/m]": q["torsion [1/m]"].abs().max()}])
    fig = Figure(figsize=(10, 8))
    ax = fig.subplots(4, 1, sharex=True)
    L = q["L [m]"]
    ax[0].plot(L, q["curvature [1/m]"], lw=0.8)
    ax[0].set_ylabel("curvature [1/m]")
    ax[1].plot(L, q["torsion [1/m]"], lw=0.8)
    lim = float(np.nanpercentile(np.abs(q["torsion [1/m]"]), 99)) * 1.5
    ax[1].set_ylim(-lim, lim)
    ax[1].set_ylabel("torsion [1/m]\n(99th pct. range)")
    ax[2].semilogy(L, np.maximum(q["max |R^T R - I| [-]"], 1e-17), lw=0.8)
    ax[2].set_ylabel("max |R^T R - I| [-]")
    ax[3].plot(L, q["rotation step [rad]"], lw=0.8, label="rotation between samples")
    ax[3].plot(L, q["|omega| dL [rad]"], lw=0.8, ls="--", label="|omega| dL")
    ax[3].set_ylabel("rotation step [rad]")
    ax[3].set_xlabel("arc length L [m]")
    ax[3].legend(fontsize=8)
    ax[0].set_title("coaster-circuit: rotation-minimising frame with bank along the circuit "
                    f"(quintic spline, samples every {step:g} m; closure {closure:.1e})")
    fig.tight_layout()
    return q, summary, fig


def run_coaster_circuit(ctx):
    """The ``coaster-circuit`` scene (module docstring)."""
    from core.scenes import SceneResult

    import warnings

    from core.signals import GridResolutionWarning

    from .rider import read_acceleration_limits
    from .train import chain_force, rider_peaks, time_above_limits_dense, wheel_force_peaks, wheel_forces

    fast = bool(getattr(ctx, "fast", False))
    tr, fr, cl, sec, main, lossy, warmup, setup = _circuit_runs(fast)
    wf = wheel_forces(main)
    loads = _rider(main, "car1")
    labels = _sections_at(sec, main.L[:, 0], cl.length)
    loads.insert(2, "section", labels)
    limits = read_acceleration_limits()
    rpk = rider_peaks(main, "car1", sections=sec)
    with warnings.catch_warnings(record=True) as caught:  # exceedances between two outputs: said in the notes
        warnings.simplefilter("always", GridResolutionWarning)
        above = time_above_limits_dense(main, limits, sec, car="car1", peaks=rpk)
    grid_warned = [str(w.message) for w in caught if issubclass(w.category, GridResolutionWarning)]
    peaks = _peaks_table(loads, wheel_force_peaks(main, sec), labels, above, rpk)
    chk, chk2, warned, bank, run2 = _bank_study(fr, cl, main, setup)
    loads2 = _rider(run2, "car1")
    bank_rows = []
    for name, c, ld, r in (("data (file's rolls)", chk, loads, main), ("designed from the main run's speed", chk2,
                                                                       loads2, run2)):
        ny = ld["n_y [g]"].to_numpy()
        pk = rider_peaks(r, "car1").iloc[0]  # over the whole run, independent of the output step
        bank_rows.append({"bank": name, "run status": r.status, "outward share of v2k [-]": c.outward_share,
                          "turns banked outward": f"{c.n_outward} of {c.n_turns}",
                          "quasi-static |n_y| RMS at the track [g]": c.lateral_rms_banked,
                          "rider |n_y| RMS [g]": float(np.sqrt(np.mean(ny**2))),
                          "rider |n_y| max [g]": pk["|n_y| max [g]"],
                          "rider n_z min [g]": pk["n_z min [g]"], "rider n_z max [g]": pk["n_z max [g]"]})
    bank_table = pd.DataFrame(bank_rows)
    bank_turns = chk.turns
    drift, t_a, t_b, T_peak = _energy_drift(main, sec)
    tab = main.table()
    tab.insert(2, "section", labels)
    runs = pd.DataFrame([{
        "run": name, "status": r.status, "message": r.message, "simulated [s]": float(r.t[-1]),
        "L1 reached [m]": float(np.max(r.L[:, 0])), "integration wall [s]": r.wall_time,
        "real-time factor": r.real_time_factor, "method": r.meta["method"], "rtol": r.meta["rtol"],
        "compilation + warm-up wall [s]": warmup if name.startswith("no") else 0.0,
    } for name, r in (("no rolling resistance or drag", main), ("rolling resistance + drag", lossy))])
    energy = pd.DataFrame([{"section": "free running, lift end to booster", "t from [s]": t_a, "t to [s]": t_b,
                            "max|E - E0| / T_peak": drift, "T_peak [J]": T_peak}])
    rank = None
    from .train import rank_table

    rank = rank_table(tr, np.linspace(0.0, cl.length, 50 if fast else 200, endpoint=False))
    rank_summary = pd.DataFrame([{"positions": len(rank), "rows": int(rank["rows"].iloc[0]),
                                  "rank min": int(rank["rank"].min()), "rank max": int(rank["rank"].max()),
                                  "dof": ", ".join(map(str, sorted(set(rank["dof"])))),
                                  "sigma_min/sigma_max min": float(rank["sigma_min/sigma_max"].min())}])
    every = max(1, int(round(1.0 / main.meta["output_step"])))
    figs = _figures(tr, fr, cl, sec, main, loads, wf)
    fq, fq_summary, figs["frame_quality"] = _frame_quality(fr, cl, step=5.0 if fast else 1.0)
    notes = (
        f"Train: {tr.p.n_cars} cars, {tr.p.n_cars - 1} bars, {tr.p.n_wheelsets} wheelsets (11 bodies, 72 coordinates, "
        f"71 constraint rows, 1 DOF; total mass {tr.p.total_mass:.0f} kg). Chain lift on the Lift section at "
        f"{CIRCUIT_SETTINGS['chain_speed']} m/s (it descends 10.7 m: the chain holds the train back, see "
        f"chain_force), booster on Launch to {CIRCUIT_SETTINGS['booster_speed']} m/s, brakes on Brake to "
        f"{CIRCUIT_SETTINGS['brake_speed']} m/s. Main run: {main.status} ({main.message}); simulated "
        f"{main.t[-1]:.1f} s in {main.wall_time:.1f} s of integration (real-time factor "
        f"{main.real_time_factor:.1f}, after a warm-up run that compiled the kernels in {warmup:.1f} s). "
        f"Peak load factors and wheel forces per section from the outputs, the section boundaries and re-integrated "
        f"states around each extreme (coaster.train.rider_peaks, wheel_force_peaks: independent of the output step). "
        f"Energy drift over the free-running section without dissipation: "
        f"{drift:.2e} of the peak kinetic energy. With rolling resistance c_rr = {CIRCUIT_SETTINGS['rolling']} and "
        f"c_d A = {CIRCUIT_SETTINGS['drag_area']} m^2: {lossy.status} ({lossy.message}). "
        f"Rider loads at the rider point of car 1 {tr.p.rider_point} m (coaster.rider); limits from "
        f"{limits['basis'].iloc[0] if 'basis' in limits else 'data/coaster/acceleration_limits.csv'}. "
        f"Time above the limits (table time_above_limits) from the run's dense solution, independent of the output "
        f"step (coaster.train.time_above_limits_dense: each crossing of a level located on re-integrated states by "
        f"Newton to {above.attrs['xtol_s']:.1g} s, extremes between two outputs searched; column 'between outputs' "
        f"counts the exceedances no output falls in)" + (f"; GridResolutionWarning: {grid_warned[0]}" if grid_warned
                                                        else "") + ". "
        f"The station rows of the data carry 40-55 deg rolls (kept as given). Track: quintic periodic spline "
        f"through the 203 control points, rotation-minimising frame with the file's rolls relative to the "
        f"vertical (coaster.frames). Bank check (coaster.track.check_bank, weighted by v^2 kappa with the main run's "
        f"speed): {100 * chk.outward_share:.0f} % of the lateral demand is on outward bank ({chk.n_outward} of "
        f"{chk.n_turns} turns)" + (f"; OutwardBankWarning: {warned[0]}" if warned else "") + ". With the bank designed "
        f"from the run's speed (coaster.track.design_bank, roll = atan(v^2 kappa / g)) the rider's |n_y| RMS is "
        f"{bank_rows[1]['rider |n_y| RMS [g]']:.3g} g against {bank_rows[0]['rider |n_y| RMS [g]']:.3g} g "
        f"(table bank_design)."
    )
    return SceneResult(
        tables={"runs": runs, "energy_drift": energy, "section_peaks": peaks, "time_above_limits": above,
                "rank_along_circuit": rank_summary, "speed": tab.iloc[::every].reset_index(drop=True),
                "wheel_forces": wf.iloc[::every].reset_index(drop=True), "rider_loads": loads.iloc[::every]
                .reset_index(drop=True), "chain_force": chain_force(main).iloc[::every].reset_index(drop=True),
                "sections": sec, "frame_quality_summary": fq_summary, "bank_design": bank_table,
                "bank_turns": bank_turns,
                "frame_quality": fq.iloc[::10 if not fast else 2].reset_index(drop=True)},
        figures=figs, notes=notes)


def circuit_scene():
    from core.scenes import Scene

    return Scene("coaster-circuit",
                 "Three-car train over the 4.9 km circuit: speed, wheel forces, rider loads against limits",
                 "The train of Pombo & Ambrosio (3 cars, 2 bars, 6 wheelsets on path-following joints, 1 DOF) over "
                 "the shared circuit: chain lift, free running, booster, brakes; energy drift without dissipation; "
                 "a run with rolling resistance and drag and its outcome.", run_coaster_circuit)


def coaster_scenes():
    """The coaster scenes (entry point ``mbsuite.scenes: coaster``)."""
    from .analytic_scene import coaster_analytic_scene

    return [coaster_analytic_scene(), circuit_scene()]
