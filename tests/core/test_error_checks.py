"""No silent wrong answers: the error checks of fixed-step methods and of every finished run.

A run reaches the end time as ``"finished"`` only when no check doubts it; otherwise
``"finished with warnings"`` (the message names the estimate) or ``"failed"`` (time and cause).
The rules are in :mod:`core.integrators.base` (fixed-step global error estimate) and
:func:`core.simulation.result_checks` (energy of conservative systems, constraint drift).
"""

from __future__ import annotations

import numpy as np
import pytest

from core import simulate
from core.benchmarks.references import pendulum_angle_exact
from core.errors import InputError
from core.integrators import METHODS
from core.models import G_EARTH, simple_pendulum
from core.results import FINISHED_STATUSES

T_END = 2.0
T_EVAL = np.linspace(0.0, T_END, 41)


@pytest.fixture(scope="module")
def pendulum():
    """IFToMM A01: 1 kg point mass on a massless 1 m link released from horizontal (conservative)."""
    model = simple_pendulum(bob="point")
    theta = np.array([pendulum_angle_exact(t, np.pi / 2, 1.0, G_EARTH) for t in T_EVAL])
    exact_xy = np.stack([np.sin(theta), -np.cos(theta)], axis=1)
    return model, exact_xy


def _settings(cls):
    """Coarse and fine settings: steps for fixed-step methods, tolerances for adaptive ones."""
    if cls.fixed_step:
        return [dict(h=0.02, rtol=1e-4, atol=1e-6), dict(h=0.005, rtol=1e-4, atol=1e-6)]
    return [dict(rtol=1e-3, atol=1e-5), dict(rtol=1e-7, atol=1e-9)]


@pytest.mark.parametrize("method", sorted(METHODS))
def test_no_clean_finish_with_an_error_beyond_ten_tolerances(pendulum, method):
    """Every integrator, coarse and fine: a run whose position error exceeds 10 × (atol + rtol · 1 m)
    at any output must not report a plain "finished"."""
    model, exact_xy = pendulum
    cls = METHODS[method]
    if cls.applicable(model) is not None:
        pytest.skip(cls.applicable(model))
    for kw in _settings(cls):
        r = simulate(model, (0.0, T_END), method, t_eval=T_EVAL, **kw)
        assert r.status in ("finished", "finished with warnings", "failed")
        if r.status == "failed":
            assert " failed at t = " in r.message
            continue
        err = float(np.max(np.abs(r.q[:, :2] - exact_xy)))
        tol = kw["atol"] + kw["rtol"] * 1.0
        if err > 10 * tol:
            assert r.status == "finished with warnings", (
                f"{method} {kw}: error {err:.3g} m = {err / tol:.3g} × tolerance, reported {r.message!r}")
            assert r.warnings and r.message.count("warning:") == len(r.warnings)


@pytest.mark.parametrize("method,h", [("generalized-alpha", 0.01), ("hem3", 0.01), ("jit-rk4", 0.02),
                                      ("jit-rk4-projection", 0.05)])
def test_fixed_step_estimate_tracks_the_global_error(pendulum, method, h):
    """The summed local estimate is within a factor 3 of the true error (measured 0.3–2.2 on this
    pendulum over h = 2e-3 … 5e-2 for hem3, hem4, generalized-alpha and hht; 0.75–2.4 for the
    jit-rk4 variants where the estimate exceeds 1, computed in their compiled loop)."""
    model, exact_xy = pendulum
    r = simulate(model, (0.0, T_END), method, t_eval=T_EVAL, h=h, rtol=1e-6, atol=1e-8)
    err = float(np.max(np.abs(r.q[:, :2] - exact_xy))) / 1e-6
    est = float(r.message.split("estimated global error ")[1].split(" ×")[0])
    assert r.status == "finished with warnings"
    assert err / 3 < est < 3 * err, (method, est, err)


@pytest.mark.parametrize("method,h", [("generalized-alpha", 10.0), ("hht", 5.0), ("hht", 10.0)])
def test_absurd_fixed_steps_do_not_finish_cleanly(method, h):
    """The issue's cases: h = 5–10 s on a 1 m pendulum (period 2 s) ran to thousands of radians
    and reported "finished"."""
    r = simulate(simple_pendulum(bob="point"), (0.0, 50.0), method, h=h, n_output=11)
    assert r.status != "finished", r.message
    if r.status == "failed":
        assert " failed at t = " in r.message
    else:
        assert "estimated global error" in r.message


_SLOW = pytest.mark.slow


