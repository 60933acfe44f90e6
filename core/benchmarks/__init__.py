"""Benchmark machinery: work-precision problems, their reference solutions, the harness and the report.

==================  ===========================================================================
module              holds
==================  ===========================================================================
``problems``        :class:`WorkPrecisionProblem`, :class:`Grid`, the registry :data:`PROBLEMS`
                    with every problem definition, and :data:`PROBLEM_SETS`
``references``      the reference solutions (chain, stiff chain, pendulum, IFToMM A02 and A04)
``testset``         Andrews' squeezer and the car axis of the IVP test set (generalized coordinates)
``harness``         runs integrators over tolerance / step-size grids into one tidy table
``report``          fastest run per error target, work-precision figures, CSV/Markdown/PNG writers
``scenes``          the ``work-precision`` scene of ``make run`` (examples/core/work_precision.py)
==================  ===========================================================================

The command ``mbsuite bench`` lives in :mod:`core.cli`.  ``import core`` does not import this
package; importing it imports neither the models nor the integrators (they load on first use).
"""

from __future__ import annotations

from .harness import (
    COLUMNS,
    COUNTERS,
    DETERMINISTIC_COLUMNS,
    MAX_REPEAT_TIME,
    available_methods,
    run_problem_set,
    run_problems,
    run_work_precision,
)
from .problems import (
    GRID_NAMES,
    PROBLEM_SETS,
    PROBLEMS,
    Grid,
    WorkPrecisionProblem,
    problem_sets,
    register_problem,
)
from .references import (
    iftomm_a02_reference,
    iftomm_a04_reference,
    n_link_chain_reference,
    pendulum_angle_exact,
    stiff_chain_rhs,
    stiff_chain_tip_reference,
)
from .report import (
    REPORT_COLUMNS,
    fastest_to_tolerance,
    report_table,
    work_precision_figure,
    work_precision_notes,
    write_work_precision,
)
from .scenes import work_precision_scenes
from .testset import AndrewsSqueezer, CarAxis

__all__ = [
    "COLUMNS",
    "MAX_REPEAT_TIME",
    "COUNTERS",
    "DETERMINISTIC_COLUMNS",
    "GRID_NAMES",
    "PROBLEMS",
    "PROBLEM_SETS",
    "REPORT_COLUMNS",
    "AndrewsSqueezer",
    "CarAxis",
    "Grid",
    "WorkPrecisionProblem",
    "available_methods",
    "fastest_to_tolerance",
    "iftomm_a02_reference",
    "iftomm_a04_reference",
    "n_link_chain_reference",
    "pendulum_angle_exact",
    "problem_sets",
    "register_problem",
    "report_table",
    "run_problem_set",
    "run_problems",
    "run_work_precision",
    "stiff_chain_rhs",
    "stiff_chain_tip_reference",
    "work_precision_figure",
    "work_precision_notes",
    "work_precision_scenes",
    "write_work_precision",
]
