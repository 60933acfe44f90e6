"""
Critical speeds: a suspended wheelset and a vehicle
===================================================

**Linear.** A wheelset with conical wheels (1:40) held by a lateral spring and a yaw spring to a
frame driven at V, Kalker linear creep. Core's ``linearize``/``eigen`` about steady running (the
non-rotating wheelset formulation) against the complete linear wheelset of
:class:`railway.vehicles.hunting.LinearWheelset` (equivalent conicity and roll of the rigid
contact-geometry table, Hertz creep coefficients at the static load, gyroscopic moment, roll-rate
creepage, gravitational stiffness, contact angle, spin creepage) and, like for like, the
classical two-degree-of-freedom closed form against the multibody wheelset with those five terms
switched off (Wickens 2003, ch. 2 and 6).

**Nonlinear.** The Manchester coach (stand-in for the ML95 trailer) on straight S1002 / UIC60
track, all wheelsets released 8 mm off centre at 90 m/s, speed lowered at 2 m/s²: the lowest
speed at which the hunting limit cycle persists, per creep law (the run-down method of Polach
2006). The run-down's threshold speed lags the fold of the limit-cycle branch; two slower
run-downs (1 and 0.5 m/s²), continued from the first one's state on the branch, and the
extrapolation of their threshold speeds to zero rate remove the lag at a fixed cost. ``mbsuite run railway-critical-speed --full`` adds the
bisection of constant-speed runs for every creep law, and the difference between the two. The
creep laws run in parallel on every local core.

For your own vehicle, pass ``definition=VehicleDefinition.from_file(...)`` in the case dicts of
:func:`railway.vehicles.critical_speed.nonlinear_critical_speed`. This script is the scene
``railway-critical-speed``.
"""

# %%
# Linear critical speed of a suspended wheelset
# ---------------------------------------------
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from core.scenes import scene_run
from core.sweep import run_sweep
from railway.contact.creep import VEHICLE_CREEP_LAWS
from railway.tables import display_units
from railway.vehicles.critical_speed import HUNTING_AMPLITUDE, linear_critical_speed, nonlinear_critical_speed
from railway.vehicles.curving import METHOD, RTOL

scene = scene_run("railway-critical-speed")
lin = linear_critical_speed()
two_pi = 2 * np.pi
linear = pd.DataFrame([
    ("critical speed, eigenvalues of core's linearisation", lin["V_core"], "m/s"),
    ("critical speed, complete linear wheelset (closed form, every term)", lin["V_cf"], "m/s"),
    ("difference", lin["V_core"] / lin["V_cf"] - 1.0, "-"),
    ("critical speed, eigenvalues, classical model's terms only (TEXTBOOK)", lin["V_textbook"], "m/s"),
    ("critical speed, classical two-degree-of-freedom closed form", lin["V_plain"], "m/s"),
    ("difference (classical)", lin["V_textbook"] / lin["V_plain"] - 1.0, "-"),
    ("hunting frequency at V_c, eigenvalues", lin["w_core"] / two_pi, "Hz"),
    ("hunting frequency at V_c, complete closed form", lin["w_cf"] / two_pi, "Hz"),
    ("hunting frequency, eigenvalues (TEXTBOOK)", lin["w_textbook"] / two_pi, "Hz"),
    ("hunting frequency, classical closed form", lin["w_plain"] / two_pi, "Hz"),
    ("equivalent conicity (rigid table)", lin["lam"], "-"),
    ("roll per lateral displacement (rigid table)", lin["rho"], "rad/m"),
    ("f11 = G a b C11 (Hertz at the static load)", lin["f11"], "N"),
    ("f22 = G a b C22", lin["f22"], "N"),
    ("half contact spacing l", lin["l"], "m"),
    ("rolling radius r0", lin["r0"], "m"),
    ("lateral spring k_y", lin["k_y"], "N/m"),
    ("yaw spring k_psi", lin["k_psi"], "N m/rad")], columns=["quantity", "value", "unit"])
scene.table("linear_critical_speed", linear)

Vg = np.linspace(0.6 * lin["V_core"], 1.3 * lin["V_core"], 8 if scene.fast else 16)
fig = Figure(figsize=(7, 3.8), layout="constrained")
ax = fig.subplots()
ax.plot(Vg, [lin["real"](V) for V in Vg], "o-", label="core: eigenvalues of the linearised model")
ax.plot(Vg, [lin["closed_form_real"](V) for V in Vg], "--", label="complete linear wheelset (closed form, railway.hunting)")
ax.axhline(0.0, c="k", lw=0.8)
ax.set(xlabel="speed V [m/s]", ylabel="real part of the hunting eigenvalue [1/s]",
       title=f"railway-critical-speed — wheelset on springs (k_y = {lin['k_y']:.3g} N/m, k_psi = {lin['k_psi']:.3g} "
             f"N m/rad), cone 1:40, Kalker linear\nV_c = {lin['V_core']:.3f} m/s (eigenvalues) vs {lin['V_cf']:.3f} m/s "
             f"(closed form)")
ax.title.set_fontsize(9)
ax.legend(fontsize=8)
ax.grid(True, alpha=0.3)
scene.figure("linear_critical_speed", fig)