@pytest.mark.parametrize("bob,method,rho", [
    ("rod", "generalized-alpha", 0.9), ("rod", "generalized-alpha", 1.0), ("point", "hht", 0.9),
    *[pytest.param(b, m, r, marks=_SLOW) for b in ("point", "rod")
      for m, r in [("generalized-alpha", 0.0), ("generalized-alpha", 0.5), ("generalized-alpha", 0.9),
                   ("generalized-alpha", 1.0), ("hht", 0.5), ("hht", 0.9), ("hht", 1.0)]
      if (b, m, r) not in {("rod", "generalized-alpha", 0.9), ("rod", "generalized-alpha", 1.0),
                           ("point", "hht", 0.9)}],
])
def test_generalized_alpha_runs_the_pendulum_at_every_easy_step(bob, method, rho):
    """Newton failed at h = 0.03–0.05 s (and 0.005 s with ρ∞ = 1): the cause was the drift of the
    velocity constraint of the plain index-3 scheme, which grew until the discrete equations had
    no nearby solution; with the (default) velocity projection every step runs to the end."""
    model = simple_pendulum(bob=bob)
    for h in (0.05, 0.04, 0.03, 0.005):
        r = simulate(model, (0.0, 8.0), method, h=h, rho_inf=rho, rtol=1e-2, atol=1e-4, n_output=5,
                     compute_multipliers=False)
        assert r.status in FINISHED_STATUSES, f"h = {h}: {r.message}"
        # outputs between steps come from the cubic Hermite interpolant (O(h⁴) off Φ = 0); the last
        # output is a step end, where the velocities were projected
        assert r.position_violation.max() < 1e-5 and r.velocity_violation[-1] < 1e-8
        # bounded motion: the energy stays within 5 % of m g L (numerical damping only removes energy)
        assert np.max(r.energy - r.energy[0]) < 0.05 * G_EARTH


def test_plain_index3_drift_is_what_made_newton_fail():
    """The same rod at h = 0.05 s, ρ∞ = 0.9 without the projection: the velocity violation grows
    far beyond its O(h²) start, the energy with it (the cause, shown)."""
    model = simple_pendulum(bob="rod")
    r = simulate(model, (0.0, 5.0), "generalized-alpha", h=0.05, rho_inf=0.9, velocity_projection=False,
                 rtol=1e-2, atol=1e-4, n_output=51, compute_multipliers=False)
    early = r.velocity_violation[r.t <= 1.0].max()
    assert r.status == "failed" or r.velocity_violation.max() > 5 * early
    assert r.status != "finished"


def test_hht_damping_range_is_checked():
    with pytest.raises(InputError, match=r"hht: rho_inf must lie in \[0.5, 1\]"):
        simulate(simple_pendulum(), (0.0, 1.0), "hht", h=0.01, rho_inf=0.2)


def test_status_reaches_summary_and_tables(pendulum):
    model, _ = pendulum
    r = simulate(model, (0.0, T_END), "hht", h=0.02, n_output=11)
    assert r.status == "finished with warnings" and r.success and r.has_warnings
    row = r.summary().iloc[0]
    assert row["status"] == "finished with warnings" and row["n warnings"] == len(r.warnings) >= 1
    assert r.coordinates().attrs["status"] == "finished with warnings"
    clean = simulate(model, (0.0, 0.2), "radau-ggl", n_output=3)
    assert clean.status == "finished" and not clean.has_warnings and clean.summary().iloc[0]["n warnings"] == 0


def test_energy_check_flags_a_drifting_conservative_run(pendulum):
    """rk45 at rtol = 1e-3 on the pendulum: 17 × the tolerance in position; the energy check says so."""
    model, _ = pendulum
    r = simulate(model, (0.0, T_END), "rk45", rtol=1e-3, atol=1e-5, t_eval=T_EVAL)
    assert r.status == "finished with warnings"
    assert any(w.startswith("energy drift") and "what the tolerances allow" in w for w in r.warnings)


@pytest.mark.parametrize("kw,message", [(dict(h=True), "h must be a number"), (dict(rtol="1e-6"), "rtol must be a number"),
                                        (dict(max_step=[0.1]), "max_step must be a number"),
                                        (dict(h="1 kg"), r"h: '1 kg' is a mass \(\[mass\]\), expected time"),
                                        (dict(h="1,5 ms"), "h: '1,5 ms' has a comma")])
def test_step_and_tolerances_that_are_not_numbers_are_refused_by_name(kw, message):
    """A hurried user's h="1e-3" failed with a bare TypeError from a comparison deep in the
    integrator's set-up; now a step is a number of seconds or a quantity with its unit (as every
    input, docs/user-guide/checked-inputs.md), and anything else is refused naming the argument."""
    for method in ("jit-rk4", "generalized-alpha", "rk45"):
        with pytest.raises(InputError, match=f"{method}: {message}"):
            simulate(simple_pendulum(bob="point"), (0.0, 0.1), method, **({"h": 1e-3} | kw))


def test_a_step_with_its_unit_is_converted():
    model = simple_pendulum(bob="point")
    a = simulate(model, (0.0, 0.1), "jit-rk4", h="1 ms", t_eval=[0.1])
    b = simulate(model, (0.0, 0.1), "jit-rk4", h=1e-3, t_eval=[0.1])
    c = simulate(model, (0.0, 0.1), "jit-rk4", h="1e-3", t_eval=[0.1])  # a bare number as text: seconds
    assert a.counters["n_steps"] == b.counters["n_steps"] == c.counters["n_steps"] == 100
    np.testing.assert_array_equal(a.q, b.q)
