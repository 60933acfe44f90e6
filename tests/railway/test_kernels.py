"""Unit tier: the allocation-free helpers of railway.contact.search.kernels against the library routines they
stand in for, bit for bit (the vehicle runs rely on the results being unchanged)."""

import numpy as np
import pytest

from railway.contact.search import kernels as K

pytestmark = pytest.mark.skipif(not K.HAVE_NUMBA, reason="numba not installed")


def test_interp3_equals_np_interp_bit_for_bit():
    rng = np.random.default_rng(3)
    xp = np.sort(rng.uniform(-1.2, 1.3, 40))
    f = [rng.normal(size=40) for _ in range(3)]
    f[2][10:12] = 0.25  # a flat piece
    # inside, outside on both sides, on the nodes and at both ends, NaN
    x = np.concatenate([rng.uniform(-1.5, 1.6, 300), xp, [xp[0], xp[-1], -np.inf, np.inf, np.nan]])
    o = [np.empty_like(x) for _ in range(3)]
    K.interp3(x, xp, f[0], f[1], f[2], o[0], o[1], o[2])
    for k in range(3):
        np.testing.assert_array_equal(o[k], np.interp(x, xp, f[k]))


def test_interp3_single_node_table():
    xp, fp = np.array([0.3]), np.array([2.0])
    x = np.array([-1.0, 0.3, 1.0])
    o = [np.empty(3) for _ in range(3)]
    K.interp3(x, xp, fp, fp, fp, o[0], o[1], o[2])
    np.testing.assert_array_equal(o[0], np.interp(x, xp, fp))


def _stack(rng, n=12, k1=6, q=45):
    breaks = np.cumsum(rng.uniform(0.5, 2.0, n + 1))
    return breaks[1:-1], breaks, rng.normal(size=(n, k1, q))


def _horner_reference(inner, breaks, stack, x):
    """Horner's scheme per column, the loop order of the kernels before the change."""
    i = np.searchsorted(inner, x, side="right")
    t = x - breaks[i]
    out = np.empty(stack.shape[2])
    for c in range(stack.shape[2]):
        acc = 0.0
        for j in range(stack.shape[1] - 1, -1, -1):
            acc = acc * t + stack[i, j, c]
        out[c] = acc
    return out


def test_piecewise_polynomials_equal_the_column_by_column_scheme():
    rng = np.random.default_rng(5)
    inner, breaks, stack = _stack(rng)
    cols = K.EVALUATE_COLUMNS
    for x in rng.uniform(breaks[0] - 0.5, breaks[-1] + 0.5, 50):
        ref = _horner_reference(inner, breaks, stack, x)
        full = np.empty(45)
        K.ppeval(inner, breaks, stack, x, full)
        np.testing.assert_array_equal(full, ref)
        short = np.full(K.FRAME_COLUMNS, np.nan)
        K.ppeval(inner, breaks, stack, x, short)  # only as many columns as out holds
        np.testing.assert_array_equal(short, ref[:K.FRAME_COLUMNS])
        part = np.full(K.FRAME_COLUMNS, np.nan)
        K.ppeval_columns(inner, breaks, stack, x, part, cols)
        for a, b in cols:
            np.testing.assert_array_equal(part[a:b], ref[a:b])
        gaps = np.ones(K.FRAME_COLUMNS, bool)
        for a, b in cols:
            gaps[a:b] = False
        assert np.all(np.isnan(part[gaps]))  # the other columns are left alone
        np.testing.assert_array_equal(np.array(K.ppeval3(inner, breaks, stack, x)), ref[:3])


def test_evaluate_columns_cover_what_evaluate_reads():
    # r 0-2, R 3-11, omega 12-14, r' 15-17, omega' 27-29, r'' 30-32 of the frame table's layout
    read = set(range(0, 18)) | set(range(27, 33))
    covered = set()
    for a, b in K.EVALUATE_COLUMNS:
        covered |= set(range(a, b))
    assert covered == read and max(covered) + 1 == K.FRAME_COLUMNS


def test_wrap_angle_is_the_angle_of_the_unit_phasor():
    """The scan's lead-angle roots phi ± acos(c), phi in (-pi, pi], wrapped by arithmetic: the result
    lies in (-pi, pi] and has the same cosine and sine as the unwrapped angle (what
    atan2(sin x, cos x) gave before, to round-off)."""
    rng = np.random.default_rng(7)
    phi = rng.uniform(-np.pi, np.pi, 2000)
    acs = np.arccos(rng.uniform(-1.0, 1.0, 2000))
    x = np.concatenate([phi + acs, phi - acs, [np.pi, 2 * np.pi, -np.pi + 1e-12, 0.0]])
    w = np.array([K.wrap_angle(float(v)) for v in x])
    assert np.all(w > -np.pi) and np.all(w <= np.pi)
    np.testing.assert_allclose(np.cos(w), np.cos(x), rtol=0, atol=4e-15)
    np.testing.assert_allclose(np.sin(w), np.sin(x), rtol=0, atol=4e-15)
    np.testing.assert_allclose(w, np.arctan2(np.sin(x), np.cos(x)), rtol=0, atol=1e-14)
