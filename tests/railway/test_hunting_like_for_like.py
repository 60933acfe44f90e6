"""Like-for-like validation of hunting (issue 21): the multibody suspended wheelset against the
linear wheelset of railway.vehicles.hunting with the same terms switched on.

Oracles: the classical two-degree-of-freedom wheelset (Wickens 2003, ch. 2; Routh–Hurwitz closed
form of railway.vehicles.hunting) against the multibody wheelset reduced by ``TEXTBOOK`` (no gyroscopic
moment, no roll rate in the creepages, no tilt of the normal forces, creep in the wheelset frame,
no spin creepage); the complete linear wheelset (railway.vehicles.hunting.LinearWheelset, every term on)
against the full multibody wheelset.  Both in the nominal-spin formulation, core's
linearize/eigen, with the closed-form inputs (conicity, roll, contact angle, Hertz and Kalker
coefficients) from the rigid contact geometry only.  Conical wheels (cone 1:40 ... 0.4) on UIC60
1:40, springs k_y = k_psi = 3e5.

Tolerances are the measured deviations rounded up (README, "Critical speed"):

* textbook-reduced multibody vs the classical closed form: V_c within +0.0030 % (1:40) and
  −0.0088 % (cone 0.4), frequency within 1.9e-4 % (cone 0.4; 3e-5 % at 1:40): the elastic
  contact (Hertz) against the rigid contact geometry of the closed form; tolerance 1.2e-4 (V_c)
  and 2.5e-6 (ω_c);
* full multibody vs the complete linear wheelset: −0.012 % (1:40) growing to −0.40 % (cone 0.4,
  equivalent conicity 0.54, roll 0.74 rad/m): terms of second order in the roll and the
  contact's elasticity the linear wheelset leaves out; tolerance per cone below.
"""

import numpy as np
import pytest
from scipy.optimize import brentq

from core.errors import InputError, ModelError
from railway.contact.forces import ContactForces
from railway.vehicles.hunting import TERMS, LinearWheelset, suspended_wheelset_critical_speed
from railway.contact.two_point import conical_wheel
from railway.vehicles.wheelset_models import TEXTBOOK, eigen_critical_speed, linear_wheelset, suspended_wheelset

K = dict(k_y=3e5, k_psi=3e5)
P = dict(m=1813.0, I=1120.0, k_y=3e5, k_psi=3e5, f11=2.9e6, f22=2.6e6, l=0.753, r0=0.46, conicity=0.0256)
FULL = dict(P, f23=3310.0, f33=4.9, roll_per_lateral=0.0337, contact_angle_slope=0.0337, delta0=0.025,
            spin_inertia=112.0, roll_inertia=1120.0, z_yy=0.068, z_psipsi=-0.0185, normal_load=8900.0)
OFF = {t: False for t in TERMS}

#: (cone, tolerance of V_c, tolerance of omega_c) of the full multibody against the complete
#: linear wheelset: measured −0.012/−0.018 % (1:40), −0.014/−0.021 % (0.05), −0.024/−0.030 % (0.1),
#: −0.10/−0.11 % (0.2), −0.20/−0.21 % (0.3), −0.40/−0.41 % (0.4); tolerance ≈ 1.25 × measured
FULL_TOL = [(1 / 40, 2.5e-4, 2.5e-4), (0.05, 2.5e-4, 3e-4), (0.1, 3e-4, 4e-4), (0.2, 1.3e-3, 1.4e-3),
            (0.3, 2.5e-3, 2.7e-3), (0.4, 5e-3, 5.2e-3)]
TEXTBOOK_TOL_V, TEXTBOOK_TOL_W = 1.2e-4, 2.5e-6


def _max_real(lw, V, **terms):
    M, C, Kt = lw.matrices(V, **terms)
    n = M.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, Kt), -np.linalg.solve(M, C)]])
    return np.max(np.linalg.eigvals(A).real)


# ---------------------------------------------------------------------------------------------
# the linear wheelset against its own equations and the classical closed forms (fast)
# ---------------------------------------------------------------------------------------------
def test_linear_wheelset_with_every_term_off_is_the_classical_closed_form():
    lw = LinearWheelset(**FULL)
    Vc, wc = lw.critical_speed(**OFF)
    Vk, wk = suspended_wheelset_critical_speed(**P)
    assert Vc == pytest.approx(Vk, rel=1e-10) and wc == pytest.approx(wk, rel=1e-10)
    # the gyroscopic yaw moment alone (normal forces without tilt: no lateral gyroscopic entry)
    # is the cubic of the earlier extended form
    Vg, wg = lw.critical_speed(**dict(OFF, gyroscopic=True))
    Vk, wk = suspended_wheelset_critical_speed(**P, spin_inertia=112.0, roll_per_lateral=0.0337)
    assert Vg == pytest.approx(Vk, rel=1e-10) and wg == pytest.approx(wk, rel=1e-9)


