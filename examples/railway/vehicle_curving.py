"""
A vehicle through a curve
=========================

The Manchester benchmark coach (``data/railway/vehicles/manchester_coach.toml``; the stand-in for
the ML95 metro trailer of Pombo & Ambrósio 2008, whose data are not public) through a left curve
of radius 200 m with 150 mm cant and 40 m clothoid transitions, at 10 and 20 m/s, with every
creep law of the package. The vehicle starts in quasi-static equilibrium and a speed control
(the train's pull) holds its speed. What a curving assessment reads:

* the wheel forces Q, Y, Y/Q, ΣY, the flange force, the Nadal limit, the creepages and T γ per
  wheel, averaged over the window in which every wheelset is in the full curve ≥ 30 m from both
  transitions;
* the lateral equilibrium of the whole vehicle in that window: the rail forces along the track's
  lateral axis against :math:`m\\,(a_c - g)\\cdot n`;
* wheel lift (Q = 0) and the peaks of Q, Y, Y/Q and the flange force from every accepted step of
  the integrator, the lifts located by bisection (not from the 20 Hz outputs).

To run your own vehicle, point ``vehicle_file`` at your TOML file (the layout of
``data/railway/vehicles/manchester_coach.toml``; every value is checked, with its unit, against
plausible ranges: see the user guide's *Checked inputs*). For your own curve, build a
:class:`railway.Track` and pass it to :func:`railway.vehicles.curving.run_curving`. This script is
the scene ``railway-curving``.

References: Pombo & Ambrósio (2008), Multibody Syst. Dyn. 19:91-114; Nadal (1908); Wickens (2003),
Fundamentals of Rail Vehicle Dynamics, ch. 7.
"""

# %%
# Model and run
# -------------
# Every (creep law, speed) case runs through :func:`core.sweep.run_sweep` on every local core. The fast
# mode runs 13 s at 10 m/s: just into the full-curve window, 2.5 s of it.
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from core.paths import data_path
from core.scenes import scene_run
from core.sweep import run_sweep
from railway.contact.creep import VEHICLE_CREEP_LAWS
from railway.tables import display_units
from railway.vehicles.curving import CURVE, METHOD, RTOL, curving_case

scene = scene_run("railway-curving")
vehicle_file = data_path("railway", "vehicles", "manchester_coach.toml")  # your vehicle file here
laws = ("polach2000", "kalker_linear") if scene.fast else VEHICLE_CREEP_LAWS
speeds = (10.0,) if scene.fast else (10.0, 20.0)
cases = [dict(law=law, speed=V, T=13.0 if scene.fast else None, vehicle_file=str(vehicle_file))
         for V in speeds for law in laws]
runs = dict(zip([(c["law"], c["speed"]) for c in cases], run_sweep(curving_case, cases, executor=scene.executor)))

# %%
# Tables
# ------
quasi_static = pd.DataFrame([row for run in runs.values() for row in run["quasi_static"]])
equilibrium = pd.DataFrame([run["equilibrium"] for run in runs.values() if run["equilibrium"] is not None])
events = pd.DataFrame([{"speed [m/s]": V, "creep law": law, "status": run["status"], **r.to_dict()}
                       for (law, V), run in runs.items() for _, r in run["events"].iterrows()])
events.attrs["source"] = ("every accepted step of each run (railway.assessment.wheel_event_statistics); "
                          "'lifts between outputs': lifts no output time falls in")
scene.table("curving_quasi_static", display_units(quasi_static))
scene.table("lateral_equilibrium", display_units(equilibrium))
scene.table("wheel_events", display_units(events))
display_units(equilibrium)

