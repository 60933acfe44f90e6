"""Vectorised wheel-rail contact search (Pombo & Ambrosio four-condition method).

Equations
---------
For a wheel surface p(theta, y) (surface of revolution, see :mod:`railway.contact.surfaces`) and a rail
surface q(s, u) (profile swept along the track), with d = p - q and the rail outward normal n_r,
candidate contact points satisfy the four conditions of Pombo, Ambrosio & Silva (2007)::

    h1 = n_r . t_theta = 0,   h2 = n_r . t_y = 0      (normals parallel)
    h3 = d . t_s = 0,         h4 = d . t_u = 0        (distance vector along the normal)

for the four surface parameters x = (theta, y, s, u).  The gap is g = d . n_r; the wheel is in
contact where g <= 0, with penetration delta = -g.  n_r points from the rail into the wheel (the
normal force on the wheel acts along +n_r).

Solution strategy
-----------------
* Every wheel has two candidates, tread and flange (zones of the profile coordinate y, see
  :class:`railway.contact.profiles.WheelProfile`), solved as separate problems, so that two-point contact
  (tread plus flange) is found.  A candidate is valid when Newton converged inside its zone.
* Newton's method with the analytic Jacobian of the four conditions (or, optionally, forward
  differences evaluated at the 5 P points x and x + h e_k in one vectorised pass); the P 4x4
  systems are solved in one batched ``np.linalg.solve``.  A step that does not reduce the merit
  ``|W h|^2`` is retried from the last accepted point with a quarter of its length.  Steps are
  limited and the parameters kept inside their zones.
* The tread gap of S1002 on UIC60 1:40 has near-equal local minima, so the contact point jumps
  across the tread.  A coarse scan of each zone in the cross-section (grid uniform in the
  profile's arc length over the whole zone, overlap included; lowest point of each wheel
  circle, rail point of the same tangent angle, sign changes of the fourth condition) gives the
  ``n_seeds`` best stationary points as seeds; Newton runs from them (and from the warm start)
  side by side and the lowest valid gap wins.  On a trajectory (``warm=True``) the warm start is
  extrapolated linearly from the last two solutions, only candidates that had a contact are
  refined, and the global re-seeding runs every ``reseed_every`` calls and whenever a contact is
  lost.
* Where Newton does not solve a scan seed (a stationary point lies near, by a sign change of
  the fourth condition), the seed is refined by a derivative-free minimisation instead
  (:meth:`ContactSearch._robust`): for a fixed wheel profile coordinate y the other three
  conditions (h1, h3, h4) are solved for (theta, s, u) -- a well-conditioned 3x3 Newton, the
  wheel point's projection on the rail -- which gives the gap psi(y) of that profile line, and
  by the envelope theorem dpsi/dy = n . t_y = h2::

      psi(y) = d . n  at  h1 = h3 = h4 = 0,        dpsi/dy = h2

  so the four-condition solutions are the stationary points of psi and the contact is its
  minimum.  psi is sampled densely in the seed's bracket and its minimum refined by Newton or,
  where that fails, golden-section search.  This finds the contact where Newton's 4x4 Jacobian
  is singular or jumps: the S1002 R13 flange root conformal with the UIC60 R13 gauge corner,
  the root/flank joint with its slope step of ~1e-5 (where the rigid contact sits over a band
  of shifts at the flange onset), and the ripples of splines through sampled, rounded profile
  points (a measured profile exported at 0.25 or 0.5 mm).
* A Newton step below ``tol_linear`` is applied without a further pass; the outputs are then
  linearised about the evaluated point (error O(step^2)).
* With numba installed the same iteration, and the seed scan, run in compiled kernels
  (:mod:`railway.contact.search.kernels`); the numpy code is the reference (tests compare both).

Where the code is
-----------------
:class:`ContactSearch` holds the parameters and the public calls and is composed of one part per
concern, each in its own module beside this one: the seed scan (:mod:`.seeds`,
:class:`~railway.contact.search.seeds.SeedScan`), the Newton solve (:mod:`.newton`,
:class:`~railway.contact.search.newton.NewtonSolve`), the robust refinement (:mod:`.robust`,
:class:`~railway.contact.search.robust.RobustRefinement`) and the zone bookkeeping -- candidates,
duplicates, validity, warm starts, multistart (:mod:`.zones`,
:class:`~railway.contact.search.zones.ZoneBookkeeping`).  The parts share the search's attributes
(each lists those it reads); they are not used alone.

References
----------
Pombo, J., Ambrosio, J. and Silva, M. (2007). A new wheel-rail contact model for railway
dynamics. Vehicle System Dynamics 45(2):165-189 (contact detection between the parametric
wheel and rail surfaces; equation numbers were not checked against the paper here).
Kiefer, J. (1953). Sequential minimax search for a maximum. Proc. Amer. Math. Soc.
4(3):502-506 (golden-section search).
"""

