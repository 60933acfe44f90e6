"""Closed forms of hunting (railway.vehicles.hunting) against the eigenvalues of their own equations."""

import numpy as np
import pytest
from scipy.optimize import brentq

from core.errors import InputError
from railway.vehicles.hunting import (
    klingel_wavelength,
    suspended_wheelset_coefficients,
    suspended_wheelset_critical_speed,
    suspended_wheelset_matrices,
)

P = dict(m=1813.0, I=1120.0, k_y=3e5, k_psi=3e5, f11=9e6, f22=8e6, l=0.75, r0=0.46, conicity=0.025)


def max_real(V, **p):
    """Largest real part of the eigenvalues of M s^2 + C s + K."""
    M, C, K = suspended_wheelset_matrices(V, **p)
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    return np.max(np.linalg.eigvals(A).real)


@pytest.mark.parametrize("scale", [0.3, 1.0, 3.0])
def test_critical_speed_is_where_the_eigenvalues_cross(scale):
    p = dict(P, k_y=P["k_y"] * scale, k_psi=P["k_psi"] / scale)
    Vc, wc = suspended_wheelset_critical_speed(**p)
    Ve = brentq(lambda V: max_real(V, **p), 1.0, 1e3, xtol=1e-12)
    assert Vc == pytest.approx(Ve, rel=1e-9)
    M, C, K = suspended_wheelset_matrices(Vc, **p)
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    ev = np.linalg.eigvals(A)
    crit = ev[np.argmax(ev.real)]
    assert abs(crit.imag) == pytest.approx(wc, rel=1e-7)
    # the polynomial is the determinant of M s^2 + C s + K
    a = suspended_wheelset_coefficients(Vc, **p)
    s = 0.3 + 2.1j
    assert np.polyval(a, s) == pytest.approx(np.linalg.det(M * s**2 + C * s + K), rel=1e-12)


def test_large_creep_limit_and_stable_cases():
    p = dict(P, f11=1e12, f22=1e12)
    Vc, _ = suspended_wheelset_critical_speed(**p)
    lim = np.sqrt(P["l"] * P["r0"] * (p["f11"] * P["l"] ** 2 * P["k_y"] + p["f22"] * P["k_psi"])
                  / (P["conicity"] * (p["f22"] * P["I"] + p["f11"] * P["l"] ** 2 * P["m"])))
    assert Vc == pytest.approx(lim, rel=1e-6)
    with pytest.raises(InputError, match="free wheelset"):
        suspended_wheelset_critical_speed(**dict(P, k_y=0.0, k_psi=0.0))


def test_klingel():
    assert klingel_wavelength(0.46, 0.75, 0.025) == pytest.approx(2 * np.pi * np.sqrt(0.46 * 0.75 / 0.025))
    with pytest.raises(InputError, match="conicity"):
        klingel_wavelength(0.46, 0.75, 0.0)


@pytest.mark.parametrize("rho", [0.0335, 0.1])
def test_gyroscopic_critical_speed_is_where_the_eigenvalues_cross(rho):
    p = dict(P, spin_inertia=112.0, roll_per_lateral=rho)
    Vc, wc = suspended_wheelset_critical_speed(**p)
    Ve = brentq(lambda V: max_real(V, **p), 1.0, 1e3, xtol=1e-12)
    assert Vc == pytest.approx(Ve, rel=1e-8)
    assert Vc > suspended_wheelset_critical_speed(**P)[0]  # the gyroscopic term stabilises here
    M, C, K = suspended_wheelset_matrices(Vc, **p)
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    ev = np.linalg.eigvals(A)
    assert abs(ev[np.argmax(ev.real)].imag) == pytest.approx(wc, rel=1e-7)