# %%
# Figures
# -------
# The leading wheelset along the track: flange force and lateral displacement, then the wheel
# loads of its two wheels (dotted: start of the transition, of the full curve, of the exit).
c = CURVE
marks = (c["lead"], c["lead"] + c["transition"], c["lead"] + c["transition"] + c["curve_length"])
for V in speeds:
    fig = Figure(figsize=(8, 6), layout="constrained")
    ax = fig.subplots(2, 1)
    for law in laws:
        run = runs[(law, V)]
        lead = run["history"][run["history"]["wheel"] == f"{run['leading']} right"]
        ax[0].plot(lead["s [m]"], lead["flange force [N]"] * 1e-3, lw=1, label=f"{law} [{run['status']}]")
        ax[1].plot(lead["s [m]"], lead["lateral displacement [m]"] * 1e3, lw=1, label=law)
    for a in ax:
        for s in marks:
            a.axvline(s, ls=":", c="k", lw=0.7)
        a.grid(True, alpha=0.3)
    ax[0].set(ylabel="flange force [kN]\n(leading outer wheel)",
              title=f"railway-curving — Manchester coach, R = {c['radius']:g} m, cant {c['cant'] * 1e3:g} mm, "
                    f"V = {V:g} m/s, {METHOD} rtol {RTOL:g}\nleading wheelset (dotted: transition, full curve)")
    ax[0].title.set_fontsize(9)
    ax[0].legend(fontsize=7)
    ax[1].set(xlabel="track arc length of the leading wheelset [m]", ylabel="lateral displacement [mm]\n(leading wheelset)")
    scene.figure(f"leading_wheelset_{int(V)}ms", fig)

    fig = Figure(figsize=(8, 3.6), layout="constrained")
    ax = fig.subplots()
    for law in laws:
        run = runs[(law, V)]
        for side, ls in (("left", "--"), ("right", "-")):
            w = run["history"][run["history"]["wheel"] == f"{run['leading']} {side}"]
            ax.plot(w["s [m]"], w["Q [N]"] * 1e-3, ls, lw=0.9, label=f"{law} {side}")
    ax.set(xlabel="track arc length of the leading wheelset [m]", ylabel="wheel load Q [kN]",
           title=f"railway-curving — wheel loads of the leading wheelset (left = inner), V = {V:g} m/s")
    ax.title.set_fontsize(9)
    ax.legend(fontsize=6, ncol=2)
    ax.grid(True, alpha=0.3)
    scene.figure(f"leading_wheel_loads_{int(V)}ms", fig)

# %%
# What the tables say
# -------------------
lifted = []
for (law, V), run in runs.items():
    for side, where in (("left", "inner"), ("right", "outer")):
        r = run["events"][run["events"]["wheel"] == f"{run['leading']} {side}"].iloc[0]
        if r["lifts"] > 0:
            n = int(r["lifts"])
            lifted.append(f"{where} wheel with {law} at {V:g} m/s (first at s = {r['lift-off first, s [m]']:.1f} m, "
                          f"t = {r['lift-off first [s]']:.4f} s; {n} lift{'s' if n > 1 else ''}, "
                          f"{r['lifted [s]'] * 1e3:.3g} ms in all, shortest {r['shortest lift [s]'] * 1e3:.3g} ms; "
                          f"{int(r['lifts between outputs'])} of them between two "
                          f"{1e3 * run['output_step']:.0f} ms outputs)")
unsteady = equilibrium[~equilibrium["quasi-static"].astype(bool)] if len(equilibrium) else equilibrium
not_qs = ", ".join(f"{r['creep law']} at {r['speed [m/s]']:g} m/s" for _, r in unsteady.iterrows()) or "none"
scene.note(
    f"The Manchester benchmark coach (data/railway/vehicles/manchester_coach.toml; stand-in for the ML95 metro "
    f"trailer of Pombo & Ambrosio, whose data are not public) through a left curve of radius {c['radius']:g} m with "
    f"{c['cant'] * 1e3:g} mm cant and {c['transition']:g} m clothoid transitions (cant ramped linearly). Cant "
    f"choice: 150 mm puts the equilibrium speed sqrt(g R h / 1.5 m) = "
    f"{np.sqrt(9.81 * c['radius'] * c['cant'] / 1.5):.1f} m/s between the two scene speeds, so 10 m/s runs with "
    f"cant excess and 20 m/s with cant deficiency. The car body is held at the speed by a proportional speed "
    f"control (the train's pull). Quasi-static table: means over the output times at which every wheelset is in "
    f"the full curve at least 30 m from both transitions. Lateral equilibrium: the rail forces on the whole "
    f"vehicle along the track's lateral axis against m (a_c - g) . n (centripetal acceleration and gravity in "
    f"the canted plane). Wheel lift (Q = 0) of the leading wheelset (from every accepted step, the lift located "
    f"by bisection to 0.1 us; table wheel_events, all wheels): {'; '.join(lifted) if lifted else 'none'}. "
    f"Kalker's linear law does not saturate: in the curve its creep forces exceed mu N many times, which is what "
    f"unloads (or lifts) the wheels in the paper's Kalker-linear results; the saturating laws keep Y/Q of the "
    f"inner wheel near mu. Flange contact flag: contact angle above 45 deg. A row of the lateral equilibrium "
    f"table is 'quasi-static' when the standard deviation of the rail forces over the window is below 5 % of "
    f"m (a_c - g) . n; rows that are not: {not_qs}. There a wheelset keeps moving on a contact jump of the S1002 "
    f"tread and the means over the outputs are not a steady state; such rows are not results to quote (docs, "
    f"Railway vehicles).\n\nReferences: Pombo & Ambrosio (2008), Multibody Syst. Dyn. 19:91-114 (curving of the "
    f"ML95 trailer, not available here); Nadal (1908); Wickens (2003), ch. 7.")
scene.done()