from __future__ import annotations

import numpy as np

from core.curves import concatenate
from core.errors import InputError

from ..profiles import WheelProfile
from ...track import RailMounting
from .newton import NewtonSolve
from .pose import wheelset_pose
from .result import ContactResult
from .robust import RobustRefinement
from .seeds import SeedScan
from .zones import ZoneBookkeeping

__all__ = ["ContactSearch", "ContactResult", "wheelset_pose"]


class ContactSearch(SeedScan, NewtonSolve, RobustRefinement, ZoneBookkeeping):
    """Contact search for all wheels of one or more wheelsets on a track.

    Parameters
    ----------
    track : Track
    wheel : WheelProfile, optional
        Default S1002 with r0 = 0.46 m.
    rails : RailMounting or (RailMounting, RailMounting), optional
        Mounted rail profile for both rails, or (left, right).  Default UIC60 1:40, gauge 1.435.
    n_wheelsets : int
    flange_back_spacing : float
        m, default 1.360.
    tol : float
        Newton step tolerance on the parameters (rad and m); the reported point is the last
        evaluated one, so its parameter error is below tol and its gap error of order tol^2 / R.
    compiled : {"auto", True, False}
        Run the Newton iteration in the numba kernel of :mod:`railway.contact.search.kernels` ("auto": when
        numba is installed).  Both implementations solve the same equations; tests compare them.
    tol_linear : float
        A Newton step smaller than this (m or rad) is applied without a further pass; the
        outputs are then linearised about the evaluated point, with errors O(tol_linear^2 / R)
        (1e-6 m gives below 1e-10 m on the gap).  Set it to ``tol`` for full iterations.
    max_iter : int
    reseed_every : int
        On trajectories, run the global tread scan every this many calls (1 = always).
    n_scan : int
        Grid points of the seed scan per zone (uniform in the profile's arc length).
    zone_overlap : float
        Overlap of the tread and flange zones (m) so that a contact at the split is found.
    fd_step : float
        Forward-difference step of the Jacobian (rad or m) when ``jacobian="fd"``.
    jacobian : {"analytic", "fd"}
        Newton Jacobian: analytic (default, see :meth:`_residual_jac`) or forward differences
        (5 P residual evaluations stacked in one vectorised pass).
    n_seeds : int
        Stationary points of the scan refined side by side at a re-seeding (the best by the
        scan's estimate of the gap; 2 by default, more where near-equal minima crowd, e.g. a
        contact-geometry table).
    extrapolate : bool
        Predict the warm start of a trajectory by linear extrapolation of the last two
        solutions (default); False starts from the last solution (for iterations that are not
        a trajectory, e.g. the Newton steps of the rigid contact, where extrapolation across
        a contact jump throws the start far off).
    flange_rail_u_max : float
        The flange candidate searches the rail only on the gauge side, u <= this value (m);
        otherwise the flange tip would pair with the rail crown (parallel normals, but the tip
        is beside the rail, not above it).
    max_penetration : float
        Stationary pairs with a gap below -max_penetration (m) are rejected: they pair a point of
        the flange lying beside the rail head with a rail point of the same normal direction
        (parallel normals, but no physical overlap).  Real penetrations are far smaller.
    """

    def __init__(self, track, wheel=None, rails=None, n_wheelsets=1, flange_back_spacing=1.360,
                 tol=1e-8, max_iter=15, reseed_every=10, n_scan=64, zone_overlap=1e-3,
                 fd_step=1e-7, flange_rail_u_max=-0.020, max_penetration=0.005,
                 jacobian="analytic", tol_linear=1e-6, compiled="auto", extrapolate=True,
                 n_seeds=2):
        self.track = track
        self.wheel = wheel if wheel is not None else WheelProfile.s1002()
        if rails is None:
            rails = RailMounting()
        if isinstance(rails, RailMounting):
            rails = (rails, rails)
        self.rails = tuple(rails)
        if not (isinstance(n_wheelsets, (int, np.integer)) and n_wheelsets >= 1):
            raise InputError(f"n_wheelsets = {n_wheelsets!r} must be a positive integer")
        if not (np.isfinite(flange_back_spacing) and 0.25 <= flange_back_spacing <= 2.0):
            raise InputError(
                f"flange-back spacing {flange_back_spacing!r} m is implausible (expected 0.25 to "
                "2.0 m, e.g. 1.360); it is in metres"
                + (" -- was it given in millimetres?" if flange_back_spacing > 2.0 else ""))
        self.n_wheelsets = int(n_wheelsets)
        self.flange_back_spacing = float(flange_back_spacing)
        self.L = 0.5 * self.flange_back_spacing - self.wheel.y_back
        self.tol, self.max_iter = float(tol), int(max_iter)
        self.reseed_every, self.n_scan = int(reseed_every), int(n_scan)
        self.fd_step = float(fd_step)
        self.max_penetration = float(max_penetration)
        self.max_iter_reseed = 8  # re-seeding with a warm start: seeds beyond reach are dropped
        if jacobian not in ("analytic", "fd"):
            raise InputError(f"jacobian must be 'analytic' or 'fd', got {jacobian!r}")
        self.jacobian = jacobian
        self.tol_linear = float(tol_linear)
        self.extrapolate = bool(extrapolate)
        if not (isinstance(n_seeds, (int, np.integer)) and n_seeds >= 1):
            raise InputError(f"n_seeds = {n_seeds!r} must be a positive integer")
        self.n_seeds = int(n_seeds)
        self._maxstep = np.array([0.02, 0.001, 0.01, 0.001])
        self._wts = np.array([1.0, 1.0, 1e3, 1e3])
        if compiled not in ("auto", True, False):
            raise InputError(f"compiled must be 'auto', True or False, got {compiled!r}")
        self._kernel = None
        self._scan_kernel = None
        if compiled:
            from .kernels import newton_kernel, scan_kernel

            self._kernel = newton_kernel()
            self._scan_kernel = scan_kernel()
            if self._kernel is None and compiled is True:
                raise ImportError("compiled=True needs numba (pip install numba)")
        w = self.wheel
        bank, off = concatenate([w.poly, self.rails[0].profile.poly, self.rails[1].profile.poly])
        self._bank = bank
        self._off_w, self._off_rl, self._off_rr = off
        ylo, yhi = self._build_zones(w, zone_overlap, flange_rail_u_max)
        self._build_scan_tables(w, ylo, yhi, n_scan)
        self._problems = self._tile(self.n_wheelsets)
        self._subset_cache = {}
        self._x = None
        self._x_prev = None
        self._calls = 0

    def _check_pose(self, r_ws, A, s_ws, n_ws):
        if (type(r_ws) is np.ndarray and type(A) is np.ndarray and type(s_ws) is np.ndarray
                and r_ws.dtype == np.float64 and A.dtype == np.float64 and s_ws.dtype == np.float64
                and r_ws.shape == (n_ws, 3) and A.shape == (n_ws, 3, 3) and s_ws.shape == (n_ws,)
                and np.isfinite(r_ws.sum() + A.sum() + s_ws.sum())):
            return r_ws, A, s_ws  # fast path on trajectories (a NaN or inf makes the sum non-finite)
        r_ws = np.asarray(r_ws, dtype=float).reshape(n_ws, 3)
        A = np.asarray(A, dtype=float).reshape(n_ws, 3, 3)
        s_ws = np.asarray(s_ws, dtype=float).reshape(n_ws)
        for name, arr in (("wheelset position", r_ws), ("wheelset rotation", A), ("arc length s", s_ws)):
            bad = ~np.isfinite(arr)
            if np.any(bad):
                idx = np.unravel_index(int(np.argmax(bad)), arr.shape)
                raise InputError(f"contact search: {name}{list(map(int, idx))} = {float(arr[idx])!r} is not finite")
        return r_ws, A, s_ws

    # ------------------------------------------------------------------------------------
    def search(self, r_ws, A, s_ws, warm=True, scan=None):
        """Contact candidates of all wheels for the given wheelset poses.

        Parameters
        ----------
        r_ws : (n_wheelsets, 3) array_like
            Wheelset centres (global, m).
        A : (n_wheelsets, 3, 3) array_like
            Wheelset orientations (columns: forward, axle to the left, up), without spin.
        s_ws : (n_wheelsets,) array_like
            Track arc length near each wheelset (m), used to evaluate the track frame for seeds.
        warm : bool
            Warm-start from the previous call (trajectory mode).
        scan : bool, optional
            Force (True) or suppress (False) the global tread scan; default: scan when there is no
            warm start, every ``reseed_every`` calls, or when a warm start failed.

        Returns
        -------
        ContactResult
        """
        n_ws = self.n_wheelsets
        r_ws, A, s_ws = self._check_pose(r_ws, A, s_ws, n_ws)
        return self._search(r_ws, A, s_ws, self._problems, warm, scan, store=True)

    # ------------------------------------------------------------------------------------
    # stateless interface: for a force element whose search state is frozen between the
    # accepted steps of an integrator (railway.vehicles.wheel_rail), nothing here reads or changes the
    # warm start of :meth:`search`
    def scan_seeds(self, r_ws, A, s_ws, ranks=None):
        """Seeds of the global cross-section scan at the given poses (no state is used or kept).

        Returns a list of ``ranks`` (default ``n_seeds``) arrays (P, 7): the seed (theta, y, s,
        u), a flag (1.0 where a stationary point lies near) and its bracket in y (see
        :meth:`_seed_scan`); P = 4 n_wheelsets problems, ordered wheelset, side, candidate.
        """
        r_ws, A, s_ws = self._check_pose(r_ws, A, s_ws, self.n_wheelsets)
        return self._seed_scan(self._problems, r_ws, A, s_ws, brackets=True,
                               ranks=ranks or self.n_seeds)

    def solve(self, seeds, r_ws, A, s_ws, scan_out=None, max_iter=None):
        """Contacts from explicit seeds, without any state (a pure function of its arguments).

        Newton runs from every seed of every problem side by side; per problem the lowest valid
        gap wins (ties: the first seed).  ``scan_out`` (from :meth:`scan_seeds`, whose seeds
        must be the last ones of ``seeds``) lets seeds that Newton cannot solve be refined by
        the robust route (:meth:`_robust`).

        Parameters
        ----------
        seeds : sequence of (P, 4) arrays
        r_ws, A, s_ws : see :meth:`search`

        Returns
        -------
        res : ContactResult
        x_all : (m, P, 4) ndarray
            Newton solution from every seed (before the robust route).
        g_all : (m, P) ndarray
            Their gaps (m), +inf where invalid.
        x_best : (P, 4) ndarray
            The parameters of ``res``.
        """
        r_ws, A, s_ws = self._check_pose(r_ws, A, s_ws, self.n_wheelsets)
        pc = self._problems
        ws = pc["ws"]
        x0 = np.concatenate([np.asarray(q, dtype=float)[:, :4] for q in seeds])
        return self._multistart(x0, pc, r_ws[ws], A[ws], False, 0, max_iter=max_iter,
                                scan_out=scan_out, return_all=True)

    def solve_pairs(self, x0, problem, r_ws, A, s_ws, robust=None, n_sample=96, secondary=None):
        """Contacts from explicit (seed, problem) pairs, without any state.

        Newton runs from every seed ``x0[k]`` (K, 4) for the problem ``problem[k]`` (an index
        into the P = 4 n_wheelsets problems; a problem may have several seeds or none); per
        problem the lowest valid gap wins (ties: the first pair).  Problems without a pair, or
        whose pairs all fail, have no contact (``valid`` False).  Cheaper than :meth:`solve` on
        trajectories, where only the candidates that had a contact at the last accepted step
        need iterating (no robust refinement here: that is :meth:`solve` with scan seeds).

        ``robust`` (P,) bool: problems that, when no pair gives them a valid contact, are
        refined by the robust minimisation of the profile-line gap over their whole zone
        (:func:`railway.contact.search.kernels.reduced_min`, ``n_sample`` samples then golden-section search):
        a contact at the joint of two profile sections or a nearly conformal one, where Newton
        on the four conditions does not converge.

        ``secondary`` (m): also return, in ``res.extra["secondary"]``, a second contact patch
        per candidate: the lowest penetrating pair solution at least ``secondary`` away on the
        wheel profile from the primary one (two penetrating minima of the gap carry load
        together, so that the force stays continuous where the lowest minimum changes).

        Returns
        -------
        res : ContactResult
        x_pairs : (K, 4) ndarray
            Newton solution of every pair.
        g_pairs : (K,) ndarray
            Their gaps (m), +inf where invalid.
        """
        r_ws, A, s_ws = self._check_pose(r_ws, A, s_ws, self.n_wheelsets)
        return self._best_pairs(x0, problem, r_ws, A, robust, n_sample, secondary)

    def reset(self):
        """Forget the warm start."""
        self._x = None
        self._x_prev = None
        self._calls = 0
