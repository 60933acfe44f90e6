"""Analyses of a prescribed motion with all frames at once (core.model.Model.*_frames,
core.analysis.kinematic_analysis with a guess per frame, the batched inverse dynamics).

Every batched quantity is checked against the frame-by-frame evaluation it replaces, at states
that are not on the constraint manifold (the protocol is a function of (t, q, v) whatever the
state), and the batched analyses against the frame-by-frame analyses and closed forms.  Equality
is to round-off: the same floating-point operations in another order (tolerance 1e-12 relative).
"""

from __future__ import annotations

import numpy as np
import pytest

from core import analysis as A
from core.drivers import harmonic, ramp, tabulated
from core.errors import DataRangeError, InputError
from core.forces import AppliedForce, AppliedTorque, SpringDamper
from core.model import ModelBuilder

RNG = np.random.default_rng(7)
TIMES = np.linspace(0.0, 1.0, 11)


def _loaded(dim):
    """Two bodies on a pin with every applied-load variant, a spring (a kind without a batched
    form) and gravity."""
    tt = np.linspace(-0.5, 1.5, 41)
    b = ModelBuilder(dim, f"loaded-{dim}d")
    if dim == 2:
        b.add_body("a", 2.0, 0.1, (0.3, 0.1), orientation=0.2)
        b.add_body("b", 1.0, 0.05, (0.9, -0.2), orientation=-0.4)
        b.add_revolute("pin", "a", "b", (0.6, 0.0))
        F = [tabulated(tt, np.sin(3 * tt), label="Fx"), 4.0]
        T = harmonic(1.5, 2.0)
        pa, pb = (0.4, 0.2), (1.0, -0.1)
    else:
        b.add_body("a", 2.0, [0.1, 0.2, 0.15], (0.3, 0.1, 0.0), orientation=list(np.array([0.9, 0.1, 0.3, 0.2]) / np.linalg.norm([0.9, 0.1, 0.3, 0.2])))
        b.add_body("b", 1.0, [0.05, 0.04, 0.03], (0.9, -0.2, 0.1))
        b.add_revolute("pin", "a", "b", (0.6, 0.0, 0.0), axis=(0.0, 0.0, 1.0))
        F = [tabulated(tt, np.sin(3 * tt), label="Fx"), 4.0, ramp(2.0)]
        T = [harmonic(1.5, 2.0), 0.0, tabulated(tt, tt**2, label="Tz")]
        pa, pb = (0.4, 0.2, 0.1), (1.0, -0.1, 0.05)
    b.add_force(AppliedForce("Fg", "a", pa, F))
    b.add_force(AppliedForce("Fb", "b", pb, F, frame="body"))
    b.add_force(AppliedTorque("Tg", "b", T))
    b.add_force(AppliedTorque("Tb", "a", T, frame="body"))
    b.add_force(SpringDamper("spring", "ground", "b", pb, pb, 50.0, 2.0, free_length=0.1))
    return b.build()


def _states(model, n):
    """Random states near the initial one (Euler parameters normalised)."""
    q = model.q0[None, :] + 0.2 * RNG.standard_normal((n, model.n_q))
    q = np.array([model.normalize(qi) for qi in q])
    v = RNG.standard_normal((n, model.n_v))
    return q, v


@pytest.mark.parametrize("dim", [2, 3])
def test_Q_frames_equals_Q(dim):
    model = _loaded(dim)
    q, v = _states(model, len(TIMES))
    Qf = model.Q_frames(TIMES, q, v)
    Q1 = np.array([model.Q(t, qi, vi) for t, qi, vi in zip(TIMES, q, v)])
    np.testing.assert_allclose(Qf, Q1, rtol=1e-12, atol=1e-12 * np.abs(Q1).max())


@pytest.mark.parametrize("dim", [2, 3])
def test_constraint_terms_and_reactions_frames_equal_single_frames(dim):
    model = _loaded(dim)
    q, v = _states(model, len(TIMES))
    phi, J, nu, ga = model.constraint_terms_frames(TIMES, q, v)
    lam = RNG.standard_normal((len(TIMES), model.n_c))
    R = model.reactions_frames(TIMES, q, lam, J=J)
    for i, t in enumerate(TIMES):
        p1, J1, n1, g1 = model.constraint_terms(t, q[i], v[i])
        np.testing.assert_allclose(phi[i], p1, atol=1e-14)
        np.testing.assert_allclose(J[i], J1.toarray(), atol=1e-14)
        np.testing.assert_allclose(nu[i], n1, atol=1e-14)
        np.testing.assert_allclose(ga[i], g1, atol=1e-13)
        # reactions() is reactions_frames() of one frame: this compares the batched Φ_q it is given
        # with the per-frame one; the reactions themselves are checked against closed forms in
        # test_analysis.py (driver moment of the compound pendulum)
        for name, val in model.reactions(t, q[i], lam[i]).items():
            np.testing.assert_allclose(R[name][i], val, rtol=1e-12, atol=1e-13)
    assert not model.frames_vectorised  # joint kinds: evaluated frame by frame


