"""The work-precision scene: the report of ``make run`` (``mbsuite run work-precision``).

Its body is the example script ``examples/core/work_precision.py``, which runs a problem set of
:mod:`core.benchmarks.problems` through :func:`core.benchmarks.harness.run_problem_set` and
writes the tables, figures and notes of :mod:`core.benchmarks.report`; :mod:`core.demo_scenes`
registers it with core's other scenes.
"""

from __future__ import annotations

__all__ = ["work_precision_scenes"]


def work_precision_scenes() -> list:
    """The scenes of the harness, ``[work-precision]`` (as registered by :mod:`core.demo_scenes`).

    ``work-precision`` runs the ``standard`` problem set on the ``standard`` grids (``--fast``:
    the ``quick`` set and grids, one repeat) on the scene's sweep executor (every local core by
    default) and writes one table and one figure per problem plus the fastest-to-tolerance
    summary.
    """
    from ..demo_scenes import SCENES

    return [scene for scene in SCENES if scene.name == "work-precision"]
