"""Core's example scripts (``examples/core/``): the scenes' bodies, run as a user runs them.

A user copies an example and runs it with ``python``, from whatever folder they are in; the
script must then write the same output folder as ``mbsuite run NAME`` (tables, figures, README,
``run.json`` saying the mode), into ``MBSUITE_OUT``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from core import demo_scenes

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples" / "core"


def test_every_core_example_is_a_registered_scene():
    """Each script of examples/core is the body of the core scene of its name (``n_link_chain.py``:
    ``n-link-chain``), and every core scene runs its script."""
    scripts = sorted(path.name for path in EXAMPLES.glob("*.py"))
    scenes = sorted(demo_scenes.SCENES, key=lambda scene: scene.name.replace("-", "_"))
    assert scripts == [scene.name.replace("-", "_") + ".py" for scene in scenes]
    for scene, script in zip(scenes, scripts):
        assert scene.run.__doc__ == f"Runs the example script examples/core/{script}.", scene.name


def test_slider_crank_example_runs_by_hand_from_any_folder(tmp_path):
    env = os.environ | {"MBSUITE_MODE": "fast", "MBSUITE_OUT": str(tmp_path / "out"), "MBSUITE_WORKERS": "1",
                        "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, str(EXAMPLES / "slider_crank.py")], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    folder = tmp_path / "out" / "slider-crank"
    for stem in ("kinematics", "driver_torque", "max_error"):
        assert (folder / f"{stem}.csv").is_file() and (folder / f"{stem}.md").is_file(), stem
    for stem in ("slider_position", "driver_torque"):
        assert (folder / f"{stem}.png").is_file(), stem
    run = json.loads((folder / "run.json").read_text(encoding="utf-8"))
    assert run["mode"] == "fast" and run["scene"] == "slider-crank" and run["status"] == "ok"
