"""The contact-mechanics example scripts (``examples/railway/``), run as a user runs them.

A user copies an example and runs it with ``python`` from whatever folder they are in; the
script must then find its data through the package (not the working directory) and write the
same output folder as ``mbsuite run NAME`` (tables, README, ``run.json`` saying the mode) into
``MBSUITE_OUT``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "railway"


@pytest.mark.parametrize("script, scene, tables", [
    ("creep_curves.py", "railway-creep-curves",
     ("Fx_vs_xi", "Fy_vs_eta", "Fy_vs_phi", "Fy_vs_eta_with_spin", "excerpt_Fx")),
    pytest.param("contact_geometry.py", "railway-contact-geometry",
                 ("contact_geometry", "excerpt", "summary", "equivalent_conicity", "transitions"),
                 marks=pytest.mark.slow),
])
def test_contact_example_runs_by_hand_from_any_folder(tmp_path, script, scene, tables):
    env = os.environ | {"MBSUITE_MODE": "fast", "MBSUITE_OUT": str(tmp_path / "out"), "MBSUITE_WORKERS": "1",
                        "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, str(EXAMPLES / script)], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    folder = tmp_path / "out" / scene
    for stem in tables:
        assert (folder / f"{stem}.csv").is_file() and (folder / f"{stem}.md").is_file(), stem
    assert (folder / "README.md").is_file()
    run = json.loads((folder / "run.json").read_text(encoding="utf-8"))
    assert run["mode"] == "fast" and run["scene"] == scene and run["status"] == "ok"
