"""
Manchester contact benchmark, Case A-2.2, against CONTACT
=========================================================

Case A-2.2 of the Manchester contact benchmark (Shackleton & Iwnicki 2008) as defined in
CONTACT's example (Vollebregt, CONTACT user guide sect. 5.7): new S1002 wheels (r0 = 460 mm,
flange-back 1360 mm) on UIC60 rails inclined 1:40, gauge 1435 mm, 10 kN per wheel, V = 2 m/s,
mu = 0.3, G = 82 GPa, nu = 0.28, lateral shifts y = 0 ... 10 mm to the right with yaw
2.4 mrad per mm: the right wheel climbs its flange. Ours is the quasi-static rolling solution
(:func:`railway.contact.quasi_static.quasi_static_rolling`): axle height, roll and spin rate
such that the vertical force of each wheel, normal and creep-force components, equals the wheel
load and the net axle moment is zero, with one Hertz ellipse per contact and the creep laws
FASTSIM, Polach 2000 and Kalker linear. CONTACT solves the exact (boundary-element) problem; its
results for its example (Revision 2447) are stored in ``data/railway``. Flange contact is a
contact angle above 45°; Nadal's ratio Y/Q is compared as well.

This script is the scene ``railway-manchester-contact``.
"""

# %%
# Model
# -----
import numpy as np
from matplotlib.figure import Figure

from core.scenes import scene_run
from railway.contact.manchester_contact import (compare_with_contact, contact_reference_per_wheel, manchester_cases,
                                                rail_profile_check, run_manchester_a22)
from railway.contact.manchester_report import (MANCHESTER_LAWS, difference_summary, flange_onset_scan,
                                               manchester_notes, manchester_table)

scene = scene_run("railway-manchester-contact")
cases = [1, 2, 6, 11, 13, 14, 17, 21] if scene.fast else None  # CONTACT's case numbers; None: all 21
grid = 20 if scene.fast else 40  # FASTSIM grid
step = 0.05e-3 if scene.fast else 0.01e-3  # m, spacing of the flange-onset scan
reference = contact_reference_per_wheel()

# %%
# Run
# ---
# Every case with every creep law, compared with CONTACT per case and wheel; the rail geometry
# (CONTACT's canted UIC60 against ours, mounted 1:40); where the flange contact starts.
contacts, wheels, comparisons = {}, {}, {}
for law in MANCHESTER_LAWS:
    params = {"n_x": grid, "n_y": grid} if law == "fastsim" else None
    contacts[law], wheels[law] = run_manchester_a22(law, cases=cases, creep_params=params)
    comparisons[law] = compare_with_contact(wheels[law], reference)
points, top = rail_profile_check()
onset = flange_onset_scan(np.arange(6.0e-3, 6.5e-3 + 1e-9, step), grid)

# %%
# Tables
# ------
# In mm, deg, mrad (yaw, roll), kN and GPa. Rows whose balance did not converge are flagged
# (``converged`` False) and left out of the summary and the figure.
for law in MANCHESTER_LAWS:
    scene.table(f"contacts_{law}", manchester_table(contacts[law]))
    scene.table(f"comparison_{law}", manchester_table(comparisons[law]))
fs = comparisons["fastsim"]
scene.table("flange_cases_fastsim", manchester_table(fs[fs["y CONTACT [m]"] >= 6.5e-3 - 1e-9][[
    "case", "side", "y CONTACT [m]", "N ours [N]", "N CONTACT [N]", "dN [%]", "Fy track ours [N]",
    "Fy track CONTACT [N]", "dFy track [N]", "contact angle ours [rad]", "contact angle CONTACT [rad]",
    "dcontact angle [rad]", "p_max ours [Pa]", "p_max CONTACT [Pa]", "dp_max [%]", "Y/Q ours [-]",
    "Y/Q CONTACT [-]"]].reset_index(drop=True)))
summary = scene.table("summary_differences", manchester_table(difference_summary(comparisons)))
scene.table("rail_profile_check", manchester_table(points))
scene.table("flange_onset_right_wheel", manchester_table(onset))
summary

# %%
# Figures
# -------
# N, Fy, contact angle and p_max against y, both wheels, every creep law, CONTACT's points.
fig = Figure(figsize=(11, 8), layout="constrained")
ax = fig.subplots(2, 2)
quantities = (("N", "N ours [N]", "N [N]", 1e-3, "normal force N [kN]"),
              ("Fy", "Fy track ours [N]", "Fy track [N]", 1e-3, "lateral force on the wheel Fy (track, + left) [kN]"),
              ("angle", "contact angle ours [rad]", "contact angle [rad]", 180.0 / np.pi, "contact angle [deg]"),
              ("pmax", "p_max ours [Pa]", "p_max [Pa]", 1e-9, "maximum pressure p_max [GPa]"))
styles = {"fastsim": "-", "polach2000": "--", "kalker_linear": ":"}
colors = {"left": "C0", "right": "C3"}
y_case = manchester_cases().set_index("case")["y CONTACT [m]"]
for k, (key, ours, theirs, factor, ylabel) in enumerate(quantities):
    a = ax[k // 2, k % 2]
    for law, label in MANCHESTER_LAWS.items():
        for side in ("left", "right"):
            c = comparisons[law]
            good = c[(c["side"] == side) & c["converged"].astype(bool)]
            a.plot(good["y CONTACT [m]"] * 1e3, good[ours] * factor, styles[law], c=colors[side], lw=1.2,
                   label=f"{label}, {side}" if k == 0 else None)
    for side in ("left", "right"):
        r = reference[reference["side"] == side]
        a.plot(y_case.loc[r["case"]] * 1e3, r[theirs] * factor, "o", mfc="none", c=colors[side], ms=5,
               label=f"CONTACT rev. 2447, {side}" if k == 0 else None)
    if key == "Fy":
        a.set_ylim(-8, 16)  # Kalker linear leaves the range (down to -68 kN): clipped
    if key == "N":
        a.set_ylim(0, 20)
    a.set(xlabel="lateral shift y to the right (CONTACT's y) [mm]", ylabel=ylabel)
    a.grid(True, alpha=0.3)
ax[0, 0].legend(fontsize=7, ncol=2)
fig.suptitle("railway-manchester-contact — Case A-2.2: ours (lines: FASTSIM solid, Polach 2000 dashed, Kalker "
             "linear dotted) vs CONTACT (circles)\nS1002 / UIC60 1:40, gauge 1435 mm, r0 460 mm, Q = 10 kN per "
             "wheel, V = 2 m/s, mu = 0.3, G = 82 GPa, nu = 0.28, yaw 2.4 mrad/mm; right wheel climbs its flange; "
             "Kalker linear leaves the N and Fy ranges (clipped)" + (f"; fast run: cases {cases}" if cases else ""),
             fontsize=9)
scene.figure("manchester_N_Fy_angle_pmax", fig)

scene.note(manchester_notes(comparisons, wheels, contacts, reference, (points, top), onset, grid, step))
scene.done()
