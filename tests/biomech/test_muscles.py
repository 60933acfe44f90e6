"""Thelen (2003) muscle curves and rigid-tendon geometry of :mod:`biomech.muscles`.

Anchor points of the published curves (Thelen 2003, Eqs. 2, 3, 6, 7), the force-velocity inversion
checked against Eq. 6 written out independently in the un-normalised form, the constant-height
pennation identities, the fibre velocity as the time derivative of the fibre length, continuity and
monotonicity, vectorisation over muscles and frames, and the errors for bad parameters.
"""

from __future__ import annotations

import numpy as np
import pytest

from biomech.muscles import (
    ThelenMuscleSet,
    active_force_length,
    force_velocity,
    normalized_fiber_velocity,
    passive_force_length,
)
from core.errors import InputError, ModelError

RNG_SEED = 20031


def random_muscles(rng, n):
    """Physiologically scaled random muscles (gait2392 ranges)."""
    return ThelenMuscleSet(
        names=[f"m{j}" for j in range(n)],
        max_isometric_force=rng.uniform(300, 3000, n),
        optimal_fiber_length=rng.uniform(0.03, 0.2, n),
        tendon_slack_length=rng.uniform(0.02, 0.4, n),
        pennation_angle_at_optimal=rng.uniform(0.0, np.deg2rad(30), n),
    )


# ---- curves --------------------------------------------------------------------------------


@pytest.mark.parametrize("gamma", [0.45, 0.5])
def test_active_force_length_peak_symmetry_and_width(gamma):
    assert active_force_length(1.0, gamma) == 1.0
    d = np.linspace(0.0, 0.8, 41)
    np.testing.assert_allclose(active_force_length(1 + d, gamma), active_force_length(1 - d, gamma), rtol=0, atol=1e-15)
    # Gaussian width: 1/e at one "standard width" sqrt(gamma) from the optimum
    np.testing.assert_allclose(active_force_length(1 + np.sqrt(gamma), gamma), np.exp(-1.0), rtol=1e-14)
    lt = np.linspace(0.3, 1.7, 281)
    f = active_force_length(lt, gamma)
    assert np.all(np.diff(f[lt <= 1.0]) > 0) and np.all(np.diff(f[lt >= 1.0]) < 0)


@pytest.mark.parametrize("k_pe, e0", [(4.0, 0.6), (5.0, 0.5)])
def test_passive_force_length_anchor_points_and_shape(k_pe, e0):
    assert passive_force_length(1.0 + e0, k_pe, e0) == pytest.approx(1.0, rel=1e-14)
    assert passive_force_length(1.0, k_pe, e0) == 0.0
    # slack below the optimal length (OpenSim's form; the paper's would be slightly negative)
    assert np.all(passive_force_length(np.linspace(0.4, 1.0, 13), k_pe, e0) == 0.0)
    lt = np.linspace(1.0, 1.0 + 1.5 * e0, 301)
    f = passive_force_length(lt, k_pe, e0)
    assert np.all(np.diff(f) > 0) and np.all(np.diff(f, 2) > 0)  # increasing and convex
    # continuous at l = 1: the first step is of the size slope * h
    h = 1e-9
    slope = k_pe / (e0 * np.expm1(k_pe))
    assert passive_force_length(1 + h, k_pe, e0) == pytest.approx(slope * h, rel=1e-6)
    # the paper's Eq. 2 for l > 1, written out
    lt = np.array([1.1, 1.3, 1.5])
    np.testing.assert_allclose(passive_force_length(lt, k_pe, e0),
                               (np.exp(k_pe * (lt - 1) / e0) - 1) / (np.exp(k_pe) - 1), rtol=1e-13)


