"""Quasi-static rolling with creep forces in the balance (railway.contact.quasi_static.quasi_static_rolling)
and the Polach (2005) parameter sets (railway.contact.creep).

Oracles: the equilibrium conditions themselves (vertical force of each wheel, free rolling),
mirror symmetry of the centred wheelset, the frictionless solver quasi_static_contact (an
independent iteration without creep forces) as mu -> 0, and the closed-form small-creepage
slope of Polach's 2005 law.
"""

import numpy as np
import pandas as pd
import pytest

from core.errors import InputError, UnknownNameError
from railway.assessment import nadal_limit
from railway.contact.creep import Polach2005, kalker_coefficients, polach2005_parameter_sets
from railway.contact.quasi_static import quasi_static_contact, quasi_static_rolling, quasi_static_wheel_table

Q = 100e3
V = 20.0


@pytest.mark.parametrize("law", ["fastsim", "polach2000", "kalker_linear"])
def test_centred_wheelset_balance_and_symmetry(law):
    df = quasi_static_rolling([0.0], 0.0, Q, V, creep_law=law, mu=0.3)
    assert df["converged"].all() and len(df) == 2
    tol = 1e-6 * Q  # the solver's default tolerance on each wheel's vertical force
    per_wheel = df.groupby("side")["Fz track [N]"].sum()
    np.testing.assert_allclose(per_wheel, Q, atol=tol)
    L, R = df[df["side"] == "left"].iloc[0], df[df["side"] == "right"].iloc[0]
    # mirror symmetry: equal loads, lateral forces on the wheels cancel
    assert abs(L["Fy track [N]"] + R["Fy track [N]"]) < tol
    assert abs(L["N [N]"] - R["N [N]"]) < 2 * tol
    assert abs(L["roll [rad]"]) < 1e-9  # symmetric to round-off (measured ~1e-12 rad)
    # free rolling of a symmetric wheelset: (almost) no longitudinal creepage; the small
    # longitudinal forces balance the axle component of the spin moments, whose normals lean
    # by the contact angle: -r (Fx_L + Fx_R) + sum Mz (n . e_axle) = 0, n . e_axle = -sigma sin g
    assert abs(L["xi [-]"]) < 1e-6 and abs(R["xi [-]"]) < 1e-6
    spin_axle = -L["Mz [N m]"] * np.sin(L["contact angle [rad]"]) + R["Mz [N m]"] * np.sin(R["contact angle [rad]"])
    roll_moment = -(L["rolling radius [m]"] * L["Fx track [N]"] + R["rolling radius [m]"] * R["Fx track [N]"])
    assert abs(roll_moment + spin_axle) <= 1e-3 * abs(spin_axle) + 1e-6 * Q * 0.46
    # rolling without slip at the contact radius: Omega r = V to the creepage tolerance
    assert L["omega [rad/s]"] * L["rolling radius [m]"] == pytest.approx(V, rel=1e-5)
    # per-wheel assessment columns are those of railway.assessment
    assert L["Q [N]"] == pytest.approx(Q, abs=tol)
    assert L["Y [N]"] == pytest.approx(-L["Fy track [N]"], rel=1e-12)
    assert R["Y [N]"] == pytest.approx(R["Fy track [N]"], rel=1e-12)
    assert L["Nadal limit [-]"] == pytest.approx(float(nadal_limit(L["contact angle [rad]"], 0.3)))


@pytest.mark.parametrize("y, psi", [(0.002, 0.0), (0.0065, 0.0), (-0.003, 0.005)])
def test_vanishing_friction_gives_the_frictionless_solution(y, psi):
    """mu -> 0 with a saturating law (FASTSIM: |F| <= mu N): the creep forces vanish and the
    solution must be that of quasi_static_contact (Hertz normal forces only).  Both solvers
    stop at a vertical-force residual of 1e-6 Q, so N agrees to ~1e-6 relative (tolerance 1e-5),
    z and roll to the elastic compliance times that residual (< 1e-9 m, 1e-8 rad)."""
    a = quasi_static_rolling([y], psi, Q, V, creep_law="fastsim", mu=1e-9)
    b = quasi_static_contact([y], Q, yaw=psi)
    assert a["converged"].all() and b["converged"].all()
    assert list(a["side"]) == list(b["side"]) and list(a["contact"]) == list(b["contact"])
    np.testing.assert_allclose(a["N [N]"], b["N [N]"], rtol=1e-5)
    np.testing.assert_allclose(a["Fy track [N]"], b["Fy [N]"], rtol=1e-5, atol=1e-6 * Q)
    np.testing.assert_allclose(a["contact angle [rad]"], b["contact angle [rad]"], atol=1e-7)
    assert a["z [m]"].iloc[0] == pytest.approx(b["z [m]"].iloc[0], abs=1e-9)
    assert a["roll [rad]"].iloc[0] == pytest.approx(b["roll [rad]"].iloc[0], abs=1e-8)
    assert np.all(np.abs(a["Fs [N]"]) <= 1e-9 * a["N [N]"] * (1 + 1e-9))


