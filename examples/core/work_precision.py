"""
Work-precision: error against run time for every integrator
===========================================================

Every registered integrator on the benchmark problems of ``core_benchmarks.md``: the N-link
chain (rigid, planar and spatial; with stiff springs), Andrews' squeezer and the car axis of the
Test Set for IVP Solvers, the pendulum over 100 s and the IFToMM Bricard mechanism A04. Each
method runs over a grid of settings (relative tolerances for error-controlled methods, step sizes
for fixed-step ones) and each run gives one point of a work-precision diagram: its error at the
end against an independent reference, against the median wall time spent in the integrator's
steps (E. Hairer and G. Wanner, *Solving Ordinary Differential Equations II*, Springer, 1996,
Sec. IV.10). The summary scores the methods as the IFToMM benchmark does, by the time needed to
reach an error target (M. González et al., Multibody Syst. Dyn. 16 (2006) 179–190).

The fast mode runs the ``quick`` problem set and grids once; the default the ``standard`` ones,
three repeats per run; ``--full`` every registered problem (the stiff chains with k = 1e8 among
them) on the ``full`` grids. The runs go through the scene's sweep executor: every local core by
default (``mbsuite run work-precision --workers N``, or ``MBSUITE_WORKERS=N`` when run by hand).

This script is the scene ``work-precision``: ``mbsuite run work-precision`` runs this very file.
"""

# %%
# Model
# -----
# The problems are registered in :mod:`core.benchmarks.problems`, each with its reference.
from core.benchmarks import (fastest_to_tolerance, problem_sets, report_table, run_problem_set,
                             work_precision_figure, work_precision_notes)
from core.scenes import scene_run
from core.sweep import executor_workers

scene = scene_run("work-precision")

grid = scene.mode if scene.mode in ("fast", "full") else "standard"
grid = "quick" if grid == "fast" else grid
problems = problem_sets()[grid]

# %%
# Run
# ---
# One sweep over every (problem, method, setting): a tidy table, one row per run.
runs = run_problem_set(problems, grid, repeats=1 if scene.fast else 3, executor=scene.executor)

# %%
# Tables
# ------
# One table per problem (error, wall time, violations, energy drift, counters, status), and the
# fastest run of each method to every error target.
for problem in problems:
    scene.table(f"wp_{problem}", report_table(runs[runs["problem"] == problem].reset_index(drop=True)))
scene.table("wp_summary", report_table(fastest_to_tolerance(runs)))

# %%
# Figures
# -------
for problem in problems:
    scene.figure(f"wp_{problem}", work_precision_figure(runs, problem))

scene.note(work_precision_notes(problems, grid, executor_workers(scene.executor)))
scene.done()
