r"""Seed scan: the global re-seeding of the contact search over the profile grid.

For grid points y_i of a zone (uniform in the profile's arc length over the whole zone, overlap
included), the wheel point of each profile circle whose normal is square to the track tangent
(the lowest point of an unyawed wheel; :func:`scan_lead_angle` for a yawed one) and its profile
tangent angle beta_i in the cross-section are computed; the rail point u_i of the same tangent
angle (normals parallel: the first two of the four conditions) comes from the monotonic
tangent-angle table of the convex rail head.  Along the grid the fourth condition::

    h4_i = (P_i - Q_i) . t_u

changes sign at the stationary points of the gap; the seeds are the sign changes with the
smallest gaps g_i = (P_i - Q_i) . n_i (global over the zone, so jumps of the contact across the
tread are found), or the smallest gap where there is no sign change.  The compiled scan
(:func:`railway.contact.search.kernels.scan`) does the same.

References
----------
Pombo, J., Ambrosio, J. and Silva, M. (2007). A new wheel-rail contact model for railway
dynamics. Vehicle System Dynamics 45(2):165-189.
"""

from __future__ import annotations

import numpy as np

from core.errors import InputError

__all__ = ["SeedScan", "scan_lead_angle"]


def _arc_grid(profile, lo, hi, n):
    """n points of [lo, hi] (m) uniform in the arc length of the curve y -> (y, F(y))."""
    yd = np.linspace(lo, hi, 20 * n + 1)
    ds = np.sqrt(1.0 + profile.poly(yd)[1] ** 2)
    arc = np.concatenate([[0.0], np.cumsum(0.5 * (ds[1:] + ds[:-1]) * np.diff(yd))])
    y = np.interp(np.linspace(0.0, arc[-1], n), arc, yd)
    y[0], y[-1] = lo, hi
    return y


