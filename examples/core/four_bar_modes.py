"""
Four-bar: static equilibrium and modes
======================================

A four-bar linkage of uniform slender rods (1 kg/m; ground 0.4 m, crank 0.1 m, coupler 0.35 m,
rocker 0.3 m: a Grashof crank–rocker) under gravity, crank at 90° and at rest, one degree of
freedom. Three analyses of the same model:

* static equilibrium, :math:`Q(q) - \\Phi_q^T\\lambda = 0` with :math:`\\Phi(q) = 0`, found by
  descent of the potential energy on the constraint manifold (a stable equilibrium);
* the eigenvalues :math:`s` of the constrained system linearised about that equilibrium,
  :math:`(s^2 M_r + s (D_r + G_r) + K_r)\\,z = 0` in the coordinates :math:`z` of the null space
  of :math:`\\Phi_q` (one pendulum-like mode);
* a free swing from the initial configuration by the index-2 (GGL) Radau IIA, whose constraint
  violations and energy drift show the quality of the integration.

This script is the scene ``four-bar-modes``: ``mbsuite run four-bar-modes`` runs this very file.
"""

# %%
# Model
# -----
from core import analysis, models, plot
from core.integrators import simulate
from core.scenes import scene_run

scene = scene_run("four-bar-modes")

model = models.four_bar(crank_rate0=0.0)  # released from rest
t_end = 0.5 if scene.fast else 3.0

# %%
# Run
# ---
equilibrium = analysis.static_equilibrium(model, method="energy")
modes, _shapes = analysis.eigen(model, q=equilibrium.q)
res = simulate(model, (0.0, t_end), "radau-ggl", rtol=1e-8, atol=1e-10, n_output=301)

# %%
# Tables
# ------
scene.table("equilibrium", equilibrium.coordinates())
scene.table("modes", modes)

# %%
# Figures
# -------
scene.figure("violations", plot.plot_violations(res, title="four-bar under gravity"))
scene.figure("energy", plot.plot_energy(res, title="four-bar under gravity"))

scene.note("Static equilibrium by energy descent on Φ = 0, then eigenvalues of the linearisation about it.")
scene.done()
