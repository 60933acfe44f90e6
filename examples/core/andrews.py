"""
Andrews' squeezer against its published solution
=================================================

Andrews' squeezing mechanism: seven rigid bodies in a plane, a closed-loop mechanism driven by a
constant torque at the crank against a spring, written as an index-3 DAE in the seven angles
:math:`q = (\\beta, \\Theta, \\gamma, \\Phi, \\delta, \\Omega, \\varepsilon)`,

.. math::

   M(q)\\,\\ddot q = f(q, \\dot q) - G(q)^T\\lambda, \\qquad 0 = g(q), \\qquad G = \\partial g/\\partial q,

with six constraints closing the two loops (E. Hairer and G. Wanner, *Solving Ordinary
Differential Equations II*, Springer, 1996, Sec. VII.7). It is a model written directly in
generalized coordinates (:class:`core.benchmarks.testset.AndrewsSqueezer`), not a Cartesian
model, and runs through the same integrators: the index-2 (GGL) Radau IIA, Radau IIA with
coordinate projection, and the generalized-α method of the index-3 equations.

Reference: the angles at t = 0.03 s published with the Test Set for IVP Solvers (F. Mazzia and
C. Magherini, release 2.4, 2008, problem ``andrews.f``).

This script is the scene ``andrews``: ``mbsuite run andrews`` runs this very file.
"""

# %%
# Model
# -----
import numpy as np
import pandas as pd

from core import plot
from core.benchmarks.testset import AndrewsSqueezer
from core.scenes import scene_run
from core.sweep import run_sweep, simulate_case

scene = scene_run("andrews")

squeezer = AndrewsSqueezer()
q_reference = np.asarray(squeezer.reference["q"])  # the seven angles at t = 0.03 s [rad]

# %%
# Run
# ---
settings = {
    "radau-ggl rtol=1e-10": ("radau-ggl", dict(rtol=1e-10, atol=1e-12)),
    "radau-projection rtol=1e-10": ("radau-projection", dict(rtol=1e-10, atol=1e-12)),
    "generalized-alpha h=1e-6": ("generalized-alpha", dict(h=1e-5 if scene.fast else 1e-6)),  # fast: 1e-5
}
# The three runs go through the scene's sweep executor (every local core by default).
cases = [dict(system=AndrewsSqueezer, t_span=(0.0, 0.03), method=method, n_output=301, **options)
         for method, options in settings.values()]
results = dict(zip(settings, run_sweep(simulate_case, cases, executor=scene.executor)))

# %%
# Tables
# ------
# The largest relative error of the seven angles at the end, with each run's counters.
rows = []
for label, res in results.items():
    error = np.max(np.abs(res.q[-1] - q_reference) / np.maximum(np.abs(q_reference), 1e-300))
    rows.append(res.summary_row(label, {
        "max rel. angle error at 0.03 s [-]": float(error) if res.success else np.nan}))
scene.table("andrews_at_0.03s", pd.DataFrame(rows))

# %%
# Figures
# -------
# The index-2 (GGL) run: its position and velocity violations are the method's own.
scene.figure("violations", plot.plot_violations(results["radau-ggl rtol=1e-10"],
                                                title="Andrews' squeezer (seven angles)"))

scene.note("Reference: Test Set for IVP Solvers (Mazzia & Magherini), andrews.f; see core/benchmarks/testset.py.")
scene.done()
