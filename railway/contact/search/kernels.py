"""Optional compiled (numba) Newton kernel of the contact search.

The numpy implementation in :mod:`railway.contact.search` is the reference; this module holds
the same four-condition Newton iteration (residual, analytic Jacobian, step limiting,
backtracking across passes, zone clipping, linearised last step) written per problem for numba.
It is used only when numba is installed (``pip install numba``); the benchmark
``benchmarks/railway_contact_speed.py`` shows why (the per-call numpy overhead dominates for the
16 small problems of a 4-wheelset vehicle).  Tests check that both give the same contacts.

The kernels are written for the vehicle's real-time factor, without changing a single bit of the
results (the curving runs are bit-identical before and after, checked on whole runs): the inner
kernels (:func:`evaluate`, the iteration loop of :func:`newton`, the piecewise polynomials)
allocate nothing and are compiled without numba's reference counting, which otherwise counts
every array argument up and down on each call (about 50 atomic operations per pass of the
Newton iteration); 3-vectors that are not outputs stay scalars; the track frame is evaluated
only in the columns a caller reads; the scan interpolates its three rail tables with one search.
"""

from __future__ import annotations

import numpy as np

try:  # optional dependency
    import numba

    import core.compiled  # noqa: F401  (keys the disk cache on all compiled sources: core.compiled.cache)

    HAVE_NUMBA = True
except ImportError:  # pragma: no cover - exercised only without numba
    numba = None
    HAVE_NUMBA = False

__all__ = ["HAVE_NUMBA", "MERIT_FLOOR_MIN", "MERIT_ROUNDOFF_ULPS", "merit_floor", "newton_kernel", "scan_kernel",
           "reduced_min_kernel"]

#: The Newton merit ``phi = |W h|^2`` of the contact conditions cannot fall below the round-off
#: of its terms: h3 and h4 are differences of global positions, so they carry a few ulps of the
#: largest coordinate (the rail arc length s, the wheelset's distance from the origin), and h1,
#: h2 a few ulps of 1.  At s = 1 300 m one ulp is 2.3e-13 m and, weighted by 1 000, the floor of
#: phi is about 5e-20: a Newton step that lands there cannot lower phi and, without this floor,
#: was refused by the backtracking until the iteration limit, so that an already converged
#: contact was reported as lost (a 37 kN force step for a 0.1 um change of the pose, and
#: integrators grinding at 10 us steps near centred running; issue 22).  A pass whose merit is
#: below ``merit_floor`` counts as converged.
MERIT_ROUNDOFF_ULPS = 16.0
#: lower bound of the merit floor (the fixed threshold the iteration used before the round-off floor)
MERIT_FLOOR_MIN = 1e-26
_EPS = float(np.finfo(float).eps)


def merit_floor(w0, w1, w2, w3, size):
    r"""Round-off floor of the Newton merit: :math:`(k\varepsilon)^2\,[w_1^2 + w_2^2 +
    (w_3^2 + w_4^2)(1 + L)^2]`, at least :data:`MERIT_FLOOR_MIN`, with k =
    :data:`MERIT_ROUNDOFF_ULPS` ulps, the merit weights w and the largest coordinate magnitude
    ``size`` [m] (scalars or numpy arrays)."""
    e = MERIT_ROUNDOFF_ULPS * _EPS
    return np.maximum(MERIT_FLOOR_MIN, e * e * (w0 * w0 + w1 * w1 + (w2 * w2 + w3 * w3) * (1.0 + size) ** 2))


