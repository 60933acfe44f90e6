"""Core demo scenes: canonical models run through the integrators and analyses.

Each scene checks its numbers against an independent oracle (closed form, published value or
minimal-coordinate reference) and puts the comparison into its tables, so the output folder is
a small validation report.  The body of each scene is an example script under
``examples/core/`` (:func:`core.scenes.example_scene`): ``mbsuite run NAME`` runs the very file
a user reads and copies.  Importing this module registers the scenes
(:func:`core.scenes.all_scenes` imports it lazily).
"""

from __future__ import annotations

from .scenes import example_scene, register_scene

SCENES = [
    example_scene("pendulum", "core/pendulum.py", "Simple pendulum: period and rod tension vs closed form",
                  "IFToMM A01 geometry at small amplitude; exact elliptic-integral period."),
    example_scene("slider-crank", "core/slider_crank.py", "Slider crank: kinematic analysis and driver torque",
                  "Closed-form slider position; inverse dynamics of the driven crank."),
    example_scene("n-link-chain", "core/n_link_chain.py", "N-link whip chain vs minimal-coordinate reference",
                  "core_benchmarks.md §1, planar and spatial models."),
    example_scene("four-bar-modes", "core/four_bar_modes.py", "Four-bar: static equilibrium and modes",
                  "Linearised constrained system."),
    example_scene("bouncing-ball", "core/bouncing_ball.py", "Bouncing ball with Lankarani–Nikravesh contact",
                  "Rebound heights vs e²."),
    example_scene("andrews", "core/andrews.py", "Andrews' squeezer (seven angles) vs published reference",
                  "Hairer & Wanner II §VII.7; Test Set for IVP Solvers."),
    example_scene("flexible-spin-up-beam", "core/flexible_spin_up_beam.py",
                  "Spin-up beam: flexible body with and without geometric stiffening",
                  "Kane, Ryan & Banerjee (1987); floating frame with cantilever modes against a geometrically exact "
                  "rigid-link chain.", full_adds="chains of 20 and 40 links as the reference."),
    example_scene("flexible-slider-crank", "core/flexible_slider_crank.py",
                  "Slider crank with an elastic rod: published model, flexible body and rigid-link rod",
                  "Simeon (1996); Test Set for IVP Solvers 'crank'.",
                  full_adds="16 elements and 5 modes; rigid-link rods of 16 and 32 links."),
    example_scene("sar-antenna", "core/sar_antenna.py",
                  "SAR antenna unfolding: actuator moments with rigid and flexible panels",
                  "After Anantharaman & Hiller (1991) and Ambrósio's review (Figs 27-28), all data assumed; "
                  "one panel against the exact cantilever modes.",
                  full_adds="a grid of deployment times, the bisected time where the flexible moments exceed "
                            "the rigid ones by 10 %, and two fixed-interface modes per panel."),
    # the work-precision report is part of the main job (``make run``)
    example_scene("work-precision", "core/work_precision.py",
                  "Work-precision: error against run time for every integrator",
                  "Every registered integrator on the benchmark problems of core_benchmarks.md (N-link chain "
                  "rigid/spatial/stiff, Andrews' squeezer, car axis, 100-s pendulum) over tolerance or step-size "
                  "grids: error against median wall time, constraint violations, energy drift, counters and "
                  "status (core.benchmarks).",
                  full_adds="every registered problem (the stiff chains with k = 1e8 among them) on the full "
                            "tolerance and step-size grids."),
]

for _s in SCENES:
    register_scene(_s)
