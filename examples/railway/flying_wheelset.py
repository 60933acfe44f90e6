"""
A free (flying) wheelset
========================

A single free wheelset (the Manchester coach's, 1813 kg) rolling on straight track, in absolute
coordinates with its spin as a full coordinate, released with a lateral offset:

* **conical wheels** (1:40 tread joined to the S1002 flank) at 5 m/s, Kalker linear: the
  kinematic oscillation, whose wavelength is Klingel's :math:`L = 2\\pi\\sqrt{r_0 l/\\lambda}`
  (Klingel 1883; Wickens 2003, eq. 2.4) with the nominal cone and with the equivalent conicity of
  the rigid contact-geometry table;
* **S1002 on UIC60 1:40** at 20 m/s, Polach 2000: growth into a limit cycle bounded by flange
  contact, against the kinematic frequency V/L at the equivalent conicity of its amplitude
  (EN 15302).

This is the flying wheelset of Simeon, Führer & Rentrop (1991). For your own profile pair, pass
``wheel=`` and ``rails=`` to :func:`railway.vehicles.wheelset_models.free_wheelset`. This script is
the scene ``railway-flying-wheelset``.
"""

# %%
# Conical wheels: the kinematic oscillation
# -----------------------------------------
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from core.integrators import simulate
from core.scenes import scene_run
from core.signals import zero_crossings
from railway.contact.geometry import contact_geometry_table, equivalent_conicity
from railway.contact.two_point import conical_wheel
from railway.tables import display_units
from railway.vehicles.hunting import klingel_wavelength
from railway.vehicles.wheelset_models import free_wheelset, released_contact_geometry

scene = scene_run("railway-flying-wheelset")
cone = conical_wheel()
V, y0 = 5.0, 0.002  # m/s, m
T = 6.0 if scene.fast else 14.0
model = free_wheelset(V, y0, wheel=cone, track_length=V * T + 60.0)
res = simulate(model, (0.0, T), "jit-dop853", rtol=1e-7, atol=1e-9, n_output=int(T * 200) + 1)
x, y = res.coordinates()["wheelset.x [m]"].to_numpy(), res.coordinates()["wheelset.y [m]"].to_numpy()
xc = zero_crossings(x, y)
L_sim = 2.0 * float(np.mean(np.diff(xc)))
# Klingel's inputs: the nominal cone, and the equivalent conicity of the profile pair
table = contact_geometry_table(np.linspace(-0.002, 0.002, 41), wheel=cone)
lam_e = float(np.polyfit(table["y [m]"], table["delta_r [m]"], 1)[0] / 2.0)
r0, l = released_contact_geometry(model)
L_k, L_e = float(klingel_wavelength(r0, l, 1.0 / 40.0)), float(klingel_wavelength(r0, l, lam_e))
cone_row = {"case": "cone 1:40, Kalker linear", "speed [m/s]": V, "release offset [m]": y0, "status": res.status,
            "wavelength simulated [m]": L_sim, "Klingel, cone 1:40 [m]": L_k, "difference cone [-]": L_sim / L_k - 1.0,
            "Klingel, equivalent conicity [m]": L_e, "difference equivalent [-]": L_sim / L_e - 1.0,
            "conicity [-]": 1.0 / 40.0, "equivalent conicity [-]": lam_e, "r0 [m]": r0,
            "half contact spacing [m]": l, "zero crossings": len(xc)}
scene.table("cone_kinematic_wavelength", display_units(pd.DataFrame([cone_row])))

fig = Figure(figsize=(8, 3.6), layout="constrained")
ax = fig.subplots()
ax.plot(x - x[0], y * 1e3, lw=1.2, label="simulated (jit-dop853, rtol 1e-7)")
ax.plot(x - x[0], y0 * 1e3 * np.cos(2 * np.pi * (x - x[0]) / L_k), "--", lw=1, label=f"Klingel, λ = 1/40: L = {L_k:.3f} m")
ax.set(xlabel="distance travelled [m]", ylabel="lateral displacement [mm]",
       title=f"railway-flying-wheelset — free wheelset, cone 1:40 on UIC60 1:40, V = {V:g} m/s, Kalker linear\n"
             f"simulated wavelength {L_sim:.3f} m")
ax.title.set_fontsize(9)
ax.legend(fontsize=8)
ax.grid(True, alpha=0.3)
scene.figure("cone_kinematic_oscillation", fig)

