"""
Two-point contact: tread and flange at once
===========================================

Two-point contact does not occur with new S1002 wheels on UIC60 rails inclined 1:40 (the contact
runs across the conformal flange root). It does with a conical 1:40 tread joined to the S1002
70° flank by a concave root of radius 8 mm, tighter than the 13 mm gauge corner of the rail. The
rigid onset is the lateral shift at which the tread and flange gaps of the left wheel are both
zero (Brent's method on :math:`g_F - g_T`); with yaw :math:`\\psi` the flange contact leads the
wheel centre along the track by about :math:`r \\tan\\gamma \\tan\\psi` (Shabana, Zaazaa &
Sugiyama 2008, ch. 5). A dense brute-force scan of the vertical gap over the wheel's surface
checks the Newton contact search independently, and the elastic Hertz contact under a 100 kN
wheel load (Johnson 1985, ch. 4) shows both contacts carrying load past the onset.

This script is the scene ``railway-two-point-contact``.
"""

# %%
# Model
# -----
# The conical wheel is written to a profile file in the output folder and read back by the
# measured-profile reader, as a user's own profile would be.
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from core.scenes import scene_run
from railway.contact.quasi_static import quasi_static_contact
from railway.contact.two_point import conical_wheel, gap_scan, local_minima, two_point_contact
from railway.tables import display_units
from railway.track import RailMounting

scene = scene_run("railway-two-point-contact")
wheel = conical_wheel(scene.out_dir / "cone40_root8_profile.txt", r0=0.46, cone=1 / 40, root_radius_mm=8.0)
yaws = (0.0, 0.010) if scene.fast else (0.0, 0.005, 0.010, 0.015)  # rad

# %%
# Run
# ---
# Per yaw angle: the rigid two-point configuration, and at it the brute-force gap scan with its
# local minima (zero gap at both contacts, no penetration anywhere).
rows, checks, scans = [], [], {}
for psi in yaws:
    contacts = two_point_contact(wheel, yaw=psi)
    first = contacts.iloc[0]
    scan = scans[psi] = gap_scan(wheel, first["shift [m]"], first["z [m]"], first["roll [rad]"], psi,
                                 dy=1e-5 if scene.fast else 5e-6, theta_max=0.06, n_theta=301)
    for _, r in contacts.iterrows():
        rows.append({"yaw [mrad]": psi * 1e3, "contact": r["contact"], "lateral shift [mm]": r["shift [m]"] * 1e3,
                     "gap [mm]": r["gap [m]"] * 1e3, "contact angle [deg]": np.degrees(r["contact angle [rad]"]),
                     "y_wheel [mm]": r["y_wheel [m]"] * 1e3, "u_rail [mm]": r["u_rail [m]"] * 1e3,
                     "rolling radius [mm]": r["rolling radius [m]"] * 1e3, "lead [mm]": r["lead [m]"] * 1e3,
                     "lead estimate r tan(gamma) tan(psi) [mm]":
                         r["rolling radius [m]"] * np.tan(r["contact angle [rad]"]) * np.tan(psi) * 1e3})
    for _, m in local_minima(scan, max_gap=1e-6).iterrows():
        checks.append({"yaw [mrad]": psi * 1e3, "brute-force minimum y_wheel [mm]": m["y_wheel [m]"] * 1e3,
                       "vertical gap [mm]": m["gap [m]"] * 1e3, "lead [mm]": m["lead [m]"] * 1e3})
    checks.append({"yaw [mrad]": psi * 1e3, "brute-force minimum y_wheel [mm]": np.nan,
                   "vertical gap [mm]": scan["gap [m]"].min() * 1e3, "lead [mm]": np.nan})
# elastic contact under 100 kN per wheel (yaw 0) around the rigid onset y0
table = pd.DataFrame(rows)
y0 = table["lateral shift [mm]"].iloc[0] * 1e-3
quasi_static = quasi_static_contact(y0 + np.array([-0.5, -0.05, 0.0, 0.05, 0.1, 0.15, 0.2, 0.3]) * 1e-3, 100e3,
                                    wheel=wheel)

# %%
# Tables
# ------
scene.table("two_point", table)
scene.table("brute_force_check", pd.DataFrame(checks))
scene.table("quasi_static", display_units(quasi_static))
table

