"""Track centrelines: the circuit reader, splines with arc length, analytic segments.

Closed forms (circle length, helix and clothoid curvature) and finite-difference consistency,
no stored numbers.
"""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from core.errors import DataFileError, InputError
from coaster.track import (CIRCUIT_FILE, CircularArc, Clothoid, CompositeCentreline, Helix,
                           SplineCentreline, Straight, VerticalLoop, chain, circuit_centreline,
                           read_circuit)


def _fd_check(curve, L, eps=1e-4):
    """max |(g^(k)(L+e) - g^(k)(L-e))/2e - g^(k+1)(L)| for k = 0..3."""
    p, m, d = curve.derivatives(L + eps), curve.derivatives(L - eps), curve.derivatives(L)
    return [float(np.max(np.abs((p[k] - m[k]) / (2 * eps) - d[k + 1]))) for k in range(4)]


# --- reader -------------------------------------------------------------------------------------
def test_reader_converts_units_and_handedness():
    data = read_circuit()
    with open(CIRCUIT_FILE, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert data.points.shape == (len(rows), 3) == (203, 3)
    for k in (0, 57, 202):
        r = rows[k]
        assert np.allclose(data.points[k], [float(r["x"]) / 100, -float(r["y"]) / 100, float(r["z"]) / 100])
        assert data.roll[k] == pytest.approx(-math.radians(float(r["roll_deg"])))
    assert set(data.section) >= {"Station", "Lift", "Brake"}


def test_circuit_length_about_4_9_km():
    data = read_circuit()
    lengths = {k: circuit_centreline(data, k).length for k in ("cubic", "quintic", "pchip", "akima")}
    # SOURCE.md: "closed circuit ~ 4.94 km"; measured 4945.30 (cubic) ... 4945.45 m (akima)
    for k, L in lengths.items():
        assert 4.90e3 < L < 4.99e3, (k, L)
    assert max(lengths.values()) - min(lengths.values()) < 0.2  # kinds agree to 40 ppm


def test_reader_names_file_and_row(tmp_path):
    text = CIRCUIT_FILE.read_text().splitlines()
    bad = list(text)
    bad[3] = bad[3].replace(bad[3].split(",")[2], "nan", 1)
    p = tmp_path / "bad.csv"
    p.write_text("\n".join(bad) + "\n")
    with pytest.raises(DataFileError, match=r"bad\.csv: row 2 \(line 4\).*column y = nan"):
        read_circuit(p)
    short = list(text)
    short[5] = ",".join(short[5].split(",")[:4])
    p.write_text("\n".join(short) + "\n")
    with pytest.raises(DataFileError, match=r"bad\.csv: row 4 \(line 6\): expected 7 fields"):
        read_circuit(p)
    with pytest.raises(DataFileError, match="not found"):
        read_circuit(tmp_path / "missing.csv")


# --- splines ------------------------------------------------------------------------------------
def _circle(n, R=10.0):
    phi = np.linspace(0, 2 * np.pi, n + 1)[:-1]
    return np.c_[R * np.cos(phi), R * np.sin(phi), 0 * phi]


@pytest.mark.parametrize("kind, order", [("cubic", 4), ("quintic", 6), ("pchip", 3), ("akima", 3)])
def test_circle_arc_length_converges(kind, order):
    """Closed spline through n points of a circle: |L - 2 pi R| falls like n^-order (or faster)."""
    R = 10.0
    e = [abs(SplineCentreline(_circle(n, R), kind=kind, closed=True).length - 2 * np.pi * R)
         for n in (12, 24)]
    # measured: cubic 7.0e-3 -> 4.4e-4, quintic 4.9e-5 -> 7.7e-7, pchip 6.8e-2 -> 8.6e-3 (akima similar)
    assert e[1] < e[0] / 2 ** (order - 0.5)
    assert SplineCentreline(_circle(48, R), kind="quintic", closed=True).length == pytest.approx(2 * np.pi * R, rel=1e-9)


@pytest.mark.parametrize("kind", ["cubic", "quintic", "pchip", "makima"])
@pytest.mark.parametrize("closed", [False, True])
def test_spline_arc_length_derivatives(kind, closed):
    """|g'| = 1 and g'' ... g'''' are the L-derivatives (central differences, away from knots)."""
    rng = np.random.default_rng(1)
    if closed:
        a = np.linspace(0, 2 * np.pi, 10)[:-1] + rng.uniform(-0.1, 0.1, 9)
        P = np.c_[40 * np.cos(a), 25 * np.sin(a), rng.uniform(-3, 3, 9)]
    else:
        P = np.c_[np.cos(np.linspace(0, 5, 9)) * 20, np.linspace(0, 80, 9), rng.uniform(-3, 3, 9)]
    c = SplineCentreline(P, kind=kind, closed=closed, bc="natural" if kind == "cubic" else "not-a-knot")
    mid = 0.5 * (c.L_knots[:-1] + c.L_knots[1:])
    d = c.derivatives(mid)
    assert np.max(np.abs(np.linalg.norm(d[1], axis=1) - 1)) < 1e-12
    assert np.allclose(c.derivatives(c.L_points)[0], P, atol=1e-9)
    err = _fd_check(c, mid, 1e-4)
    assert max(err) < 1e-6, err


def test_spline_bad_input_names_index():
    P = np.c_[np.arange(6.0), np.zeros(6), np.zeros(6)]
    Q = P.copy(); Q[3] = Q[2]
    with pytest.raises(InputError, match="control points 2 and 3 coincide"):
        SplineCentreline(Q)
    Q = P.copy(); Q[4, 1] = np.nan
    with pytest.raises(InputError, match="point 4 coordinate 1"):
        SplineCentreline(Q)
    with pytest.raises(InputError, match="at least 4"):
        SplineCentreline(P[:3])
    x = np.array([0.0, 1, 2, 3, 4, 3, 2, 1])  # every coordinate turns at point 4 -> PCHIP cusp
    with pytest.raises(InputError, match=r"zero speed.*\(knot 4\)"):
        SplineCentreline(np.c_[x, x**2, -x], kind="pchip")
    with pytest.raises(InputError, match="unknown spline kind"):
        SplineCentreline(P, kind="linear")


# --- analytic segments ---------------------------------------------------------------------------
@pytest.mark.parametrize("seg", [Straight(10, 0.2), CircularArc(20, 1.0, turn=-1), Helix(5, 1, 7),
                                 Clothoid(30, 0.0, 0.05), Clothoid(30, 0.04, -0.02), VerticalLoop(8, 3)],
                         ids=lambda s: type(s).__name__)
def test_segment_derivatives_consistent(seg):
    L = np.linspace(0.2, seg.length - 0.2, 9)
    d = seg.derivatives(L)
    assert np.max(np.abs(np.linalg.norm(d[1], axis=1) - 1)) < 1e-14
    assert max(_fd_check(seg, L)) < 1e-7


def test_segment_closed_forms():
    R, c = 5.0, 1.5
    h = math.hypot(R, c)
    k, tau = Helix(R, c, 3).curvature_torsion(np.linspace(0, 10, 5))
    assert np.allclose(k, R / h**2, rtol=1e-14) and np.allclose(tau, c / h**2, rtol=1e-13)
    L = np.linspace(0, 30, 7)
    k, _ = Clothoid(30, 0.0, 0.05).curvature_torsion(L)
    assert np.allclose(k, L / (30 / 0.05), atol=1e-15)  # kappa = L/A^2, A^2 = R L_t
    loop = VerticalLoop(10.0)
    end = loop.derivatives([loop.length])
    assert np.allclose(end[0, 0], 0, atol=1e-12) and np.allclose(end[1, 0], [1, 0, 0])
    top = loop.derivatives([loop.length / 2])[0, 0]
    assert np.allclose(top, [0, 0, 20.0], atol=1e-12)


def test_chain_and_composite():
    segs = chain([Straight(10), Clothoid(20, 0, 1 / 25), CircularArc(25, 0.8), Clothoid(20, 1 / 25, 0),
                  Straight(5)])
    comp = CompositeCentreline(segs)
    assert comp.length == pytest.approx(10 + 20 + 25 * 0.8 + 20 + 5)
    L = np.linspace(0.5, comp.length - 0.5, 40)
    assert max(_fd_check(comp, L[np.min(np.abs(L[:, None] - comp.breaks), axis=1) > 1e-3])[:2]) < 1e-7
    # kappa is continuous through the clothoids (G2 track)
    k, _ = comp.curvature_torsion(comp.breaks[1:-1])
    kl = np.linalg.norm(comp.derivatives(comp.breaks[1:-1], side="left")[2], axis=1)
    assert np.allclose(k, kl, atol=1e-12)
    with pytest.raises(InputError, match=r"joint 0->1 \(Straight -> Helix\)"):
        CompositeCentreline(chain([Straight(10), Helix(5, 1, 2)]))
