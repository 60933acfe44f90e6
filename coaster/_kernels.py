r"""Compiled (numba) kernels of the coaster's elements for :mod:`core.compiled`.

* :func:`path_joint_kernel` — :class:`coaster.path_joint.PathFollowingJoint` with its track a
  :class:`core.curves.TabulatedFramedCurve` (the table of a
  :class:`coaster.frames.RotationMinimisingFrame`, or any tabulated framed curve): the same
  Φ, Φ_q, γ as the Python joint (equations in :mod:`coaster.path_joint`), the track evaluated
  from the quintic Hermite table by Horner's rule (columns of ``PiecewisePoly._stack``: values
  0-14, d/ds 15-29, d²/ds² 30-44 of r (0-2), R row-major (3-11), Ω (12-14)).
* :func:`track_forces_kernel` — :class:`coaster.train.TrackForces` (rolling resistance, drag,
  speed-control sections on the arc-length coordinates).

Data layout of the path joint (one element per kind; ``fd`` one row)::

    fd[0, :14] = s0, length, closed, n_pieces, k1, s′ (3), ξ′ (3), ζ′ (3)
    fd[0, 14:] = inner breaks (n − 1), breaks (n + 1), stack (n × k1 × 45, C order)
    ix[0] = body, q index of L, v index of L

The tests compare both paths to round-off (tests/coaster/test_train.py).
"""

from __future__ import annotations

import numba
import numpy as np

from core.compiled import vector as V
from core.compiled.protocol import (
    L_DIM,
    OK,
    WANT_GAMMA,
    WANT_NU,
    WANT_PHI,
    CompiledConstraints,
    CompiledForces,
    body_slot,
    constraint_kernel,
    force_kernel,
)
from core.curves import TabulatedFramedCurve
from core.errors import NotCompilable

_internal = numba.njit(cache=True, fastmath=False, boundscheck=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)

HEADER = 14
_NEEDED = (0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 27, 28, 29, 30, 31, 32)


@_internal
def _table_eval(fd, s, out):
    """Needed columns of the table at arc length s into ``out`` (45,)."""
    s0, length, closed, n, k1 = fd[0, 0], fd[0, 1], fd[0, 2], int(fd[0, 3]), int(fd[0, 4])
    if closed != 0.0:
        x = (s - s0) % length
        s = s0 + x
    o_in = HEADER
    o_br = o_in + n - 1
    o_st = o_br + n + 1
    # piece: number of inner breaks <= s (searchsorted side="right")
    lo = 0
    hi = n - 1
    while lo < hi:
        mid = (lo + hi) // 2
        if fd[0, o_in + mid] <= s:
            lo = mid + 1
        else:
            hi = mid
    i = lo
    t = s - fd[0, o_br + i]
    base = o_st + i * k1 * 45
    for c in range(45):
        if c > 17 and c < 27 or c > 32:
            continue
        acc = 0.0
        for j in range(k1 - 1, -1, -1):
            acc = acc * t + fd[0, base + j * 45 + c]
        out[c] = acc


