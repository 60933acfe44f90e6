"""The energy-drift check scales with the requested tolerance (core.simulation.result_checks).

Oracles: the energy m g y of a pendulum bob, whose height the error control holds to
atol + rtol |y| (|y| ≈ 1 m below the pivot whatever the amplitude), and the check's own formula
applied to a drift made to measure.
"""

import numpy as np
import pytest

from core import simulate
from core.models import G_EARTH, simple_pendulum
from core.simulation import ENERGY_WARN_FACTOR, result_checks


def _energy_warnings(r):
    return [w for w in r.warnings if w.startswith("energy drift")]


def test_a_run_that_meets_its_tolerance_is_not_warned_about():
    """bdf at rtol 1e-11 on a 0.01 rad pendulum: drift 1.3e-10 J, i.e. a height error of
    1.3 (rtol · 1 m + atol): within its tolerance.  The former limit, rtol × the peak kinetic
    energy (4.9e-4 J) + atol (|M v| + |Q|), allowed 1e-11 J and called it "12.8 ×"."""
    m = simple_pendulum(bob="point", angle0=0.01)
    rtol, atol = 1e-11, 1e-12
    r = simulate(m, (0.0, 2.0), "bdf", rtol=rtol, atol=atol, n_output=41)
    drift = float(np.max(np.abs(r.energy - r.energy[0])))
    height_error = drift / (1.0 * G_EARTH)  # m g δy, m = 1 kg
    assert height_error < ENERGY_WARN_FACTOR * (rtol * 1.0 + atol)  # it met its tolerance ...
    assert drift > 3.0 * (rtol * 4.9e-4 + atol * 10.0)  # ... and the former check would have warned
    assert not _energy_warnings(r), r.warnings


def test_a_run_whose_drift_exceeds_its_tolerance_is_still_warned_about():
    """bdf at rtol 1e-8 on a 1 rad pendulum: drift 1.9e-6 J, a height error of 200 (rtol · 1 m):
    warned; so is rk45 at rtol 1e-3 from horizontal (tests/core/test_error_checks.py)."""
    m = simple_pendulum(bob="point", angle0=1.0)
    r = simulate(m, (0.0, 2.0), "bdf", rtol=1e-8, atol=1e-10, n_output=41)
    assert r.status == "finished with warnings"
    w = _energy_warnings(r)
    assert w and "what the tolerances allow" in w[0] and "Σ|Q_j q_j|" in w[0]


@pytest.mark.parametrize("rtol", [1e-4, 1e-8, 1e-11])
def test_the_limit_scales_with_the_tolerance(rtol):
    """The same motion with a drift of k × (rtol (E_kin + Σ|Q_j q_j|) + atol p): warned for k above
    the factor, not below, at every tolerance."""
    m = simple_pendulum(bob="point", angle0=0.3)
    r = simulate(m, (0.0, 1.0), "radau", rtol=1e-10, atol=1e-12, n_output=21)
    t, Q, V = r.t, r.q, r.v
    atol = 1e-2 * rtol
    kinetic = max(0.5 * float(V[i] @ (m.M(t[i], Q[i]) @ V[i])) for i in range(len(t)))
    qQ = max(float(np.sum(np.abs(m.Q(t[i], Q[i], V[i]) * Q[i]))) for i in range(len(t)))
    p = max(float(np.sum(np.abs(m.M(t[i], Q[i]) @ V[i]))) + float(np.sum(np.abs(m.Q(t[i], Q[i], V[i]))))
            for i in range(len(t)))
    allowed = rtol * (kinetic + qQ) + atol * p
    assert qQ == pytest.approx(G_EARTH * np.max(np.abs(Q[:, 1])), rel=1e-12)  # m g |y|, only y is loaded
    E0 = float(r.energy[0])
    for k, warned in ((0.5 * ENERGY_WARN_FACTOR, False), (2.0 * ENERGY_WARN_FACTOR, True)):
        energy = E0 + k * allowed * np.linspace(0.0, 1.0, len(t))
        out = [w for w in result_checks(m, t, Q, V, energy, np.zeros(len(t)), rtol, atol) if w.startswith("energy")]
        assert bool(out) == warned, (rtol, k, out)
