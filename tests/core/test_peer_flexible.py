"""Consistency of the Exudyn peer models of ``benchmarks/peer_flexible.py`` with mbsuite (not timed).

Skipped when Exudyn (the optional ``bench`` extra) is not installed.  The benchmark hands mbsuite's
reduced beam component to Exudyn's ``ObjectFFRFreducedOrder`` as inertia invariants computed from
mbsuite's own fields; these tests check that Exudyn's flexible body then has mbsuite's mass matrix,
that its forces differ from mbsuite's exactly by the terms the benchmark names as missing
(``_missing_terms``: Exudyn's equations assume a mass matrix M_s ⊗ I₃, a beam's is not), and that the
spin-up beam, whose hub does not translate, moves alike in both codes.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("exudyn")

_BENCH = Path(__file__).resolve().parents[2] / "benchmarks"


@pytest.fixture(scope="module")
def pf():
    sys.path.insert(0, str(_BENCH))
    try:
        spec = importlib.util.spec_from_file_location("peer_flexible", _BENCH / "peer_flexible.py")
        mod = importlib.util.module_from_spec(spec)
        sys.modules["peer_flexible"] = mod  # dataclasses look their module up there
        spec.loader.exec_module(mod)
        yield mod
    finally:
        sys.modules.pop("peer_flexible", None)
        sys.path.remove(str(_BENCH))


@pytest.mark.parametrize("name", ["spin-up", "slider-crank"])
def test_exudyn_body_has_mbsuite_mass_matrix_and_forces_up_to_the_named_terms(pf, name):
    case = pf.spin_up_case(1e-6) if name == "spin-up" else pf.slider_crank_case(1e-4)
    xm = pf.build_exudyn(case)
    for seed in (1, 2):
        chk = pf.check_exudyn_against_mbsuite(xm, seed=seed)
        assert chk["mass matrix"] < 1e-12
        assert chk["forces + missing terms"] < 1e-10
        assert chk["forces"] > 1e3 * chk["forces + missing terms"]  # the terms are there, and they are these
        if name == "spin-up":  # with the hub at rest in translation they act on the reaction only
            assert chk["modal forces, frame not translating"] < 1e-12


def test_spin_up_moves_alike_in_both_codes(pf):
    """0–2 s of the spin-up (no stiffening): Exudyn's generalized-α at h = 1 ms and mbsuite's
    radau-projection at rtol 1e-9 agree within 1e-5 of the peak tip deflection (measured 2e-7)."""
    case = pf.spin_up_case(1e-6)
    xm = pf.build_exudyn(case)
    r = pf.exudyn_solve(xm, pf.exc.SolverOptions("GeneralizedAlpha", implicit=True), h=1e-3, t_end=2.0)
    assert r.ok, r.message
    n = len(r.t)
    np.testing.assert_allclose(r.t, case.grid[:n], atol=1e-9)
    v_ex = pf.quantity_from_modes(case, r.t, r.frame, r.qf)
    res = pf.simulate(case.model, (0.0, 2.0), "radau-projection", t_eval=case.grid[:n], rtol=1e-9, atol=1e-9,
                      compute_multipliers=False)
    assert res.success, res.message
    v_mb = pf.mbsuite_quantity(case, np.asarray(res.t), np.asarray(res.q))
    peak = np.max(np.abs(v_mb))
    assert peak > 0.01
    assert np.max(np.abs(v_ex - v_mb)) < 1e-5 * peak
