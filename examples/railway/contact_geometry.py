"""
Contact geometry of a wheel and rail profile pair
=================================================

The rigid (zero-penetration) contact of a wheelset on straight track against its lateral shift:
the rolling-radius difference :math:`\\Delta r = r_L - r_R`, the contact angles, where the
contacts lie on wheel and rail, where flange contact starts, and the equivalent conicity after
EN 15302 (the conicity of the cone with the same kinematic wavelength,
:math:`\\lambda_e = 4\\pi^2 r_0 e / L^2`) at 2, 3 and 4 mm amplitude. The contact points follow
from the four-condition contact search of Pombo, Ambrósio & Silva (2007); a jump of the contact
across the tread and the flange-contact onset are located between the table's rows by bisection.

As shipped it computes new S1002 wheels (r0 = 460 mm, EN 13715) on UIC60 rails (EN 13674-1)
inclined 1:40, gauge 1435 mm, flange-back spacing 1360 mm. **For your own profiles, change only
the block "Your profiles here"**: measured profiles are files of two columns, lateral and
vertical in mm (see :mod:`railway.contact.profiles` for the sign conventions).
This script is the scene ``railway-contact-geometry``.
"""

# %%
# Your profiles here
# ------------------
# The shipped profiles: S1002 from its analytic definition (``data/railway/s1002_definition.csv``)
# and UIC60 from its arcs. Measured profiles instead, for example::
#
#     wheel = WheelProfile.from_file("my_wheel.txt", r0=0.46, y_back=-70.0)
#     rail = RailProfile.from_file("my_rail.txt")
from core.paths import data_path
from railway.contact.profiles import RailProfile, WheelProfile

wheel = WheelProfile.s1002(r0=0.46, path=data_path("railway", "s1002_definition.csv"))
rail = RailProfile.uic60()
gauge, inclination, flange_back_spacing = 1.435, 1 / 40, 1.360  # m, tan(alpha), m

# %%
# Model
# -----
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from core.scenes import scene_run
from railway.contact.geometry import conicity_table, contact_geometry_table, contact_transitions, flange_contact_onset
from railway.tables import display_units

scene = scene_run("railway-contact-geometry")
n = 101 if scene.fast else 401
track = dict(gauge=gauge, inclination=inclination, flange_back_spacing=flange_back_spacing)

# %%
# Run
# ---
# The table over +-10 mm, the conicity, and every jump and the flange onset by bisection to 0.1 um.
df = contact_geometry_table(np.linspace(-0.010, 0.010, n), wheel=wheel, rail=rail, **track)
con = conicity_table(df, [0.002, 0.003, 0.004])
trans = contact_transitions(df, wheel=wheel, rail=rail)
y_f, g_f = flange_contact_onset(df, wheel=wheel, rail=rail, transitions=trans)  # between the rows

# %%
# Tables
# ------
# In mm, deg (contact angles) and mrad (roll, yaw). The excerpt: 1 ... 6 mm and the first row
# with flange contact.
table = scene.table("contact_geometry", display_units(df))
first_flange = float(df[(df["y [m]"] > 0) & df["flange_L"]]["y [m]"].min())
picks = [0.001, 0.002, 0.003, 0.004, 0.005, 0.006, first_flange]
idx = [int(np.argmin(np.abs(df["y [m]"].to_numpy() - p))) for p in picks]
scene.table("excerpt", table.iloc[idx][["lateral shift [mm]", "delta_r [mm]", "gamma_L [deg]", "gamma_R [deg]",
                                        "y_wheel_L [mm]", "u_rail_L [mm]", "flange_L"]].reset_index(drop=True))
amps = con["amplitude [m]"].to_numpy() * 1e3
summary = scene.table("summary", pd.DataFrame(
    [("flange-contact onset, lateral shift", y_f * 1e3, "mm"), ("contact angle at onset", np.degrees(g_f), "deg")]
    + [(f"equivalent conicity at {a:g} mm (EN 15302 wavelength)", v, "-")
       for a, v in zip(amps, con["conicity wavelength [-]"])]
    + [(f"equivalent conicity at {a:g} mm (harmonic linearisation)", v, "-")
       for a, v in zip(amps, con["conicity harmonic [-]"])],
    columns=["quantity", "value", "unit"]))
