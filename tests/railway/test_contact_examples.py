"""The railway example scripts (``examples/railway/``), run as a user runs them.

A user copies an example and runs it with ``python`` from whatever folder they are in; the
script must then find its data through the package (not the working directory) and write the
same output folder as ``mbsuite run NAME`` (tables, README, ``run.json`` saying the mode) into
``MBSUITE_OUT`` (``tests/example_run.py``).
"""

from __future__ import annotations

import pandas as pd
import pytest

from tests.example_run import run_example, tables_written


@pytest.mark.parametrize("script, scene, tables", [
    ("creep_curves.py", "railway-creep-curves",
     ("Fx_vs_xi", "Fy_vs_eta", "Fy_vs_phi", "Fy_vs_eta_with_spin", "excerpt_Fx")),
    pytest.param("contact_geometry.py", "railway-contact-geometry",
                 ("contact_geometry", "excerpt", "summary", "equivalent_conicity", "transitions"),
                 marks=pytest.mark.slow),
    pytest.param("vehicle_curving.py", "railway-curving", ("curving_quasi_static", "lateral_equilibrium", "wheel_events"),
                 marks=pytest.mark.slow),
])
def test_railway_example_runs_by_hand_from_any_folder(tmp_path, script, scene, tables):
    folder = run_example(f"railway/{script}", scene, tmp_path)
    assert tables_written(folder, tables) == []
    assert (folder / "README.md").is_file()


def test_the_flying_wheelset_example_reproduces_klingel_by_hand(tmp_path):
    """Run by hand from another folder, the example gives the scene's wavelength check: within
    1 % of Klingel's with the nominal cone (tests/railway/test_vehicle_scenes.py's tolerance)."""
    folder = run_example("railway/flying_wheelset.py", "railway-flying-wheelset", tmp_path)
    assert tables_written(folder, ("cone_kinematic_wavelength", "s1002_limit_cycle")) == []
    row = pd.read_csv(folder / "cone_kinematic_wavelength.csv").iloc[0]
    assert abs(row["difference cone [-]"]) < 0.01