@pytest.mark.parametrize("af, flen", [(0.3, 1.8), (0.25, 1.4)])
def test_force_velocity_anchor_points(af, flen):
    assert force_velocity(0.0, 1.0, af, flen) == 1.0
    assert force_velocity(-1.0, 1.0, af, flen) == 0.0  # zero force at v = -v_max (activation 1)
    assert np.all(force_velocity(np.array([-1.5, -1.0001, -3.0]), 1.0, af, flen) == 0.0)  # no pushing
    # eccentric plateau approaches Flen from below
    v = np.array([1.0, 10.0, 100.0, 1e4])
    f = force_velocity(v, 1.0, af, flen)
    assert np.all(f < flen) and np.all(np.diff(f) > 0)
    assert flen - f[-1] < 1e-3 * (flen - 1)
    # maximum shortening velocity scales with k = 0.25 + 0.75 a
    assert force_velocity(-0.25 - 0.75 * 0.4, 0.4, af, flen) == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("activation", [1.0, 0.4])
def test_force_velocity_continuity_monotonicity_and_slopes(activation):
    af, flen = 0.3, 1.8
    k = 0.25 + 0.75 * activation
    v = np.linspace(-1.2 * k, 2.0, 4001)
    f = force_velocity(v, activation, af, flen)
    assert np.all(np.diff(f) >= 0)
    assert np.max(np.abs(np.diff(f))) < 0.02  # no jump on a grid of 8e-4
    # slopes at the isometric point: (1 + 1/Af)/k shortening, twice that lengthening (Thelen's choice)
    h = 1e-7
    left = (1.0 - force_velocity(-h, activation, af, flen)) / h
    right = (force_velocity(h, activation, af, flen) - 1.0) / h
    assert left == pytest.approx((1 + 1 / af) / k, rel=1e-5)
    assert right == pytest.approx(2 * (1 + 1 / af) / k, rel=1e-5)