scene.table("equivalent_conicity", display_units(con))
scene.table("transitions", display_units(trans))
summary

# %%
# Figures
# -------
setting = (f"{wheel.name} (r0 {wheel.r0 * 1e3:g} mm) / {rail.name} 1:{1 / inclination:g}, gauge {gauge * 1e3:g} mm, "
           f"flange-back {flange_back_spacing * 1e3:g} mm, {n} shifts")
ys = table["lateral shift [mm]"]
fig = Figure(figsize=(7, 4), layout="constrained")
ax = fig.subplots()
ax.plot(ys, table["delta_r [mm]"], lw=1.2)
ax.axvline(y_f * 1e3, ls=":", c="k", lw=0.8, label=f"flange contact from {y_f * 1e3:.4f} mm")
ax.set(xlabel="lateral shift y [mm]", ylabel=r"$\Delta r = r_L - r_R$ [mm]",
       title=f"contact geometry — rolling-radius difference\n{setting}")
ax.title.set_fontsize(9)
ax.legend(fontsize=8)
ax.grid(True, alpha=0.3)
scene.figure("delta_r", fig)

fig = Figure(figsize=(7, 4), layout="constrained")
ax = fig.subplots()
ax.plot(ys, table["gamma_L [deg]"], lw=1.2, label="left wheel")
ax.plot(ys, table["gamma_R [deg]"], lw=1.2, label="right wheel")
ax.set(xlabel="lateral shift y [mm]", ylabel="contact angle [deg]",
       title=f"contact geometry — contact angles\n{setting}")
ax.title.set_fontsize(9)
ax.legend()
ax.grid(True, alpha=0.3)
scene.figure("contact_angle", fig)

fig = Figure(figsize=(10, 4), layout="constrained")
axes = fig.subplots(1, 2)
for what, ylabel, a in (("y_wheel", "wheel contact y from taping line [mm]", axes[0]),
                        ("u_rail", "rail contact u from rail axis [mm]", axes[1])):
    a.plot(ys, table[f"{what}_L [mm]"], ".", ms=2, label="left")
    a.plot(ys, table[f"{what}_R [mm]"], ".", ms=2, label="right")
    a.set(xlabel="lateral shift y [mm]", ylabel=ylabel)
    a.legend()
    a.grid(True, alpha=0.3)
fig.suptitle(f"contact geometry — contact positions on wheel and rail\n{setting}", fontsize=10)
scene.figure("contact_positions", fig)

conicity = con["conicity wavelength [-]"]
scene.note(
    f"Rigid (zero-penetration) contact of new {wheel.name} wheels (r0 = {wheel.r0 * 1e3:g} mm) on {rail.name} rails "
    f"inclined 1:{1 / inclination:g}, gauge {gauge * 1e3:g} mm (14 mm below the top), flange-back spacing "
    f"{flange_back_spacing * 1e3:g} mm, {n} lateral shifts over +-10 mm. Flange contact starts at {y_f * 1e3:.4f} mm "
    f"(located between the table's rows by bisection to 0.1 um) with a contact angle of {np.degrees(g_f):.2f} deg; "
    f"equivalent conicity (EN 15302, exact kinematic wavelength) {conicity.iloc[0]:.3f} / {conicity.iloc[1]:.3f} / "
    f"{conicity.iloc[2]:.3f} at 2 / 3 / 4 mm. "
    + (f"The contact point jumps across the {wheel.name} tread (near-equal minima of the gap), hence the steps in the "
       "contact positions; table 'transitions' gives every jump, located by bisection. "
       if (trans["kind"] == "contact jump").any() else "The contact point moves continuously across the tread. ")
    + "Tables in mm, deg (contact angles) and mrad (roll, yaw).")
scene.note("References: Pombo, Ambrosio & Silva (2007), VSD 45:165-189 (four-condition contact search); "
           "EN 15302:2008+A1:2010 (equivalent conicity); EN 13715 (S1002); EN 13674-1 (60E1/UIC60); "
           "Wickens (2003), Fundamentals of Rail Vehicle Dynamics, ch. 2.")
scene.done()