# The kernels are module-level functions (inside this ``if``), not closures: numba's on-disk
# cache can index a module-level function that calls others by their global names, while
# closures built by a factory got a new cache entry (and a recompilation) in every process.
if HAVE_NUMBA:
    njit = numba.njit(cache=True, fastmath=False)
    # kernels that allocate nothing: compiled without numba's reference counting, which would
    # otherwise increment and decrement every array argument on each call (about 50 atomic
    # operations per call of ``evaluate``, a fifth of the contact search's time)
    njit_norc = numba.njit(cache=True, fastmath=False, _nrt=False)

    @njit_norc
    def ppeval(inner, breaks, stack, x, out):
        """Piecewise polynomial (local coefficients, highest power first) at x: the first
        ``len(out)`` components (all of them when ``out`` is as long as the stack is wide).
        Horner's scheme per component, the components in the inner loop (contiguous)."""
        i = np.searchsorted(inner, x, side="right")
        _horner(stack, i, x - breaks[i], out, 0, min(stack.shape[2], out.shape[0]))

    @njit_norc
    def ppeval_columns(inner, breaks, stack, x, out, columns):
        """:func:`ppeval` of the column ranges ``columns`` (n, 2) only (half-open, into the
        same places of ``out``); the other entries of ``out`` are left as they are."""
        i = np.searchsorted(inner, x, side="right")
        t = x - breaks[i]
        for r in range(columns.shape[0]):
            _horner(stack, i, t, out, columns[r, 0], columns[r, 1])

    @njit_norc
    def _horner(stack, i, t, out, c0, c1):
        for c in range(c0, c1):
            out[c] = 0.0
        for j in range(stack.shape[1] - 1, -1, -1):
            for c in range(c0, c1):
                out[c] = out[c] * t + stack[i, j, c]

    @njit_norc
    def ppeval3(inner, breaks, stack, x):
        """The first three components of :func:`ppeval` (a profile's F, F', F'') as scalars."""
        i = np.searchsorted(inner, x, side="right")
        t = x - breaks[i]
        a0 = a1 = a2 = 0.0
        for j in range(stack.shape[1] - 1, -1, -1):
            a0 = a0 * t + stack[i, j, 0]
            a1 = a1 * t + stack[i, j, 1]
            a2 = a2 * t + stack[i, j, 2]
        return a0, a1, a2

    @njit_norc
    def mv(A, x0, x1, x2):
        """A (3, 3) times (x0, x1, x2) as three scalars (the summation order of matvec)."""
        return (A[0, 0] * x0 + A[0, 1] * x1 + A[0, 2] * x2,
                A[1, 0] * x0 + A[1, 1] * x1 + A[1, 2] * x2,
                A[2, 0] * x0 + A[2, 1] * x1 + A[2, 2] * x2)

    @njit_norc
    def cr(a0, a1, a2, b0, b1, b2):
        """Cross product of two scalar triples."""
        return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0

    @njit_norc
    def dt(a0, a1, a2, b0, b1, b2):
        """Dot product of two scalar triples."""
        return a0 * b0 + a1 * b1 + a2 * b2

    @njit_norc
    def dot(a, b):
        return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]

    @njit_norc
    def solve4(J, h, dx, M):
        """dx = -J^-1 h by Gaussian elimination with partial pivoting in the work array M (4, 5);
        dx = 0 when J is singular."""
        for i in range(4):
            for j in range(4):
                M[i, j] = J[i, j]
            M[i, 4] = -h[i]
        for c in range(4):
            piv = c
            for rr in range(c + 1, 4):
                if abs(M[rr, c]) > abs(M[piv, c]):
                    piv = rr
            if abs(M[piv, c]) < 1e-300:
                for k in range(4):
                    dx[k] = 0.0
                return
            if piv != c:
                for k in range(5):
                    tmp = M[c, k]
                    M[c, k] = M[piv, k]
                    M[piv, k] = tmp
            for rr in range(c + 1, 4):
                f = M[rr, c] / M[c, c]
                for k in range(c, 5):
                    M[rr, k] -= f * M[c, k]
        for c in range(3, -1, -1):
            acc = M[c, 4]
            for k in range(c + 1, 4):
                acc -= M[c, k] * dx[k]
            dx[c] = acc / M[c, c]

    #: Columns of the track frame's piecewise polynomial that :func:`evaluate` reads (layout of
    #: core.curves.TabulatedFramedCurve: values 0-14, d/ds 15-29, d2/ds2 30-44): r, R, omega,
    #: r', omega', r''; FRAME_COLUMNS is one past the last.
    EVALUATE_COLUMNS = np.array([[0, 18], [27, 33]], dtype=np.int64)
    FRAME_COLUMNS = 33

    @njit_norc
    def evaluate(x, sig, r0, L, ow, orr, Y0, Z0, ca, sa, rws, A,
                 b_inner, b_breaks, b_stack, f_inner, f_breaks, f_stack,
                 h, J, p, q, n, d, ts, Rl, qss, tth, ty, tu, dn, R, scal, o):
        """Residuals h and Jacobian J of the four contact conditions at x = (theta, y_w, s, u)
        with the points, normal and tangents written into the given arrays (ContactSearch._residual_jac).
        The 3-vectors that are not outputs stay scalars (no temporary arrays); ``o`` holds at
        least FRAME_COLUMNS entries."""
        th, yw, s, u = x[0], x[1], x[2], x[3]
        F, F1, F2 = ppeval3(b_inner, b_breaks, b_stack, yw + ow)
        v, v1, v2 = ppeval3(b_inner, b_breaks, b_stack, u + orr)
        r = r0 + F
        st, ct = np.sin(th), np.cos(th)
        p0, p1, p2 = mv(A, r * st, sig * (yw + L), -r * ct)
        p[0] = p0 + rws[0]
        p[1] = p1 + rws[1]
        p[2] = p2 + rws[2]
        tth[0], tth[1], tth[2] = mv(A, ct, 0.0, st)
        ty[0], ty[1], ty[2] = mv(A, F1 * st, sig, -F1 * ct)
        a0, a1, a2 = mv(A, -st, 0.0, ct)  # d tth / d theta
        y0, y1, y2 = mv(A, F2 * st, 0.0, -F2 * ct)  # d ty / d y_w
        # track frame
        ppeval_columns(f_inner, f_breaks, f_stack, s, o, EVALUATE_COLUMNS)
        for i in range(3):
            for j in range(3):
                R[i, j] = o[3 + 3 * i + j]
        om0, om1, om2 = o[12], o[13], o[14]
        a = Y0 + u * ca - v * sa
        b = Z0 + u * sa + v * ca
        Rl[0], Rl[1], Rl[2] = mv(R, 0.0, sig * a, b)
        tu[0], tu[1], tu[2] = mv(R, 0.0, sig * (ca - v1 * sa), sa + v1 * ca)
        u0, u1, u2 = mv(R, 0.0, -sig * v2 * sa, v2 * ca)  # d tu / d u
        for k in range(3):
            q[k] = o[k] + Rl[k]
        r0_, r1_, r2_ = cr(om0, om1, om2, Rl[0], Rl[1], Rl[2])  # om x Rl
        w0, w1, w2 = cr(om0, om1, om2, tu[0], tu[1], tu[2])  # om x tu
        m0, m1, m2 = cr(o[27], o[28], o[29], Rl[0], Rl[1], Rl[2])  # om' x Rl
        k0, k1, k2 = cr(om0, om1, om2, r0_, r1_, r2_)  # om x (om x Rl)
        ts[0] = o[15] + r0_
        ts[1] = o[16] + r1_
        ts[2] = o[17] + r2_
        qss[0] = o[30] + m0 + k0
        qss[1] = o[31] + m1 + k1
        qss[2] = o[32] + m2 + k2
        c0, c1, c2 = cr(ts[0], ts[1], ts[2], tu[0], tu[1], tu[2])
        cn = np.sqrt(dt(c0, c1, c2, c0, c1, c2))
        n[0] = sig * c0 / cn
        n[1] = sig * c1 / cn
        n[2] = sig * c2 / cn
        for k in range(3):
            d[k] = p[k] - q[k]
        # dn/ds, dn/du
        e0, e1, e2 = cr(qss[0], qss[1], qss[2], tu[0], tu[1], tu[2])
        f0, f1, f2 = cr(ts[0], ts[1], ts[2], w0, w1, w2)
        s0_, s1_, s2_ = sig * (e0 + f0) / cn, sig * (e1 + f1) / cn, sig * (e2 + f2) / cn
        e0, e1, e2 = cr(w0, w1, w2, tu[0], tu[1], tu[2])
        f0, f1, f2 = cr(ts[0], ts[1], ts[2], u0, u1, u2)
        g0, g1, g2 = sig * (e0 + f0) / cn, sig * (e1 + f1) / cn, sig * (e2 + f2) / cn
        ps = dt(s0_, s1_, s2_, n[0], n[1], n[2])
        pu = dt(g0, g1, g2, n[0], n[1], n[2])
        dn[0, 0] = s0_ - ps * n[0]
        dn[0, 1] = s1_ - ps * n[1]
        dn[0, 2] = s2_ - ps * n[2]
        dn[1, 0] = g0 - pu * n[0]
        dn[1, 1] = g1 - pu * n[1]
        dn[1, 2] = g2 - pu * n[2]
        n0, n1, n2 = n[0], n[1], n[2]
        t0, t1, t2 = tth[0], tth[1], tth[2]
        b0, b1, b2 = ty[0], ty[1], ty[2]
        x0, x1, x2 = ts[0], ts[1], ts[2]
        v0_, v1_, v2_ = tu[0], tu[1], tu[2]
        d0, d1, d2 = d[0], d[1], d[2]
        h[0] = dt(n0, n1, n2, t0, t1, t2)
        h[1] = dt(n0, n1, n2, b0, b1, b2)
        h[2] = dt(d0, d1, d2, x0, x1, x2)
        h[3] = dt(d0, d1, d2, v0_, v1_, v2_)
        J[0, 0] = dt(n0, n1, n2, a0, a1, a2); J[0, 1] = 0.0
        J[0, 2] = dt(dn[0, 0], dn[0, 1], dn[0, 2], t0, t1, t2)
        J[0, 3] = dt(dn[1, 0], dn[1, 1], dn[1, 2], t0, t1, t2)
        J[1, 0] = F1 * h[0]; J[1, 1] = dt(n0, n1, n2, y0, y1, y2)
        J[1, 2] = dt(dn[0, 0], dn[0, 1], dn[0, 2], b0, b1, b2)
        J[1, 3] = dt(dn[1, 0], dn[1, 1], dn[1, 2], b0, b1, b2)
        J[2, 0] = r * dt(t0, t1, t2, x0, x1, x2); J[2, 1] = dt(b0, b1, b2, x0, x1, x2)
        J[2, 2] = -dt(x0, x1, x2, x0, x1, x2) + dt(d0, d1, d2, qss[0], qss[1], qss[2])
        J[2, 3] = -dt(v0_, v1_, v2_, x0, x1, x2) + dt(d0, d1, d2, w0, w1, w2)
        J[3, 0] = r * dt(t0, t1, t2, v0_, v1_, v2_); J[3, 1] = dt(b0, b1, b2, v0_, v1_, v2_)
        J[3, 2] = -dt(x0, x1, x2, v0_, v1_, v2_) + dt(d0, d1, d2, w0, w1, w2)
        J[3, 3] = -dt(v0_, v1_, v2_, v0_, v1_, v2_) + dt(d0, d1, d2, u0, u1, u2)
        scal[0] = r; scal[1] = F1; scal[2] = F2; scal[3] = v1; scal[4] = v2

    @njit
    def newton(x0, sig, r0, L, ow, orr, Y0, Z0, ca, sa, lo, hi, rws, A,
               b_inner, b_breaks, b_stack, f_inner, f_breaks, f_stack,
               tol_lin, max_iter, maxstep, wts):
        P = x0.shape[0]
        X = x0.copy()
        H0 = np.zeros((P, 4)); conv = np.zeros(P, dtype=np.bool_)
        GAP = np.empty(P); S = np.empty((P, 11)); V = np.empty((P, 3, 3))
        h = np.empty(4); J = np.empty((4, 4)); dx = np.empty(4)
        p = np.empty(3); q = np.empty(3); n = np.empty(3); d = np.empty(3); ts = np.empty(3)
        Rl = np.empty(3); qss = np.empty(3); tth = np.empty(3); ty = np.empty(3); tu = np.empty(3)
        dn = np.empty((2, 3)); R = np.empty((3, 3)); scal = np.empty(5)
        x = np.empty(4); x_acc = np.empty(4); dx_acc = np.zeros(4); xn = np.empty(4)
        o = np.empty(min(FRAME_COLUMNS, f_stack.shape[2]))
        M4 = np.empty((4, 5))
        max_it = _newton_loop(x0, sig, r0, L, ow, orr, Y0, Z0, ca, sa, lo, hi, rws, A,
                              b_inner, b_breaks, b_stack, f_inner, f_breaks, f_stack,
                              tol_lin, max_iter, maxstep, wts, X, H0, conv, GAP, S, V,
                              h, J, dx, p, q, n, d, ts, Rl, qss, tth, ty, tu, dn, R, scal,
                              x, x_acc, dx_acc, xn, o, M4)
        return X, H0, conv, max_it, GAP, S, V

    @njit_norc
    def _newton_loop(x0, sig, r0, L, ow, orr, Y0, Z0, ca, sa, lo, hi, rws, A,
                     b_inner, b_breaks, b_stack, f_inner, f_breaks, f_stack,
                     tol_lin, max_iter, maxstep, wts, X, H0, conv, GAP, S, V,
                     h, J, dx, p, q, n, d, ts, Rl, qss, tth, ty, tu, dn, R, scal,
                     x, x_acc, dx_acc, xn, o, M4):
        """The iterations of :func:`newton`, pair by pair, into its arrays (allocates nothing,
        compiled without reference counting: the many array arguments of :func:`evaluate`
        would otherwise be counted up and down on every pass); returns the most passes used."""
        P = x0.shape[0]
        max_it = 0
        for pi in range(P):
            for k in range(4):
                x[k] = x0[pi, k]
                x_acc[k] = x[k]
                dx_acc[k] = 0.0
            phi_acc = np.inf
            alpha = 1.0
            was_clipped = False
            cvd = False
            it = 0
            rp, Ap = rws[pi], A[pi]  # views made once per problem, not per pass
            size = max(abs(rp[0]), abs(rp[1]), abs(rp[2]), abs(x[2]))
            ef = MERIT_ROUNDOFF_ULPS * _EPS
            floor = ef * ef * (wts[0] ** 2 + wts[1] ** 2 + (wts[2] ** 2 + wts[3] ** 2) * (1.0 + size) ** 2)
            if floor < MERIT_FLOOR_MIN:
                floor = MERIT_FLOOR_MIN
            for it in range(1, max_iter + 1):
                evaluate(x, sig[pi], r0[pi], L[pi], ow[pi], orr[pi], Y0[pi], Z0[pi], ca[pi],
                         sa[pi], rp, Ap, b_inner, b_breaks, b_stack, f_inner, f_breaks,
                         f_stack, h, J, p, q, n, d, ts, Rl, qss, tth, ty, tu, dn, R, scal, o)
                solve4(J, h, dx, M4)
                big = 0.0
                scale = 1.0
                for k in range(4):
                    if not np.isfinite(dx[k]):
                        dx[k] = 0.0
                    a_ = abs(dx[k])
                    if a_ > 0.0 and maxstep[k] / a_ < scale:
                        scale = maxstep[k] / a_
                for k in range(4):
                    dx[k] *= scale
                    if abs(dx[k]) > big:
                        big = abs(dx[k])
                phi = 0.0
                for k in range(4):
                    phi += (h[k] * wts[k]) ** 2
                accept = (phi <= phi_acc * (1.0 - 1e-4 * alpha)) or (phi < floor) or (phi_acc == np.inf)
                done = False
                if accept and (big < tol_lin or phi < floor):
                    cvd = True
                    done = True
                else:
                    if accept:
                        alpha = 1.0
                        phi_acc = phi
                        for k in range(4):
                            x_acc[k] = x[k]
                            dx_acc[k] = dx[k]
                    else:
                        alpha *= 0.25
                    clipped = False
                    for k in range(4):
                        xn[k] = x_acc[k] + alpha * dx_acc[k]
                        if xn[k] < lo[pi, k] or xn[k] > hi[pi, k]:
                            clipped = True
                    clipped = clipped and accept
                    stuck = (clipped and was_clipped) or alpha < 1e-4
                    if accept:
                        was_clipped = clipped
                    if stuck or it == max_iter:
                        done = True
                if done:
                    break
                for k in range(4):
                    x[k] = min(max(xn[k], lo[pi, k]), hi[pi, k])
            if it > max_it:
                max_it = it
            # store the evaluated point (plus the linearised last step when converged)
            r = scal[0]
            if cvd:
                dth, dy, ds, du = dx[0], dx[1], dx[2], dx[3]
                nn = 0.0
                for k in range(3):
                    p[k] += r * dth * tth[k] + dy * ty[k]
                    q[k] += ds * ts[k] + du * tu[k]
                    n[k] += ds * dn[0, k] + du * dn[1, k]
                    Rl[k] += du * tu[k]
                    nn += n[k] * n[k]
                nn = np.sqrt(nn)
                for k in range(3):
                    n[k] /= nn
                    d[k] = p[k] - q[k]
                scal[0] = r + scal[1] * dy
                for k in range(4):
                    x[k] += dx[k]
            for k in range(4):
                X[pi, k] = x[k]
                H0[pi, k] = h[k]
            conv[pi] = cvd
            # outputs: gap, parameters, rolling radius, contact angle, wheel angle, curvatures
            F1, F2, v1, v2 = scal[1], scal[2], scal[3], scal[4]
            wq = 1.0 + F1 * F1
            GAP[pi] = dot(d, n)
            nl = n[0] * R[0, 1] + n[1] * R[1, 1] + n[2] * R[2, 1]
            nu = n[0] * R[0, 2] + n[1] * R[1, 2] + n[2] * R[2, 2]
            for k in range(4):
                S[pi, k] = x[k]
            S[pi, 4] = scal[0]
            S[pi, 5] = np.arctan2(-sig[pi] * nl, nu)
            S[pi, 6] = np.arctan(-F1)
            S[pi, 7] = 1.0 / (scal[0] * np.sqrt(wq))
            S[pi, 8] = -F2 / wq**1.5
            S[pi, 9] = -dot(n, qss) / dot(ts, ts)
            S[pi, 10] = -v2 / (1.0 + v1 * v1) ** 1.5
            # a stationary point is a contact only where the gap has a minimum across the
            # profiles: relative lateral curvature B = (k_wheel_lat + k_rail_lat)/2 > 0
            # (ContactSearch._newton, "Saddles are not contacts")
            if not (S[pi, 8] + S[pi, 10] > 0.0):
                conv[pi] = False
            for k in range(3):
                V[pi, 0, k] = p[k]; V[pi, 1, k] = q[k]; V[pi, 2, k] = n[k]
        return max_it


    @njit_norc
    def interp3(x, xp, f1, f2, f3, o1, o2, o3):
        """``o_k = np.interp(x, xp, f_k)`` for three tables on one abscissa ``xp`` (increasing),
        one search per point; the arithmetic and edge cases of numba's np.interp (NumPy's
        arr_interp: a NaN x gives NaN, beyond the ends the end values, the other direction
        where the interpolation gives NaN)."""
        n = xp.shape[0]
        for i in range(x.shape[0]):
            xv = x[i]
            if np.isnan(xv):
                o1[i] = o2[i] = o3[i] = xv
                continue
            j = np.searchsorted(xp, xv, side="right") - 1
            if j < 0:
                o1[i], o2[i], o3[i] = f1[0], f2[0], f3[0]
            elif j >= n - 1:
                o1[i], o2[i], o3[i] = f1[n - 1], f2[n - 1], f3[n - 1]
            elif xp[j] == xv:
                o1[i], o2[i], o3[i] = f1[j], f2[j], f3[j]
            else:
                o1[i] = _lerp(xv, xp, f1, j)
                o2[i] = _lerp(xv, xp, f2, j)
                o3[i] = _lerp(xv, xp, f3, j)

    @njit_norc
    def _lerp(xv, xp, fp, j):
        slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
        r = slope * (xv - xp[j]) + fp[j]
        if np.isnan(r):  # if we get NaN in one direction, try the other
            r = slope * (xv - xp[j + 1]) + fp[j + 1]
            if np.isnan(r) and fp[j] == fp[j + 1]:
                r = fp[j]
        return r

    @njit_norc
    def wrap_angle(x):
        """``x`` wrapped into (-pi, pi], for ``x`` in (-2 pi, 2 pi] (a sum or difference of an angle
        of (-pi, pi] and one of [0, pi]); equal to ``atan2(sin x, cos x)`` up to round-off."""
        if x > np.pi:
            return x - 2.0 * np.pi
        if x <= -np.pi:
            return x + 2.0 * np.pi
        return x

    @njit
    def scan(r, ax, d, pos, tan, lat, up, sig, L, yg, rg, F1g, side_left, b0, u0, Y0, Z0,
             b1, u1, Y1, Z1, ulo, uhi, theta, s0, n_rank, out):
        """Seeds of the global cross-section scan (see ContactSearch._seed_scan), per problem."""
        P, G = yg.shape
        Yo = np.empty(G); Zw = np.empty(G); xi = np.empty(G); beta = np.empty(G)
        gap = np.empty(G); h4 = np.empty(G); ok = np.empty(G, dtype=np.bool_)
        gmid = np.empty(G - 1); tt = np.empty(G - 1); th = np.empty(G)
        cbeta = np.empty(G); sbeta = np.empty(G)
        ug = np.empty(G); Yr = np.empty(G); Zr = np.empty(G)
        for p in range(P):
            # the lead angle of each profile line (ContactSearch.scan_lead_angle)
            f0 = ax[p, 1] * d[p, 2] - ax[p, 2] * d[p, 1]
            f1 = ax[p, 2] * d[p, 0] - ax[p, 0] * d[p, 2]
            f2 = ax[p, 0] * d[p, 1] - ax[p, 1] * d[p, 0]
            Ac = sig[p] * (d[p, 0] * tan[p, 0] + d[p, 1] * tan[p, 1] + d[p, 2] * tan[p, 2])
            Bc = sig[p] * (f0 * tan[p, 0] + f1 * tan[p, 1] + f2 * tan[p, 2])
            at = ax[p, 0] * tan[p, 0] + ax[p, 1] * tan[p, 1] + ax[p, 2] * tan[p, 2]
            Rc = np.hypot(Ac, Bc)
            phi = np.arctan2(Bc, Ac)
            cphi, sphi = (Ac / Rc, Bc / Rc) if Rc > 0.0 else (1.0, 0.0)  # phi = atan2(0, 0) = 0
            for g in range(G):
                # the two roots phi ± acs wrapped into (-pi, pi] by arithmetic, and their cosine
                # and sine from the angle-sum formulas (SeedScan's scan_lead_angle): four
                # transcendental calls a grid point fewer than wrapping through atan2(sin, cos)
                c = min(max(-F1g[p, g] * at / Rc, -1.0), 1.0)
                acs = np.arccos(c)
                sa = np.sqrt((1.0 - c) * (1.0 + c))  # sin(acs), accurate also near |c| = 1
                t1a = wrap_angle(phi + acs)
                t2a = wrap_angle(phi - acs)
                if abs(t1a) <= abs(t2a):
                    th[g] = t1a
                    ct, st = cphi * c - sphi * sa, sphi * c + cphi * sa
                else:
                    th[g] = t2a
                    ct, st = cphi * c + sphi * sa, sphi * c - cphi * sa
                e0 = ct * d[p, 0] + st * f0
                e1 = ct * d[p, 1] + st * f1
                e2 = ct * d[p, 2] + st * f2
                w = sig[p] * (yg[p, g] + L)
                rel0 = r[p, 0] + w * ax[p, 0] - rg[p, g] * e0 - pos[p, 0]
                rel1 = r[p, 1] + w * ax[p, 1] - rg[p, g] * e1 - pos[p, 1]
                rel2 = r[p, 2] + w * ax[p, 2] - rg[p, g] * e2 - pos[p, 2]
                Yo[g] = (rel0 * lat[p, 0] + rel1 * lat[p, 1] + rel2 * lat[p, 2]) * sig[p]
                Zw[g] = rel0 * up[p, 0] + rel1 * up[p, 1] + rel2 * up[p, 2]
                xi[g] = rel0 * tan[p, 0] + rel1 * tan[p, 1] + rel2 * tan[p, 2]
                t0 = -F1g[p, g] * e0 + sig[p] * ax[p, 0]
                t1 = -F1g[p, g] * e1 + sig[p] * ax[p, 1]
                t2 = -F1g[p, g] * e2 + sig[p] * ax[p, 2]
                bz = t0 * up[p, 0] + t1 * up[p, 1] + t2 * up[p, 2]
                by = (t0 * lat[p, 0] + t1 * lat[p, 1] + t2 * lat[p, 2]) * sig[p]
                beta[g] = np.arctan2(bz, by)
                bn = np.hypot(by, bz)
                cbeta[g], sbeta[g] = (by / bn, bz / bn) if bn > 0.0 else (1.0, 0.0)
            if side_left[p]:
                interp3(beta, b0, u0, Y0, Z0, ug, Yr, Zr)
            else:
                interp3(beta, b1, u1, Y1, Z1, ug, Yr, Zr)
            j0 = 0
            gbest = 1e300
            for g in range(G):
                cb, sb = cbeta[g], sbeta[g]
                dY, dZ = Yo[g] - Yr[g], Zw[g] - Zr[g]
                ok[g] = (ug[g] > ulo[p]) and (ug[g] < uhi[p])
                gap[g] = -dY * sb + dZ * cb if ok[g] else np.inf
                h4[g] = dY * cb + dZ * sb
                gv = gap[g] if np.isfinite(gap[g]) else 1e300
                if gv < gbest:
                    gbest = gv
                    j0 = g
            for g in range(G - 1):
                ch = (h4[g] * h4[g + 1] <= 0.0) and ok[g] and ok[g + 1]
                den = h4[g] - h4[g + 1] if ch else 1.0
                t = min(max(h4[g] / den, 0.0), 1.0)
                tt[g] = t
                gmid[g] = gap[g] + t * (gap[g + 1] - gap[g]) if ch else np.inf
            jprev = -1
            for rank in range(n_rank):
                if rank > 0:
                    gmid[jprev] = np.inf
                j = 0
                for g in range(1, G - 1):
                    if gmid[g] < gmid[j]:
                        j = g
                jprev = j
                if np.isfinite(gmid[j]):
                    jj, tj = j, tt[j]
                else:
                    jj = min(j0, G - 2)
                    tj = 1.0 if j0 == G - 1 else 0.0
                out[rank, p, 0] = theta[p] - (th[jj] + tj * (th[jj + 1] - th[jj]))
                out[rank, p, 1] = yg[p, jj] + tj * (yg[p, jj + 1] - yg[p, jj])
                out[rank, p, 2] = s0[p] + xi[jj] + tj * (xi[jj + 1] - xi[jj])
                out[rank, p, 3] = ug[jj] + tj * (ug[jj + 1] - ug[jj])
                # sign change found, and the bracket one grid interval either side
                out[rank, p, 4] = 1.0 if np.isfinite(gmid[j]) else 0.0
                out[rank, p, 5] = yg[p, max(jj - 1, 0)]
                out[rank, p, 6] = yg[p, min(jj + 2, G - 1)]



    @njit_norc
    def _reduced_gap(x, sig, r0, L, ow, orr, Y0, Z0, ca, sa, rws, A, b_inner, b_breaks, b_stack,
                     f_inner, f_breaks, f_stack, lo, hi, maxstep, buf):
        """psi(y): solve h1 = h3 = h4 = 0 for (theta, s, u) at the wheel profile coordinate
        x[1] (x updated in place, warm start); returns the gap d . n, +inf when the 3x3
        Newton does not converge or leaves the rail's range (ContactSearch._reduced)."""
        h, J, p, q, n, d, ts, Rl, qss, tth, ty, tu, dn, R, scal, o, M, dx = buf
        for it in range(14):
            evaluate(x, sig, r0, L, ow, orr, Y0, Z0, ca, sa, rws, A, b_inner, b_breaks, b_stack,
                     f_inner, f_breaks, f_stack, h, J, p, q, n, d, ts, Rl, qss, tth, ty, tu, dn, R,
                     scal, o)
            if abs(h[0]) < 1e-12 and abs(h[2]) < 1e-13 and abs(h[3]) < 1e-13:
                break
            k3 = (0, 2, 3)
            for a in range(3):
                for b in range(3):
                    M[a, b] = J[k3[a], k3[b]]
                M[a, 3] = -h[k3[a]]
            ok = True
            for c in range(3):  # Gaussian elimination with partial pivoting
                piv = c
                for rr in range(c + 1, 3):
                    if abs(M[rr, c]) > abs(M[piv, c]):
                        piv = rr
                if abs(M[piv, c]) < 1e-300:
                    ok = False
                    break
                if piv != c:
                    for k in range(4):
                        tmp = M[c, k]
                        M[c, k] = M[piv, k]
                        M[piv, k] = tmp
                for rr in range(c + 1, 3):
                    f = M[rr, c] / M[c, c]
                    for k in range(c, 4):
                        M[rr, k] -= f * M[c, k]
            if not ok:
                return np.inf
            for c in range(2, -1, -1):
                acc = M[c, 3]
                for k in range(c + 1, 3):
                    acc -= M[c, k] * dx[k]
                dx[c] = acc / M[c, c]
            scale = 1.0
            for a in range(3):
                if not np.isfinite(dx[a]):
                    return np.inf
                lim = maxstep[k3[a]]
                if abs(dx[a]) * scale > lim:
                    scale = lim / abs(dx[a])
            for a in range(3):
                k = k3[a]
                v = x[k] + scale * dx[a]
                x[k] = min(max(v, lo[k]), hi[k])
        if not (abs(h[0]) < 1e-9 and abs(h[2]) < 1e-10 and abs(h[3]) < 1e-10):
            return np.inf
        if not (x[3] > lo[3] and x[3] < hi[3]):
            return np.inf
        g = d[0] * n[0] + d[1] * n[1] + d[2] * n[2]
        return g if np.isfinite(g) else np.inf

    @njit
    def reduced_min(x0, ylo, yhi, sig, r0, L, ow, orr, Y0, Z0, ca, sa, lo, hi, rws, A,
                    b_inner, b_breaks, b_stack, f_inner, f_breaks, f_stack, maxstep,
                    n_sample, tol):
        """Robust contact per problem: the minimum of the gap psi(y) of the wheel profile line y
        over [ylo, yhi] (n_sample samples, warm-started from one to the next, then golden-section
        search between the neighbours of the lowest sample to ``tol`` on y).  For contacts where
        Newton on the four conditions does not converge: a stationary point at a joint of
        profile sections (slope step) or a nearly conformal contact (ContactSearch._robust).
        Returns X (P, 4) and ok (P,)."""
        P = x0.shape[0]
        X = x0.copy()
        ok = np.zeros(P, dtype=np.bool_)
        buf = (np.empty(4), np.empty((4, 4)), np.empty(3), np.empty(3), np.empty(3), np.empty(3),
               np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3),
               np.empty((2, 3)), np.empty((3, 3)), np.empty(5),
               np.empty(min(FRAME_COLUMNS, f_stack.shape[2])), np.empty((3, 4)), np.empty(3))
        xs = np.empty(4)
        xbest = np.empty(4)
        gr = 0.5 * (np.sqrt(5.0) - 1.0)
        for pi in range(P):
            for k in range(4):
                xs[k] = x0[pi, k]
            gbest = np.inf
            ibest = -1
            ys = np.empty(n_sample)
            for j in range(n_sample):
                ys[j] = ylo[pi] + (yhi[pi] - ylo[pi]) * j / (n_sample - 1)
                xs[3] += ys[j] - xs[1]
                xs[1] = ys[j]
                g = _reduced_gap(xs, sig[pi], r0[pi], L[pi], ow[pi], orr[pi], Y0[pi], Z0[pi], ca[pi],
                                 sa[pi], rws[pi], A[pi], b_inner, b_breaks, b_stack, f_inner, f_breaks,
                                 f_stack, lo[pi], hi[pi], maxstep, buf)
                if g < gbest:
                    gbest, ibest = g, j
                    for k in range(4):
                        xbest[k] = xs[k]
                if not np.isfinite(g):  # restart the warm start from the seed
                    for k in range(4):
                        xs[k] = x0[pi, k]
            if ibest < 0:
                continue
            a = ys[max(ibest - 1, 0)]
            b = ys[min(ibest + 1, n_sample - 1)]
            c = b - gr * (b - a)
            dd = a + gr * (b - a)
            xc = xbest.copy()
            xc[3] += c - xc[1]
            xc[1] = c
            fc = _reduced_gap(xc, sig[pi], r0[pi], L[pi], ow[pi], orr[pi], Y0[pi], Z0[pi], ca[pi], sa[pi],
                              rws[pi], A[pi], b_inner, b_breaks, b_stack, f_inner, f_breaks, f_stack,
                              lo[pi], hi[pi], maxstep, buf)
            xd = xbest.copy()
            xd[3] += dd - xd[1]
            xd[1] = dd
            fdd = _reduced_gap(xd, sig[pi], r0[pi], L[pi], ow[pi], orr[pi], Y0[pi], Z0[pi], ca[pi], sa[pi],
                               rws[pi], A[pi], b_inner, b_breaks, b_stack, f_inner, f_breaks, f_stack,
                               lo[pi], hi[pi], maxstep, buf)
            while b - a > tol:
                if fc <= fdd:  # the minimum lies in [a, d]
                    b, dd, fdd = dd, c, fc
                    for k in range(4):
                        xd[k] = xc[k]
                    c = b - gr * (b - a)
                    xc[3] += c - xc[1]
                    xc[1] = c
                    fc = _reduced_gap(xc, sig[pi], r0[pi], L[pi], ow[pi], orr[pi], Y0[pi], Z0[pi], ca[pi],
                                      sa[pi], rws[pi], A[pi], b_inner, b_breaks, b_stack, f_inner, f_breaks,
                                      f_stack, lo[pi], hi[pi], maxstep, buf)
                else:
                    a, c, fc = c, dd, fdd
                    for k in range(4):
                        xc[k] = xd[k]
                    dd = a + gr * (b - a)
                    xd[3] += dd - xd[1]
                    xd[1] = dd
                    fdd = _reduced_gap(xd, sig[pi], r0[pi], L[pi], ow[pi], orr[pi], Y0[pi], Z0[pi], ca[pi],
                                       sa[pi], rws[pi], A[pi], b_inner, b_breaks, b_stack, f_inner,
                                       f_breaks, f_stack, lo[pi], hi[pi], maxstep, buf)
            if min(fc, fdd) < gbest:
                src = xc if fc <= fdd else xd
                for k in range(4):
                    xbest[k] = src[k]
            for k in range(4):
                X[pi, k] = xbest[k]
            # a minimum at the end of the interval is no contact of this zone (the gap keeps
            # falling beyond it: the neighbouring zone holds the contact)
            ok[pi] = ylo[pi] + 1e-7 < xbest[1] < yhi[pi] - 1e-7
        return X, ok


def scan_kernel():
    """The compiled seed scan (compiled on first use), or None without numba."""
    return scan if HAVE_NUMBA else None


def newton_kernel():
    """The compiled Newton kernel (compiled on first use), or None without numba."""
    return newton if HAVE_NUMBA else None


def reduced_min_kernel():
    """The compiled robust minimisation of the profile-line gap, or None without numba."""
    return reduced_min if HAVE_NUMBA else None