def _slider_crank():
    r, l, th0 = 0.1, 0.3, 0.3
    B = np.array([r * np.cos(th0), r * np.sin(th0)])
    C = np.array([r * np.cos(th0) + np.sqrt(l * l - (r * np.sin(th0)) ** 2), 0.0])
    b = ModelBuilder(2, "slider-crank")
    b.add_body("crank", 1.0, 0.01, B / 2, orientation=th0)
    b.add_body("rod", 1.5, 0.02, (B + C) / 2, orientation=float(np.arctan2(-B[1], C[0] - B[0])))
    b.add_body("slider", 0.5, 0.001, C)
    b.add_revolute("O", "ground", "crank", (0.0, 0.0))
    b.add_revolute("A", "crank", "rod", B)
    b.add_revolute("B", "rod", "slider", C)
    b.add_translational("T", "ground", "slider", C, (1.0, 0.0))
    b.add_angle_driver("drive", "O", ramp(2.0))
    return b.build(assemble=True)


def _batched_equals_sequential(model, times):
    """A guess per frame (the sequential solution perturbed by 1 mm / 1 mrad) takes the batched
    path and gives the sequential analysis's positions, velocities and accelerations; returns the
    batched table."""
    seq = A.kinematic_analysis(model, times)
    guess = seq[model.coordinate_names].to_numpy() + 1e-3 * RNG.uniform(-1, 1, (len(times), model.n_q))
    assert A._kinematic_frames(model, times, guess, 1e-10, 50) is not None  # the batched path ran
    bat = A.kinematic_analysis(model, times, q_guess=guess)
    assert bat.attrs["status"] == "finished"
    # Newton's last step is quadratic: the converged residual is far below tol = 1e-10
    np.testing.assert_allclose(bat.to_numpy(), seq.to_numpy(), atol=1e-9)
    return bat


def test_kinematic_analysis_all_frames_equals_frame_by_frame():
    _batched_equals_sequential(_slider_crank(), np.linspace(0.0, np.pi, 37))  # a revolution at 2 rad/s


def test_kinematic_analysis_all_frames_spatial():
    """The same for a spatial rod driven about a tilted revolute axis (Euler parameters: the
    guesses are normalised and the Newton steps retracted frame by frame)."""
    from core.drivers import harmonic

    b = ModelBuilder(3, "driven-rod-3d")
    b.add_body("rod", 2.0, [0.1, 0.12, 0.02], (0.0, 0.0, -0.4))
    b.add_revolute("pivot", "ground", "rod", (0.0, 0.0, 0.0), axis=(1.0, 0.3, 0.0))
    b.add_angle_driver("drive", "pivot", harmonic(0.8, 2.5))
    model = b.build(assemble=True)
    bat = _batched_equals_sequential(model, np.linspace(0.0, 2.0, 41))
    fast = A.inverse_dynamics_from_kinematics(model, bat)
    assert fast.attrs["max_residual"] < 1e-9


def test_kinematic_analysis_guess_per_frame_checked():
    model = _slider_crank()
    with pytest.raises(InputError, match=r"q_guess has shape \(3, 9\)"):
        A.kinematic_analysis(model, TIMES, q_guess=np.zeros((3, model.n_q)))


def test_batched_inverse_dynamics_equals_frame_by_frame(monkeypatch):
    """The batched solve of Φ_qᵀλ = Q − M a returns the minimum-norm multipliers of the
    frame-by-frame least squares (unique for a square regular Φ_q), with the reactions."""
    model = _slider_crank()
    times = np.linspace(0.0, 3.0, 31)
    kin = A.kinematic_analysis(model, times)
    _, vn, an = A._names(model)
    assert A._inverse_dynamics_frames(model, times, kin[model.coordinate_names].to_numpy(), kin[vn].to_numpy(),
                                      kin[an].to_numpy()) is not None  # the batched path runs
    fast = A.inverse_dynamics_from_kinematics(model, kin)
    monkeypatch.setattr(A, "_inverse_dynamics_frames", lambda *args: None)
    slow = A.inverse_dynamics_from_kinematics(model, kin)
    assert list(fast.columns) == list(slow.columns)
    scale = np.abs(slow.to_numpy()).max()
    np.testing.assert_allclose(fast.drop(columns="residual").to_numpy(), slow.drop(columns="residual").to_numpy(),
                               atol=1e-12 * scale)
    assert fast.attrs["max_residual"] < 1e-10 * scale


def test_time_function_values_on_arrays():
    tt = np.linspace(0.0, 1.0, 11)
    f = tabulated(tt, tt**3, label="cubic")
    x = np.array([0.05, 0.5, 0.93])
    for order in (0, 1, 2):
        np.testing.assert_allclose(f.values(x, order), [f(xi)[order] for xi in x], rtol=1e-14)
    with pytest.raises(DataRangeError, match=r"'cubic': time 1.2 outside"):
        f.values(np.array([0.5, 1.2]))
    g = harmonic(2.0, 3.0)  # a closed form, evaluated element by element
    np.testing.assert_allclose(g.values(x, 1), 6.0 * np.cos(3.0 * x), rtol=1e-14)
