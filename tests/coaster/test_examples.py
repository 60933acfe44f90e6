"""The coaster example scripts (``examples/coaster/``): the scenes' bodies, run as a user runs them.

A user copies an example and runs it with ``python`` from whatever folder they are in; the script
must then write the same output folder as ``mbsuite run NAME`` (tables, figures, README,
``run.json`` saying the mode) into ``MBSUITE_OUT``.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from coaster.rider import read_acceleration_limits
from coaster.scenes import coaster_scenes
from tests.example_run import run_example, tables_written

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples" / "coaster"


def test_every_coaster_scene_runs_its_example():
    scripts = {"coaster-analytic": "analytic.py", "coaster-circuit": "circuit.py",
               "coaster-from-control-points": "from_control_points.py"}
    assert sorted(p.name for p in EXAMPLES.glob("*.py")) == sorted(scripts.values())
    for scene in coaster_scenes():
        assert scene.run.__doc__ == f"Runs the example script examples/coaster/{scripts[scene.name]}.", scene.name


def test_from_control_points_example_runs_by_hand_from_any_folder(tmp_path):
    """A user's own track from control points: the train finishes it, the rider's loads are judged
    against every row of the limits table."""
    folder = run_example("coaster/from_control_points.py", "coaster-from-control-points", tmp_path)
    assert tables_written(folder, ("ride", "sections", "rider_peaks", "time_above_limits")) == []
    for stem in ("speed", "load_factors", "wheel_forces", "track_3d"):
        assert (folder / f"{stem}.png").is_file(), stem
    assert "Run: finished" in (folder / "README.md").read_text(encoding="utf-8")
    above = pd.read_csv(folder / "time_above_limits.csv")
    assert len(above) == len(read_acceleration_limits()) and above["verdict"].notna().all()