@pytest.mark.parametrize("terms", [{}, OFF] + [{t: False} for t in TERMS])
def test_linear_wheelset_critical_speed_is_where_its_eigenvalues_cross(terms):
    lw = LinearWheelset(**FULL)
    Vc, wc = lw.critical_speed(**terms)
    Ve = brentq(lambda V: _max_real(lw, V, **terms), 0.8 * Vc, 1.2 * Vc, xtol=1e-12)
    assert Vc == pytest.approx(Ve, rel=1e-8)
    M, C, Kt = lw.matrices(Vc, **terms)
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(M, Kt), -np.linalg.solve(M, C)]])
    ev = np.linalg.eigvals(A)
    assert abs(ev[np.argmax(ev.real)].imag) == pytest.approx(wc, rel=1e-7)


def test_linear_wheelset_refuses_unknown_terms():
    with pytest.raises(InputError, match="unknown terms"):
        LinearWheelset(**FULL).critical_speed(roll_coupling=False)


def test_reduced_contact_forces_are_refused_where_they_cannot_run():
    with pytest.raises(InputError, match="numpy reference path"):
        ContactForces(creep_model="kalker_linear", compiled=True, spin_creepage=False)
    assert ContactForces(creep_model="kalker_linear", contact_angle=False).reduced == ["contact_angle"]
    with pytest.raises(ModelError, match="nominal-spin"):
        suspended_wheelset(30.0, 3e5, 3e5, wheel=conical_wheel(), gyroscopic=False)


# ---------------------------------------------------------------------------------------------
# multibody against closed form, cone 1:40 (fast: two critical speeds, about 3 s each)
# ---------------------------------------------------------------------------------------------
def _compare(cone, options):
    wheel = conical_wheel(cone=cone)
    lw = linear_wheelset(wheel=wheel, **K)
    Vcf, wcf = lw.critical_speed(**options)
    V, w = eigen_critical_speed(bracket=(0.9 * Vcf, 1.1 * Vcf), wheel=wheel, xtol=1e-6 * Vcf, **K, **options)
    return V / Vcf - 1.0, w / wcf - 1.0


def test_textbook_multibody_wheelset_is_the_classical_wheelset():
    """Cone 1:40: measured +0.0030 % (V_c) and −3e-7 (ω_c) against the classical closed form with
    the equivalent conicity 0.02564 (54.186 m/s at 14.712 rad/s)."""
    dV, dw = _compare(1 / 40, TEXTBOOK)
    assert abs(dV) < TEXTBOOK_TOL_V and abs(dw) < TEXTBOOK_TOL_W


def test_full_multibody_wheelset_is_the_complete_linear_wheelset():
    """Cone 1:40: measured −0.012 % (V_c = 56.084 m/s against 56.091 m/s) and −0.018 % (ω_c)."""
    dV, dw = _compare(1 / 40, {})
    assert abs(dV) < FULL_TOL[0][1] and abs(dw) < FULL_TOL[0][2]


# ---------------------------------------------------------------------------------------------
# over the conicity range and term by term (slow)
# ---------------------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("cone", [0.05, 0.1, 0.2, 0.3, 0.4])
def test_textbook_multibody_wheelset_over_the_conicity_range(cone):
    dV, dw = _compare(cone, TEXTBOOK)
    assert abs(dV) < TEXTBOOK_TOL_V and abs(dw) < TEXTBOOK_TOL_W


@pytest.mark.slow
@pytest.mark.parametrize("cone, tol_V, tol_w", FULL_TOL[1:])
def test_full_multibody_wheelset_over_the_conicity_range(cone, tol_V, tol_w):
    dV, dw = _compare(cone, {})
    assert abs(dV) < tol_V and abs(dw) < tol_w


@pytest.mark.slow
@pytest.mark.parametrize("term", TERMS)
def test_each_term_alone_and_left_out_matches_the_linear_wheelset(term):
    """Cone 1:40, the textbook model plus one term, and the full model less one term: within
    the full model's tolerance (the five terms are the whole difference between the two)."""
    for options in ({k: v for k, v in TEXTBOOK.items() if k != term}, {term: False}):
        dV, dw = _compare(1 / 40, options)
        assert abs(dV) < FULL_TOL[0][1] and abs(dw) < FULL_TOL[0][2]
