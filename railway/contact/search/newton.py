r"""Newton solve of the four contact conditions (Pombo, Ambrosio & Silva 2007).

For a wheel surface p(theta, y) and a rail surface q(s, u), with d = p - q and the rail outward
normal n_r, the contact points satisfy::

    h1 = n_r . t_theta = 0,   h2 = n_r . t_y = 0      (normals parallel)
    h3 = d . t_s = 0,         h4 = d . t_u = 0        (distance vector along the normal)

for x = (theta, y, s, u); the gap is g = d . n_r.  Newton's method with the analytic Jacobian
(:meth:`NewtonSolve._residual_jac`) or forward differences (5 P residuals in one vectorised
pass); the P 4x4 systems in one batched ``np.linalg.solve``.  A step that does not reduce the
merit ``|W h|^2`` is retried from the last accepted point with a quarter of its length, and a pass
whose merit is at its round-off floor (:func:`railway.contact.search.kernels.merit_floor`: a few
ulps of the largest coordinate, the rail arc length on a long track) has converged; steps are
limited and the parameters kept inside their zones.  A step below ``tol_linear`` is applied
without a further pass, the outputs linearised about the evaluated point (error O(step^2)).  A
converged stationary point is a contact only where the gap has a minimum across the profiles
(:meth:`NewtonSolve._minimum`).  With numba the same iteration runs in
:func:`railway.contact.search.kernels.newton`.

References
----------
Pombo, J., Ambrosio, J. and Silva, M. (2007). A new wheel-rail contact model for railway
dynamics. Vehicle System Dynamics 45(2):165-189 (equation numbers were not checked against the
paper here).
"""

from __future__ import annotations

import numpy as np

from .kernels import merit_floor

__all__ = ["NewtonSolve"]

_I1, _I2 = np.array([1, 2, 0]), np.array([2, 0, 1])


def _cross(a, b):
    """Cross product of (..., 3) arrays (cheaper than np.cross for small arrays)."""
    return a[..., _I1] * b[..., _I2] - a[..., _I2] * b[..., _I1]