@constraint_kernel
def path_joint_kernel(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err):
    """Compiled :class:`coaster.path_joint.PathFollowingJoint` (equations there)."""
    dim = lay[L_DIM]
    b, qL, vL = ix[0, 0], ix[0, 1], ix[0, 2]
    L = q[qL]
    Ld = v[vL]
    o = np.empty(45)
    _table_eval(fd, L, o)
    s0, s1, s2 = fd[0, 5], fd[0, 6], fd[0, 7]
    # point rows
    if flags & WANT_PHI:
        a0, a1, a2 = V.Av(A, b, s0, s1, s2)
        phi[row0] = r[b, 0] + a0 - o[0]
        phi[row0 + 1] = r[b, 1] + a1 - o[1]
        phi[row0 + 2] = r[b, 2] + a2 - o[2]
    for i in range(3):
        e0 = 1.0 if i == 0 else 0.0
        e1 = 1.0 if i == 1 else 0.0
        e2 = 1.0 if i == 2 else 0.0
        c0, c1, c2 = V.uC(A, b, s0, s1, s2, e0, e1, e2)
        V.put_row(G, row0 + i, 0, dim, e0, e1, e2, c0, c1, c2)
        for j in range(6):
            G[row0 + i, 1, j] = 0.0
        G[row0 + i, 1, 0] = -o[15 + i]
    if flags & WANT_NU:
        for i in range(6):
            nu[row0 + i] = 0.0
    if flags & WANT_GAMMA:
        g0, g1, g2 = V.aq(A, w, b, s0, s1, s2)
        gam[row0] = -g0 + Ld * Ld * o[30]
        gam[row0 + 1] = -g1 + Ld * Ld * o[31]
        gam[row0 + 2] = -g2 + Ld * Ld * o[32]
    Om0, Om1, Om2 = o[12], o[13], o[14]
    dO0, dO1, dO2 = o[27], o[28], o[29]
    # rows (n, ξ), (b, ξ), (n, ζ): frame column e of R (row-major at o[3:12]) and body vector ū
    for k in range(3):
        col = 1 if k != 1 else 2
        ub = 8 if k != 2 else 11
        e0, e1, e2 = o[3 + col], o[6 + col], o[9 + col]
        u_0, u_1, u_2 = fd[0, ub], fd[0, ub + 1], fd[0, ub + 2]
        uu0, uu1, uu2 = V.Av(A, b, u_0, u_1, u_2)
        row = row0 + 3 + k
        if flags & WANT_PHI:
            phi[row] = e0 * uu0 + e1 * uu1 + e2 * uu2
        c0, c1, c2 = V.uC(A, b, u_0, u_1, u_2, e0, e1, e2)
        V.put_row(G, row, 0, dim, 0.0, 0.0, 0.0, c0, c1, c2)
        de0, de1, de2 = V.cross(Om0, Om1, Om2, e0, e1, e2)
        for j in range(6):
            G[row, 1, j] = 0.0
        G[row, 1, 0] = de0 * uu0 + de1 * uu1 + de2 * uu2
        if flags & WANT_GAMMA:
            x0, x1, x2 = V.cross(dO0, dO1, dO2, e0, e1, e2)
            y0, y1, y2 = V.cross(Om0, Om1, Om2, de0, de1, de2)
            dde0, dde1, dde2 = x0 + y0, x1 + y1, x2 + y2
            wu0, wu1, wu2 = V.vel(A, w, b, u_0, u_1, u_2)
            q0, q1, q2 = V.aq(A, w, b, u_0, u_1, u_2)
            gam[row] = -(Ld * Ld * (dde0 * uu0 + dde1 * uu1 + dde2 * uu2)
                         + 2.0 * Ld * (de0 * wu0 + de1 * wu1 + de2 * wu2)
                         + (e0 * q0 + e1 * q1 + e2 * q2))
    return OK


def _table_of(curve, owner):
    table = getattr(curve, "table", curve)
    if not isinstance(table, TabulatedFramedCurve):
        raise NotCompilable(f"{owner}: its track {getattr(curve, 'name', curve)!r} is not tabulated "
                            "(the compiled path needs a core.curves.TabulatedFramedCurve, e.g. a "
                            "RotationMinimisingFrame); use the numpy integrators")
    return table


_PACK_CACHE: dict = {}


def _packed_table(table):
    key = id(table)
    hit = _PACK_CACHE.get(key)
    if hit is not None and hit[0] is table:
        return hit[1]
    pp = table.table
    n, k1, m3 = pp._stack.shape
    if m3 != 45:
        raise NotCompilable(f"track {table.name!r}: table with {m3} columns, expected 45")
    head = np.array([table.nodes[0], table.length, 1.0 if table.closed else 0.0, n, k1])
    arr = np.concatenate([head, pp._inner, pp.breaks, pp._stack.ravel()])
    _PACK_CACHE[key] = (table, arr)
    return arr


