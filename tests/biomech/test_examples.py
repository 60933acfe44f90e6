"""The biomechanics example scripts (``examples/biomech/``): the scenes' bodies, run as a user runs them.

A user copies an example, puts their own OpenSim files in its "your files here" block and runs it
with ``python`` from whatever folder they are in; the script must then write the same output folder
as ``mbsuite run NAME`` (tables, figures, README, ``run.json`` saying the mode) into ``MBSUITE_OUT``.
"""

from __future__ import annotations

from pathlib import Path

from biomech.scenes import biomech_scenes
from tests.example_run import run_example, tables_written

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples" / "biomech"


def test_every_biomech_scene_runs_its_example():
    scenes = biomech_scenes()
    assert sorted(p.name for p in EXAMPLES.glob("*.py")) == sorted(s.name.replace("-", "_") + ".py" for s in scenes)
    for scene in scenes:
        script = scene.name.replace("-", "_") + ".py"
        assert scene.run.__doc__ == f"Runs the example script examples/biomech/{script}.", scene.name


def test_gait_inverse_dynamics_example_runs_by_hand_from_any_folder(tmp_path):
    folder = run_example("biomech/gait_inverse_dynamics.py", "gait-inverse-dynamics", tmp_path)
    assert tables_written(folder, ("joint_moments_summary", "pelvis_residuals", "anthropometric_model_vs_gait10dof",
                                   "timing", "joint_moments", "joint_reactions")) == []
    assert (folder / "joint_moments.png").is_file()
