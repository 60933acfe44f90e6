"""Railway scenes: registration through the entry point and fast smoke runs."""

import pytest

from core.scenes import Scene, run_scene
from railway.scenes import railway_scenes

NAMES = ["railway-contact-geometry", "railway-creep-curves", "railway-two-point-contact",
         "railway-manchester-contact", "railway-flying-wheelset", "railway-critical-speed", "railway-curving",
         "railway-irregular-track", "railway-ride-comfort"]


def test_scene_list():
    scenes = railway_scenes()
    assert [s.name for s in scenes] == NAMES
    assert all(isinstance(s, Scene) for s in scenes)


def test_creep_curves_scene_fast(tmp_path):
    scene = {s.name: s for s in railway_scenes()}["railway-creep-curves"]
    res = run_scene(scene, tmp_path, fast=True)
    ex = res.tables["excerpt_Fx"]
    # at small creepage every law starts on Kalker's slope: |Fx| <= the linear value
    lin = ex["Fx kalker_linear [kN]"].abs()
    for col in ex.columns:
        if col.startswith("Fx "):
            assert (ex[col].abs() <= lin * (1 + 1e-9)).all(), col
    assert (tmp_path / "railway-creep-curves" / "Fx_vs_xi.png").exists()
    assert "Kalker" in res.notes


@pytest.mark.slow
@pytest.mark.parametrize("name", ["railway-contact-geometry", "railway-two-point-contact"])
def test_geometry_scenes_fast(tmp_path, name):
    scene = {s.name: s for s in railway_scenes()}[name]
    res = run_scene(scene, tmp_path, fast=True)
    assert res.tables and res.figures
    assert (tmp_path / name / "README.md").exists()


@pytest.mark.slow
@pytest.mark.parametrize("name", ["railway-flying-wheelset", "railway-critical-speed", "railway-curving",
                                  "railway-irregular-track", "railway-ride-comfort"])
def test_vehicle_scenes_fast(tmp_path, name):
    """The vehicle scenes' fast variants write their tables, figures and README."""
    scene = {s.name: s for s in railway_scenes()}[name]
    res = run_scene(scene, tmp_path, fast=True)
    assert res.tables and res.figures
    assert (tmp_path / name / "README.md").exists()
    for table in res.tables.values():
        assert len(table) > 0


@pytest.mark.slow
def test_ride_comfort_scene_fast_shows_the_bending_mode(tmp_path):
    """At 30 m/s the track excites the car body up to V / 3 m = 10 Hz, above the assumed 9 Hz
    bending: the flexible car body's vertical comfort component at the centre exceeds the rigid
    one's, and the indices are finite for every floor point."""
    scene = {s.name: s for s in railway_scenes()}["railway-ride-comfort"]
    res = run_scene(scene, tmp_path, fast=True)
    t = res.tables["ride_comfort"]
    assert t["N_MV [-]"].notna().all() and (t["N_MV [-]"] > 0).all()
    c = t[t["floor point"] == "centre"].set_index("car body")
    assert c.loc["flexible", "a_ZP95 Wb [m/s2]"] > 1.2 * c.loc["rigid", "a_ZP95 Wb [m/s2]"]