def compile_path_joint(joint, layout) -> CompiledConstraints:
    """Pack a :class:`coaster.path_joint.PathFollowingJoint` for :func:`path_joint_kernel`."""
    owner = f"path joint {joint.name!r}"
    table = _table_of(joint.curve, owner)
    arr = _packed_table(table)
    fd = np.empty((1, HEADER + arr.size - 5))
    fd[0, :5] = arr[:5]
    fd[0, 5:8] = joint.point
    fd[0, 8:11] = joint.xi
    fd[0, 11:14] = joint.zeta
    fd[0, HEADER:] = arr[5:]
    b = int(joint.q_index[0]) // layout.n_q_body
    sL = layout.extra_slot(joint.coordinate, owner)
    slots = np.array([[body_slot(b, layout.n_bodies), sL, -1]] * 6, np.int64)
    ix = np.array([[b, layout.extra_q_index(joint.coordinate, owner), layout.extra_v_index(joint.coordinate, owner)]],
                  np.int64)
    return CompiledConstraints(kernel=path_joint_kernel, fd=fd, ix=ix, rows=6, slots=slots, names=[joint.name],
                               what="path-following joint")


# --- track forces ---------------------------------------------------------------------------------
#: fd row: n, rolling, g, v_smooth, ½ρ c_d A, period, n_sections, then n loads, then 7 numbers per
#: section: L_start, L_end, target, F_max, gain, sign (−1 brake, +1 booster), ramp
TF_HEADER = 7


@_internal
def _step(x):
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    return x * x * (3.0 - 2.0 * x)


@force_kernel
def track_forces_kernel(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    """Compiled :class:`coaster.train.TrackForces` (ix[e]: v indices of the coordinates, lead first;
    the q index of the lead coordinate in the last column)."""
    for e in range(fd.shape[0]):
        n = int(fd[e, 0])
        crr, g, veps, cdrag, period, nsec = fd[e, 1], fd[e, 2], fd[e, 3], fd[e, 4], fd[e, 5], int(fd[e, 6])
        for i in range(n):
            Ld = v[ix[e, i]]
            Q[ix[e, i]] -= crr * fd[e, TF_HEADER + i] * g * np.tanh(Ld / veps)
        Ld0 = v[ix[e, 0]]
        Q[ix[e, 0]] -= cdrag * Ld0 * abs(Ld0)
        x = q[ix[e, n]]
        if period > 0.0:
            x = x % period
        o = TF_HEADER + n
        for k in range(nsec):
            Ls, Le, vt, Fm, kg, sg, rp = (fd[e, o + 7 * k], fd[e, o + 7 * k + 1], fd[e, o + 7 * k + 2],
                                          fd[e, o + 7 * k + 3], fd[e, o + 7 * k + 4], fd[e, o + 7 * k + 5],
                                          fd[e, o + 7 * k + 6])
            if rp > 0.0:
                wgt = _step((x - Ls) / rp) * _step((Le - x) / rp)
            else:
                wgt = 1.0 if (x >= Ls and x <= Le) else 0.0
            if wgt == 0.0:
                continue
            dv = (Ld0 - vt) if sg < 0.0 else (vt - Ld0)
            F = kg * dv
            if F < 0.0:
                F = 0.0
            if F > Fm:
                F = Fm
            Q[ix[e, 0]] += sg * wgt * F
    return OK


def compile_track_forces(kind, layout) -> CompiledForces:
    """Pack a :class:`coaster.train.TrackForcesKind`."""
    rows, irows = [], []
    for el in kind.elements:
        row = [len(el.coordinates), el.rolling, el.gravity, el.v_smooth,
               0.5 * el.air_density * el.drag_area, el.period, len(el.sections), *el.loads]
        for s in el.sections:
            row += [s.L_start, s.L_end, s.target_speed, s.max_force, s.gain, s.sign, s.ramp]
        rows.append(row)
        irows.append([layout.extra_v_index(c, el.name) for c in el.coordinates]
                     + [layout.extra_q_index(el.coordinates[0], el.name)])
    wf = max(len(x) for x in rows)
    wi = max(len(x) for x in irows)
    fd = np.zeros((len(rows), wf))
    ix = np.zeros((len(irows), wi), np.int64)
    for k, (a, bb) in enumerate(zip(rows, irows)):
        fd[k, :len(a)] = a
        ix[k, :len(bb)] = bb
    return CompiledForces(forces=track_forces_kernel, fd=fd, ix=ix, names=list(kind.names), what="track forces")
