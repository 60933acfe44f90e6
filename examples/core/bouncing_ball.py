"""
Bouncing ball with Lankarani–Nikravesh contact
==============================================

A solid sphere of radius 0.1 m and mass 1 kg dropped from rest, its lowest point 1 m above a
rigid plane. The contact is a continuous force law, Lankarani and Nikravesh's Hertz contact with
hysteresis damping tuned to a coefficient of restitution e = 0.9
(:class:`core.forces.PlaneContact`, K = 1e7 N/m^1.5),

.. math::

   F_n = K \\delta^{3/2}\\left(1 + \\frac{3(1 - e^2)}{4}\\frac{\\dot\\delta}{\\dot\\delta^{(-)}}\\right),

with :math:`\\delta` the penetration and :math:`\\dot\\delta^{(-)} = \\sqrt{2 g h_0}` the approach
velocity of the first impact. An exact restitution law would give apex heights
:math:`h_i = e^{2i} h_0`: each rebound height is e² times the previous one. The
Lankarani–Nikravesh damping factor is derived for small dissipation and meets this to within a
few per cent for e close to 1 (H. M. Lankarani and P. E. Nikravesh, J. Mech. Des. 112 (1990)
369–376, Eq. 17; its error grows like (1 − e)², P. Flores et al., Multibody Syst. Dyn. 25 (2011)
357–375, Fig. 6).

This script is the scene ``bouncing-ball``: ``mbsuite run bouncing-ball`` runs this very file.
"""

# %%
# Model
# -----
import numpy as np
import pandas as pd

from core import models, plot
from core.integrators import simulate
from core.scenes import scene_run

scene = scene_run("bouncing-ball")

e, h0, radius = 0.9, 1.0, 0.1  # restitution [-], drop height of the ball's bottom [m], radius [m]
model = models.bouncing_ball(radius=radius, restitution=e, height0=h0)
t_end = 1.5 if scene.fast else 3.5

# %%
# Run
# ---
# Radau IIA with a step limit of 1 ms, so that no impact (a few ms long) is stepped over.
res = simulate(model, (0.0, t_end), "radau", rtol=1e-9, atol=1e-11, n_output=4001, max_step=1e-3)

# %%
# Tables
# ------
# The apexes are the local maxima of the centre's height y after the first impact.
y = res.q[:, 1]
k = np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:])) + 1
apex = y[k] - radius
rows = [{"bounce [-]": i + 1, "apex height [m]": float(a), "e^(2i) h0 [m]": h0 * e ** (2 * (i + 1)),
         "ratio to previous [-]": float(a / (apex[i - 1] if i else h0))} for i, a in enumerate(apex)]
scene.table("rebounds", pd.DataFrame(rows))

# %%
# Figures
# -------
history = res.coordinates()
height = history.columns[2]  # the ball's y coordinate
scene.figure("height", plot.plot_time_history(history, [height], ylabel=f"ball centre {height}",
                                              title=f"bouncing ball (e = {e:g}, h0 = {h0:g} m)"))

scene.note("Each rebound height ratio equals e² for an exact restitution law; the Lankarani–Nikravesh "
           "force reproduces e to within a few per cent for e close to 1 (Lankarani & Nikravesh 1990).")
scene.done()