def scan_lead_angle(sig, F1, d, ax, tan):
    r"""Angle theta (P, G) of the wheel point of each profile line whose surface normal is square
    to the track tangent t, measured about the axle a from the lowest point direction -d.

    The wheel point at profile coordinate y and angle theta is P = c + sig (y + L) a - r(y) e_r
    with e_r = cos(theta) d + sin(theta) f, f = a x d; its normal is parallel to
    sig e_r + F'(y) a, so the condition n . t = 0 reads

    .. math:: \sigma (d\cdot t) \cos\theta + \sigma (f\cdot t) \sin\theta = -F'(y)\,(a\cdot t)

    i.e. R cos(theta - phi) = C; of its two roots the one nearer the lowest point.  An unyawed
    wheel (a . t = 0, d . t = 0) has theta = 0; a yawed one leads or lags by about
    arctan(F' tan psi) -- a few millimetres on the tread, 16 mm ahead on a 70 deg flange at
    12 mrad (the contact the cross-section of the lowest point would miss).
    """
    f = np.cross(ax, d)
    A = sig * np.einsum("pk,pk->p", d, tan)
    B = sig * np.einsum("pk,pk->p", f, tan)
    C = -F1 * np.einsum("pk,pk->p", ax, tan)[:, None]
    R = np.hypot(A, B)[:, None]
    phi = np.arctan2(B, A)[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        acs = np.arccos(np.clip(C / R, -1.0, 1.0))
    t1 = np.angle(np.exp(1j * (phi + acs)))
    t2 = np.angle(np.exp(1j * (phi - acs)))
    return np.where(np.abs(t1) <= np.abs(t2), t1, t2)


class SeedScan:
    """The seed scan of :class:`~railway.contact.search.ContactSearch` (a part of it, not used alone).

    Reads the search's ``track``, ``rails``, ``L``, ``n_scan`` and ``_scan_kernel``; builds the
    scan grids ``_scan`` and the rail tangent-angle tables ``_rail_tab``.
    """

    def _build_scan_tables(self, w, ylo, yhi, n_scan):
        """Scan grids of the tread and flange zones (``_scan``) and the rail tables (``_rail_tab``)."""
        # scan grids of the tread and flange zones, and the rail tangent-angle tables
        G = self.n_scan
        if G < 8:
            raise InputError(f"n_scan = {n_scan!r}: the seed scan needs at least 8 grid points")
        # scan grids of the whole zones (overlap included), uniform in the profile's arc length
        # so that the steep flank and the tight flange root get as many points per mm of
        # profile as the flat tread
        yz = np.stack([_arc_grid(w, ylo[0], yhi[0], G), _arc_grid(w, ylo[1], yhi[1], G)])
        Fz, F1z, _ = w.poly(yz)
        self._scan = dict(y=yz, r=w.r0 + Fz, F1=F1z)
        self._rail_tab = []
        for m in self.rails:
            ug = np.linspace(m.u_min, m.u_max, 4001)
            Yo, Z, a1, b1, _, _ = m.mounted(ug)
            beta = np.arctan2(b1, a1)  # decreasing along u for a convex head
            order = np.argsort(beta)
            self._rail_tab.append((beta[order], ug[order], Yo[order], Z[order]))

    def _seed_scan(self, pc, r_ws, A, s_ws, second=False, brackets=False, ranks=None):
        """Seeds (P, 4) from a coarse scan of each zone in the track cross-section.

        With ``second=True`` a list [best, second best] is returned, with ``ranks=k`` a list of
        the k best (``second`` is ``ranks=2``).  With ``brackets=True``
        each seed array has three more columns: 1.0 where the seed is a sign change of the
        fourth condition (a stationary point lies near) else 0.0, and the profile coordinates
        (m) of the grid points one interval either side of it, a bracket of that stationary
        point for :meth:`_robust`.

        For grid points y_i of the zone, the lowest point of the wheel circle (towards the rail)
        and its profile tangent angle beta_i in the cross-section are computed; the rail point
        u_i with the same tangent angle (normals parallel, the first two conditions) comes from
        the monotonic tangent-angle table of the convex rail head.  Along the grid the remaining
        condition h4_i = (P_i - Q_i) . t_u changes sign at the stationary points; the seed is the
        sign change with the smallest gap g_i = (P_i - Q_i) . n_i (global over the zone, so
        jumps of the contact across the tread are found), or the smallest gap when there is
        no sign change.
        """
        P = pc["sig"].size
        ws = pc["ws"]
        # frames and directions per wheelset, then per problem
        fr_pos, _, fr_R, _ = self.track._frame(s_ws)
        up_w = fr_R[:, :, 2]
        ax_w = A[:, :, 1]  # axle direction
        d_w = up_w - np.sum(up_w * ax_w, axis=1)[:, None] * ax_w
        d_w /= np.linalg.norm(d_w, axis=1)[:, None]  # lowest point direction is -d
        fr_pos, fr_R, ax, d = fr_pos[ws], fr_R[ws], ax_w[ws], d_w[ws]
        tan, lat, up = fr_R[:, :, 0], fr_R[:, :, 1], fr_R[:, :, 2]
        sig = pc["sig"]
        yg, rg, F1g = (self._scan[k][pc["cand"]] for k in ("y", "r", "F1"))  # (P, G)
        n_rank = int(ranks) if ranks else (2 if second else 1)
        listed = bool(ranks) or second
        if self._scan_kernel is not None:  # the same scan, compiled (railway.contact.search.kernels)
            dl = np.einsum("pkj,pk->pj", A[ws], -d)
            theta = np.arctan2(dl[:, 0], -dl[:, 2])
            (b0, u0, Y0, Z0), (b1, u1, Y1, Z1) = self._rail_tab
            out = np.empty((n_rank, P, 7))
            self._scan_kernel(np.ascontiguousarray(r_ws[ws]), ax, d, fr_pos, tan, lat, up, sig,
                              self.L, yg, rg, F1g, sig > 0, b0, u0, Y0, Z0, b1, u1, Y1, Z1,
                              pc["ulo"], pc["uhi"], theta, s_ws[ws], out.shape[0], out)
            if not brackets:
                out = out[:, :, :4]
            return list(out) if listed else out[0]
        # the point of each profile line whose normal is square to the track tangent (the
        # contact leads or lags the lowest point of a yawed wheel): e_r = cos(th) d + sin(th) f
        th = scan_lead_angle(sig, F1g, d, ax, tan)  # (P, G)
        f = np.cross(ax, d)
        e_r = np.cos(th)[:, :, None] * d[:, None, :] + np.sin(th)[:, :, None] * f[:, None, :]
        ctr = r_ws[ws][:, None, :] + (sig[:, None] * (yg + self.L))[:, :, None] * ax[:, None, :]
        pts = ctr - rg[:, :, None] * e_r
        rel = pts - fr_pos[:, None, :]
        Yo = np.einsum("pgk,pk->pg", rel, lat) * sig[:, None]
        Zw = np.einsum("pgk,pk->pg", rel, up)
        xi = np.einsum("pgk,pk->pg", rel, tan)
        ty = -F1g[:, :, None] * e_r + (sig[:, None, None] * ax[:, None, :])
        beta = np.arctan2(np.einsum("pgk,pk->pg", ty, up),
                          np.einsum("pgk,pk->pg", ty, lat) * sig[:, None])
        ug = np.empty_like(beta)
        Yr = np.empty_like(beta)
        Zr = np.empty_like(beta)
        for side, (b_tab, u_tab, Y_tab, Z_tab) in zip((1.0, -1.0), self._rail_tab):
            m = sig == side
            ug[m] = np.interp(beta[m], b_tab, u_tab)
            Yr[m] = np.interp(beta[m], b_tab, Y_tab)
            Zr[m] = np.interp(beta[m], b_tab, Z_tab)
        cb, sb = np.cos(beta), np.sin(beta)
        dY, dZ = Yo - Yr, Zw - Zr
        ok = (ug > pc["ulo"][:, None]) & (ug < pc["uhi"][:, None])
        gap = np.where(ok, -dY * sb + dZ * cb, np.inf)
        h4 = dY * cb + dZ * sb
        change = (h4[:, :-1] * h4[:, 1:] <= 0.0) & ok[:, :-1] & ok[:, 1:]
        t = np.clip(h4[:, :-1] / np.where(change, h4[:, :-1] - h4[:, 1:], 1.0), 0.0, 1.0)
        with np.errstate(invalid="ignore"):
            gmid = np.where(change, gap[:, :-1] + t * (gap[:, 1:] - gap[:, :-1]), np.inf)
        ii = np.arange(P)
        j0 = np.argmin(np.where(np.isfinite(gap), gap, 1e300), axis=1)
        dl = np.einsum("pkj,pk->pj", A[ws], -d)
        theta = np.arctan2(dl[:, 0], -dl[:, 2])
        seeds = []
        j = np.zeros(P, dtype=int)
        for rank in range(n_rank):
            if rank:  # the next-best stationary point (near-equal minima of the tread gap)
                gmid = gmid.copy()
                gmid[ii, j] = np.inf
            j = np.argmin(gmid, axis=1)
            has = np.isfinite(gmid[ii, j])
            jj = np.where(has, j, np.minimum(j0, yg.shape[1] - 2))
            tj = np.where(has, t[ii, j], np.where(j0 == yg.shape[1] - 1, 1.0, 0.0))

            def lerp(a, jj=jj, tj=tj):
                return a[ii, jj] + tj * (a[ii, jj + 1] - a[ii, jj])

            cols = [theta - lerp(th), lerp(yg), s_ws[ws] + lerp(xi), lerp(ug)]
            if brackets:
                G = yg.shape[1]
                cols += [has.astype(float), yg[ii, np.maximum(jj - 1, 0)],
                         yg[ii, np.minimum(jj + 2, G - 1)]]
            seeds.append(np.stack(cols, axis=1))
        return seeds if listed else seeds[0]
