"""
Creep curves of every creep law
===============================

The tangential force of one representative wheel-rail contact (N = 100 kN, Hertz semi-axes
a = 6 mm in rolling direction and b = 4 mm, mu = 0.3, G = 80 GPa, nu = 0.28) against each
creepage, with every creep law of :mod:`railway.contact.creep`: Kalker's linear theory
(:math:`F_x = -G a b\\, C_{11} \\xi`, coefficients of Kalker 1990, Table E.3), the heuristic of
Shen, Hedrick & Elkins (1983), Polach (2000), Polach (2005) with falling friction, and FASTSIM
(Kalker 1982). Shown: :math:`F_x(\\xi)`, :math:`F_y(\\eta)`, the spin force :math:`F_y(\\varphi)`
and the effect of spin on :math:`F_y(\\eta)`.

This script is the scene ``railway-creep-curves``.
"""

# %%
# Model
# -----
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from core.scenes import scene_run
from railway.contact.creep import Fastsim, Polach2005
from railway.contact.creep_curve import creep_curve
from railway.tables import display_units

scene = scene_run("railway-creep-curves")
contact = dict(normal_force=100e3, a=0.006, b=0.004, G=80e9, nu=0.28, mu=0.3)  # N, m, m, Pa, -, -
n = 21 if scene.fast else 101
grid = 20 if scene.fast else 40
laws = ["kalker_linear", "shen_hedrick_elkins", "polach2000",
        Polach2005(k_A=1.0, k_S=1.0, A=0.38, B=0.7, speed=20.0), Fastsim(grid, grid)]

# %%
# Run
# ---
xi_df = creep_curve(laws, "xi", np.linspace(0.0, 0.01, n), **contact)
eta_df = creep_curve(laws, "eta", np.linspace(0.0, 0.01, n), **contact)
phi_df = creep_curve(laws, "phi", np.linspace(0.0, 2.0, n), **contact)
eta_spin = creep_curve(laws, "eta", np.linspace(0.0, 0.01, n), phi=0.5, **contact)

# %%
# Tables
# ------
# In kN (forces, load), kN m (spin moment), mm (semi-axes) and GPa (G); the excerpt gives Fx of
# every law at three creepages.
scene.table("Fx_vs_xi", display_units(xi_df))
scene.table("Fy_vs_eta", display_units(eta_df))
scene.table("Fy_vs_phi", display_units(phi_df))
scene.table("Fy_vs_eta_with_spin", display_units(eta_spin))
rows = []
for xi in (0.001, 0.002, 0.004):
    at = creep_curve(laws, "xi", [xi], **contact)
    rows.append({"xi [-]": xi} | {f"Fx {name} [kN]": fx / 1e3 for name, fx in zip(at["model"], at["Fx [N]"])})
scene.table("excerpt_Fx", pd.DataFrame(rows))

# %%
# Figures
# -------
# Forces on the wheel oppose the creepage: plotted as -F / (mu N).
mu_n = contact["mu"] * contact["normal_force"]
setting = (f"N = {contact['normal_force'] / 1e3:g} kN, a = {contact['a'] * 1e3:g} mm, b = {contact['b'] * 1e3:g} mm, "
           f"mu = {contact['mu']:g}, G = {contact['G'] / 1e9:g} GPa, nu = {contact['nu']:g}; FASTSIM {grid}x{grid}")


def new_axes():
    fig = Figure(figsize=(7, 4), layout="constrained")
    return fig, fig.subplots()


def finish(ax, xlabel, ylabel, title):
    ax.set(xlabel=xlabel, ylabel=ylabel, title=f"{title}\n{setting}")
    ax.title.set_fontsize(9)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)


for stem, df, col, fcol, xlabel, what in (
        ("Fx_vs_xi", xi_df, "xi [-]", "Fx [N]", r"longitudinal creepage $\xi$ [-]",
         r"$F_x(\xi)$, $\eta = \varphi = 0$"),
        ("Fy_vs_eta", eta_df, "eta [-]", "Fy [N]", r"lateral creepage $\eta$ [-]", r"$F_y(\eta)$, $\xi = \varphi = 0$"),
        ("Fy_vs_phi", phi_df, "phi [1/m]", "Fy [N]", r"spin $\varphi$ [1/m] ($\xi=\eta=0$)",
         r"$F_y(\varphi)$, $\xi = \eta = 0$")):
    fig, ax = new_axes()
    for name, sub in df.groupby("model", sort=False):
        ax.plot(sub[col], -sub[fcol] / mu_n, label=name)
    finish(ax, xlabel, f"-{fcol.split()[0]} / (mu N) [-]", f"creep curves — {what}")
    scene.figure(stem, fig)

fig, ax = new_axes()
for (name, no_spin), (_, spin) in zip(eta_df.groupby("model", sort=False), eta_spin.groupby("model", sort=False)):
    line, = ax.plot(no_spin["eta [-]"], -no_spin["Fy [N]"] / mu_n, label=name)
    ax.plot(spin["eta [-]"], -spin["Fy [N]"] / mu_n, ls="--", c=line.get_color())
finish(ax, r"lateral creepage $\eta$ [-]", "-Fy / (mu N) [-]",
       r"creep curves — spin effect on $F_y(\eta)$: solid $\varphi = 0$, dashed $\varphi = 0.5$ 1/m")
scene.figure("spin_effect", fig)

scene.note(
    "Creep curves of every creep law at one contact: N = 100 kN, a = 6 mm (rolling), b = 4 mm, mu = 0.3, G = 80 GPa, "
    "nu = 0.28. Forces on the wheel oppose the creepage (plotted as -F/(mu N)). Kalker linear does not saturate; "
    f"FASTSIM on a {grid}x{grid} grid; Polach 2005 with falling friction A = 0.38, B = 0.7 s/m at V = 20 m/s (the "
    "parameter set quoted in the project notes from Spiryagin, Polach & Cole 2013 for a locomotive; not checked "
    "against Polach 2005, Table 2). Spin: Fy(phi) at xi = eta = 0 and Fy(eta) with phi = 0.5 1/m; "
    "Shen-Hedrick-Elkins saturates the linear spin force to mu N, a known weakness of the heuristic. Tables in kN "
    "(forces, load), kN m (spin moment), mm (semi-axes) and GPa (G).")
scene.note("References: Kalker (1990), Three-dimensional elastic bodies in rolling contact, Table E.3; Kalker (1982), "
           "VSD 11:1-13 (FASTSIM); Shen, Hedrick & Elkins (1983), VSD 12 Suppl.:79-83; Polach (2000), VSD 33 "
           "Suppl.:728-739; Polach (2005), Wear 258:992-1000.")
scene.done()
