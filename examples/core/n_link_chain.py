"""
N-link whip chain against its minimal-coordinate reference
==========================================================

A chain of N = 8 uniform links (4 in the fast mode), 1 m and 1 kg in total, hanging from a
pivot and released from rest in the horizontal position: the tip whips through as the chain
falls. The chain is built twice, as a planar model (x, y, θ per link) and as a spatial one
(Euler parameters), and each runs through three integrators of different kinds: the index-2
(GGL) Radau IIA, the generalized-α method of the index-3 equations, and DOP853 with coordinate
projection.

The tip position at t = 1 s is compared with the reference: Lagrange's equations of the chain in
the N absolute link angles (``core_benchmarks.md`` §1), integrated by DOP853 at
rtol = atol = 1e-13 (:func:`core.benchmarks.references.n_link_chain_reference`). The planar and
the spatial model must give the same tip error.

This script is the scene ``n-link-chain``: ``mbsuite run n-link-chain`` runs this very file.
"""

# %%
# Model
# -----
import functools

import numpy as np
import pandas as pd

from core import models, plot
from core.benchmarks.references import n_link_chain_reference
from core.scenes import scene_run
from core.sweep import run_sweep, simulate_case

scene = scene_run("n-link-chain")

n = 4 if scene.fast else 8
tip_reference, _history = n_link_chain_reference(n, 1.0)
chains = {"planar": models.n_link_chain(n, planar=True), "spatial": models.n_link_chain(n, planar=False)}

# %%
# Run
# ---
settings = {
    "radau-ggl rtol=1e-8": ("radau-ggl", dict(rtol=1e-8, atol=1e-10)),
    "generalized-alpha h=1e-4": ("generalized-alpha", dict(h=1e-4)),
    "dop853-projection rtol=1e-8": ("dop853-projection", dict(rtol=1e-8, atol=1e-10)),
}
# The six runs go through the scene's sweep executor (every local core by default); each builds
# its chain in the process that runs it.
runs = [(kind, label) for kind in chains for label in settings]
cases = [dict(system=functools.partial(models.n_link_chain, n, planar=kind == "planar"), t_span=(0.0, 1.0),
              method=settings[label][0], n_output=101, **settings[label][1]) for kind, label in runs]
results = dict(zip(runs, run_sweep(simulate_case, cases, executor=scene.executor)))

# %%
# Tables
# ------
# The tip error at t = 1 s in the plane of the motion, with each run's counters and violations.
rows = []
for (kind, label), res in results.items():
    tip = models.chain_tip(chains[kind], res.q[-1])
    error = float(np.linalg.norm(tip[:2] - tip_reference[:2])) if res.success else np.nan
    rows.append(res.summary_row(label, {"model": kind, "tip error [m]": error}))
scene.table("tip_error", pd.DataFrame(rows))

# %%
# Figures
# -------
# The tip's path and the constraint violations of the planar chain under Radau IIA (GGL).
model, res = chains["planar"], results["planar", "radau-ggl rtol=1e-8"]
tips = np.array([models.chain_tip(model, q) for q in res.q])
path = pd.DataFrame({"t [s]": res.t, "tip x [m]": tips[:, 0], "tip y [m]": tips[:, 1]})
path.attrs.update(meta=res.meta, status=res.status)
subject = f"{n}-link chain (planar)"
scene.figure("tip_path", plot.plot_xy_path(path, "tip x [m]", "tip y [m]", title=subject))
scene.figure("violations", plot.plot_violations(res, title=subject))

scene.note(f"N = {n} uniform links, total 1 m and 1 kg, released horizontally (core_benchmarks.md §1). "
           "Reference: minimal-coordinate ODE, DOP853 at rtol = atol = 1e-13. The planar and spatial "
           "(Euler parameter) models must give the same tip error.")
scene.done()
