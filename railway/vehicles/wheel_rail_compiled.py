r"""Compiled kernels of the wheel–rail force element, for core's compiled integrators.

:class:`railway.vehicles.wheel_rail.WheelRailKind` joins core's compiled path (``jit-rk45``,
``jit-dop853``, ``jit-radau``) through ``compiled(layout)``, which returns the kernels below with
core's fixed signatures (:mod:`core.compiled.protocol`); this module registers
:func:`compile_wheel_rail` as ``WheelRailKind.compiled_form`` when it is imported (the package
:mod:`railway.vehicles` imports it), so that the numpy kind never imports its kernels and the two
modules form no import circle (issue 22; the rules both apply are in
:mod:`railway.vehicles.wheel_rail_rules`).  The kernels are the numpy kind's algorithm
(see :mod:`railway.vehicles.wheel_rail`) written for numba, built from the same compiled pieces the
contact search and the contact forces already use:

* the track projection, Newton on (r − g(s))·g′(s) = 0 on the track's frame table
  (:func:`railway.contact.search.kernels.ppeval`), from the arc length of the last accepted step;
* the unspun wheelset frame [f, a, u] from the axle and the track's up vector;
* the contact Newton iteration (:func:`railway.contact.search.kernels.newton`) from the two tracked points of
  the search state, their rail arc length moved with the wheelset, lowest valid gap per
  candidate, the zone-overlap duplicate rule of :meth:`railway.contact.search.ContactSearch._finish`;
* Hertz, Lankarani–Nikravesh and every creep law of the package (:func:`railway.contact.forces.kernel`);
* generalized forces on the wheelset bodies.

The accept kernel is the numpy kind's :meth:`~railway.vehicles.wheel_rail.WheelRailKind.accept_step`:
the global cross-section scan (:func:`railway.contact.search.kernels.scan`) every ``reseed_every`` accepted
steps and whenever a tracked contact was lost, the two lowest distinct stationary points kept,
and the derailment checks, which end the run with status ``failed`` (kernel status
``ELEMENT_FAILED``; the message, from :func:`describe_failure`, names the wheel and its Y/Q).

Differences from the numpy path, by design: scan seeds that Newton cannot solve are not refined
by the robust route of :meth:`railway.contact.search.ContactSearch._robust` (it stays on the
numpy path); a rail body (``rail_body``) is refused with :class:`core.errors.NotCompilable`.
``tests/railway/test_wheel_rail.py`` checks that both paths give the same forces.

Data layout
-----------
One row of ``fd`` and ``ix`` per element.  ``ix[e]``: header (:data:`IX_*`), then for each
float segment of :data:`SEGMENTS` its offset into ``fd[e]`` and three dimensions, then the
wheelset body indices.  The state row ``state[e]``: header (:data:`ST_*`), the tracked points
(2, P, 4), the wheelset arc lengths (n_ws), the validity of every candidate (P) and the last
accepted Y/Q of every wheel (2 n_ws); P = 4 n_ws problems ordered wheelset, side (left, right),
candidate (tread, flange).
"""

from __future__ import annotations

import numba
import numpy as np

from core.compiled.protocol import (
    ELEMENT_FAILED,
    OK,
    CompiledForces,
    accept_kernel,
    force_kernel,
)

from ..contact.search.kernels import newton, ppeval, ppeval_columns, reduced_min, scan
from ..contact.forces import kernel as contact_forces
from .wheel_rail import WheelRailKind
from .wheel_rail_rules import ACCEPT_RANKS, BLEND_GAP, DUPLICATE, NEIGHBOUR_OFFSETS, SEPARATION, climb_message

__all__ = ["compile_wheel_rail", "describe_failure"]

_jit = numba.njit(cache=True, fastmath=False, nogil=True)

# --- ix header --------------------------------------------------------------------------------
IX_NWS, IX_MODEL, IX_MAXIT, IX_RESEED, IX_G, IX_NTAB = 0, 1, 2, 3, 4, 5
IX_SEG0 = 8
SEGMENTS = ("b_inner", "b_breaks", "b_stack", "f_inner", "f_breaks", "f_stack",
            "sig", "r0", "L", "ow", "orr", "Y0", "Z0", "ca", "sa", "lo", "hi", "lo_e", "hi_e",
            "ulo", "uhi", "flange", "yg", "rg", "F1g", "rail_l", "rail_r", "tab", "maxstep", "wts",
            "scal", "cp")
_SEG = {name: k for k, name in enumerate(SEGMENTS)}
# segment indices as module constants (numba reads module-level ints as compile-time constants)
K_B_INNER = 0
K_B_BREAKS = 1
K_B_STACK = 2
K_F_INNER = 3
K_F_BREAKS = 4
K_F_STACK = 5
K_SIG = 6
K_R0 = 7
K_L = 8
K_OW = 9
K_ORR = 10
K_Y0 = 11
K_Z0 = 12
K_CA = 13
K_SA = 14
K_LO = 15
K_HI = 16
K_LO_E = 17
K_HI_E = 18
K_ULO = 19
K_UHI = 20
K_FLANGE = 21
K_YG = 22
K_RG = 23
K_F1G = 24
K_RAIL_L = 25
K_RAIL_R = 26
K_TAB = 27
K_MAXSTEP = 28
K_WTS = 29
K_SCAL = 30
K_CP = 31
# scalars of segment "scal"
(SC_TOL, SC_T0, SC_DT, SC_KSUM, SC_G, SC_MU, SC_CHI, SC_V0, SC_MAXPEN, SC_YSPLIT, SC_YTIP, SC_YCLIMB,
 SC_MAXLAT, SC_MAXDROP, SC_R0, SC_LENGTH, SC_CLOSED, SC_LW) = range(18)
# --- state header -----------------------------------------------------------------------------
ST_ACC, ST_FAIL, ST_IDX, ST_V1, ST_YQ0, ST_YQ1, ST_V2 = range(7)
ST_HEAD = 8
FAIL_FLANGE_CLIMB, FAIL_LEFT_RAILS, FAIL_OFF_TRACK = 1, 2, 3


def _seg_index(k):
    return IX_SEG0 + 4 * k


@_jit
def _seg1(fd, ix, e, k):
    j = IX_SEG0 + 4 * k
    o = ix[e, j]
    return fd[e, o:o + ix[e, j + 1]]


@_jit
def _seg2(fd, ix, e, k):
    j = IX_SEG0 + 4 * k
    o = ix[e, j]
    n0, n1 = ix[e, j + 1], ix[e, j + 2]
    return fd[e, o:o + n0 * n1].reshape((n0, n1))


@_jit
def _seg3(fd, ix, e, k):
    j = IX_SEG0 + 4 * k
    o = ix[e, j]
    n0, n1, n2 = ix[e, j + 1], ix[e, j + 2], ix[e, j + 3]
    return fd[e, o:o + n0 * n1 * n2].reshape((n0, n1, n2))


#: Track-frame columns the projection's iterations read: r, r', r'' (railway.contact.search.kernels.EVALUATE_COLUMNS)
PROJECT_COLUMNS = np.array([[0, 3], [15, 18], [30, 33]], dtype=np.int64)


