"""Old module paths (before the split into railway.contact / railway.vehicles / railway.cli, issue
22) keep working: the same module object, a DeprecationWarning naming the new place, attributed
to the importing line; a module that never existed still raises ModuleNotFoundError."""

from __future__ import annotations

import importlib
import importlib.metadata
import sys
import warnings

import pytest

import railway
from railway.moved_modules import MOVED


@pytest.fixture
def fresh(monkeypatch):
    """Forget the old names, so that importing one goes through the finder again."""
    for old in MOVED:
        monkeypatch.delitem(sys.modules, old, raising=False)


@pytest.mark.parametrize("old, new", sorted(MOVED.items()))
def test_old_path_is_the_same_module_and_warns(fresh, old, new):
    with pytest.warns(DeprecationWarning, match=f"^{old} moved to {new}$"):
        mod = importlib.import_module(old)
    assert mod is importlib.import_module(new)
    assert sys.modules[old] is sys.modules[new]
    assert mod.__name__ == new and mod.__spec__.name == new  # its own spec, not the alias's


def test_import_statements_of_old_paths(fresh):
    with pytest.warns(DeprecationWarning) as record:
        import railway.profiles
        from railway.contact_search import ContactSearch
        from railway.wheel_rail import contact_history
    from railway.contact.profiles import WheelProfile
    from railway.contact.search import ContactSearch as NewContactSearch
    from railway.vehicles.wheel_rail import contact_history as new_contact_history

    assert railway.profiles.WheelProfile is WheelProfile
    assert ContactSearch is NewContactSearch and contact_history is new_contact_history
    assert [str(w.message) for w in record] == [
        "railway.profiles moved to railway.contact.profiles",
        "railway.contact_search moved to railway.contact.search",
        "railway.wheel_rail moved to railway.vehicles.wheel_rail",
    ]
    # the warning points at the importing line, not at the import machinery
    assert {w.filename for w in record} == {__file__}


def test_old_path_as_attribute_of_the_package(fresh):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        assert railway.vehicle is importlib.import_module("railway.vehicles.vehicle")
    with pytest.raises(AttributeError, match="no_such_thing"):
        railway.no_such_thing  # noqa: B018


def test_monkeypatch_through_the_old_path_is_seen_by_the_new(fresh, monkeypatch):
    with pytest.warns(DeprecationWarning):
        old = importlib.import_module("railway.creep")
    monkeypatch.setattr(old, "_patched_by_test", 1, raising=False)
    assert importlib.import_module("railway.contact.creep")._patched_by_test == 1


@pytest.mark.parametrize("name", ["railway.no_such_module", "railway.contact.no_such_module",
                                  "railway.vehicles.no_such_module"])
def test_a_module_that_never_existed_is_still_not_found(name):
    with pytest.raises(ModuleNotFoundError, match=name.replace(".", r"\.")):
        importlib.import_module(name)


def test_public_names_of_the_package_are_unchanged():
    assert set(railway.__all__) == {
        "ContactForces", "ContactResult", "ContactSearch", "Curve", "Irregularities",
        "IrregularityStepWarning", "RailMounting", "RailwayInputWarning", "RailProfile", "RailSurface",
        "Straight", "SuspensionGeometryWarning", "Track", "TrackFrame", "Transition", "Vehicle",
        "VehicleDefinition", "WheelProfile", "WheelRailContact", "WheelSurface", "build_vehicle",
        "conicity_table", "contact_geometry_table", "contact_history", "contact_transitions",
        "equivalent_conicity", "flange_contact_onset", "parse_inclination", "quasi_static_contact",
        "quasi_static_summary", "read_profile_file", "rigid_contact", "s1002_exact", "uic60_exact",
        "wheelset_pose",
    }
    for name in railway.__all__:
        assert getattr(railway, name) is not None


def test_entry_points_resolve():
    eps = importlib.metadata.entry_points()
    command = next(e for e in eps.select(group="mbsuite.commands") if e.name == "railway")
    scenes = next(e for e in eps.select(group="mbsuite.scenes") if e.name == "railway")
    from railway.cli import register
    from railway.scenes import railway_scenes

    assert command.load() is register and scenes.load() is railway_scenes