def test_friction_carries_part_of_the_flange_load():
    """On a steep flange the creep force has a large vertical component: with friction the
    normal force needed for the same wheel load is far smaller than without (CONTACT: 15.4 kN
    with mu = 0.3 against 10 kN / cos(66 deg) = 25 kN frictionless)."""
    y, psi = -0.0065, -0.0156  # Manchester case 14 in our frame
    a = quasi_static_rolling([y], psi, 10e3, 2.0, creep_law="fastsim", mu=0.3, E=2 * 82e9 * 1.28)
    b = quasi_static_contact([y], 10e3, yaw=psi, E=2 * 82e9 * 1.28)
    fa = a[(a["side"] == "right")].iloc[0]
    fb = b[(b["side"] == "right")].iloc[0]
    assert fa["contact angle [rad]"] > np.radians(60)
    assert fa["Fz track [N]"] == pytest.approx(10e3, abs=1e-2)
    # vertical share of the normal force plus that of the creep force = the load
    up_creep = fa["Fz track [N]"] - fa["N [N]"] * np.cos(fa["contact angle [rad]"] + fa["roll [rad]"])
    assert up_creep > 2e3
    assert fa["N [N]"] < 0.7 * fb["N [N]"]


def test_unconverged_cases_are_flagged_not_dropped():
    df = quasi_static_rolling([0.0, -0.0065], [0.0, -0.0156], 10e3, 2.0, mu=0.3, max_iter=1)
    assert not df["converged"].any()
    assert df["status"].str.startswith("no balance").all()
    w = quasi_static_wheel_table(df)
    assert len(w) == 4 and not w["converged"].any()
    # a shift beyond the flange has no rigid contact: NaN rows with the rigid status
    far = quasi_static_rolling([0.0, 0.06], 0.0, Q, V)
    bad = far[far["y [m]"] == 0.06]
    assert len(bad) == 2 and not bad["converged"].any() and bad["N [N]"].isna().all()
    assert bad["status"].str.startswith("out of reach").all()
    assert far[far["y [m]"] == 0.0]["converged"].all()


def test_bad_input_is_named():
    with pytest.raises(InputError, match="speed 0.0 m/s"):
        quasi_static_rolling([0.0], 0.0, Q, 0.0)
    with pytest.raises(InputError, match="yaw"):
        quasi_static_rolling([0.0, 0.001], [0.0, 0.0, 0.0], Q, V)
    with pytest.raises(InputError, match="wheel load -1"):
        quasi_static_rolling([0.0], 0.0, -1.0, V)
    with pytest.raises(UnknownNameError, match="no_such_law"):
        quasi_static_rolling([0.0], 0.0, Q, V, creep_law="no_such_law")


# ------------------------------------------------------------------------------------------
# Polach (2005) parameter sets
# ------------------------------------------------------------------------------------------

def test_polach2005_sets_are_flagged_second_hand():
    sets = polach2005_parameter_sets()
    assert sorted(sets["set"]) == ["dry", "wet"]
    assert sets["status"].str.contains("second-hand, not checked").all()
    assert sets["source"].str.contains("Table 2").all()
    with pytest.raises(UnknownNameError, match="damp"):
        Polach2005.from_parameter_set("damp")


def _creep_curve(law, xi, mu=0.3):
    N, a, b, G, nu = 100e3, 6e-3, 4e-3, 80e9, 0.28
    return law(xi, 0.0, 0.0, N, a, b, G, nu, mu).Fx


@pytest.mark.parametrize("name", ["dry", "wet"])
def test_published_sets_give_falling_friction_default_does_not(name):
    """With the dry and wet sets the force magnitude peaks and then falls with creepage (the
    falling friction mu(w) of Polach 2005, w = V |s|); with the defaults (k_A = k_S = 1, A = 1,
    B = 0) the law is Polach 2000 and the force rises monotonically to mu N."""
    xi = np.linspace(1e-4, 0.3, 600)
    law = Polach2005.from_parameter_set(name, speed=20.0)
    F = np.abs(_creep_curve(law, xi))
    k = int(np.argmax(F))
    assert 0 < k < xi.size - 1  # an interior peak
    assert F[-1] < 0.9 * F[k]  # and a clear fall after it (measured: dry 0.56, wet 0.81)
    F0 = np.abs(_creep_curve(Polach2005(speed=20.0), xi))
    assert np.all(np.diff(F0) >= -1e-9 * F0[1:])
    assert F0[-1] == pytest.approx(0.3 * 100e3, rel=0.02)


@pytest.mark.parametrize("name", ["dry", "wet"])
def test_published_sets_initial_slope(name):
    """Small creepage: F -> (2 Q mu / pi)(k_A + k_S) eps = (k_A + k_S)/2 times Kalker's
    -G a b C11 xi (Polach 2005, Eq. for F with eps -> 0); checked at xi = 1e-7."""
    law = Polach2005.from_parameter_set(name, speed=20.0)
    row = polach2005_parameter_sets().set_index("set").loc[name]
    C11 = kalker_coefficients(6e-3 / 4e-3, 0.28)[0][0]
    lin = -80e9 * 6e-3 * 4e-3 * C11 * 1e-7
    Fx = _creep_curve(law, np.array([1e-7]))[0]
    assert Fx == pytest.approx(0.5 * (row["k_A [-]"] + row["k_S [-]"]) * lin, rel=1e-4)


def test_polach2005_set_runs_in_the_rolling_solver():
    law = Polach2005.from_parameter_set("wet", speed=V)
    df = quasi_static_rolling([0.002], 0.003, Q, V, creep_law=law, mu=0.3)
    assert df["converged"].all()
    assert isinstance(df, pd.DataFrame) and df.attrs["creep_law"] == "polach2005"