@_jit
def _project(f_inner, f_breaks, f_stack, p, s0, length, closed, o):
    """Arc length of the foot of the perpendicular from p (NaN when not over the track); ``o``
    holds every column of the frame at the returned arc length."""
    s = s0
    for _ in range(30):
        ppeval_columns(f_inner, f_breaks, f_stack, s, o, PROJECT_COLUMNS)
        e0, e1, e2 = p[0] - o[0], p[1] - o[1], p[2] - o[2]
        f = e0 * o[15] + e1 * o[16] + e2 * o[17]
        df = -(o[15] * o[15] + o[16] * o[16] + o[17] * o[17]) + e0 * o[30] + e1 * o[31] + e2 * o[32]
        step = -f / df if df != 0.0 else 0.0
        lim = 0.25 * (np.sqrt(e0 * e0 + e1 * e1 + e2 * e2) + 1.0)
        if not np.isfinite(step):
            step = 0.0
        if step > lim:
            step = lim
        if step < -lim:
            step = -lim
        s += step
        if abs(step) < 1e-10:
            if closed < 0.5 and (s < 0.0 or s > length):
                return np.nan
            ppeval(f_inner, f_breaks, f_stack, s, o)
            return s
    return np.nan


@_jit
def _poses(r, A, rd, w, bw, fd, ix, e, s_prev, s_out, rws, Ans, vws, wws, o):
    """Wheelset centres, unspun frames, velocities and global angular velocities; arc lengths
    (NaN for a wheelset that is not over the track)."""
    f_inner, f_breaks = _seg1(fd, ix, e, K_F_INNER), _seg1(fd, ix, e, K_F_BREAKS)
    f_stack = _seg3(fd, ix, e, K_F_STACK)
    sc = _seg1(fd, ix, e, K_SCAL)
    for k in range(bw.shape[0]):
        b = bw[k]
        for i in range(3):
            rws[k, i] = r[b, i]
            vws[k, i] = rd[b, i]
            wws[k, i] = A[b, i, 0] * w[b, 0] + A[b, i, 1] * w[b, 1] + A[b, i, 2] * w[b, 2]
        s = _project(f_inner, f_breaks, f_stack, rws[k], s_prev[k], sc[SC_LENGTH], sc[SC_CLOSED], o)
        s_out[k] = s
        if not np.isfinite(s):
            ppeval(f_inner, f_breaks, f_stack, s_prev[k], o)
        # unspun frame: a = A e_y, f = a x up / |.|, u = f x a
        a0, a1, a2 = A[b, 0, 1], A[b, 1, 1], A[b, 2, 1]
        u0, u1, u2 = o[5], o[8], o[11]
        f0, f1, f2 = a1 * u2 - a2 * u1, a2 * u0 - a0 * u2, a0 * u1 - a1 * u0
        fn = np.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
        f0 /= fn
        f1 /= fn
        f2 /= fn
        Ans[k, 0, 0], Ans[k, 1, 0], Ans[k, 2, 0] = f0, f1, f2
        Ans[k, 0, 1], Ans[k, 1, 1], Ans[k, 2, 1] = a0, a1, a2
        Ans[k, 0, 2], Ans[k, 1, 2], Ans[k, 2, 2] = f1 * a2 - f2 * a1, f2 * a0 - f0 * a2, f0 * a1 - f1 * a0


@_jit
def _solve(fd, ix, e, rws, Ans, x0, prob):
    """Newton from (seed, problem) pairs (x0[k] for problem prob[k], sorted by problem); per
    problem the lowest valid gap (ties: the first pair).

    Returns xb (P, 4), valid (P), gap (P), S (P, 11), V (P, 3, 3), X (K, 4), G (K), and every
    pair's S (K, 11) and V (K, 3, 3)."""
    X, Ga, Sp, Vp = _newton_pairs(fd, ix, e, rws, Ans, x0, prob)
    xb, valid, gap, Sb, Vb = _best(fd, ix, e, prob, X, Ga, Sp, Vp)
    return xb, valid, gap, Sb, Vb, X, Ga, Sp, Vp


@_jit
def _newton_pairs(fd, ix, e, rws, Ans, x0, prob):
    """Newton from every (seed, problem) pair on its own: X (K, 4), G (K) (the gap, +inf where
    the pair is no contact: not converged, a saddle, too deep or outside its zone), S (K, 11),
    V (K, 3, 3).  Each pair's result depends on that pair only."""
    K = prob.shape[0]
    sig, r0, L = _seg1(fd, ix, e, K_SIG), _seg1(fd, ix, e, K_R0), _seg1(fd, ix, e, K_L)
    ow, orr = _seg1(fd, ix, e, K_OW), _seg1(fd, ix, e, K_ORR)
    Y0, Z0 = _seg1(fd, ix, e, K_Y0), _seg1(fd, ix, e, K_Z0)
    ca, sa = _seg1(fd, ix, e, K_CA), _seg1(fd, ix, e, K_SA)
    lo, hi = _seg2(fd, ix, e, K_LO), _seg2(fd, ix, e, K_HI)
    lo_e, hi_e = _seg2(fd, ix, e, K_LO_E), _seg2(fd, ix, e, K_HI_E)
    sc = _seg1(fd, ix, e, K_SCAL)
    Ga = np.full(K, np.inf)
    if K == 0:
        return x0.copy(), Ga, np.zeros((0, 11)), np.zeros((0, 3, 3))
    msig, mr0, mL, mow, morr = np.empty(K), np.empty(K), np.empty(K), np.empty(K), np.empty(K)
    mY0, mZ0, mca, msa = np.empty(K), np.empty(K), np.empty(K), np.empty(K)
    mlo, mhi = np.empty((K, 4)), np.empty((K, 4))
    mr = np.empty((K, 3))
    mA = np.empty((K, 3, 3))
    for i in range(K):
        p = prob[i]
        msig[i], mr0[i], mL[i], mow[i], morr[i] = sig[p], r0[p], L[p], ow[p], orr[p]
        mY0[i], mZ0[i], mca[i], msa[i] = Y0[p], Z0[p], ca[p], sa[p]
        k = p // 4
        for c in range(4):
            mlo[i, c] = lo[p, c]
            mhi[i, c] = hi[p, c]
        for c in range(3):
            mr[i, c] = rws[k, c]
            for d in range(3):
                mA[i, c, d] = Ans[k, c, d]
    X, H0, conv, it, GAP, S, V = newton(
        x0, msig, mr0, mL, mow, morr, mY0, mZ0, mca, msa, mlo, mhi, mr, mA,
        _seg1(fd, ix, e, K_B_INNER), _seg1(fd, ix, e, K_B_BREAKS), _seg3(fd, ix, e, K_B_STACK),
        _seg1(fd, ix, e, K_F_INNER), _seg1(fd, ix, e, K_F_BREAKS), _seg3(fd, ix, e, K_F_STACK),
        sc[SC_TOL], ix[e, IX_MAXIT], _seg1(fd, ix, e, K_MAXSTEP), _seg1(fd, ix, e, K_WTS))
    for i in range(K):
        p = prob[i]
        ok = conv[i] and np.isfinite(GAP[i]) and GAP[i] > -sc[SC_MAXPEN]
        for c in range(4):
            if not (X[i, c] > lo_e[p, c] and X[i, c] < hi_e[p, c]):
                ok = False
        Ga[i] = GAP[i] if ok else np.inf
    return X, Ga, S, V