class NewtonSolve:
    """The Newton solve of :class:`~railway.contact.search.ContactSearch` (a part of it).

    Reads the search's ``track``, ``_bank``, ``tol``, ``tol_linear``, ``max_iter``, ``jacobian``,
    ``fd_step``, ``_maxstep``, ``_wts``, ``_kernel`` and ``_rep`` (zone bookkeeping).
    """

    def _residual_jac(self, x, pc, r_ws, AT):
        """Residuals h (M, 4) of the four contact conditions and their analytic Jacobian.

        With the wheel tangents t_theta (unit), t_y, the rail tangents t_s, t_u and
        n = sigma c/|c|, c = t_s x t_u, the derivatives are (omega the track's Darboux vector)::

            dp/dtheta = r t_theta, dp/dy = t_y, dq/ds = t_s, dq/du = t_u
            dt_theta/dtheta = A (-sin, 0, cos),  dt_y/dtheta = F' t_theta,
            dt_y/dy = A (F'' sin, 0, -F'' cos)
            dt_u/du = R (0, sigma Yo'', Z''),  dt_u/ds = dt_s/du = omega x t_u,
            dt_s/ds = q_ss = r'' + omega' x (R l) + omega x (omega x (R l))
            dn = (I - n n^T) sigma dc / |c|
        """
        M = x.shape[0]
        th, yw, s, u = x[:, 0], x[:, 1], x[:, 2], x[:, 3]
        prof = self._bank.eval_raw(np.concatenate([yw + pc["ow"], u + pc["orr"]]))
        F, F1, F2 = prof[:M, 0], prof[:M, 1], prof[:M, 2]
        v, v1, v2 = prof[M:, 0], prof[M:, 1], prof[M:, 2]
        sig = pc["sig"]
        r = pc["r0"] + F
        st, ct = np.sin(th), np.cos(th)
        zero = np.zeros(M)
        loc = np.stack([r * st, sig * (yw + pc["L"]), -r * ct, ct, zero, st,
                        F1 * st, sig, -F1 * ct, -st, zero, ct, F2 * st, zero, -F2 * ct],
                       axis=1).reshape(M, 5, 3)
        gw = loc @ AT
        p = gw[:, 0] + r_ws
        tth, ty, dtth, dtyy = gw[:, 1], gw[:, 2], gw[:, 3], gw[:, 4]
        # rail
        pos, dpos, ddpos, R, om, dom = self.track._frame_fast(s)
        ca, sa = pc["ca"], pc["sa"]
        a = pc["Y0"] + u * ca - v * sa
        b = pc["Z0"] + u * sa + v * ca
        locr = np.stack([zero, sig * a, b, zero, sig * (ca - v1 * sa), sa + v1 * ca,
                         zero, -sig * v2 * sa, v2 * ca], axis=1).reshape(M, 3, 3)
        gr = locr @ np.swapaxes(R, 1, 2)
        Rl, tu, dtuu = gr[:, 0], gr[:, 1], gr[:, 2]
        q = pos + Rl
        # cross products batched in three calls
        c1 = _cross(np.stack([om, om, dom], axis=1), np.stack([Rl, tu, Rl], axis=1))
        omRl, omtu = c1[:, 0], c1[:, 1]
        ts = dpos + omRl
        qss = ddpos + c1[:, 2] + _cross(om, omRl)
        c3 = _cross(np.stack([ts, qss, ts, omtu, ts], axis=1),
                    np.stack([tu, tu, omtu, tu, dtuu], axis=1))
        c = c3[:, 0]
        cn = np.sqrt(np.einsum("ij,ij->i", c, c))
        n = c * (sig / cn)[:, None]
        d = p - q
        dcs = np.stack([c3[:, 1] + c3[:, 2], c3[:, 3] + c3[:, 4]], axis=1) * (sig / cn)[:, None, None]
        dn = dcs - np.einsum("mjk,mk->mj", dcs, n)[:, :, None] * n[:, None, :]  # (M, 2, 3)
        # residuals and Jacobian via stacked dot products
        Lv = np.stack([n, n, d, d,                                  # h
                       n, n, dn[:, 0], dn[:, 1],                    # dh1/d(th, y, s, u)
                       n, n, dn[:, 0], dn[:, 1],                    # dh2
                       ts, ts, ts, ts, d, d,                        # dh3
                       tu, tu, tu, tu, d, d], axis=1)               # dh4
        Rv = np.stack([tth, ty, ts, tu,
                       dtth, zero[:, None] * tth, tth, tth,
                       tth, dtyy, ty, ty,
                       tth, ty, -ts, -tu, qss, omtu,
                       tth, ty, -ts, -tu, omtu, dtuu], axis=1)
        dots = np.einsum("mkj,mkj->mk", Lv, Rv)
        h = dots[:, :4]
        J = np.empty((M, 4, 4))
        J[:, 0, :] = dots[:, 4:8]
        J[:, 0, 1] = 0.0
        J[:, 1, :] = dots[:, 8:12]
        J[:, 1, 0] *= F1
        J[:, 2, 0] = r * dots[:, 12]
        J[:, 2, 1] = dots[:, 13]
        J[:, 2, 2] = dots[:, 14] + dots[:, 16]
        J[:, 2, 3] = dots[:, 15] + dots[:, 17]
        J[:, 3, 0] = r * dots[:, 18]
        J[:, 3, 1] = dots[:, 19]
        J[:, 3, 2] = dots[:, 20] + dots[:, 22]
        J[:, 3, 3] = dots[:, 21] + dots[:, 23]
        info = dict(p=p, q=q, n=n, d=d, r=r, F1=F1, F2=F2, v1=v1, v2=v2, R=R, Rl=Rl, ts=ts,
                    qss=qss, tth=tth, ty=ty, tu=tu, dn=dn)
        return h, J, info

    def _residual(self, x, pc, r_ws, AT, full=False):
        """Residuals h (M, 4) of the four contact conditions at parameters x (M, 4)."""
        M = x.shape[0]
        th, yw, s, u = x[:, 0], x[:, 1], x[:, 2], x[:, 3]
        prof = self._bank.eval_raw(np.concatenate([yw + pc["ow"], u + pc["orr"]]))
        F, F1 = prof[:M, 0], prof[:M, 1]
        v, v1 = prof[M:, 0], prof[M:, 1]
        sig = pc["sig"]
        r = pc["r0"] + F
        st, ct = np.sin(th), np.cos(th)
        zero = np.zeros(M)
        loc = np.stack([r * st, sig * (yw + pc["L"]), -r * ct, ct, zero, st,
                        F1 * st, sig, -F1 * ct], axis=1).reshape(M, 3, 3)
        gw = loc @ AT
        p = gw[:, 0] + r_ws
        # rail
        pos, dpos, _, R, om, _ = self.track._frame_fast(s)
        ca, sa = pc["ca"], pc["sa"]
        a = pc["Y0"] + u * ca - v * sa
        b = pc["Z0"] + u * sa + v * ca
        a1 = ca - v1 * sa
        b1 = sa + v1 * ca
        locr = np.stack([zero, sig * a, b, zero, sig * a1, b1], axis=1).reshape(M, 2, 3)
        gr = locr @ np.swapaxes(R, 1, 2)
        Rl = gr[:, 0]
        q = pos + Rl
        ts = dpos + _cross(om, Rl)
        tu = gr[:, 1]
        n = _cross(ts, tu)
        n *= (sig / np.sqrt(np.einsum("ij,ij->i", n, n)))[:, None]
        d = p - q
        h = np.einsum("mkj,mkj->mk", np.stack([n, n, d, d], axis=1),
                      np.stack([gw[:, 1], gw[:, 2], ts, tu], axis=1))
        if not full:
            return h
        return h, dict(p=p, q=q, n=n, d=d, r=r, F1=F1, F2=prof[:M, 2], v1=v1, v2=prof[M:, 2],
                       R=R, Rl=Rl, ts=ts)

    def _newton(self, x, pc, r_ws, AP, max_iter=None):
        """Vectorised Newton on all problems; returns x, residual, converged, passes, info.

        Only the problems not yet finished are evaluated in a pass.
        """
        if self._kernel is not None and self.jacobian == "analytic":
            return self._newton_compiled(x, pc, r_ws, AP, max_iter or self.max_iter)
        AT = np.swapaxes(AP, 1, 2)
        max_iter = max_iter or self.max_iter
        P = x.shape[0]
        hstep = self.fd_step
        E = np.eye(4) * hstep
        lo_all, hi_all = pc["lo"], pc["hi"]
        maxstep = self._maxstep
        wts = self._wts  # merit weights (h3, h4 are lengths in m)
        x = x.copy()
        # a last step below tol_linear is applied without another pass, with the outputs
        # linearised about the evaluated point (error O(|dx|^2)); analytic Jacobian only
        tol_lin = max(self.tol, self.tol_linear) if self.jacobian == "analytic" else self.tol
        dx_fin = np.zeros_like(x)
        conv = np.zeros(P, dtype=bool)
        done = np.zeros(P, dtype=bool)
        was_clipped = np.zeros(P, dtype=bool)
        x_acc = x.copy()
        phi_acc = np.full(P, np.inf)
        dx_acc = np.zeros_like(x)
        alpha = np.ones(P)
        H0_all = np.zeros((P, 4))
        info_all = None
        idx = None  # None: all problems active
        for it in range(1, max_iter + 1):
            if idx is None:
                xa, pca, ra, Aa, lo, hi = x, pc, r_ws, AT, lo_all, hi_all
            else:
                xa = x[idx]
                pca = {k: (v[idx] if isinstance(v, np.ndarray) else v) for k, v in pc.items()}
                ra, Aa, lo, hi = r_ws[idx], AT[idx], lo_all[idx], hi_all[idx]
            n = xa.shape[0]
            if self.jacobian == "analytic":
                H0, J, info = self._residual_jac(xa, pca, ra, Aa)
            else:
                X = np.concatenate([xa, xa + E[0], xa + E[1], xa + E[2], xa + E[3]])
                H = self._residual(X, self._rep(pca, 5), np.concatenate([ra] * 5),
                                   np.concatenate([Aa] * 5))
                H0 = H[:n]
                info = self._residual_jac(xa, pca, ra, Aa)[2]  # outputs at the base points
                J = np.stack([(H[(k + 1) * n:(k + 2) * n] - H0) for k in range(4)], axis=2) / hstep
            with np.errstate(all="ignore"):
                try:
                    dx = -np.linalg.solve(J, H0[:, :, None])[:, :, 0]
                except np.linalg.LinAlgError:
                    dx = np.zeros_like(H0)
                    ok = np.abs(np.linalg.det(J)) > 1e-300
                    dx[ok] = -np.linalg.solve(J[ok], H0[ok][:, :, None])[:, :, 0]
            dx = np.where(np.isfinite(dx), dx, 0.0)
            scale = np.min(np.minimum(1.0, maxstep / (np.abs(dx) + 1e-300)), axis=1)
            dx *= scale[:, None]
            if idx is None:
                H0_all = H0
                info_all = info
                sl = slice(None)
            else:
                H0_all[idx] = H0
                for k, v in info.items():
                    info_all[k][idx] = v
                sl = idx
            # backtracking across passes on the merit |W h|^2: a step that does not reduce it
            # is retried from the last accepted point with a quarter of its length
            phi = np.sum((H0 * wts) ** 2, axis=1)
            floor = merit_floor(*wts, np.maximum(np.max(np.abs(ra), axis=1), np.abs(xa[:, 2])))
            pa, al = phi_acc[sl], alpha[sl]
            accept = (phi <= pa * (1.0 - 1e-4 * al)) | (phi < floor) | ~np.isfinite(pa)
            cv = accept & ((np.max(np.abs(dx), axis=1) < tol_lin) | (phi < floor))
            dx_fin[sl] = np.where(cv[:, None], dx, 0.0)
            al = np.where(accept, 1.0, 0.25 * al)
            xacc = np.where(accept[:, None], xa, x_acc[sl])
            dxacc = np.where(accept[:, None], dx, dx_acc[sl])
            xn = xacc + al[:, None] * dxacc
            clipped = accept & np.any((xn < lo) | (xn > hi), axis=1)
            stuck = (clipped & was_clipped[sl]) | (al < 1e-4)
            was_clipped[sl] = np.where(accept, clipped, was_clipped[sl])
            alpha[sl], x_acc[sl], dx_acc[sl] = al, xacc, dxacc
            phi_acc[sl] = np.where(accept, phi, pa)
            conv[sl] = cv
            dn = cv | stuck
            x[sl] = np.where(dn[:, None], xa, np.clip(xn, lo, hi))
            done[sl] = dn
            if np.all(done):
                break
            idx = np.nonzero(~done)[0]
        if self.jacobian == "analytic" and np.any(dx_fin):
            x = x + dx_fin
            info_all = self._linear_update(info_all, dx_fin)
        conv &= self._minimum(info_all)
        return x, H0_all, conv, it, info_all

    @staticmethod
    def _minimum(info):
        """Saddles are not contacts: a converged stationary point of the gap is a contact only
        where the gap has a minimum across the profiles, i.e. where the relative lateral
        curvature B = (k_wheel_lateral + k_rail_lateral)/2 is positive.  Where a concave wheel
        profile is more curved than the convex rail head under it (B < 0: e.g. the S1002 tread
        near 6 mm inboard of the taping line, radius 234 mm, on the UIC60 R300 crown) the
        stationary point is a maximum of the gap along the profile between two minima -- the
        contacts lie at those minima.  Hertz has no meaning there (its ellipse would be
        clipped to an elongated one, with semi-axes of decimetres and forces of hundreds of kN
        from micrometres of penetration)."""
        F1, F2, v1, v2 = info["F1"], info["F2"], info["v1"], info["v2"]
        B = 0.5 * (-F2 / (1.0 + F1**2) ** 1.5 - v2 / (1.0 + v1**2) ** 1.5)
        return B > 0.0

    def _newton_compiled(self, x, pc, r_ws, AP, max_iter):
        """The same Newton iteration in the compiled kernel of :mod:`railway.contact.search.kernels`."""
        A = np.ascontiguousarray(AP)
        b, f = self._bank, self.track.pp_frame
        tol_lin = max(self.tol, self.tol_linear)
        X, H0, conv, it, gap, S, V = self._kernel(
            np.ascontiguousarray(x, dtype=float), pc["sig"], pc["r0"], pc["L"], pc["ow"],
            pc["orr"], pc["Y0"], pc["Z0"], pc["ca"], pc["sa"], pc["lo"], pc["hi"],
            np.ascontiguousarray(r_ws), A, b._inner, b.breaks, b._stack, f._inner, f.breaks,
            f._stack, tol_lin, max_iter, self._maxstep, self._wts)
        return X, H0, conv, int(it), dict(gap=gap, S=S, V=V)

    @staticmethod
    def _linear_update(info, dx):
        """First-order update of the contact outputs for a parameter step dx (P, 4)."""
        info = dict(info)
        dth, dy, ds, du = dx[:, 0:1], dx[:, 1:2], dx[:, 2:3], dx[:, 3:4]
        info["p"] = info["p"] + (info["r"][:, None] * dth) * info["tth"] + dy * info["ty"]
        info["q"] = info["q"] + ds * info["ts"] + du * info["tu"]
        n = info["n"] + ds * info["dn"][:, 0] + du * info["dn"][:, 1]
        info["n"] = n / np.sqrt(np.einsum("ij,ij->i", n, n))[:, None]
        info["d"] = info["p"] - info["q"]
        info["r"] = info["r"] + info["F1"] * dx[:, 1]
        info["Rl"] = info["Rl"] + du * info["tu"]
        return info

    def _outputs(self, x, pc, info):
        """(gap (P,), S (P, 11), V (P, 3, 3)) from the numpy Newton's intermediate arrays."""
        if "S" in info:
            return info["gap"], info["S"], info["V"]
        n, d, R = info["n"], info["d"], info["R"]
        gap = np.einsum("ij,ij->i", d, n)
        F1, F2, v1, v2_, r = info["F1"], info["F2"], info["v1"], info["v2"], info["r"]
        wq = 1.0 + F1**2
        nR = np.einsum("ij,ijk->ik", n, R)  # normal in the track frame (t, lateral, up)
        k_rx = -np.einsum("ij,ij->i", n, info["qss"]) / np.einsum("ij,ij->i", info["ts"], info["ts"])
        S = np.stack([x[:, 0], x[:, 1], x[:, 2], x[:, 3], r,
                      np.arctan2(-pc["sig"] * nR[:, 1], nR[:, 2]), np.arctan(-F1),
                      1.0 / (r * np.sqrt(wq)), -F2 / wq**1.5, k_rx, -v2_ / (1.0 + v1**2) ** 1.5],
                     axis=1)
        return gap, S, np.stack([info["p"], info["q"], n], axis=1)
