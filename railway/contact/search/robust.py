r"""Robust refinement where Newton on the four conditions fails: the minimum of the profile-line gap.

For a fixed wheel profile coordinate y the other three conditions (h1, h3, h4) are solved for
(theta, s, u) -- a well-conditioned 3x3 Newton, the wheel point's projection on the rail
(:meth:`RobustRefinement._reduced`) -- which gives the gap psi(y) of that profile line; by the
envelope theorem::

    psi(y) = d . n  at  h1 = h3 = h4 = 0,        dpsi/dy = n . t_y = h2

so the four-condition solutions are the stationary points of psi and the contact is its minimum.
psi is sampled densely in a bracket and its minimum refined by Newton or, where that fails,
golden-section search (:meth:`RobustRefinement._robust`); over a whole zone by the compiled
:func:`railway.contact.search.kernels.reduced_min` (:meth:`RobustRefinement._robust_zone`).  This
finds the contact where Newton's 4x4 Jacobian is singular or jumps: the S1002 R13 flange root
conformal with the UIC60 R13 gauge corner, the root/flank joint with its slope step, the ripples
of splines through sampled, rounded profile points.

References
----------
Kiefer, J. (1953). Sequential minimax search for a maximum. Proc. Amer. Math. Soc.
4(3):502-506 (golden-section search).
"""

from __future__ import annotations

import numpy as np

__all__ = ["RobustRefinement"]