@_jit
def _best(fd, ix, e, prob, X, Ga, S, V):
    """Per problem the pair of lowest gap G (ties: the first pair; a problem whose pairs are all
    +inf keeps its first pair's point, not valid), then the zone-overlap duplicates dropped:
    xb (P, 4), valid (P), gap (P), Sb (P, 11), Vb (P, 3, 3)."""
    n_ws = ix[e, IX_NWS]
    P = 4 * n_ws
    sc = _seg1(fd, ix, e, K_SCAL)
    xb = np.zeros((P, 4))
    valid = np.zeros(P, dtype=np.bool_)
    gap = np.full(P, np.inf)
    Sb = np.full((P, 11), np.nan)
    Vb = np.full((P, 3, 3), np.nan)
    best = np.full(P, -1, dtype=np.int64)
    for i in range(prob.shape[0]):
        p = prob[i]
        if best[p] < 0 or Ga[i] < gap[p]:
            best[p] = i
            gap[p] = Ga[i]
            valid[p] = np.isfinite(Ga[i])
    for p in range(P):
        i = best[p]
        if i < 0:
            continue
        for c in range(4):
            xb[p, c] = X[i, c]
        if valid[p]:
            for c in range(11):
                Sb[p, c] = S[i, c]
            for c in range(3):
                for d in range(3):
                    Vb[p, c, d] = V[i, c, d]
    _dedup(xb, valid, gap, Sb, Vb, sc[SC_YSPLIT])
    return xb, valid, gap, Sb, Vb


@_jit
def _solve_added(fd, ix, e, rws, Ans, x1, prob1, src, X0, G0, S0, V0):
    """:func:`_solve` of the pairs (x1, prob1) where row i is the already solved pair
    ``src[i]`` of (X0, G0, S0, V0) or, with ``src[i] < 0``, a new one: Newton runs on the new
    pairs only (each pair's result depends on that pair alone, so this equals solving all)."""
    K1 = prob1.shape[0]
    n_new = 0
    for i in range(K1):
        if src[i] < 0:
            n_new += 1
    xn = np.empty((n_new, 4))
    pn = np.empty(n_new, dtype=np.int64)
    j = 0
    for i in range(K1):
        if src[i] < 0:
            for c in range(4):
                xn[j, c] = x1[i, c]
            pn[j] = prob1[i]
            j += 1
    Xn, Gn, Sn, Vn = _newton_pairs(fd, ix, e, rws, Ans, xn, pn)
    X = np.empty((K1, 4))
    Ga = np.empty(K1)
    Sp = np.empty((K1, 11))
    Vp = np.empty((K1, 3, 3))
    j = 0
    for i in range(K1):
        k = src[i]
        if k >= 0:
            X[i], Ga[i], Sp[i], Vp[i] = X0[k], G0[k], S0[k], V0[k]
        else:
            X[i], Ga[i], Sp[i], Vp[i] = Xn[j], Gn[j], Sn[j], Vn[j]
            j += 1
    xb, valid, gap, Sb, Vb = _best(fd, ix, e, prob1, X, Ga, Sp, Vp)
    return xb, valid, gap, Sb, Vb, X, Ga, Sp, Vp


@_jit
def _second(xb, valid, X, Ga, Sp, Vp, prob, sep):
    """Second contact patch per candidate (railway.vehicles.wheel_rail, "Two patches per zone"): the
    lowest penetrating pair solution at least ``sep`` away from the primary on the wheel
    profile.  Returns valid2 (P), gap2 (P), S2 (P, 11), V2 (P, 3, 3)."""
    P = valid.shape[0]
    valid2 = np.zeros(P, dtype=np.bool_)
    gap2 = np.full(P, np.inf)
    S2 = np.full((P, 11), np.nan)
    V2 = np.full((P, 3, 3), np.nan)
    best = np.full(P, -1, dtype=np.int64)
    for i in range(prob.shape[0]):
        p = prob[i]
        q = p ^ 1  # the other zone of the same wheel: its contact is not this zone's second
        same = valid[q] and abs(X[i, 1] - xb[q, 1]) < DUPLICATE
        if valid[p] and Ga[i] < 0.0 and abs(X[i, 1] - xb[p, 1]) > sep and Ga[i] < gap2[p] and not same:
            gap2[p] = Ga[i]
            best[p] = i
    for p in range(P):
        i = best[p]
        if i < 0:
            continue
        valid2[p] = True
        for c in range(11):
            S2[p, c] = Sp[i, c]
        for c in range(3):
            for d in range(3):
                V2[p, c, d] = Vp[i, c, d]
    return valid2, gap2, S2, V2


