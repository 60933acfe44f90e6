r"""Zone bookkeeping of the contact search: candidates, duplicates, warm starts, multistart.

The problems of one wheelset are (left tread, left flange, right tread, right flange): each
candidate searches its own zone of the wheel profile (the tread and flange zones overlap by
``zone_overlap`` at the split, so a contact there is found) and of the rail (the flange only on
the gauge side).  Duplicates in the overlap are resolved in favour of the zone that holds the
point; a candidate is valid when it converged inside its zone with a plausible gap.  On a
trajectory the warm start is extrapolated linearly from the last two solutions, only candidates
that had a contact are refined, and the global re-seeding runs every ``reseed_every`` calls and
whenever a contact is lost; at a re-seeding the scan seeds (and the warm start) are refined side
by side and the lowest valid gap wins, with a second chance (:meth:`ZoneBookkeeping._rescue`) for
scan seeds that Newton did not solve.
"""

from __future__ import annotations

import numpy as np

from .result import FLANGE, TREAD, ContactResult

__all__ = ["ZoneBookkeeping"]

#: two solutions closer than this on the wheel profile (m) are one stationary point
_SAME_POINT = 1e-4


class ZoneBookkeeping:
    """The zone bookkeeping of :class:`~railway.contact.search.ContactSearch` (a part of it).

    Reads the search's ``wheel``, ``rails``, ``L``, ``max_penetration``, ``reseed_every``,
    ``extrapolate``, ``n_seeds``, ``max_iter_reseed``, its warm-start state (``_x``, ``_x_prev``,
    ``_calls``, ``_valid_prev``, ``_subset_cache``) and the seed scan, Newton solve and robust
    refinement.
    """

    def _build_zones(self, w, zone_overlap, flange_rail_u_max):
        """The four problems of one wheelset (``_unit``); returns the zones' bounds in y (ylo, yhi)."""
        # problems for one wheelset: (left tread, left flange, right tread, right flange)
        sig = np.array([1.0, 1.0, -1.0, -1.0])
        cand = np.array([TREAD, FLANGE, TREAD, FLANGE])
        ylo = np.where(cand == TREAD, w.y_split - zone_overlap, w.y_flange_min)
        yhi = np.where(cand == TREAD, w.x_max, w.y_split + zone_overlap)
        mL, mR = self.rails
        ulo = np.where(sig > 0, mL.u_min, mR.u_min)
        uhi = np.where(sig > 0, mL.u_max, mR.u_max)
        uhi = np.where(cand == FLANGE, np.minimum(uhi, flange_rail_u_max), uhi)
        self._unit = dict(sig=sig, cand=cand, ylo=ylo, yhi=yhi, ulo=ulo, uhi=uhi,
                          ow=np.full(4, self._off_w), orr=np.where(sig > 0, self._off_rl, self._off_rr),
                          Y0=np.where(sig > 0, mL.Y0, mR.Y0), Z0=np.where(sig > 0, mL.Z0, mR.Z0),
                          ca=np.where(sig > 0, mL.ca, mR.ca), sa=np.where(sig > 0, mL.sa, mR.sa))
        return ylo, yhi

    def _tile(self, n_ws):
        P = 4 * n_ws
        pc = {k: np.tile(v, n_ws) for k, v in self._unit.items()}
        pc["ws"] = np.repeat(np.arange(n_ws), 4)
        pc["L"] = np.full(P, self.L)
        pc["r0"] = np.full(P, self.wheel.r0)
        lo = np.stack([np.full(P, -np.inf), pc["ylo"], np.full(P, -np.inf), pc["ulo"]], axis=1)
        hi = np.stack([np.full(P, np.inf), pc["yhi"], np.full(P, np.inf), pc["uhi"]], axis=1)
        pc["lo"], pc["hi"] = lo, hi
        pc["lo_e"], pc["hi_e"] = lo + 1e-12, hi - 1e-12  # strict-inside bounds
        pc["is_flange"] = pc["cand"] == FLANGE
        return pc

    def _rep(self, pc, k):
        """pc with every array repeated k times (cached: the problem sets are fixed)."""
        cache = self.__dict__.setdefault("_rep_cache", {})
        key = (id(pc), k)
        hit = cache.get(key)
        if hit is not None and hit[0] is pc:
            return hit[1]
        out = {key_: (np.concatenate([v] * k) if isinstance(v, np.ndarray) else v)
               for key_, v in pc.items()}
        if len(cache) > 16:
            cache.clear()
        cache[key] = (pc, out)
        return out

    def _finish(self, x, H0, conv, pc, info, iterations):
        """Validity, outputs and per-wheel (tread, flange) arrays."""
        P = x.shape[0]
        gap, S, V = self._outputs(x, pc, info)
        inside = np.all((x > pc["lo_e"]) & (x < pc["hi_e"]), axis=1)
        valid = conv & inside & (gap > -self.max_penetration) & np.isfinite(gap)
        # duplicates in the zone overlap: keep the candidate whose own zone holds the point
        v2, x2 = valid.reshape(-1, 2), x.reshape(-1, 2, 4)
        same = (v2[:, 0] & v2[:, 1] & (np.abs(x2[:, 0, 1] - x2[:, 1, 1]) < 1e-5)
                & (np.abs(x2[:, 0, 3] - x2[:, 1, 3]) < 1e-5))
        if np.any(same):
            in_flange = x2[:, 0, 1] < self.wheel.y_split
            valid &= ~np.stack([same & in_flange, same & ~in_flange], axis=1).reshape(-1)
        nanm = np.where(valid, 1.0, np.nan)
        S = (S * nanm[:, None]).reshape(P // 2, 2, 11)
        V = (V * nanm[:, None, None]).reshape(P // 2, 2, 3, 3)
        gap = np.where(valid, gap, np.inf).reshape(P // 2, 2)
        valid = valid.reshape(P // 2, 2)
        return ContactResult(
            point_wheel=V[:, :, 0], point_rail=V[:, :, 1], normal=V[:, :, 2], gap=gap,
            penetration=-gap, in_contact=valid & (gap <= 0.0), valid=valid,
            theta=S[..., 0], y_wheel=S[..., 1], s_rail=S[..., 2], u_rail=S[..., 3],
            rolling_radius=S[..., 4], contact_angle=S[..., 5], wheel_angle=S[..., 6],
            k_wheel_rolling=S[..., 7], k_wheel_lateral=S[..., 8], k_rail_rolling=S[..., 9],
            k_rail_lateral=S[..., 10], flange=pc["is_flange"].reshape(P // 2, 2),
            residual=np.max(np.abs(H0), axis=1).reshape(P // 2, 2), iterations=iterations)

    def _valid_gap(self, x, conv, info, pc):
        """Validity (converged inside the zones, plausible gap) and gap (inf when invalid)."""
        inside = np.all((x > pc["lo_e"]) & (x < pc["hi_e"]), axis=1)
        g = info["gap"] if "gap" in info else np.einsum("ij,ij->i", info["d"], info["n"])
        ok = conv & inside & (g > -self.max_penetration)
        return ok, np.where(ok, g, np.inf)

    def _gsv(self, x, pc, info):
        """Outputs in the compiled kernel's form dict(gap, S, V) (copies)."""
        if "S" in info:
            return {k: np.array(v, copy=True) for k, v in info.items()}
        gap, S, V = self._outputs(x, pc, info)
        return dict(gap=np.array(gap), S=np.array(S), V=np.array(V))

    def _search(self, r_ws, A, s_ws, pc, warm, scan, store):
        ws = pc["ws"]
        rP, AP = r_ws[ws], A[ws]
        have_warm = warm and self._x is not None and store and self._x.shape[0] == ws.size
        if scan is None:
            scan = (not have_warm) or (self._calls % self.reseed_every == 0)
        self._calls += 1
        if store:
            s_prev, self._s_prev = getattr(self, "_s_prev", s_ws), s_ws.copy()
        if have_warm:
            # predictor: linear extrapolation of the last two solutions (theta, y, u); the rail
            # arc length moves with the wheelset
            x0 = self._x.copy()
            xp = self._x_prev if self.extrapolate else None
            if xp is not None and xp.shape == x0.shape:
                ext = 2.0 * x0 - xp
                ok = np.isfinite(ext)
                x0 = np.where(ok, np.clip(ext, pc["lo"], pc["hi"]), x0)
            x0[:, 2] = self._x[:, 2] + (s_ws - s_prev)[ws]
            bad = ~np.isfinite(x0)
            if np.any(bad):
                x0 = np.where(bad, self._seed_scan(pc, r_ws, A, s_ws), x0)
        if have_warm and not scan:
            # only candidates that had a stationary point last time are refined; the others are
            # picked up by the periodic re-seeding when they come into reach
            act = self._valid_prev
            key = act.tobytes()
            if self._subset_cache.get("key") != key:
                ia = np.nonzero(act)[0]
                self._subset_cache = dict(key=key, ia=ia, wsi=ws[ia], pc={
                    k: (v[ia] if isinstance(v, np.ndarray) else v) for k, v in pc.items()})
            sc = self._subset_cache
            ia, pcs, wsi = sc["ia"], sc["pc"], sc["wsi"]
            xa, Ha, ca, it, infa = self._newton(x0[ia], pcs, r_ws[wsi], A[wsi])
            va, ga = self._valid_gap(xa, ca, infa, pcs)
            if not np.all(va):  # a contact that existed was lost: re-seed those problems
                bad = np.nonzero(~va)[0]
                pcb = {k: (v[bad] if isinstance(v, np.ndarray) else v) for k, v in pcs.items()}
                xs = self._seed_scan(pc, r_ws, A, s_ws)[ia[bad]]
                x2, H2, c2, it2, info2 = self._newton(xs, pcb, r_ws[wsi[bad]], A[wsi[bad]])
                v2, g2 = self._valid_gap(x2, c2, info2, pcb)
                j = bad[v2]
                xa[j], Ha[j], ca[j] = x2[v2], H2[v2], c2[v2]
                for k in infa:
                    infa[k][j] = info2[k][v2]
                it += it2
            if ia.size == ws.size:
                x, H0, conv, info = xa, Ha, ca, infa
            else:
                x, H0, conv = x0.copy(), np.full(x0.shape, np.inf), np.zeros(ws.size, dtype=bool)
                x[ia], H0[ia], conv[ia] = xa, Ha, ca
                info = {}
                for k, v in infa.items():
                    full = np.full((ws.size,) + v.shape[1:], np.nan)
                    full[ia] = v
                    info[k] = full
            res = self._finish(x, H0, conv, pc, info, it)
            if store:
                self._x_prev, self._x = self._x, x
                self._valid_prev = res.valid.ravel()
            return res
        # re-seeding: the two best stationary points of the scan (and the warm start), refined
        # side by side; the lowest valid gap wins
        scan_out = self._seed_scan(pc, r_ws, A, s_ws, brackets=True, ranks=self.n_seeds)
        seeds = [q[:, :4] for q in scan_out]
        if have_warm:
            seeds.insert(0, x0)
        return self._multistart(np.concatenate(seeds), pc, rP, AP, store, 0,
                                max_iter=self.max_iter_reseed if have_warm else None,
                                scan_out=scan_out)

    def _multistart(self, x0, pc, rP, AP, store, it0, max_iter=None, scan_out=None,
                    return_all=False):
        """Newton from several seeds per problem side by side; keep the lowest valid gap.

        With ``scan_out`` (the bracketed scan seeds), scan seeds at a stationary point that
        Newton did not solve are handed to :meth:`_rescue`; its result replaces the Newton
        result where its gap is lower.  With ``return_all`` the Newton solutions of every seed
        (m, P, 4) and their gaps (m, P) (+inf where invalid) are returned as well.
        """
        P = rP.shape[0]
        m = x0.shape[0] // P
        pcm = self._rep(pc, m)
        x, H0, conv, it, info = self._newton(x0, pcm, np.concatenate([rP] * m),
                                             np.concatenate([AP] * m), max_iter=max_iter)
        _, g = self._valid_gap(x, conv, info, pcm)
        g = g.reshape(m, P)
        x_all, g_all = x.reshape(m, P, 4).copy(), g.copy()
        # seeds that Newton did not solve (converged inside the zones; a solved seed may still
        # be invalid by a too deep penetration, which no second attempt changes)
        solved = (conv & np.all((x > pcm["lo_e"]) & (x < pcm["hi_e"]), axis=1)).reshape(m, P)
        if scan_out is not None:
            # a scan seed at a stationary point that Newton could not solve is refined by
            # _rescue, unless a solved seed already gave a lower gap
            fail = np.stack([(q[:, 4] > 0.5) for q in scan_out]) & ~solved[m - len(scan_out):]
            lost = np.any(fail, axis=0)
            scan_out = [np.where(f[:, None], q, np.where(np.arange(q.shape[1]) == 4, 0.0, q))
                        for f, q in zip(fail, scan_out)]
        else:
            lost = ~np.any(solved, axis=0)
        best = np.argmin(g, axis=0)  # first seed (the warm start) wins ties
        sel = best * P + np.arange(P)
        info1 = {k: v[sel] for k, v in info.items()}
        x, H0, conv = x[sel], H0[sel], conv[sel]
        if scan_out is not None and np.any(lost):
            bad = np.nonzero(lost)[0]
            pcb = {k: (v[bad] if isinstance(v, np.ndarray) else v) for k, v in pc.items()}
            x2, H2, c2, info2, it2 = self._rescue(pcb, rP[bad], AP[bad], [q[bad] for q in scan_out],
                                                  newton=max_iter is not None)
            v2, g2 = self._valid_gap(x2, c2, info2, pcb)
            v2 &= g2 < g[best, np.arange(P)][bad]
            if np.any(v2):
                info1 = self._gsv(x, pc, info1)
                j = bad[v2]
                x[j], H0[j], conv[j] = x2[v2], H2[v2], c2[v2]
                for k in info1:
                    info1[k][j] = info2[k][v2]
            it += it2
        res = self._finish(x, H0, conv, pc, info1, it0 + it)
        if store:
            self._x_prev, self._x = None, x
            self._valid_prev = res.valid.ravel()
        if return_all:
            return res, x_all, g_all, x
        return res

    def _rescue(self, pc, rP, AP, scan_out, newton=True):
        """Second chance for scan seeds that Newton did not solve (flag column 4 set).

        Each such seed is solved again with the full iteration count (``newton``: the first
        pass had the shorter re-seeding limit) and, if that fails too, refined by
        :meth:`_robust` in its bracket; the lowest valid gap per problem is returned as
        x, H, conv, info (gap, S, V), passes (gap +inf where nothing was found).
        """
        P = rP.shape[0]
        x = np.array(scan_out[0][:, :4])
        H = np.full((P, 4), np.inf)
        conv = np.zeros(P, dtype=bool)
        info = dict(gap=np.full(P, np.inf), S=np.full((P, 11), np.nan), V=np.full((P, 3, 3), np.nan))
        gbest = np.full(P, np.inf)
        it = 0

        def merge(todo, xn, Hn, cn, infn, gn):
            better = gn < gbest[todo]
            j = todo[better]
            x[j], H[j], conv[j], gbest[j] = xn[better], Hn[better], cn[better], gn[better]
            for k, v in info.items():
                v[j] = infn[k][better]

        for q in scan_out:
            todo = np.nonzero(q[:, 4] > 0.5)[0]
            if todo.size and newton:
                pct = {k: (v[todo] if isinstance(v, np.ndarray) else v) for k, v in pc.items()}
                xn, Hn, cn, itn, infn = self._newton(q[todo, :4], pct, rP[todo], AP[todo])
                it += itn
                _, gn = self._valid_gap(xn, cn, infn, pct)
                merge(todo, xn, Hn, cn, self._gsv(xn, pct, infn), gn)
                solved = cn & np.all((xn > pct["lo_e"]) & (xn < pct["hi_e"]), axis=1)
                todo = todo[~solved]
            if todo.size:
                pct = {k: (v[todo] if isinstance(v, np.ndarray) else v) for k, v in pc.items()}
                xn, Hn, cn, infn, itn = self._robust(q[todo, :4], pct, rP[todo], AP[todo],
                                                     q[todo, 5], q[todo, 6])
                it += itn
                _, gn = self._valid_gap(xn, cn, infn, pct)
                merge(todo, xn, Hn, cn, infn, gn)
        return x, H, conv, info, it

    def _best_pairs(self, x0, problem, r_ws, A, robust, n_sample, secondary):
        """:meth:`~railway.contact.search.ContactSearch.solve_pairs` at checked poses: Newton from
        every (seed, problem) pair, the lowest valid gap per problem, the robust route over the
        zone where asked and nothing was found, the second patches."""
        pc = self._problems
        ws = pc["ws"]
        P = ws.size
        problem = np.asarray(problem, dtype=np.int64)
        x0 = np.asarray(x0, dtype=float).reshape(-1, 4)
        if problem.size:
            pck = {k: (v[problem] if isinstance(v, np.ndarray) else v) for k, v in pc.items()}
            xk, Hk, ck, it, infk = self._newton(x0, pck, r_ws[ws[problem]], A[ws[problem]])
            _, gk = self._valid_gap(xk, ck, infk, pck)
            gsv = self._gsv(xk, pck, infk)
        else:
            xk, Hk, ck, it, gk = x0.copy(), np.zeros((0, 4)), np.zeros(0, bool), 0, np.zeros(0)
            gsv = dict(gap=np.zeros(0), S=np.zeros((0, 11)), V=np.zeros((0, 3, 3)))
        # per problem: the pair with the lowest valid gap (the first one on ties)
        x = np.full((P, 4), np.nan)
        H0 = np.full((P, 4), np.inf)
        conv = np.zeros(P, dtype=bool)
        info = dict(gap=np.full(P, np.inf), S=np.full((P, 11), np.nan), V=np.full((P, 3, 3), np.nan))
        if problem.size:
            order = np.lexsort((np.arange(problem.size), gk, problem))  # problem, gap, pair
            first = order[np.r_[True, problem[order][1:] != problem[order][:-1]]]
            p = problem[first]
            x[p], H0[p], conv[p] = xk[first], Hk[first], ck[first] & np.isfinite(gk[first])
            for key in info:
                info[key][p] = gsv[key][first]
        x = np.where(np.isnan(x), pc["lo"].clip(-1.0, 1.0), x)  # placeholders of problems without pairs
        if robust is not None:
            g_best = np.where(conv, info["gap"], np.inf)
            ok_best = conv & np.all((x > pc["lo_e"]) & (x < pc["hi_e"]), axis=1) & (g_best > -self.max_penetration)
            todo = np.flatnonzero(np.asarray(robust, bool) & ~ok_best)
            if todo.size:
                xr, Hr, cr, infr = self._robust_zone(todo, x, r_ws, A, n_sample)
                x[todo], H0[todo], conv[todo] = xr, Hr, cr
                for key in info:
                    info[key][todo] = infr[key]
        res = self._finish(x, H0, conv, pc, info, it)
        if secondary is not None:
            res.extra["secondary"] = self._secondary(res, problem, xk, Hk, ck, gk, gsv, secondary)
        return res, xk, gk

    def _secondary(self, res, problem, xk, Hk, ck, gk, gsv, separation):
        """A second contact patch per candidate: the lowest *penetrating* pair solution whose wheel
        profile coordinate differs from the primary contact's by more than ``separation`` (m) and
        that is not the other zone's primary contact of the same wheel (closer than 0.1 mm to it);
        a ContactResult like ``res`` (invalid where there is none)."""
        pc = self._problems
        P = pc["ws"].size
        y1 = res.y_wheel.ravel()
        x2 = np.full((P, 4), np.nan)
        H2 = np.full((P, 4), np.inf)
        c2 = np.zeros(P, dtype=bool)
        info2 = dict(gap=np.full(P, np.inf), S=np.full((P, 11), np.nan), V=np.full((P, 3, 3), np.nan))
        if problem.size:
            far = res.valid.ravel()[problem] & (np.abs(xk[:, 1] - y1[problem]) > separation)
            # not the other zone's contact of the same wheel (the zones overlap at the split)
            other = problem ^ 1
            far &= ~(res.valid.ravel()[other] & (np.abs(xk[:, 1] - y1[other]) < _SAME_POINT))
            g = np.where(far & (gk < 0.0), gk, np.inf)
            order = np.lexsort((np.arange(problem.size), g, problem))
            first = order[np.r_[True, problem[order][1:] != problem[order][:-1]]]
            first = first[np.isfinite(g[first])]
            p = problem[first]
            x2[p], H2[p], c2[p] = xk[first], Hk[first], ck[first]
            for key in info2:
                info2[key][p] = gsv[key][first]
        x2 = np.where(np.isnan(x2), pc["lo"].clip(-1.0, 1.0), x2)
        return self._finish(x2, H2, c2, pc, info2, 0)