# %%
# S1002 / UIC60: a limit cycle bounded by flange contact
# ------------------------------------------------------
V2, y02 = 20.0, 0.001
T = 4.0 if scene.fast else 12.0
model = free_wheelset(V2, y02, creep_law="polach2000", track_length=V2 * T + 60.0)
res = simulate(model, (0.0, T), "jit-dop853", rtol=1e-6, atol=1e-8, n_output=int(T * 400) + 1)
t, y = res.t, res.coordinates()["wheelset.y [m]"].to_numpy()
half = t >= 0.5 * t[-1]
tc = zero_crossings(t[half], y[half])
f_sim = 1.0 / (2.0 * float(np.mean(np.diff(tc)))) if tc.size > 2 else np.nan
# amplitude: mean of the lateral extremes between the crossings of the second half
extremes = [np.max(np.abs(y[half][(t[half] >= a) & (t[half] <= b)])) for a, b in zip(tc[:-1], tc[1:])]
amp = float(np.mean(extremes)) if extremes else np.nan
geo = contact_geometry_table(np.linspace(-0.010, 0.010, 401))
lam = float(equivalent_conicity(geo["y [m]"].to_numpy(), geo["delta_r [m]"].to_numpy(), [amp])[0])
L_eq = float(klingel_wavelength(0.46, 0.75, lam))
s1002_row = {"case": "S1002 / UIC60 1:40, Polach 2000", "speed [m/s]": V2, "release offset [m]": y02,
             "status": res.status, "limit-cycle amplitude [m]": amp,
             "largest excursion [m]": float(np.max(np.abs(y[half]))), "frequency simulated [Hz]": f_sim,
             "equivalent conicity at the amplitude [-]": lam, "V / L(equivalent) [Hz]": V2 / L_eq,
             "frequency ratio [-]": f_sim * L_eq / V2}
scene.table("s1002_limit_cycle", display_units(pd.DataFrame([s1002_row])))

fig = Figure(figsize=(8, 3.6), layout="constrained")
ax = fig.subplots()
ax.plot(t * V2, y * 1e3, lw=0.9)
for side in (1, -1):
    ax.axhline(side * 6.2518, ls=":", c="k", lw=0.8)
ax.set(xlabel="distance travelled [m]", ylabel="lateral displacement [mm]",
       title=f"railway-flying-wheelset — free S1002 wheelset on UIC60 1:40, V = {V2:g} m/s, Polach 2000, "
             f"jit-dop853 rtol 1e-6 [{res.status}]\nlimit cycle {amp * 1e3:.2f} mm, {f_sim:.3f} Hz; "
             f"dotted: rigid flange-contact onset ±6.2518 mm")
ax.title.set_fontsize(9)
ax.grid(True, alpha=0.3)
scene.figure("s1002_limit_cycle", fig)

scene.note(
    f"Free wheelset (Manchester coach wheelset, 1813 kg), absolute coordinates with the spin as a full coordinate. "
    f"Cone 1:40 (conical tread joined to the S1002 flank, railway.contact.two_point): simulated kinematic wavelength "
    f"{L_sim:.3f} m against Klingel's 2 pi sqrt(r0 l / lambda) = {L_k:.3f} m with the nominal cone "
    f"({(L_sim / L_k - 1) * 100:+.2f} %) and {L_e:.3f} m with the equivalent conicity {lam_e:.5f} of the rigid "
    f"contact-geometry table, whose roll of the wheelset changes the rolling-radius difference "
    f"({(L_sim / L_e - 1) * 100:+.2f} %). S1002: the motion grows from {y02 * 1e3:g} mm into a limit cycle of "
    f"{amp * 1e3:.2f} mm (mean extreme) bounded by flange contact at {f_sim:.3f} Hz; the kinematic frequency V/L at "
    f"the equivalent conicity {lam:.3f} of that amplitude (EN 15302, exact wavelength) is {V2 / L_eq:.3f} Hz: the "
    f"limit cycle with flange impacts is not the kinematic sinusoid (ratio {f_sim * L_eq / V2:.3f}).\n\n"
    "References: Klingel (1883); Wickens (2003), Fundamentals of Rail Vehicle Dynamics, ch. 2; EN 15302; the "
    "flying wheelset of Simeon, Führer & Rentrop (1991).")
scene.done()