@_jit
def _weigh_patches(vb, Sb, gb, out, Fg, Mg, P):
    """Shares of every wheel's patches (railway.vehicles.wheel_rail.patch_shares): per wheel the patches
    (tread, flange) primary and second, duplicates of an earlier loaded patch dropped, the
    others weighted by the product over their overlapping neighbours of the same zone."""
    idx = np.empty(4, dtype=np.int64)
    loaded = np.empty(4, dtype=np.bool_)
    dup = np.empty(4, dtype=np.bool_)
    share = np.empty(4)
    for wi in range(P // 2):
        idx[0], idx[1], idx[2], idx[3] = 2 * wi, 2 * wi + 1, P + 2 * wi, P + 2 * wi + 1
        for i in range(4):
            p = idx[i]
            loaded[i] = vb[p] and out[p, 0] > 0.0 and np.isfinite(Sb[p, 1]) and np.isfinite(gb[p])
            dup[i] = False
            share[i] = 1.0
        for i in range(1, 4):
            for j in range(i):
                if (loaded[i] and loaded[j] and not dup[j]
                        and abs(Sb[idx[i], 1] - Sb[idx[j], 1]) < DUPLICATE):
                    dup[i] = True
        for i in range(4):
            if dup[i]:
                share[i] = 0.0
                continue
            if not loaded[i]:
                continue
            pi = idx[i]
            for j in range(4):
                if j == i or j % 2 != i % 2 or not loaded[j] or dup[j]:
                    continue  # patches of the same zone share
                pj = idx[j]
                bsum = out[pi, 8] + out[pj, 8]
                w = (abs(Sb[pj, 1] - Sb[pi, 1]) - bsum) / (0.5 * (bsum if bsum > 0.0 else 1.0))
                w = min(max(w, 0.0), 1.0)
                sig = 0.5 * (1.0 + np.tanh((gb[pj] - gb[pi]) / BLEND_GAP))
                share[i] *= w + (1.0 - w) * sig
        for i in range(4):
            if share[i] == 1.0:
                continue
            p = idx[i]
            for k in range(4):
                out[p, k] *= share[i]
            for k in range(3):
                Fg[p, k] *= share[i]
                Mg[p, k] *= share[i]


@_jit
def _both(valid, gap, S, V, valid2, gap2, S2, V2):
    """Primary and secondary patches stacked (2P) for the forces kernel."""
    P = valid.shape[0]
    vb = np.empty(2 * P, dtype=np.bool_)
    gb = np.empty(2 * P)
    Sb = np.empty((2 * P, 11))
    Vb = np.empty((2 * P, 3, 3))
    for p in range(P):
        vb[p], vb[P + p] = valid[p], valid2[p]
        gb[p], gb[P + p] = gap[p], gap2[p]
        for c in range(11):
            Sb[p, c], Sb[P + p, c] = S[p, c], S2[p, c]
        for c in range(3):
            for d in range(3):
                Vb[p, c, d], Vb[P + p, c, d] = V[p, c, d], V2[p, c, d]
    return vb, gb, Sb, Vb


@_jit
def _dedup(xb, valid, gap, Sb, Vb, y_split):
    """Zone-overlap duplicates: keep the candidate whose own zone holds the point."""
    P = valid.shape[0]
    for w_ in range(P // 2):
        pt, pf = 2 * w_, 2 * w_ + 1
        if (valid[pt] and valid[pf] and abs(xb[pt, 1] - xb[pf, 1]) < 1e-5
                and abs(xb[pt, 3] - xb[pf, 3]) < 1e-5):
            drop = pt if xb[pt, 1] < y_split else pf
            valid[drop] = False
            gap[drop] = np.inf
            for c in range(11):
                Sb[drop, c] = np.nan
            for c in range(3):
                for d in range(3):
                    Vb[drop, c, d] = np.nan


@_jit
def _forces(fd, ix, e, valid, gap, S, V, rws, vws, wws, Ans):
    """Contact forces of all candidates: out (P, 10), Fg (P, 3), Mg (P, 3), vmin."""
    P = valid.shape[0]
    sc = _seg1(fd, ix, e, K_SCAL)
    pen = np.empty(P)
    kwr, kwl, krr, krl = np.empty(P), np.empty(P), np.empty(P), np.empty(P)
    Pt = np.zeros((P, 3))
    Nr = np.zeros((P, 3))
    ws_of = np.empty(P, dtype=np.int64)
    fwd = np.empty((rws.shape[0], 3))
    for k in range(rws.shape[0]):
        for i in range(3):
            fwd[k, i] = Ans[k, i, 0]
    for p in range(P):
        pen[p] = -gap[p]
        kwr[p], kwl[p], krr[p], krl[p] = S[p, 7], S[p, 8], S[p, 9], S[p, 10]
        ws_of[p] = (p // 4) % rws.shape[0]
        if valid[p]:
            for i in range(3):
                Pt[p, i] = V[p, 0, i]
                Nr[p, i] = V[p, 2, i]
    out = np.empty((P, 10))
    Fg = np.empty((P, 3))
    Mg = np.empty((P, 3))
    vmin = contact_forces(pen, valid, kwr, kwl, krr, krl, Pt, Nr, ws_of, rws, vws, wws, fwd,
                          sc[SC_T0], sc[SC_DT], _seg2(fd, ix, e, K_TAB), sc[SC_KSUM], sc[SC_G],
                          sc[SC_MU], sc[SC_CHI], sc[SC_V0], ix[e, IX_MODEL], _seg1(fd, ix, e, K_CP),
                          out, Fg, Mg)
    return out, Fg, Mg, vmin


@_jit
def _state_views(state, e, n_ws):
    P = 4 * n_ws
    row = state[e]
    a = ST_HEAD
    seeds = row[a:a + 8 * P].reshape((2, P, 4))
    a += 8 * P
    s_ws = row[a:a + n_ws]
    a += n_ws
    val = row[a:a + P]
    a += P
    yq = row[a:a + 2 * n_ws]
    return seeds, s_ws, val, yq


@_jit
def _robust_merge(fd, ix, e, rws, Ans, xb, valid, gap, S, V, mask):
    """Problems in ``mask`` without a valid contact: the robust minimisation of the profile-line
    gap over the whole zone (railway.contact.search.kernels.reduced_min, 96 samples), merged into the results
    (ContactSearch._robust_zone)."""
    n_ws = ix[e, IX_NWS]
    P = 4 * n_ws
    K = 0
    for p in range(P):
        if mask[p] and not valid[p]:
            K += 1
    if K == 0:
        return
    idx = np.empty(K, dtype=np.int64)
    i = 0
    for p in range(P):
        if mask[p] and not valid[p]:
            idx[i] = p
            i += 1
    sig, r0, L = _seg1(fd, ix, e, K_SIG), _seg1(fd, ix, e, K_R0), _seg1(fd, ix, e, K_L)
    ow, orr = _seg1(fd, ix, e, K_OW), _seg1(fd, ix, e, K_ORR)
    Y0, Z0 = _seg1(fd, ix, e, K_Y0), _seg1(fd, ix, e, K_Z0)
    ca, sa = _seg1(fd, ix, e, K_CA), _seg1(fd, ix, e, K_SA)
    lo, hi = _seg2(fd, ix, e, K_LO), _seg2(fd, ix, e, K_HI)
    lo_e, hi_e = _seg2(fd, ix, e, K_LO_E), _seg2(fd, ix, e, K_HI_E)
    sc = _seg1(fd, ix, e, K_SCAL)
    x0 = np.empty((K, 4))
    msig, mr0, mL, mow, morr = np.empty(K), np.empty(K), np.empty(K), np.empty(K), np.empty(K)
    mY0, mZ0, mca, msa, ylo, yhi = np.empty(K), np.empty(K), np.empty(K), np.empty(K), np.empty(K), np.empty(K)
    mlo, mhi = np.empty((K, 4)), np.empty((K, 4))
    mr = np.empty((K, 3))
    mA = np.empty((K, 3, 3))
    for i in range(K):
        p = idx[i]
        for c in range(4):
            x0[i, c] = xb[p, c]
            mlo[i, c] = lo[p, c]
            mhi[i, c] = hi[p, c]
        msig[i], mr0[i], mL[i], mow[i], morr[i] = sig[p], r0[p], L[p], ow[p], orr[p]
        mY0[i], mZ0[i], mca[i], msa[i] = Y0[p], Z0[p], ca[p], sa[p]
        ylo[i], yhi[i] = lo_e[p, 1] + 1e-9, hi_e[p, 1] - 1e-9
        k = p // 4
        for c in range(3):
            mr[i, c] = rws[k, c]
            for d in range(3):
                mA[i, c, d] = Ans[k, c, d]
    bi, bb, bs = _seg1(fd, ix, e, K_B_INNER), _seg1(fd, ix, e, K_B_BREAKS), _seg3(fd, ix, e, K_B_STACK)
    fi, fb, fs = _seg1(fd, ix, e, K_F_INNER), _seg1(fd, ix, e, K_F_BREAKS), _seg3(fd, ix, e, K_F_STACK)
    ms = _seg1(fd, ix, e, K_MAXSTEP)
    X, ok = reduced_min(x0, ylo, yhi, msig, mr0, mL, mow, morr, mY0, mZ0, mca, msa, mlo, mhi, mr, mA,
                        bi, bb, bs, fi, fb, fs, ms, 96, 1e-9)
    X1, H, cv, it, GAP, S1, V1 = newton(X, msig, mr0, mL, mow, morr, mY0, mZ0, mca, msa, mlo, mhi, mr, mA,
                                        bi, bb, bs, fi, fb, fs, 0.0, 1, ms, _seg1(fd, ix, e, K_WTS))
    for i in range(K):
        p = idx[i]
        good = ok[i] and np.isfinite(GAP[i]) and GAP[i] > -sc[SC_MAXPEN]
        for c in range(4):
            if not (X1[i, c] > lo_e[p, c] and X1[i, c] < hi_e[p, c]):
                good = False
        if not good:
            continue
        valid[p] = True
        gap[p] = GAP[i]
        for c in range(4):
            xb[p, c] = X1[i, c]
        for c in range(11):
            S[p, c] = S1[i, c]
        for c in range(3):
            for d in range(3):
                V[p, c, d] = V1[i, c, d]
    _dedup(xb, valid, gap, S, V, sc[SC_YSPLIT])


@force_kernel
def wheel_rail_forces(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    """Generalized forces of all wheels (module docstring)."""
    nvb = lay[3]
    o = np.empty(45)
    for e in range(ix.shape[0]):
        n_ws = ix[e, IX_NWS]
        P = 4 * n_ws
        bw = ix[e, ix.shape[1] - n_ws:]
        seeds, s_prev, _, _ = _state_views(state, e, n_ws)
        rws, vws, wws = np.empty((n_ws, 3)), np.empty((n_ws, 3)), np.empty((n_ws, 3))
        Ans = np.empty((n_ws, 3, 3))
        s = np.empty(n_ws)
        _poses(r, A, rd, w, bw, fd, ix, e, s_prev, s, rws, Ans, vws, wws, o)
        # pairs: both tracked points of every candidate valid at the last accepted step (the
        # second only where distinct), sorted by problem
        _, _, val_prev, _ = _state_views(state, e, n_ws)
        K = 0
        for p in range(P):
            if val_prev[p] > 0.5:
                K += 1
                if abs(seeds[1, p, 1] - seeds[0, p, 1]) > 1e-9:
                    K += 1
        x0 = np.empty((K, 4))
        prob = np.empty(K, dtype=np.int64)
        i = 0
        for p in range(P):
            if val_prev[p] > 0.5:
                k = p // 4
                ds = s[k] - s_prev[k] if np.isfinite(s[k]) else 0.0
                for j in range(2):
                    if j == 1 and not abs(seeds[1, p, 1] - seeds[0, p, 1]) > 1e-9:
                        continue
                    for c in range(4):
                        x0[i, c] = seeds[j, p, c]
                    x0[i, 2] += ds
                    prob[i] = p
                    i += 1
        xb, valid, gap, S, V, Xp, Gp, Sp, Vp = _solve(fd, ix, e, rws, Ans, x0, prob)
        prob_used = prob
        n_lost = 0
        for p in range(P):
            if val_prev[p] > 0.5 and not valid[p]:
                n_lost += 1
        if n_lost > 0:
            # a tracked stationary point vanished: add the scan's flagged seeds of those
            # candidates (at this pose: a function of q), problem-major, tracked pairs first
            sd = _scan_seeds(fd, ix, e, rws, Ans, s, o)
            K2 = K
            for p in range(P):
                if val_prev[p] > 0.5 and not valid[p]:
                    for j in range(2):
                        if sd[j, p, 4] > 0.5:
                            K2 += 1
            x1 = np.empty((K2, 4))
            prob1 = np.empty(K2, dtype=np.int64)
            i = 0
            i_old = 0
            for p in range(P):
                while i_old < K and prob[i_old] == p:
                    for c in range(4):
                        x1[i, c] = x0[i_old, c]
                    prob1[i] = p
                    i += 1
                    i_old += 1
                if val_prev[p] > 0.5 and not valid[p]:
                    for j in range(2):
                        if sd[j, p, 4] > 0.5:
                            for c in range(4):
                                x1[i, c] = sd[j, p, c]
                            prob1[i] = p
                            i += 1
            xb, valid, gap, S, V, Xp, Gp, Sp, Vp = _solve(fd, ix, e, rws, Ans, x1, prob1)
            prob_used = prob1
            lostm = np.zeros(P, dtype=np.bool_)
            for p in range(P):
                lostm[p] = val_prev[p] > 0.5 and not valid[p]
            _robust_merge(fd, ix, e, rws, Ans, xb, valid, gap, S, V, lostm)
        valid2, gap2, S2, V2 = _second(xb, valid, Xp, Gp, Sp, Vp, prob_used, SEPARATION)
        for p in range(P):
            if not np.isfinite(s[p // 4]):  # not over the track: no contact
                valid[p] = False
                gap[p] = np.inf
                valid2[p] = False
                gap2[p] = np.inf
        vb, gb, Sb, Vb = _both(valid, gap, S, V, valid2, gap2, S2, V2)
        out, Fg, Mg, vmin = _forces(fd, ix, e, vb, gb, Sb, Vb, rws, vws, wws, Ans)
        _weigh_patches(vb, Sb, gb, out, Fg, Mg, P)
        if ix[e, IX_MODEL] >= 0 and vmin < 1e-3:
            err[1] = e
            return ELEMENT_FAILED
        for k in range(n_ws):
            b = bw[k]
            F0 = F1 = F2 = M0 = M1 = M2 = 0.0
            for c in range(8):
                p = 4 * k + c if c < 4 else P + 4 * k + c - 4
                if not vb[p]:
                    continue
                ax_, ay_, az_ = Vb[p, 0, 0] - rws[k, 0], Vb[p, 0, 1] - rws[k, 1], Vb[p, 0, 2] - rws[k, 2]
                fx, fy, fz = Fg[p, 0], Fg[p, 1], Fg[p, 2]
                F0 += fx
                F1 += fy
                F2 += fz
                M0 += ay_ * fz - az_ * fy + Mg[p, 0]
                M1 += az_ * fx - ax_ * fz + Mg[p, 1]
                M2 += ax_ * fy - ay_ * fx + Mg[p, 2]
            i0 = b * nvb
            Q[i0] += F0
            Q[i0 + 1] += F1
            Q[i0 + 2] += F2
            for i in range(3):  # body-frame moment A^T M
                Q[i0 + 3 + i] += A[b, 0, i] * M0 + A[b, 1, i] * M1 + A[b, 2, i] * M2
    return OK


@_jit
def _scan_seeds(fd, ix, e, rws, Ans, s, o, n_rank=2):
    """The global scan's ``n_rank`` best stationary points per problem: (n_rank, P, 7)."""
    n_ws = ix[e, IX_NWS]
    P = 4 * n_ws
    G = ix[e, IX_G]
    f_inner, f_breaks = _seg1(fd, ix, e, K_F_INNER), _seg1(fd, ix, e, K_F_BREAKS)
    f_stack = _seg3(fd, ix, e, K_F_STACK)
    sig = _seg1(fd, ix, e, K_SIG)
    sc = _seg1(fd, ix, e, K_SCAL)
    rP, ax, d, pos, tan, lat, up = (np.empty((P, 3)), np.empty((P, 3)), np.empty((P, 3)), np.empty((P, 3)),
                                    np.empty((P, 3)), np.empty((P, 3)), np.empty((P, 3)))
    theta, s0 = np.empty(P), np.empty(P)
    for k in range(n_ws):
        ppeval(f_inner, f_breaks, f_stack, s[k], o)
        a0, a1, a2 = Ans[k, 0, 1], Ans[k, 1, 1], Ans[k, 2, 1]
        u0, u1, u2 = o[5], o[8], o[11]
        au = a0 * u0 + a1 * u1 + a2 * u2
        d0, d1, d2 = u0 - au * a0, u1 - au * a1, u2 - au * a2
        dn = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        d0 /= dn
        d1 /= dn
        d2 /= dn
        # theta of the lowest point -d in the unspun frame: dl = A^T (-d)
        l0 = -(Ans[k, 0, 0] * d0 + Ans[k, 1, 0] * d1 + Ans[k, 2, 0] * d2)
        l2 = -(Ans[k, 0, 2] * d0 + Ans[k, 1, 2] * d1 + Ans[k, 2, 2] * d2)
        th = np.arctan2(l0, -l2)
        for c in range(4):
            p = 4 * k + c
            for i in range(3):
                rP[p, i] = rws[k, i]
                pos[p, i] = o[i]
                tan[p, i] = o[3 + 3 * i]
                lat[p, i] = o[4 + 3 * i]
                up[p, i] = o[5 + 3 * i]
            ax[p, 0], ax[p, 1], ax[p, 2] = a0, a1, a2
            d[p, 0], d[p, 1], d[p, 2] = d0, d1, d2
            theta[p] = th
            s0[p] = s[k]
    rl = _seg2(fd, ix, e, K_RAIL_L)
    rr = _seg2(fd, ix, e, K_RAIL_R)
    out = np.empty((n_rank, P, 7))
    side_left = np.empty(P, dtype=np.bool_)
    for p in range(P):
        side_left[p] = sig[p] > 0
    scan(rP, ax, d, pos, tan, lat, up, sig, sc[SC_LW], _seg2(fd, ix, e, K_YG), _seg2(fd, ix, e, K_RG),
         _seg2(fd, ix, e, K_F1G), side_left, rl[0], rl[1], rl[2], rl[3], rr[0], rr[1], rr[2], rr[3],
         _seg1(fd, ix, e, K_ULO), _seg1(fd, ix, e, K_UHI), theta, s0, n_rank, out)
    return out


@_jit
def _accept_pairs(fd, ix, e, seeds, s, s_prev, val_prev, rws, Ans, reseed, o):
    """(x0, prob): tracked points of the candidates that had a contact (the second where
    distinct) and, when re-seeding, the flagged scan seeds; sorted by problem (tracked first)."""
    n_ws = ix[e, IX_NWS]
    P = 4 * n_ws
    sd = _scan_seeds(fd, ix, e, rws, Ans, s, o, ACCEPT_RANKS) if reseed else np.zeros((ACCEPT_RANKS, P, 7))
    K = 0
    for p in range(P):
        if val_prev[p] > 0.5:
            K += 2 if abs(seeds[1, p, 1] - seeds[0, p, 1]) > 1e-9 else 1
        for j in range(ACCEPT_RANKS):
            if sd[j, p, 4] > 0.5 or (reseed and j == 0):
                K += 1
    x0 = np.empty((K, 4))
    prob = np.empty(K, dtype=np.int64)
    from_scan = np.zeros(K, dtype=np.bool_)
    i = 0
    for p in range(P):
        ds = s[p // 4] - s_prev[p // 4]
        if val_prev[p] > 0.5:
            for j in range(2):  # the two tracked points
                if j == 1 and not abs(seeds[1, p, 1] - seeds[0, p, 1]) > 1e-9:
                    continue
                for c in range(4):
                    x0[i, c] = seeds[j, p, c]
                x0[i, 2] += ds
                prob[i] = p
                i += 1
        for j in range(ACCEPT_RANKS):
            # the zone's lowest sampled point also without a sign change (a minimum and a
            # maximum of the gap within one grid interval; railway.vehicles.wheel_rail.accept_pairs)
            if sd[j, p, 4] > 0.5 or (reseed and j == 0):
                for c in range(4):
                    x0[i, c] = sd[j, p, c]
                prob[i] = p
                from_scan[i] = sd[j, p, 4] > 0.5
                i += 1
    flagged = np.zeros(P, dtype=np.bool_)
    for p in range(P):
        for j in range(ACCEPT_RANKS):
            if sd[j, p, 4] > 0.5:
                flagged[p] = True
    return x0, prob, flagged, from_scan


@_jit
def _with_neighbours(x0, prob, xb, valid, gap, from_scan, Ga):
    """(x1, prob1, src, n_new): the pairs x0 with NEIGHBOUR_OFFSETS seeds beside every
    penetrating contact and beside every flagged scan seed whose Newton iteration was refused
    (Ga = inf) (railway.vehicles.wheel_rail.neighbour_seeds), sorted by problem (stable: existing pairs
    first); ``src[i]`` is the row of x0 that row i copies, -1 for a new seed."""
    P = valid.shape[0]
    K = prob.shape[0]
    no = len(NEIGHBOUR_OFFSETS)
    n_new = 0
    for p in range(P):
        if valid[p] and gap[p] < 0.0:
            n_new += no
    for i in range(K):
        if from_scan[i] and not np.isfinite(Ga[i]):
            n_new += no
    x1 = np.empty((K + n_new, 4))
    prob1 = np.empty(K + n_new, dtype=np.int64)
    src = np.full(K + n_new, -1, dtype=np.int64)
    i = 0
    i_old = 0
    for p in range(P):
        k0 = i_old
        while i_old < K and prob[i_old] == p:
            for c in range(4):
                x1[i, c] = x0[i_old, c]
            prob1[i] = p
            src[i] = i_old
            i += 1
            i_old += 1
        if valid[p] and gap[p] < 0.0:
            i = _put_neighbours(x1, prob1, i, xb[p], p)
        for k in range(k0, i_old):
            if from_scan[k] and not np.isfinite(Ga[k]):
                i = _put_neighbours(x1, prob1, i, x0[k], p)
    return x1, prob1, src, n_new


@_jit
def _put_neighbours(x1, prob1, i, centre, p):
    """Rows i, i+1, ... of (x1, prob1): ``centre`` moved by each NEIGHBOUR_OFFSETS on the wheel
    profile (and the rail coordinate alike), for problem p; returns the next free row."""
    for j in range(len(NEIGHBOUR_OFFSETS)):
        for c in range(4):
            x1[i, c] = centre[c]
        x1[i, 1] += NEIGHBOUR_OFFSETS[j]
        x1[i, 3] += NEIGHBOUR_OFFSETS[j]
        prob1[i] = p
        i += 1
    return i


@accept_kernel
def wheel_rail_accept(t, q, v, r, A, rd, w, lay, fd, ix, state, err):
    """Search-state update after an accepted step, with the derailment checks (module docstring)."""
    o = np.empty(45)
    for e in range(ix.shape[0]):
        n_ws = ix[e, IX_NWS]
        P = 4 * n_ws
        bw = ix[e, ix.shape[1] - n_ws:]
        sc = _seg1(fd, ix, e, K_SCAL)
        seeds, s_prev, val_prev, yq_prev = _state_views(state, e, n_ws)
        row = state[e]
        rws, vws, wws = np.empty((n_ws, 3)), np.empty((n_ws, 3)), np.empty((n_ws, 3))
        Ans = np.empty((n_ws, 3, 3))
        s = np.empty(n_ws)
        _poses(r, A, rd, w, bw, fd, ix, e, s_prev, s, rws, Ans, vws, wws, o)
        for k in range(n_ws):
            if not np.isfinite(s[k]):
                row[ST_FAIL] = FAIL_OFF_TRACK
                row[ST_IDX] = k
                err[1] = e
                return ELEMENT_FAILED
        reseed = (int(row[ST_ACC]) + 1) % ix[e, IX_RESEED] == 0
        while True:
            x0, prob, flagged, from_scan = _accept_pairs(fd, ix, e, seeds, s, s_prev, val_prev, rws, Ans, reseed, o)
            xb, valid, gap, S, V, X, Gm, Sp, Vp = _solve(fd, ix, e, rws, Ans, x0, prob)
            if reseed:
                prevm = np.zeros(P, dtype=np.bool_)
                for p in range(P):
                    prevm[p] = val_prev[p] > 0.5 or flagged[p]
                _robust_merge(fd, ix, e, rws, Ans, xb, valid, gap, S, V, prevm)
            lost_any = False
            for p in range(P):
                if val_prev[p] > 0.5 and not valid[p]:
                    lost_any = True
            if not lost_any or reseed:
                break
            reseed = True
        # seeds beside every penetrating contact (railway.vehicles.wheel_rail.neighbour_seeds)
        x1, prob1, src, n_new = _with_neighbours(x0, prob, xb, valid, gap, from_scan, Gm)
        if n_new > 0:
            # Newton on the new seeds only; the pairs solved above keep their results
            xb, valid, gap, S, V, X, Gm, Sp, Vp = _solve_added(fd, ix, e, rws, Ans, x1, prob1, src, X, Gm, Sp, Vp)
            x0, prob = x1, prob1
            if reseed:
                prevm = np.zeros(P, dtype=np.bool_)
                for p in range(P):
                    prevm[p] = val_prev[p] > 0.5 or flagged[p]
                _robust_merge(fd, ix, e, rws, Ans, xb, valid, gap, S, V, prevm)
        valid2, gap2, S2, V2 = _second(xb, valid, X, Gm, Sp, Vp, prob, SEPARATION)
        vb, gb, Sb, Vb = _both(valid, gap, S, V, valid2, gap2, S2, V2)
        out, Fg, Mg, vmin = _forces(fd, ix, e, vb, gb, Sb, Vb, rws, vws, wws, Ans)
        _weigh_patches(vb, Sb, gb, out, Fg, Mg, P)
        # per wheel: Y/Q (module docstring of railway.vehicles.wheel_rail), the highest penetrating
        # contact on the flange (lowest y_wheel); per wheelset: lateral displacement and drop.
        # The checks in the numpy kind's order: flange climb first, then a wheelset that left
        # the rails.
        worst_y, worst_w = np.inf, -1
        left_k, left_lat, left_drop = -1, 0.0, 0.0
        yq_now = np.empty(2 * n_ws)
        f_inner, f_breaks = _seg1(fd, ix, e, K_F_INNER), _seg1(fd, ix, e, K_F_BREAKS)
        f_stack = _seg3(fd, ix, e, K_F_STACK)
        for k in range(n_ws):
            ppeval(f_inner, f_breaks, f_stack, s[k], o)
            for side in range(2):
                wi = 2 * k + side
                Fz = Fy = 0.0
                for c in range(4):  # tread, flange, and their second patches
                    p = 4 * k + 2 * side + c if c < 2 else P + 4 * k + 2 * side + c - 2
                    Fz += Fg[p, 0] * o[5] + Fg[p, 1] * o[8] + Fg[p, 2] * o[11]
                    Fy += Fg[p, 0] * o[4] + Fg[p, 1] * o[7] + Fg[p, 2] * o[10]
                Y = -Fy * (1.0 if side == 0 else -1.0)
                yq_now[wi] = Y / Fz if Fz > 0.0 else np.nan
                for c in range(4):
                    p = 4 * k + 2 * side + c if c < 2 else P + 4 * k + 2 * side + c - 2
                    if vb[p] and gb[p] < 0.0 and Sb[p, 1] < worst_y:
                        worst_y, worst_w = Sb[p, 1], wi
            e0, e1, e2 = rws[k, 0] - o[0], rws[k, 1] - o[1], rws[k, 2] - o[2]
            lat_d = e0 * o[4] + e1 * o[7] + e2 * o[10]
            drop = sc[SC_R0] - (e0 * o[5] + e1 * o[8] + e2 * o[11])
            if left_k < 0 and (abs(lat_d) > sc[SC_MAXLAT] or drop > sc[SC_MAXDROP]):
                left_k, left_lat, left_drop = k, lat_d, drop
        if worst_y < sc[SC_YCLIMB]:
            row[ST_FAIL] = FAIL_FLANGE_CLIMB
            row[ST_IDX] = worst_w
            row[ST_V1] = worst_y
            row[ST_YQ0] = yq_prev[worst_w]
            row[ST_YQ1] = yq_now[worst_w]
            err[1] = e
            return ELEMENT_FAILED
        if left_k >= 0:
            wi = 2 * left_k + (0 if left_lat > 0.0 else 1)  # the wheel on the side it moved to
            row[ST_FAIL] = FAIL_LEFT_RAILS
            row[ST_IDX] = wi
            row[ST_V1] = left_lat
            row[ST_V2] = left_drop
            row[ST_YQ0] = yq_prev[wi]
            row[ST_YQ1] = yq_now[wi]
            err[1] = e
            return ELEMENT_FAILED
        for wi in range(2 * n_ws):
            yq_prev[wi] = yq_now[wi]
        # the two lowest distinct stationary points become the tracked seeds (candidates
        # without a contact keep theirs)
        K = prob.shape[0]
        for p in range(P):
            if not valid[p]:
                val_prev[p] = 0.0
                continue
            jbest, gbest = -1, np.inf
            for i in range(K):
                if prob[i] == p and abs(X[i, 1] - xb[p, 1]) > 1e-4 and np.isfinite(Gm[i]) and Gm[i] < gbest:
                    q_ = p ^ 1  # not the other zone's contact (railway.vehicles.wheel_rail._two_lowest_pairs)
                    if valid[q_] and abs(X[i, 1] - xb[q_, 1]) < DUPLICATE:
                        continue
                    gbest, jbest = Gm[i], i
            for c in range(4):
                seeds[0, p, c] = xb[p, c]
                seeds[1, p, c] = X[jbest, c] if jbest >= 0 else xb[p, c]
            val_prev[p] = 1.0
        for k in range(n_ws):
            s_prev[k] = s[k]
        row[ST_ACC] += 1.0
    return OK


def describe_failure(kind, state) -> str:
    """The derailment (or loss of the track) that ended a compiled run, from the state rows."""
    for e, st in enumerate(kind.sets):
        row = state[e]
        code = int(row[ST_FAIL])
        if code == 0:
            continue
        i = int(row[ST_IDX])
        if code == FAIL_FLANGE_CLIMB:
            wheel = f"{st.wheelset_names[i // 2]} {('left', 'right')[i % 2]}"
            w = st.wheel
            climb = float(w.evaluate(np.array([row[ST_V1]]))[0][0] - w.evaluate(np.array([w.y_flank_top]))[0][0])
            return climb_message(wheel, st.name, climb, w, st.e.flange_climb_height,
                                 f"last Y/Q {row[ST_YQ0]:.3g} at the previous accepted step, "
                                 f"{row[ST_YQ1]:.3g} now")
        if code == FAIL_LEFT_RAILS:
            wheel = f"{st.wheelset_names[i // 2]} {('left', 'right')[i % 2]}"
            return (f"derailment of wheelset {st.wheelset_names[i // 2]!r} ({st.name}): it left the rails "
                    f"(lateral displacement {row[ST_V1] * 1e3:.1f} mm, limit "
                    f"{st.e.max_lateral_displacement * 1e3:g} mm; centre {row[ST_V2] * 1e3:.1f} mm below its "
                    f"nominal height, limit {st.e.max_drop * 1e3:g} mm); wheel {wheel!r}: last Y/Q "
                    f"{row[ST_YQ0]:.3g} at the previous accepted step, {row[ST_YQ1]:.3g} now")
        if code == FAIL_OFF_TRACK:
            s_prev = _state_views(state, e, st.n_ws)[1]
            return st.off_track_message(i, np.full(3, np.nan), float(s_prev[i]))
    return ""


# ---------------------------------------------------------------------------------------------
def _segments(st):
    """The float segments of one element (name -> array), see SEGMENTS."""
    cs, cf = st.cs, st.cf
    pc = cs._problems
    b, f = cs._bank, st.track.pp_frame
    (b0, u0, Y0, Z0), (b1, u1, Y1, Z1) = cs._rail_tab
    yg, rg, F1g = (cs._scan[k][pc["cand"]] for k in ("y", "r", "F1"))
    code, cp = cf._model_code, cf._model_params
    if cf._kernel is None or code is None:
        cf._build_table()
    sc = np.zeros(18)
    sc[SC_TOL] = max(cs.tol, cs.tol_linear)
    sc[SC_T0], sc[SC_DT], sc[SC_KSUM], sc[SC_G] = cf._t0, cf._dt, cf._ksum, cf.G
    sc[SC_MU], sc[SC_CHI], sc[SC_V0] = cf.mu, cf._chi, cf.v0
    sc[SC_MAXPEN], sc[SC_YSPLIT], sc[SC_YTIP] = cs.max_penetration, st.wheel.y_split, st.wheel.y_tip
    sc[SC_YCLIMB], sc[SC_MAXLAT], sc[SC_MAXDROP] = st.y_climb, st.e.max_lateral_displacement, st.e.max_drop
    sc[SC_R0], sc[SC_LENGTH] = st.wheel.r0, st.track.length
    sc[SC_CLOSED] = 1.0 if getattr(st.track, "closed", False) else 0.0
    sc[SC_LW] = cs.L
    return dict(
        b_inner=b._inner, b_breaks=b.breaks, b_stack=b._stack, f_inner=f._inner, f_breaks=f.breaks,
        f_stack=f._stack, sig=pc["sig"], r0=pc["r0"], L=pc["L"], ow=pc["ow"], orr=pc["orr"], Y0=pc["Y0"],
        Z0=pc["Z0"], ca=pc["ca"], sa=pc["sa"], lo=pc["lo"], hi=pc["hi"], lo_e=pc["lo_e"], hi_e=pc["hi_e"],
        ulo=pc["ulo"], uhi=pc["uhi"], flange=pc["is_flange"].astype(float), yg=yg, rg=rg, F1g=F1g,
        rail_l=np.vstack([b0, u0, Y0, Z0]), rail_r=np.vstack([b1, u1, Y1, Z1]), tab=cf._tab,
        maxstep=cs._maxstep, wts=cs._wts, scal=sc, cp=np.asarray(cp, float))


def _state_row(st) -> np.ndarray:
    """The numpy kind's search state of one element as a compiled state row."""
    n_ws = st.n_ws
    P = 4 * n_ws
    row = np.zeros(ST_HEAD + 8 * P + n_ws + P + 2 * n_ws)
    row[-2 * n_ws:] = np.nan  # last Y/Q: none yet
    s = st.state
    if s is None:
        return row
    row[ST_ACC] = s.accepted
    a = ST_HEAD
    row[a:a + 8 * P] = s.seeds.ravel()
    a += 8 * P
    row[a:a + n_ws] = s.s_ws
    a += n_ws
    row[a:a + P] = s.valid.astype(float)
    a += P
    row[a:a + 2 * n_ws] = s.last_YQ if s.last_YQ.size else np.nan  # NaN: a lifted wheel, or none yet
    return row


def _state_from_row(st, row):
    """The inverse of :func:`_state_row`: a compiled state row (recorded after an accepted step,
    :func:`core.results.search_states_at_steps`) as the numpy kind's search state."""
    from .wheel_rail import _State

    n_ws = st.n_ws
    P = 4 * n_ws
    row = np.asarray(row, float)
    a = ST_HEAD
    seeds = row[a:a + 8 * P].reshape((2, P, 4)).copy()
    a += 8 * P
    s_ws = row[a:a + n_ws].copy()
    a += n_ws
    valid = row[a:a + P] != 0.0
    a += P
    return _State(seeds=seeds, s_ws=s_ws, valid=valid, accepted=int(row[ST_ACC]),
                  last_YQ=row[a:a + 2 * n_ws].copy())


def compile_wheel_rail(kind, layout) -> CompiledForces:
    """The compiled form of a :class:`railway.vehicles.wheel_rail.WheelRailKind` (module docstring)."""
    from core.errors import NotCompilable

    for st in kind.sets:
        if st.rb is not None:
            raise NotCompilable(f"wheel-rail contact {st.name!r}: rails on a body (rail_body) run on the numpy "
                                "path only")
        if st.spin is not None:
            raise NotCompilable(f"wheel-rail contact {st.name!r}: the nominal-spin formulation (for linear "
                                "analyses) runs on the numpy path only")
        if st.cf.reduced:
            raise NotCompilable(f"wheel-rail contact {st.name!r}: the reduced contact forces (switched off: "
                                f"{st.cf.reduced}) run on the numpy path only")
        if st.cf._model_code is None:
            raise NotCompilable(f"wheel-rail contact {st.name!r}: creep law {st.cf.creep_law!r} has no "
                                "compiled form (user laws and join='raw' run on the numpy path)")
    rows_f, rows_i = [], []
    for st in kind.sets:
        seg = _segments(st)
        flat, head = [], np.zeros(IX_SEG0 + 4 * len(SEGMENTS), np.int64)
        off = 0
        for k, name in enumerate(SEGMENTS):
            arr = np.ascontiguousarray(seg[name], dtype=float)
            shp = list(arr.shape) + [1] * (3 - arr.ndim)
            head[_seg_index(k):_seg_index(k) + 4] = [off, *shp[:3]]
            flat.append(arr.ravel())
            off += arr.size
        head[IX_NWS], head[IX_MODEL] = st.n_ws, int(st.cf._model_code)
        head[IX_MAXIT], head[IX_RESEED] = st.cs.max_iter, st.e.reseed_every
        head[IX_G] = st.cs.n_scan
        rows_f.append(np.concatenate(flat))
        rows_i.append(np.concatenate([head, st.bw]))
    nf = max(r.size for r in rows_f)
    ni = max(r.size for r in rows_i)
    if len({r.size for r in rows_i}) > 1:
        raise NotCompilable(f"wheel-rail contact {kind.names[0]!r}: several elements with different numbers of "
                            "wheelsets are not supported on the compiled path")
    fd = np.zeros((len(rows_f), nf))
    ix = np.zeros((len(rows_i), ni), np.int64)
    for e, (rf, ri) in enumerate(zip(rows_f, rows_i)):
        fd[e, :rf.size] = rf
        ix[e, :ri.size] = ri
    states = [_state_row(st) for st in kind.sets]
    ns = max(x.size for x in states)
    state = np.zeros((len(states), ns))
    for e, x in enumerate(states):
        state[e, :x.size] = x

    def initial_state():
        rows = [_state_row(st) for st in kind.sets]
        out = np.zeros_like(state)
        for e, x in enumerate(rows):
            out[e, :x.size] = x
        return out

    return CompiledForces(forces=wheel_rail_forces, fd=np.ascontiguousarray(fd), ix=np.ascontiguousarray(ix),
                          names=list(kind.names), accept=wheel_rail_accept, state=state, what="wheel-rail contact",
                          initial_state=initial_state,
                          # the contact forces on a wheelset depend on that wheelset's state only
                          groups=[[int(b)] for st in kind.sets for b in st.bw],
                          describe_failure=lambda stt: describe_failure(kind, stt))


# the numpy kind reaches its kernels through this registration, never by importing this module
WheelRailKind.compiled_form = staticmethod(compile_wheel_rail)
WheelRailKind.state_from_compiled = staticmethod(_state_from_row)