@pytest.mark.parametrize("activation", [1.0, 0.7, 0.2])
def test_force_velocity_inverts_thelen_eq6(activation):
    """Eq. 6-7 written out with a f_L (not normalised): v(F) must give back f_V = F/(a f_L)."""
    af, flen, fl = 0.3, 1.8, 0.73
    afl = activation * fl
    fv = np.concatenate([np.linspace(0.0, 1.0, 21), np.linspace(1.0, 1.79, 40)[1:]])
    force = afl * fv  # F~ = a f_L f_V
    b = np.where(force <= afl, afl + force / af, (2 + 2 / af) * (afl * flen - force) / (flen - 1))
    v = (0.25 + 0.75 * activation) * (force - afl) / b  # Eq. 6, normalised by v_max
    np.testing.assert_allclose(force_velocity(v, activation, af, flen), fv, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(normalized_fiber_velocity(fv, activation, af, flen), v, rtol=1e-13, atol=1e-15)


def test_force_velocity_opensim_linear_extrapolation():
    af, flen, theta = 0.3, 1.8, 0.95
    k, c = 1.0, (2 + 2 / af) / (flen - 1)
    fv_star = theta * flen
    v_star = k * (fv_star - 1) / (c * (flen - fv_star))
    v = np.linspace(-1.0, 3.0, 2001)
    plain = force_velocity(v, 1.0, af, flen)
    ext = force_velocity(v, 1.0, af, flen, fv_linear_extrap_threshold=theta)
    below = v <= v_star
    np.testing.assert_array_equal(ext[below], plain[below])
    assert force_velocity(v_star, 1.0, af, flen, theta) == pytest.approx(fv_star, rel=1e-14)
    above = v > v_star + 1e-9
    assert np.allclose(np.diff(ext[above], 2), 0.0, atol=1e-12)  # linear
    h = 1e-6  # C1 at the junction
    slope_left = (force_velocity(v_star, 1.0, af, flen) - force_velocity(v_star - h, 1.0, af, flen)) / h
    slope_right = (force_velocity(v_star + h, 1.0, af, flen, theta) - fv_star) / h
    assert slope_right == pytest.approx(slope_left, rel=1e-4)
    assert ext[-1] > flen  # unlike the hyperbola, the continuation passes Flen


# ---- geometry -------------------------------------------------------------------------------


def test_pennation_geometry_identity():
    rng = np.random.default_rng(RNG_SEED)
    mus = random_muscles(rng, 12)
    l_mt = mus.tendon_slack_length + mus.optimal_fiber_length * rng.uniform(0.6, 1.5, (50, 12))
    kin = mus.fiber_kinematics(l_mt, np.zeros_like(l_mt))
    assert not kin.clamped.any()
    h = mus.optimal_fiber_length * np.sin(mus.pennation_angle_at_optimal)
    np.testing.assert_allclose(kin.fiber_length * np.sin(kin.pennation_angle), np.broadcast_to(h, l_mt.shape),
                               rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(kin.fiber_length * np.cos(kin.pennation_angle), l_mt - mus.tendon_slack_length,
                               rtol=1e-13)
    np.testing.assert_allclose(kin.cos_pennation, np.cos(kin.pennation_angle), rtol=1e-14)
    # at l_MT = l_TS + l_opt cos(alpha0) the fibre is at its optimal length and angle
    kin0 = mus.fiber_kinematics(mus.tendon_slack_length + mus.optimal_fiber_length
                                * np.cos(mus.pennation_angle_at_optimal), np.zeros(12))
    np.testing.assert_allclose(kin0.norm_fiber_length, 1.0, rtol=1e-14)
    np.testing.assert_allclose(kin0.pennation_angle, mus.pennation_angle_at_optimal, rtol=1e-12, atol=1e-15)


def test_fiber_velocity_is_time_derivative_of_fiber_length():
    rng = np.random.default_rng(RNG_SEED + 1)
    mus = random_muscles(rng, 6)
    amp = 0.2 * mus.optimal_fiber_length
    l0 = mus.tendon_slack_length + mus.optimal_fiber_length
    omega = 2 * np.pi * 1.3

    def path(t):
        return l0 + amp * np.sin(omega * t), amp * omega * np.cos(omega * t)

    t = np.linspace(0.0, 1.0, 11)[:, None]
    h = 1e-6
    l_mt, v_mt = path(t)
    kin = mus.fiber_kinematics(l_mt, v_mt)
    lp = mus.fiber_kinematics(path(t + h)[0], v_mt).fiber_length
    lm = mus.fiber_kinematics(path(t - h)[0], v_mt).fiber_length
    np.testing.assert_allclose(kin.fiber_velocity, (lp - lm) / (2 * h), rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(kin.fiber_velocity, v_mt * kin.cos_pennation, rtol=1e-14)
    np.testing.assert_allclose(kin.norm_fiber_velocity,
                               kin.fiber_velocity / (mus.max_contraction_velocity * mus.optimal_fiber_length),
                               rtol=1e-14)


def test_clamped_fibre_below_minimum_length():
    mus = ThelenMuscleSet(["pennated", "straight"], [1000.0, 800.0], [0.05, 0.1], [0.3, 0.2], [0.4, 0.0])
    l_min = mus.minimum_fiber_length
    h = mus.parallelogram_height
    np.testing.assert_allclose(l_min, [max(h[0] / np.sin(np.arccos(0.1)), 0.0005), 0.001])
    x_min = np.sqrt(l_min**2 - h**2)
    x = np.linspace(-0.01, 0.01, 2001)[:, None] + x_min  # across the clamp boundary
    kin = mus.fiber_kinematics(mus.tendon_slack_length + x, np.full_like(x, 0.3))
    np.testing.assert_array_equal(kin.clamped, x < x_min)
    assert np.all(kin.fiber_length >= l_min * (1 - 1e-14))
    assert np.all(kin.pennation_angle <= mus.maximum_pennation_angle + 1e-14)
    assert np.all(kin.fiber_velocity[kin.clamped] == 0.0)
    assert np.max(np.abs(np.diff(kin.fiber_length, axis=0))) < 1.1e-5  # continuous, grid step 1e-5
    forces = mus.rigid_tendon_forces(mus.tendon_slack_length + x, np.zeros_like(x))
    assert np.all(forces.active_force_per_activation[kin.clamped] == 0.0)
    # a path shorter than the tendon itself is clamped, not NaN
    short = mus.rigid_tendon_forces(mus.tendon_slack_length - 0.05, np.zeros(2))
    assert short.kinematics.clamped.all() and np.all(np.isfinite(short.passive_force))


# ---- forces for static optimisation --------------------------------------------------------


def test_rigid_tendon_forces_definition():
    rng = np.random.default_rng(RNG_SEED + 2)
    mus = random_muscles(rng, 9)
    lt = rng.uniform(0.6, 1.5, (30, 9))
    a0 = mus.pennation_angle_at_optimal
    h = mus.optimal_fiber_length * np.sin(a0)
    l_m = lt * mus.optimal_fiber_length
    l_mt = mus.tendon_slack_length + np.sqrt(l_m**2 - h**2)
    v_mt = rng.uniform(-0.5, 0.5, (30, 9))
    out = mus.rigid_tendon_forces(l_mt, v_mt)
    kin = out.kinematics
    np.testing.assert_allclose(kin.norm_fiber_length, lt, rtol=1e-12)
    cos_a = np.sqrt(l_m**2 - h**2) / l_m
    vt = v_mt * cos_a / (mus.max_contraction_velocity * mus.optimal_fiber_length)
    f0 = mus.max_isometric_force
    np.testing.assert_allclose(out.active_force_per_activation,
                               f0 * active_force_length(lt, 0.5) * force_velocity(vt, 1.0, 0.3, 1.8) * cos_a,
                               rtol=1e-12)
    np.testing.assert_allclose(out.passive_force, f0 * passive_force_length(lt, 4.0, 0.6) * cos_a, rtol=1e-12,
                               atol=1e-12)
    assert np.all(out.active_force_per_activation >= 0) and np.all(out.passive_force >= 0)
    # isometric at the optimal length: A = F0 cos(alpha0), P = 0
    iso = mus.rigid_tendon_forces(mus.tendon_slack_length + mus.optimal_fiber_length * np.cos(a0), np.zeros(9))
    np.testing.assert_allclose(iso.active_force_per_activation, f0 * np.cos(a0), rtol=1e-12)
    np.testing.assert_allclose(iso.passive_force, 0.0, atol=1e-12)
    # OpenSim's use_muscle_physiology = false
    raw = mus.rigid_tendon_forces(l_mt, v_mt, use_muscle_physiology=False)
    np.testing.assert_array_equal(raw.active_force_per_activation, np.broadcast_to(f0, l_mt.shape))
    assert np.all(raw.passive_force == 0.0)


def test_active_capacity_continuous_in_path_length():
    rng = np.random.default_rng(RNG_SEED + 3)
    mus = random_muscles(rng, 5)
    s = np.linspace(0.5, 1.6, 5001)[:, None]
    l_mt = mus.tendon_slack_length + s * mus.optimal_fiber_length
    out = mus.rigid_tendon_forces(l_mt, np.zeros_like(l_mt))
    step = np.abs(np.diff(out.active_force_per_activation, axis=0)) / mus.max_isometric_force
    assert step.max() < 1e-3
    # passive force grows monotonically with the path length
    assert np.all(np.diff(out.passive_force, axis=0) >= -1e-12)


def test_vectorised_over_muscles_and_frames_equals_loop():
    rng = np.random.default_rng(RNG_SEED + 4)
    n, nf = 7, 13
    mus = random_muscles(rng, n)
    l_mt = mus.tendon_slack_length + mus.optimal_fiber_length * rng.uniform(0.2, 1.6, (nf, n))
    v_mt = rng.uniform(-1.0, 1.0, (nf, n)) * mus.optimal_fiber_length * 10
    batch = mus.rigid_tendon_forces(l_mt, v_mt)
    for j in range(n):
        single = ThelenMuscleSet([mus.names[j]], mus.max_isometric_force[j], mus.optimal_fiber_length[j],
                                 mus.tendon_slack_length[j], mus.pennation_angle_at_optimal[j])
        for k in range(nf):
            one = single.rigid_tendon_forces([l_mt[k, j]], [v_mt[k, j]])
            assert one.active_force_per_activation[0] == batch.active_force_per_activation[k, j]
            assert one.passive_force[0] == batch.passive_force[k, j]
            assert one.kinematics.pennation_angle[0] == batch.kinematics.pennation_angle[k, j]
    # 1-D input (one frame) and 3-D input (trials x frames x muscles) keep their leading shape
    assert mus.rigid_tendon_forces(l_mt[0], v_mt[0]).passive_force.shape == (n,)
    assert mus.rigid_tendon_forces(l_mt.reshape(1, nf, n), v_mt.reshape(1, nf, n)).passive_force.shape == (1, nf, n)


# ---- errors ---------------------------------------------------------------------------------


def test_bad_parameters_name_the_muscle():
    args = (["soleus", "tibant"], [3000.0, 900.0], [0.05, 0.1], [0.25, 0.22])
    with pytest.raises(ModelError, match="tibant.*pennation_angle_at_optimal.*degrees"):
        ThelenMuscleSet(*args, [0.4, 30.0])  # degrees by mistake
    with pytest.raises(ModelError, match="soleus.*max_isometric_force"):
        ThelenMuscleSet(["soleus", "tibant"], [-1.0, 900.0], [0.05, 0.1], [0.25, 0.22], 0.0)
    with pytest.raises(ModelError, match="duplicate muscle name 'soleus'"):
        ThelenMuscleSet(["soleus", "soleus"], 1000.0, 0.05, 0.2, 0.0)
    with pytest.raises(ModelError, match="flen"):
        ThelenMuscleSet(*args, 0.0, flen=1.0)
    with pytest.raises(ModelError, match="optimal_fiber_length must be a scalar or have shape"):
        ThelenMuscleSet(["a", "b"], 1000.0, [0.05, 0.1, 0.2], 0.2, 0.0)
    mus = ThelenMuscleSet(*args, 0.0)
    with pytest.raises(InputError, match="non-finite value nan for muscle 'tibant' at frame index \\(1,\\)"):
        mus.fiber_kinematics([[0.3, 0.3], [0.3, np.nan]], np.zeros((2, 2)))
    with pytest.raises(InputError, match="musculotendon_length must have shape"):
        mus.fiber_kinematics([0.3, 0.3, 0.3], [0.0, 0.0, 0.0])
    with pytest.raises(InputError, match="no muscle named 'gastroc'"):
        mus.index("gastroc")
    assert mus.index("tibant") == 1


def test_parameters_are_read_only_and_broadcast():
    mus = ThelenMuscleSet(["a", "b", "c"], 1000.0, 0.1, 0.2, 0.1, kshape_active=0.45)
    assert mus.n_muscles == len(mus) == 3
    np.testing.assert_array_equal(mus.kshape_active, [0.45] * 3)
    with pytest.raises(ValueError):
        mus.max_isometric_force[0] = 5.0


def test_from_muscle_records_fills_defaults():
    from types import SimpleNamespace

    records = [
        SimpleNamespace(name="soleus", max_isometric_force=3549.0, optimal_fiber_length=0.05,
                        tendon_slack_length=0.25, pennation_angle_at_optimal=0.4363, kshape_active=None),
        SimpleNamespace(name="tibant", max_isometric_force=905.0, optimal_fiber_length=0.098,
                        tendon_slack_length=0.223, pennation_angle_at_optimal=0.0873, kshape_active=0.45,
                        flen=1.4),
    ]
    mus = ThelenMuscleSet.from_muscles(records, max_contraction_velocity=8.0)
    assert mus.names == ("soleus", "tibant")
    np.testing.assert_array_equal(mus.kshape_active, [0.5, 0.45])
    np.testing.assert_array_equal(mus.flen, [1.8, 1.4])
    np.testing.assert_array_equal(mus.max_contraction_velocity, [8.0, 8.0])
    with pytest.raises(ModelError, match="muscle 'x': no tendon_slack_length"):
        ThelenMuscleSet.from_muscles([SimpleNamespace(name="x", max_isometric_force=1.0, optimal_fiber_length=0.1,
                                                      pennation_angle_at_optimal=0.0)])
