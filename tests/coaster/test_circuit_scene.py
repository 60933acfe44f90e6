"""The ``coaster-circuit`` scene end to end (fast mode): files written, the main run completes the
circuit, energy conserved on the free-running section, the lossy run's outcome reported, rank 71."""

from __future__ import annotations

import pandas as pd
import pytest

from coaster.scenes import circuit_scene, coaster_scenes
from core.scenes import run_scene


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    d = tmp_path_factory.mktemp("scene")
    run_scene(circuit_scene(), d, fast=True)
    return d / "coaster-circuit"


def test_registered():
    assert [s.name for s in coaster_scenes()] == ["coaster-analytic", "coaster-circuit", "coaster-from-control-points"]


def test_circuit_scene_outputs(out):
    for f in ("runs.csv", "energy_drift.csv", "section_peaks.csv", "time_above_limits.csv", "wheel_forces.csv",
              "rider_loads.csv", "speed.csv", "circuit_3d.png", "speed.png", "wheel_forces.png", "README.md"):
        assert (out / f).is_file(), f
    runs = pd.read_csv(out / "runs.csv")
    assert runs["status"].iloc[0] == "finished", runs["message"].iloc[0]
    assert runs["status"].iloc[1] in ("finished", "rolled back")
    if runs["status"].iloc[1] == "rolled back":
        assert "rolls back" in runs["message"].iloc[1]
    assert pd.read_csv(out / "energy_drift.csv")["max|E - E0| / T_peak"].iloc[0] < 1e-6
    rank = pd.read_csv(out / "rank_along_circuit.csv")
    assert rank["rank min"].iloc[0] == 71 and rank["rank max"].iloc[0] == 71
    peaks = pd.read_csv(out / "section_peaks.csv")
    assert {"Lift", "Outbound", "Launch", "Brake"} <= set(peaks["section"])


def test_circuit_frame_quality(out):
    """The rotation-minimising frame along the whole circuit: orthonormal, on the centreline, and
    without a jump (the rotation between neighbouring samples equals |Omega| dL)."""
    fq = pd.read_csv(out / "frame_quality_summary.csv").iloc[0]
    assert fq["max |R^T R - I| [-]"] < 1e-8
    assert fq["max |t - g'| [-]"] < 1e-8
    assert fq["max |r - g| [m]"] < 1e-7
    # a jump (a Frenet flip) gives a ratio of order pi / (|Omega| dL) >> 1; a smooth frame differs
    # from the midpoint rate by O(dL^2 |Omega''| / |Omega|): 1.7 % at the fast mode's 5 m samples
    assert fq["max rotation step / (|omega| dL) [-]"] < 1.05
    assert fq["frame closure max |R(length) - R(0)| [-]"] < 1e-9
    assert (out / "frame_quality.png").is_file()


def test_circuit_scene_bank_study_and_warm_up(out):
    """Issue 21: the circuit's outward bank is flagged in the notes, the designed bank lowers the rider's
    lateral load, and the real-time factor is of a run after the compiling warm-up (reported on its own)."""
    runs = pd.read_csv(out / "runs.csv")
    assert runs["compilation + warm-up wall [s]"].iloc[0] > 0
    bank = pd.read_csv(out / "bank_design.csv")
    assert bank["outward share of v2k [-]"].iloc[0] > 0.9 and bank["outward share of v2k [-]"].iloc[1] < 0.05
    assert bank["rider |n_y| RMS [g]"].iloc[1] < 0.25 * bank["rider |n_y| RMS [g]"].iloc[0]
    assert (bank["run status"] == "finished").all()
    assert "OutwardBankWarning" in (out / "README.md").read_text()