class RobustRefinement:
    """The robust refinement of :class:`~railway.contact.search.ContactSearch` (a part of it).

    Reads the search's ``track``, ``_bank``, ``_problems``, ``_maxstep``, ``_wts``, ``_kernel``
    and its Newton solve (``_residual_jac``, ``_newton``) and outputs (``_gsv``).
    """

    def _robust_zone(self, todo, x, r_ws, A, n_sample):
        """Robust minimisation of the profile-line gap over the whole zone of problems ``todo``
        (compiled kernel; outputs at the minimum by one Newton evaluation).  Returns x, H,
        conv, info (gap, S, V) for those problems."""
        from .kernels import reduced_min_kernel

        pc = self._problems
        ws = pc["ws"][todo]
        pct = {k: (v[todo] if isinstance(v, np.ndarray) else v) for k, v in pc.items()}
        x0 = x[todo].copy()
        # a start inside the zone: theta from the current x (finite), s the wheelset's arc length
        kern = reduced_min_kernel()
        if kern is None:  # numpy fallback: the bracketed robust route over the zone
            X, H, conv, info, _ = self._robust(x0, pct, r_ws[ws], A[ws], pct["lo_e"][:, 1], pct["hi_e"][:, 1])
            return X, H, conv, info
        b, f = self._bank, self.track.pp_frame
        X, ok = kern(np.ascontiguousarray(x0), pct["lo_e"][:, 1] + 1e-9, pct["hi_e"][:, 1] - 1e-9,
                     pct["sig"], pct["r0"], pct["L"], pct["ow"], pct["orr"], pct["Y0"], pct["Z0"],
                     pct["ca"], pct["sa"], pct["lo"], pct["hi"], np.ascontiguousarray(r_ws[ws]),
                     np.ascontiguousarray(A[ws]), b._inner, b.breaks, b._stack, f._inner, f.breaks,
                     f._stack, self._maxstep, int(n_sample), 1e-9)
        # outputs at the minimum: one evaluation of the Newton kernel (no step taken)
        X1, H, _, _, gap, S, V = self._kernel(
            np.ascontiguousarray(X), pct["sig"], pct["r0"], pct["L"], pct["ow"], pct["orr"], pct["Y0"],
            pct["Z0"], pct["ca"], pct["sa"], pct["lo"], pct["hi"], np.ascontiguousarray(r_ws[ws]),
            np.ascontiguousarray(A[ws]), b._inner, b.breaks, b._stack, f._inner, f.breaks, f._stack,
            0.0, 1, self._maxstep, self._wts)
        return X, H, ok & np.isfinite(gap), dict(gap=gap, S=S, V=V)

    def _reduced(self, x, pc, rP, AT, iters=12):
        """Solve h1 = h3 = h4 = 0 for (theta, s, u) at the fixed wheel coordinate y = x[:, 1].

        Returns x, h (all four residuals), info (numpy form) and psi: the gap g = d . n of the
        wheel point nearest to the rail, +inf where the rail point left the rail's range or the
        iteration did not converge.  psi(y) is the signed distance of the wheel profile line y
        from the rail, and dpsi/dy = n . t_y = h2 (envelope theorem): the four-condition
        solutions are the stationary points of psi.
        """
        k3 = np.array([0, 2, 3])
        x = x.copy()
        lo, hi = pc["lo"][:, k3], pc["hi"][:, k3]
        ms = self._maxstep[k3]
        for _ in range(iters):
            h, J, info = self._residual_jac(x, pc, rP, AT)
            Js = J[:, k3][:, :, k3]
            with np.errstate(all="ignore"):
                try:
                    dx = -np.linalg.solve(Js, h[:, k3, None])[:, :, 0]
                except np.linalg.LinAlgError:
                    dx = np.zeros((x.shape[0], 3))
                    ok = np.abs(np.linalg.det(Js)) > 1e-300
                    dx[ok] = -np.linalg.solve(Js[ok], h[ok][:, k3, None])[:, :, 0]
            dx = np.where(np.isfinite(dx), dx, 0.0)
            dx *= np.min(np.minimum(1.0, ms / (np.abs(dx) + 1e-300)), axis=1)[:, None]
            x[:, k3] = np.clip(x[:, k3] + dx, lo, hi)
            if np.max(np.abs(dx)) < 1e-13:  # converged (quadratically) to round-off
                break
        if np.max(np.abs(dx)) >= 1e-13:
            h, _, info = self._residual_jac(x, pc, rP, AT)
        g = np.einsum("ij,ij->i", info["d"], info["n"])
        ok = ((np.abs(h[:, 0]) < 1e-9) & (np.abs(h[:, 2]) < 1e-10) & (np.abs(h[:, 3]) < 1e-10)
              & (x[:, 3] > pc["lo_e"][:, 3]) & (x[:, 3] < pc["hi_e"][:, 3]) & np.isfinite(g))
        return x, h, info, np.where(ok, g, np.inf)

    def _robust(self, x0, pc, rP, AP, ylo, yhi, tol=1e-9, n_dense=64, max_shift=6):
        """Robust refinement: the minimum of psi(y) (see :meth:`_reduced`) in a bracket.

        Newton on the four conditions fails where the Jacobian is (nearly) singular or jumps:
        a concave flange root nearly conformal with the rail's gauge corner (S1002 R13 root on
        the UIC60 R13 corner), a stationary point at a joint of profile sections where the
        slope or curvature jumps (the S1002 root/flank joint has a slope step of about 1e-5),
        or the ripples of a spline through coarsely sampled, rounded points (slope noise of
        order 1e-4 where the tread is nearly conformal with the rail crown makes many
        stationary points).  The gap psi(y) of the wheel profile line y is continuous; here
        it is sampled at ``n_dense`` points of the bracket [ylo, yhi] (one vectorised call).
        From the lowest sample Newton on the four conditions is tried once more; where it
        converges between the neighbouring samples to a gap no higher than the sample's, that
        is the result.  Otherwise the minimum is refined by golden-section search (Kiefer
        1953; no derivative needed) between the neighbours of the lowest sample to ``tol``
        (m) on y.  A lowest sample at
        a bracket end that is not a zone end moves the bracket on by its width (at most
        ``max_shift`` times).  At a smooth minimum the result is the four-condition solution
        (h2 = dpsi/dy = 0 to the tolerance); at a slope step it is the minimum distance.

        Returns x, H, conv, info (gap, S, V), passes.
        """
        AT = np.swapaxes(AP, 1, 2)
        P = x0.shape[0]
        zlo, zhi = pc["lo_e"][:, 1], pc["hi_e"][:, 1]
        a_all = np.clip(np.minimum(ylo, yhi), zlo, zhi)
        b_all = np.clip(np.maximum(ylo, yhi), zlo, zhi)
        width = np.maximum(b_all - a_all, 1e-5)
        b_all = np.minimum(a_all + width, zhi)
        x_all = np.array(x0, dtype=float)
        y_all = np.clip(x_all[:, 1], zlo, zhi)
        passes = 0
        moving = np.ones(P, dtype=bool)
        found = np.zeros(P, dtype=bool)
        t = np.linspace(0.0, 1.0, n_dense)

        def sub(d, ix):
            return {key: (v[ix] if isinstance(v, np.ndarray) else v) for key, v in d.items()}

        for _ in range(max_shift + 1):
            idx = np.nonzero(moving)[0]
            k = idx.size
            a0, b0 = a_all[idx], b_all[idx]
            # dense samples: warm start with the rail point moved along with the wheel point
            Y = a0[:, None] + (b0 - a0)[:, None] * t[None, :]  # (k, n)
            Xs = np.repeat(x_all[idx], n_dense, axis=0)
            Xs[:, 3] += Y.ravel() - Xs[:, 1]
            Xs[:, 1] = Y.ravel()
            pcr = {key: (np.repeat(v[idx], n_dense, axis=0) if isinstance(v, np.ndarray) else v)
                   for key, v in pc.items()}
            Xs[:, 3] = np.clip(Xs[:, 3], pcr["lo_e"][:, 3], pcr["hi_e"][:, 3])
            Xs, _, _, G = self._reduced(Xs, pcr, np.repeat(rP[idx], n_dense, axis=0),
                                        np.repeat(AT[idx], n_dense, axis=0))
            passes += 1
            G = G.reshape(k, n_dense)
            Xs = Xs.reshape(k, n_dense, 4)
            ar = np.arange(k)
            im = np.argmin(G, axis=1)
            gm, xm = G[ar, im], Xs[ar, im]
            has = np.isfinite(gm)
            found[idx] = has
            a = Y[ar, np.maximum(im - 1, 0)]
            b = Y[ar, np.minimum(im + 1, n_dense - 1)]
            pci = sub(pc, idx)
            # Newton on the four conditions from the lowest sample: where it converges between
            # the neighbouring samples to a gap no higher than the sample's (a smooth minimum),
            # that is the result
            xn, _, cn, itn, infn = self._newton(xm, pci, rP[idx], AP[idx])
            passes += itn
            gn = infn["gap"] if "gap" in infn else np.einsum("ij,ij->i", infn["d"], infn["n"])
            newton_ok = (has & cn & np.all((xn > pci["lo_e"]) & (xn < pci["hi_e"]), axis=1)
                         & (xn[:, 1] >= a) & (xn[:, 1] <= b) & (gn <= gm + 1e-12))
            yb, xb = np.where(newton_ok, xn[:, 1], xm[:, 1]), np.where(newton_ok[:, None], xn, xm)
            # elsewhere golden section between the neighbours of the lowest sample
            gi = np.nonzero(has & ~newton_ok)[0]
            if gi.size:
                pcg, rg_, Ag = sub(pci, gi), rP[idx][gi], AT[idx][gi]

                def psi(y, xs, pcg=pcg, rg_=rg_, Ag=Ag):
                    xs = xs.copy()
                    xs[:, 1] = y
                    xs, _, _, g = self._reduced(xs, pcg, rg_, Ag)
                    return xs, g

                ag, bg, x_start = a[gi], b[gi], xm[gi]
                gr = 0.5 * (np.sqrt(5.0) - 1.0)
                c = bg - gr * (bg - ag)
                d = ag + gr * (bg - ag)
                xc, fc = psi(c, x_start)
                xd, fd = psi(d, x_start)
                n_gold = max(int(np.ceil(np.log(tol / max(np.max(bg - ag), tol)) / np.log(gr))), 1)
                passes += n_gold + 2
                for _ in range(n_gold):
                    left = fc <= fd  # the minimum lies in [a, d]
                    bg = np.where(left, d, bg)
                    ag = np.where(left, ag, c)
                    d_new = np.where(left, c, ag + gr * (bg - ag))
                    c_new = np.where(left, bg - gr * (bg - ag), d)
                    xe, fe = psi(np.where(left, c_new, d_new), np.where(left[:, None], xc, xd))
                    xc, fc, xd, fd = (np.where(left[:, None], xe, xd), np.where(left, fe, fd),
                                      np.where(left[:, None], xc, xe), np.where(left, fc, fe))
                    c, d = c_new, d_new
                pick = fc <= fd
                better = np.where(pick, fc, fd) <= gm[gi]  # else keep the lowest sample
                yb[gi] = np.where(better, np.where(pick, c, d), yb[gi])
                xb[gi] = np.where(better[:, None], np.where(pick[:, None], xc, xd), xb[gi])
            y_all[idx], x_all[idx] = yb, xb
            # the lowest sample at a bracket end (not a zone end): the minimum lies beyond it
            at_lo = has & (im == 0) & (a0 > zlo[idx] + tol)
            at_hi = has & (im == n_dense - 1) & (b0 < zhi[idx] - tol)
            moving[:] = False
            moving[idx] = at_lo | at_hi
            if not np.any(moving):
                break
            w = width[idx]
            a_all[idx] = np.clip(np.where(at_lo, a0 - w, np.where(at_hi, b0 - 0.1 * w, a0)),
                                 zlo[idx], zhi[idx])
            b_all[idx] = np.clip(np.where(at_hi, b0 + w, np.where(at_lo, a0 + 0.1 * w, b0)),
                                 zlo[idx], zhi[idx])
        x_all[:, 1] = y_all
        x, h, info, g = self._reduced(x_all, pc, rP, AT)
        passes += 1
        conv = np.isfinite(g) & found & ~moving
        return x, h, conv, self._gsv(x, pc, info), passes