# %%
# Figures
# -------
# The gap scan on a log scale: gaps at the contacts are zero to round-off (~1e-12 mm) and drawn
# below the visible range, so that the line runs off the bottom edge there.
setting = f"{wheel.name} / UIC60 1:40, gauge 1435 mm, flange-back 1360 mm"
floor_mm = 1e-6
fig = Figure(figsize=(7, 4), layout="constrained")
ax = fig.subplots()
for psi, scan in scans.items():
    ax.semilogy(scan["y_wheel [m]"] * 1e3, np.maximum(scan["gap [m]"] * 1e3, 1e-3 * floor_mm), lw=0.8,
                label=f"yaw {psi * 1e3:g} mrad")
ax.set(xlabel="wheel profile coordinate y [mm] (flange < 0)", ylabel="min over theta of vertical gap [mm]",
       title=(f"two-point contact — brute-force gap scan at the rigid two-point configuration\n"
              f"{setting}; y-range floored at {floor_mm:g} mm (zero gap at the contacts)"), ylim=(floor_mm, 30))
ax.title.set_fontsize(9)
ax.legend()
ax.grid(True, alpha=0.3)
scene.figure("gap_scan", fig)

# Cross-section of the left wheel and rail at the rigid onset without yaw; the wheel drawn in the
# wheelset frame, its small roll (< 0.3 mrad) neglected.
at_onset = table[table["yaw [mrad]"] == 0.0]
shift = at_onset["lateral shift [mm]"].iloc[0] * 1e-3
mount = RailMounting()
Yo, Z, *_ = mount.mounted(np.linspace(mount.u_min, mount.u_max, 600))
L = 0.68 - wheel.y_back  # wheelset centre to taping line: half the flange-back spacing + |y_back|
yw = np.linspace(wheel.x_min, wheel.x_max, 800)
fig = Figure(figsize=(7, 5), layout="constrained")
ax = fig.subplots()
ax.plot(Yo * 1e3, Z * 1e3, c="k", lw=1.5, label="UIC60 1:40 (left rail)")
ax.plot((shift + yw + L) * 1e3, -wheel.evaluate(yw)[0] * 1e3, c="C0", lw=1.5,
        label=f"{wheel.name}, shift {shift * 1e3:.2f} mm")
for yc in at_onset["y_wheel [mm]"] * 1e-3:
    ax.plot((shift + yc + L) * 1e3, -wheel.evaluate(yc)[0] * 1e3, "o", c="C3")
ax.set(xlabel="lateral position from track centre [mm]", ylabel="height [mm]", xlim=(680, 800), ylim=(-35, 10),
       aspect="equal", title=(f"two-point contact — cross-section at the rigid onset (contacts: dots), yaw 0\n"
                              f"{wheel.name} / UIC60 1:40, lateral shift {shift * 1e3:.2f} mm"))
ax.title.set_fontsize(9)
ax.legend(fontsize=8)
ax.grid(True, alpha=0.3)
scene.figure("cross_section", fig)

scene.note(
    "Two-point contact does not occur with new S1002 on UIC60 1:40 (the contact runs across the conformal flange "
    "root). It does with a conical 1:40 tread joined to the S1002 70 deg flank by a concave root of radius 8 mm, "
    "tighter than the 13 mm gauge corner of the rail (profile written to cone40_root8_profile.txt and read back by "
    "the measured-profile reader). The rigid onset is the lateral shift where tread and flange gaps of the left wheel "
    "are both zero (Brent's method on g_F - g_T); with yaw the flange contact leads the wheel centre ('lead', along "
    "the track). check: dense brute-force vertical gap scan over (theta, y), independent of the Newton search: two "
    "local minima with zero gap, no penetration (last row per yaw: global minimum). quasi_static: elastic Hertz "
    "contact under 100 kN vertical load per wheel (yaw 0): the flange takes load from the onset on, with both "
    "contacts loaded. Tables in mm, deg (contact angles), mrad (yaw, roll) and kN.")
scene.note("References: Pombo, Ambrosio & Silva (2007), VSD 45:165-189; Shabana, Zaazaa & Sugiyama (2008), Railroad "
           "Vehicle Dynamics, ch. 5; Johnson (1985), Contact Mechanics, ch. 4.")
scene.done()