# %%
# Nonlinear critical speed of the coach, per creep law
# ----------------------------------------------------
laws = ("polach2000",) if scene.fast else VEHICLE_CREEP_LAWS
V0, V1, rate = (90.0, 60.0, 3.0) if scene.fast else (90.0, 40.0, 2.0)
cases = [dict(law=law, V0=V0, V1=V1, rate=rate, two_rate=not scene.fast, bisect=scene.full) for law in laws]
out = run_sweep(nonlinear_critical_speed, cases, executor=scene.executor)
nonlinear = scene.table("nonlinear_critical_speed", display_units(pd.DataFrame([o["row"] for o in out])))
nonlinear

# %%
# The bifurcation diagram
# -----------------------
fig = Figure(figsize=(7.5, 4.2), layout="constrained")
ax = fig.subplots()
for law, o in zip(laws, out):
    Vt, amp, status = o["curve"]
    ax.plot(Vt, amp * 1e3, lw=1.2, label=f"{law} [{status}]")
ax.set(xlabel="speed V [m/s] (run-down, decreasing)", ylabel="hunting amplitude, leading wheelset [mm]",
       title=f"railway-critical-speed — Manchester coach on S1002 / UIC60 1:40, run-down from {V0:g} m/s at "
             f"{rate:g} m/s² (ended 1 s after the hunting stopped), {METHOD} rtol {RTOL:g}\nbifurcation diagram: "
             f"limit-cycle amplitude (max |y| over 0.5 s)")
ax.title.set_fontsize(9)
ax.invert_xaxis()
ax.legend(fontsize=8)
ax.grid(True, alpha=0.3)
scene.figure("bifurcation", fig)

scene.note(
    f"Linear: a wheelset with conical wheels (1:40) held by a lateral spring and a yaw spring (two longitudinal "
    f"springs at ±1 m) to a frame driven at V, Kalker linear creep. Core's `linearize`/`eigen` about steady running "
    f"in the non-rotating wheelset formulation (nominal spin, railway.vehicles.wheel_rail) give V_c = "
    f"{lin['V_core']:.3f} m/s (Brent's method on the hunting eigenvalue's real part to 1 mm/s); the complete linear "
    f"wheelset of railway.vehicles.hunting (LinearWheelset: equivalent conicity {lin['lam']:.5f} and roll "
    f"{lin['rho']:.5f} rad/m of the rigid contact-geometry table, Hertz creep coefficients at the static load, "
    f"gyroscopic moment, roll-rate creepage, gravitational stiffness, contact angle, spin creepage) gives "
    f"{lin['V_cf']:.3f} m/s ({(lin['V_core'] / lin['V_cf'] - 1) * 100:+.3f} %). Like for like with the classical "
    f"two-degree-of-freedom model: the multibody wheelset with those five terms switched off "
    f"(railway.vehicles.wheelset_models.TEXTBOOK) gives {lin['V_textbook']:.3f} m/s against the classical closed "
    f"form's {lin['V_plain']:.3f} m/s ({(lin['V_textbook'] / lin['V_plain'] - 1) * 100:+.4f} %). A linearisation of "
    f"the absolute (spinning) formulation is not valid: its body frames turn with the spin, so it is the snapshot "
    f"of a periodic system.\n\n"
    f"Nonlinear: the Manchester coach (stand-in for the ML95 trailer) on straight track, all wheelsets released "
    f"8 mm off centre at {V0:g} m/s (above the critical speed: the flange-bounded limit cycle forms within the first "
    f"second), speed lowered at {rate:g} m/s² by the speed control (each run-down ends 1 s after the hunting has "
    f"stopped: below the fold the centred running is stable); the nonlinear critical speed is the lowest speed "
    f"at which the hunting limit cycle of the leading wheelset persists: the run-down gives the speed where its "
    f"amplitude (max |y| over 0.5 s) falls below {HUNTING_AMPLITUDE * 1e3:g} mm, which lags the fold; "
    + ("" if scene.fast else
       f"two slower run-downs at {rate / 2:g} and {rate / 4:g} m/s² from the first one's state 4.5 m/s above that "
       f"speed give two more threshold speeds, and these two extrapolated to zero rate (lag proportional to the "
       f"rate) give the nonlinear critical speed (column 'two-rate critical speed'); ")
    + ("bisection of 3 s constant-speed runs started from the run-down's state refines it to 0.1 m/s (hunting "
       f"persists when the last second's amplitude is at least 0.8 times the first second's and above "
       f"{HUNTING_AMPLITUDE * 1e3:g} mm); the table's critical speed is the bisected one, and 'two-rate minus "
       f"bisected' the check of the fixed-cost method. " if scene.full else
       "`--full` adds the bisection of 3 s constant-speed runs to 0.1 m/s for every creep law. ")
    + f"Polach 2005 uses "
    f"the 'dry' parameter set (second-hand, see data/railway), FASTSIM a 10 x 10 grid. The creep laws run through "
    f"core.sweep.run_sweep, on every local core by default.\n\nReferences: Wickens (2003), ch. 2 and 6; Polach "
    f"(2006), VSD 44 Suppl. (nonlinear critical speed by run-down).")
scene.done()
