"""Track frames: Frenet and rotation-minimising + bank, against closed forms.

Helix: kappa = R/h^2, tau = c/h^2, Frenet omega = e_z/h (notes/coaster.md, closed forms).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from core.curves import FramedCurve
from core.errors import InputError
from coaster.frames import Bank, FrenetFrame, RotationMinimisingFrame, frame_quality
from coaster.track import (CircularArc, Clothoid, CompositeCentreline, Helix, SplineCentreline,
                           Straight, chain, circuit_centreline, read_circuit)

R_H, C_H = 5.0, 1.0
H = math.hypot(R_H, C_H)


def _helix_spline(dphi, kind):
    """Spline through helix points every dphi over phi in [-2 pi, 6 pi]; L of phi = 0 and 4 pi."""
    phi = np.arange(-2 * np.pi, 6 * np.pi + 1e-9, dphi)
    P = np.c_[R_H * np.cos(phi), R_H * np.sin(phi), C_H * phi]
    c = SplineCentreline(P, kind=kind)
    i0 = int(np.argmin(np.abs(phi)))
    i1 = int(np.argmin(np.abs(phi - 4 * np.pi)))
    return c, c.L_points[i0], c.L_points[i1]


def _helix_errors(dphi, kind):
    c, a, b = _helix_spline(dphi, kind)
    L = np.linspace(a, b, 400)
    k, tau = c.curvature_torsion(L)
    _, om, _ = FrenetFrame(c).frame(L)
    return (np.max(np.abs(k - R_H / H**2)), np.max(np.abs(tau - C_H / H**2)),
            np.max(np.abs(om - [0, 0, 1 / H])))


@pytest.mark.parametrize("kind, p_kappa, p_tau", [("cubic", 2, 1), ("quintic", 4, 3)])
def test_helix_from_spline_converges_at_spline_order(kind, p_kappa, p_tau):
    """kappa error ~ dphi^(k-1), tau and Omega ~ dphi^(k-2) for a spline of degree k."""
    e1 = _helix_errors(np.pi / 6, kind)
    e2 = _helix_errors(np.pi / 12, kind)
    rk, rt, ro = (math.log2(a / b) for a, b in zip(e1, e2))
    assert rk > p_kappa - 0.3, (e1, e2)
    assert rt > p_tau - 0.3, (e1, e2)
    assert ro > p_tau - 0.3, (e1, e2)
    if kind == "quintic":
        assert e2[0] < 1e-4 * R_H / H**2 and e2[2] < 1e-3 / H


def test_frenet_equals_rmf_plus_bank_on_helix():
    """On a helix the Frenet frame is the RMF turned by theta = theta_0 + tau L about t."""
    hel = Helix(R_H, C_H, 4 * np.pi)
    fr = FrenetFrame(hel)
    tau = C_H / H**2
    R0 = RotationMinimisingFrame(hel).frame([0.0])[0][0]
    Rf0 = fr.frame([0.0])[0][0]
    th0 = math.atan2(Rf0[:, 1] @ R0[:, 2], Rf0[:, 1] @ R0[:, 1])
    bank = Bank(lambda L: np.vstack([th0 + tau * L, np.full(L.shape, tau), 0 * L, 0 * L]))
    rmf = RotationMinimisingFrame(hel, bank=bank, max_step=0.5)
    assert isinstance(rmf, FramedCurve)
    L = np.linspace(0, hel.length, 77)
    Rf, omf, domf = fr.frame(L)
    f = rmf.evaluate(L)
    assert np.max(np.abs(f.R - Rf)) < 1e-9          # measured 1.1e-10 (table, max_step 0.5 m)
    assert np.max(np.abs(f.omega - omf)) < 1e-9
    assert np.max(np.abs(f.omega - [0, 0, 1 / H])) < 1e-9
    assert np.max(np.abs(f.domega)) < 1e-9
    Rr, omr, domr = rmf.frame(L)                    # exact omega, omega'
    assert np.max(np.abs(omr - [0, 0, 1 / H])) < 1e-14 and np.max(np.abs(domr)) < 1e-14


def test_rmf_on_straight_and_frenet_error():
    s = Straight(20.0, grade=0.1)
    with pytest.raises(InputError, match=r"below kappa_min .* at L = 0.0 m"):
        FrenetFrame(s).frame(np.linspace(0, 20, 5))
    Rf, om, _ = FrenetFrame(s, fallback="vertical").frame([3.0])
    assert np.allclose(om, 0) and abs(Rf[0, 2, 1]) < 1e-15   # lateral horizontal
    rmf = RotationMinimisingFrame(s)
    f = rmf.evaluate(np.linspace(0, 20, 11))
    assert np.max(np.abs(f.R - f.R[0])) < 1e-14 and np.max(np.abs(f.omega)) < 1e-15


def _s_curve():
    return CompositeCentreline(chain([Straight(10), Clothoid(20, 0, 1 / 30), CircularArc(30, 0.6),
                                      Clothoid(40, 1 / 30, -1 / 30), CircularArc(30, 0.6, turn=-1),
                                      Clothoid(20, -1 / 30, 0), Straight(10)]))


def test_s_curve_inflection_flips_frenet_not_rmf():
    track = _s_curve()
    L_infl = 10 + 20 + 30 * 0.6 + 20        # kappa = 0 mid-way along the reversing clothoid
    L = np.linspace(35.03, 75.03, 401)      # avoids the straights; neither samples nor midpoints
    assert np.min(np.abs(L - L_infl)) > 0.01  # hit the inflection itself
    q_f = frame_quality(FrenetFrame(track), track, L)
    i = int(q_f["rotation_step_rad"].idxmax())
    assert q_f["rotation_step_rad"][i] > 3.0                      # a 180 deg flip ...
    assert q_f["L_m"][i - 1] < L_infl < q_f["L_m"][i]             # ... at the inflection
    rmf = RotationMinimisingFrame(track, max_step=1.0)
    q_r = frame_quality(rmf, track, np.linspace(0, track.length, 801))
    dev = np.abs(q_r["rotation_step_rad"] - q_r["expected_step_rad"]) / q_r["expected_step_rad"].clip(1e-3)
    assert np.nanmax(dev) < 1e-2                               # smooth: step = |omega| dL to O(dL^2)
    assert q_r["orthonormality"].max() < 1e-10 and q_r["tangent_error"].max() < 1e-10
    assert np.abs(q_r["twist_1_m"]).max() < 1e-12              # no bank: no twist about t
    # the RMF's up vector stays up on a flat S-curve (Frenet's b flips between +z and -z)
    assert np.min(rmf.evaluate(L).R[:, 2, 2]) > 1 - 1e-12


@pytest.fixture(scope="module")
def circuit():
    data = read_circuit()
    return data, circuit_centreline(data, "quintic")


def test_circuit_frames_close(circuit):
    data, cl = circuit
    rel = RotationMinimisingFrame(cl)                      # bank relative to the frame: holonomy folded in
    bank = Bank.from_samples(cl.L_points, data.roll, closed=True, length=cl.length)
    ver = RotationMinimisingFrame(cl, bank=bank, bank_reference="vertical")
    for fr in (rel, ver):
        f0, f1 = fr.evaluate([0.0]), fr.evaluate([cl.length * (1 - 1e-15)])
        assert np.max(np.abs(f0.R - f1.R)) < 1e-9         # measured < 1e-12
        assert fr.rmf_error < 1e-10
    assert abs(rel.holonomy) > 0.1                         # a real holonomy (measured -0.663 rad)
    # bank relative to the vertical: zero bank keeps the lateral axis horizontal
    flat = RotationMinimisingFrame(cl, bank_reference="vertical")
    L = np.linspace(0, cl.length, 997)
    assert np.max(np.abs(flat.evaluate(L).R[:, 2, 1])) < 1e-9
    # and the rolled frame reproduces the file's rolls at the control points (roll about t)
    Rv = ver.evaluate(cl.L_points).R
    Rf = flat.evaluate(cl.L_points).R
    roll = np.arctan2(np.einsum("ij,ij->i", Rv[:, :, 1], Rf[:, :, 2]),
                      np.einsum("ij,ij->i", Rv[:, :, 1], Rf[:, :, 1]))
    assert np.max(np.abs(roll - data.roll)) < 1e-8


def test_circuit_frame_quality(circuit):
    data, cl = circuit
    rmf = RotationMinimisingFrame(cl)
    q = frame_quality(rmf, cl, n=2001)
    assert list(q.columns)[:3] == ["L_m", "orthonormality", "tangent_error"]
    assert q["orthonormality"].max() < 1e-8 and q["tangent_error"].max() < 1e-8
    dev = np.abs(q["rotation_step_rad"] - q["expected_step_rad"])
    assert np.nanmax(dev) < 1e-3                    # no jump anywhere (measured 7.0e-5 on 2.5 m steps)
    # dR/dL = [omega]x R (central differences of the table)
    L = np.linspace(10, cl.length - 10, 50)
    e = 1e-4
    dR = (rmf.evaluate(L + e).R - rmf.evaluate(L - e).R) / (2 * e)
    f = rmf.evaluate(L)
    assert np.max(np.abs(dR - f.dR())) < 1e-6
