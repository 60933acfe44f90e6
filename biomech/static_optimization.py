r"""Static optimisation: muscle forces that produce the measured generalized forces, frame by frame.

Per frame, with n muscles, m coordinates and a rigid tendon (:mod:`biomech.muscles`), the tendon
force of muscle j is linear in its activation, :math:`F_j = A_j a_j + P_j`, and the generalized
forces must be produced by the muscles and the reserve actuators::

    R (A ∘ a + P) + G u = tau          (m equations; "moment equations")
    a_lo <= a <= a_hi                   (activations, [0, 1] by default)
    u_lo <= u <= u_hi                   (reserve controls, unbounded by default)

R (m x n) holds the moment arm of muscle j about coordinate i [m, or dimensionless for a
translational coordinate], A [N per unit activation] and P [N] the active capacity and the passive
force along the tendon, tau [N m, or N] the generalized forces from inverse dynamics.  A reserve
actuator on coordinate i has optimal force r_i [N m or N] and control u_i: it adds r_i u_i to
equation i, i.e. G = [r_i e_i] over the coordinates that have one.

Criteria (p >= 1)::

    "activation"  J = sum_j a_j^p                   + w sum_i |u_i|^p   (OpenSim, p = 2)
    "stress"      J = sum_j (F_j / (σ PCSA_j))^p    + w sum_i |u_i|^p   (Crowninshield & Brand, p = 3)

with PCSA_j = F0_j / σ unless anatomical PCSAs are given, so that by default the stress term is
sum_j (F_j / F0_j)^p.

*Reserves follow OpenSim's rule.*  OpenSim's ``StaticOptimizationTarget`` minimises
:math:`\sum |x_k|^p` over *all* actuators, where x_k is a muscle's activation or another
actuator's control, and the actuator's force is x_k times its optimal force.  A reserve that
must deliver a generalized force f therefore costs :math:`|f / r_i|^p`: a reserve with a small
optimal force is expensive (with r = 1 N m and p = 2, 10 N m of reserve costs 100, as much as
100 fully active muscles).  This module uses the same rule, with the same exponent p, and an
optional extra weight w (default 1, i.e. exactly OpenSim's rule).

*The stress criterion, normalised.*  Crowninshield & Brand minimise :math:`\sum (F_j/PCSA_j)^3`.
With the specific tension σ (31.39 N/cm² = 3.2 kgf/cm², the value of Ambrósio's group) and
PCSA_j = F0_j / σ, :math:`(F_j/PCSA_j)^3 = σ^3 (F_j/F0_j)^3`: the minimiser does not depend on σ,
and the O(1) quantity :math:`s_j = F_j/(σ PCSA_j)`, the stress as a fraction of σ, is what this
module minimises (σ³ times smaller than the stress cubed in N/cm², which is badly scaled).  When
anatomical PCSAs are given instead, :math:`s_j = F_j / (σ PCSA_j)`; σ then only sets the exchange
rate between muscle stress and reserve controls.  The muscle force includes the passive force P
(s = c ∘ a + d with c = A/(σ PCSA), d = P/(σ PCSA)); OpenSim's static optimisation leaves the
passive force out of its constraints altogether (opensim-core #3910), here it is carried as a
known force.

Cone programme
--------------
The problem is built once per model as one cvxpy problem with parameters (DPP), so every later
frame only changes parameter values and reuses the compiled problem data:

* ``B = R diag(A)`` is one parameter (m x n) and ``b = tau - R P`` one parameter (m): the
  equality is ``B a + G u == b`` with no parameter x parameter product;
* the stress criterion adds parameters c, d >= 0 (n) with s = c ∘ a + d;
* a power term :math:`\sum x^p` with p = 2 and x a variable is ``sum_squares`` (Clarabel takes
  the quadratic objective natively); p = 1 is a sum (``norm1`` for the signed reserves); every other
  case is, by default (``epigraph="soc"``), ``cp.power(s, p)``, which cvxpy rewrites into
  second-order cones (exact for p = 3; the project notes had found it 'optimal_inaccurate' on some
  frames with 43 and 92 muscles, but on the gait trials it ended 'optimal' on every feasible frame,
  README), or, with ``epigraph="power_cone"``, the epigraph :math:`t_k \ge |x_k|^p` as Clarabel's
  native 3-D power cone ``PowCone3D(t, 1, x, 1/p)`` (:math:`t^{1/p} 1^{1 - 1/p} \ge |x|`),
  objective :math:`\sum t_k` (it left one gait2392 frame as a solver error after the retries).  On the synthetic frames of this project's tests and benchmark
  both forms end 'optimal' on (nearly) every frame at the first attempt, each occasionally needing
  a retry; the SOC form meets the moment equations more tightly (residual ~1e-12 against ~1e-9 N m).
  On the real trials the SOC form is the more robust one, so it is the default: gait2392 (92
  muscles, 74 frames of the right gait cycle, sum s^3) ends 'optimal' on all 74 frames with SOC and
  on 73 with power cones (one solver error left after the retries); gait10dof18musc on all 74 with
  either.

Accuracy.  Clarabel stops when the duality gap is below 1e-8 in absolute terms or relative to
max(1, ``|J|``), so for J < 1 the test is absolute.  For a criterion with curvature m along the
feasible set the activations are then accurate to about sqrt(2e-8 / m): ~1e-7 for the QP of
sum a^2, ~1e-5 to 1e-4 for sum s^3 (curvature 6 c^2 s), less (in relative terms) on frames of
very low effort.  Tighter ``solver_options`` (``tol_gap_abs``, ``tol_gap_rel``, ``tol_feas``)
buy more digits.  (OpenSim's own optimiser stops at a convergence criterion of 1e-4.)

Solved by Clarabel (interior point).  Interior-point runs on power cones occasionally stall
("InsufficientProgress", raised by cvxpy as a solver error) or stop at the reduced tolerances;
such a frame is solved again with the settings of ``retry_options`` (a shorter maximum step
fraction first), and the retries are listed in its ``message``.  Frames are independent; a frame
that fails does not stop the trial:

* ``"optimal"``: solved to Clarabel's tolerances;
* ``"optimal_inaccurate"``: Clarabel's reduced tolerances only; the solution is kept and flagged;
* ``"infeasible"`` (or ``"infeasible_inaccurate"``): the muscles (with the reserves and their
  bounds) cannot produce tau.  The frame then carries the activations of the *least-deficit*
  problem, :math:`\min \|B a + G u - b\|_2^2 + 10^{-6}\sum a^2` within the same bounds, so that
  its residual shows which coordinate lacks capacity and by how much;
* ``"solver_error"``: Clarabel failed; NaN solution;
* ``"invalid_input"``: a non-finite or negative input in that frame (named in ``message``); NaN.

The residual max ``|R F + G u - tau|`` is reported for every frame in the units of the coordinates.

References
----------
.. [1] R. D. Crowninshield, R. A. Brand, "A physiologically based criterion of muscle force
   prediction in locomotion", J. Biomech. 14 (1981) 793-801 (criterion sum (f_i / A_i)^n, n = 3,
   with A_i the PCSA).
.. [2] F. C. Anderson, M. G. Pandy, "Static and dynamic optimization solutions for gait are
   practically equivalent", J. Biomech. Eng. 123 (2001) 381-390 (static optimisation of gait:
   sum of squared activations subject to the joint-moment equations).
.. [3] M. P. T. Silva, J. A. C. Ambrósio, "Solution of redundant muscle forces in human locomotion
   with multibody dynamics and optimization tools", Mech. Based Des. Struct. Mach. 31 (2003)
   381-411 (sigma = 31.39 N/cm^2).
.. [4] opensim-core, ``OpenSim/Analyses/StaticOptimizationTarget.cpp`` (objective sum ``|x|^p`` over all
   actuators, optimal force of a muscle from ``calcInextensibleTendonActiveFiberForce(s, 1.0)``).
.. [5] A. Agrawal, B. Amos, S. Barratt, S. Boyd, S. Diamond, J. Z. Kolter, "Differentiable convex
   optimization layers", NeurIPS 2019 (disciplined parametrized programming, DPP);
   P. J. Goulart, Y. Chen, "Clarabel: an interior-point solver for conic programs with quadratic
   objectives", arXiv:2405.12762 (2024).
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from core.errors import InputError, ModelError, UnknownOptionError

from .checks import checked_options, name_hint

__all__ = [
    "SPECIFIC_TENSION",
    "DEFAULT_RETRY_OPTIONS",
    "CRITERIA",
    "FrameSolution",
    "StaticOptimization",
]

#: Specific tension σ = 31.39 N/cm² = 3.2 kgf/cm² in Pa (Silva & Ambrósio 2003 after
#: Crowninshield & Brand 1981).
SPECIFIC_TENSION = 31.39e4

#: Criterion name -> default exponent p.
CRITERIA = {"activation": 2.0, "stress": 3.0}

#: Clarabel settings tried, in turn, when a frame ends with a solver failure or an inaccurate
#: status (interior-point runs with power cones occasionally stall with InsufficientProgress;
#: a shorter maximum step fraction has rescued every such frame met in the tests).
DEFAULT_RETRY_OPTIONS = ({"max_step_fraction": 0.9}, {"max_step_fraction": 0.8, "static_regularization_constant": 1e-7})

_SOLUTION_STATUSES = ("optimal", "optimal_inaccurate")
_INFEASIBLE_STATUSES = ("infeasible", "infeasible_inaccurate")


def _rank(status: str) -> int:
    """2: a definite answer, 1: an inaccurate one, 0: none."""
    if status in ("optimal", "infeasible", "unbounded"):
        return 2
    if status in ("optimal_inaccurate", "infeasible_inaccurate", "unbounded_inaccurate"):
        return 1
    return 0


@dataclass
class _Attempt:
    status: str
    message: str
    solver_time: float
    iterations: int
    activations: np.ndarray | None
    reserve_controls: np.ndarray | None


class _ClarabelData:
    """Clarabel's problem data as a fixed-pattern linear map of the parameters.

    cvxpy canonicalises the DPP problem once into a tensor T with [A | b] = T p (p the vector of
    parameter values plus a one); ``problem.solve`` then rebuilds scipy sparse matrices from it and
    reformats them for every frame, which costs ten times Clarabel's own solve on the 18-muscle
    model.  Here the same tensor of cvxpy (``ParamConeProg.reduced_A``, kept with its explicit
    zeros so the sparsity pattern is fixed) is applied as one sparse matrix-vector product per
    frame and its values are written into the fixed pattern: Clarabel's A = -T_A p, b = T_b p (the
    signs of cvxpy's Clarabel interface), cones from cvxpy's cone dimensions, P and q constant (the
    criterion has no parameter in its objective; checked on the first two frames).  The map is
    verified against ``problem.get_problem_data`` on the first two frames, and a frame whose status
    is not 'optimal' is solved again by ``problem.solve`` (with the retries), so the reported
    solution always comes from one of the two equal routes.
    """

    def __init__(self, problem, cp, variables):
        from cvxpy.cvxcore.python import canonInterface
        from cvxpy.reductions.solvers.conic_solvers.clarabel_conif import CLARABEL, dims_to_solver_cones

        self._ci, self._clarabel_if = canonInterface, CLARABEL
        data, _, _ = problem.get_problem_data(cp.CLARABEL, enforce_dpp=True)
        pp = data[cp.settings.PARAM_PROB]
        self.pp = pp
        ra = pp.reduced_A
        ra.cache(keep_zeros=True)
        self.T = ra.reduced_mat.tocsr()
        indices, indptr, shape = ra.problem_data_index
        self.nA = int(indptr[-2])
        self.A_indices = np.asarray(indices[: self.nA])
        self.A_indptr = np.asarray(indptr[:-1])
        self.A_shape = (int(shape[0]), int(shape[1]) - 1)
        self.b_rows = np.asarray(indices[self.nA:])
        self.P = data["P"] if "P" in data else None
        self.q = np.asarray(data["c"], float)
        self.cones = dims_to_solver_cones(data["dims"])
        self.cols = [(pp.var_id_to_col[v.id], v.size) for v in variables]
        self.solver = None
        self._settings_key = None
        self._P_triu = None
        self.verified = 0
        self.ok = self._matches(data)

    def _param_vec(self):
        pp = self.pp
        return self._ci.get_parameter_vector(pp.total_param_size, pp.param_id_to_col, pp.param_id_to_size,
                                             lambda i: np.asarray(pp.id_to_param[i].value))

    def param_vec(self, values: dict):
        """The parameter vector p from values given directly (parameter -> array), laid out as
        cvxpy's ``get_parameter_vector`` lays out the parameters' own values (column-major, the
        constant 1 at its column): no cvxpy value checks on the per-frame path."""
        pp = self.pp
        p = np.zeros(pp.total_param_size + 1)
        for pid, col in pp.param_id_to_col.items():
            if pid == self._ci.lo.CONSTANT_ID:
                p[col] = 1.0
            else:
                p[col:col + pp.param_id_to_size[pid]] = np.asarray(values[pp.id_to_param[pid]], float).ravel(order="F")
        return p

    def data(self, p=None):
        import scipy.sparse as sp

        flat = self.T @ (self._param_vec() if p is None else p)
        A = sp.csc_array((-flat[: self.nA], self.A_indices, self.A_indptr), shape=self.A_shape)
        b = np.zeros(self.A_shape[0])
        b[self.b_rows] = flat[self.nA:]
        return A, b

    def _matches(self, data):
        A, b = self.data()
        ok = (A.shape == data["A"].shape and abs(A - data["A"]).max() <= 1e-12 * max(1.0, abs(data["A"]).max())
              and np.allclose(b, data["b"], rtol=1e-12, atol=1e-12))
        return bool(ok)

    def verify(self, problem, cp):
        """Compare the map with cvxpy's data at the current parameters (first frames)."""
        data, _, _ = problem.get_problem_data(cp.CLARABEL, enforce_dpp=True)
        same_obj = np.array_equal(np.asarray(data["c"], float), self.q) and (
            (self.P is None and "P" not in data) or (self.P is not None and abs(data["P"] - self.P).max() == 0))
        self.ok = self.ok and same_obj and self._matches(data)
        self.verified += 1
        return self.ok

    def solve(self, options, p=None):
        """(status, solver time, iterations, [variable values]) with cvxpy's status names; ``p``
        the parameter vector (:meth:`param_vec`), default from the parameters' values.

        The solver is built once; later frames with the same options pass Clarabel only the new
        values of A's fixed pattern and b (``update(A=values, b=b)``, Clarabel's data update)."""
        import clarabel
        import scipy.sparse as sp

        flat = self.T @ (self._param_vec() if p is None else p)
        b = np.zeros(self.A_shape[0])
        b[self.b_rows] = flat[self.nA:]
        key = tuple(sorted(options.items()))
        if self.solver is None or key != self._settings_key or not self.solver.is_data_update_allowed():
            A = sp.csc_array((-flat[: self.nA], self.A_indices, self.A_indptr), shape=self.A_shape)
            n = self.A_shape[1]
            if self._P_triu is None:
                self._P_triu = sp.triu(self.P if self.P is not None else sp.csc_array((n, n))).tocsc()
            settings = self._clarabel_if.parse_solver_opts(False, options)
            self.solver = clarabel.DefaultSolver(self._P_triu, self.q, A, b, self.cones, settings)
            self._settings_key = key
        else:
            self.solver.update(A=-flat[: self.nA], b=b)
        sol = self.solver.solve()
        status = self._clarabel_if.STATUS_MAP.get(str(sol.status), "solver_error")
        x = np.asarray(sol.x, float)
        values = [x[c:c + k] for c, k in self.cols]
        return str(status), float(sol.solve_time), int(sol.iterations), values


@dataclass
class FrameSolution:
    """Solution of one frame.

    Attributes
    ----------
    activations : ndarray, shape (n_muscles,)
        a [-] (NaN when the frame has no solution).
    forces : ndarray, shape (n_muscles,)
        Tendon forces F = A a + P [N].
    reserve_controls : ndarray, shape (n_reserves,)
        u [-].
    reserve_forces : ndarray, shape (n_reserves,)
        r u [N m or N], in the units of their coordinates.
    residual : ndarray, shape (n_coordinates,)
        R F + G u - tau [N m or N].
    status : str
        ``"optimal"``, ``"optimal_inaccurate"``, ``"infeasible"``, ``"infeasible_inaccurate"``,
        ``"unbounded"``, ``"solver_error"`` or ``"invalid_input"`` (module docstring).
    message : str
        Explanation for a status other than ``"optimal"`` (empty otherwise).
    objective : float
        The criterion J at the solution [-] (NaN without solution; for infeasible frames the
        least-deficit solution's J).
    solve_time : float
        Wall time of the frame [s], including cvxpy's parameter update and Clarabel.
    solver_time : float
        Clarabel's own time [s] (setup and solve).
    iterations : int
        Clarabel's interior-point iterations (-1 if unknown).
    """

    activations: np.ndarray
    forces: np.ndarray
    reserve_controls: np.ndarray
    reserve_forces: np.ndarray
    residual: np.ndarray
    status: str
    message: str
    objective: float
    solve_time: float
    solver_time: float
    iterations: int

    @property
    def max_residual(self) -> float:
        """max ``|R F + G u - tau|`` [N m or N] (NaN without solution)."""
        return float(np.max(np.abs(self.residual))) if np.all(np.isfinite(self.residual)) else math.nan


def _power_sum(x, p: float, n: int, nonneg: bool, is_variable: bool, epigraph: str, cp):
    """Return (expression of sum |x|^p, extra constraints), as described in the module docstring."""
    if p == 1.0:
        return (cp.sum(x) if nonneg else cp.norm1(x)), []
    if p == 2.0 and is_variable:
        return cp.sum_squares(x), []
    t = cp.Variable(n, nonneg=True)
    if epigraph == "soc":
        return cp.sum(t), [cp.power(x if nonneg else cp.abs(x), p) <= t]
    return cp.sum(t), [cp.PowCone3D(t, np.ones(n), x, 1.0 / p)]


class StaticOptimization:
    r"""Static-optimisation problem of one model, built once, solved per frame (module docstring).

    Parameters
    ----------
    muscle_names : sequence of str, length n_muscles
        Names of the muscles (columns of R).
    coordinate_names : sequence of str, length n_coordinates
        Names of the coordinates (rows of R).
    max_isometric_force : array_like, shape (n_muscles,)
        F0 [N] (used by the stress criterion).
    criterion : {"activation", "stress"}
        ``"activation"``: sum a^p (OpenSim); ``"stress"``: sum (F/(σ PCSA))^p (Crowninshield & Brand).
    exponent : float, optional
        p >= 1; default 2 for ``"activation"``, 3 for ``"stress"``.
    pcsa : array_like, shape (n_muscles,), optional
        Physiological cross-sectional areas [m²] for the stress criterion; default F0/σ.
    specific_tension : float
        σ [Pa], default :data:`SPECIFIC_TENSION` (31.39 N/cm²).
    reserve_optimal_force : float or array_like, shape (n_coordinates,), optional
        Optimal force r_i of a reserve actuator on each coordinate [N m or N]; 0 means no reserve
        on that coordinate; a scalar applies to all; None (default): no reserves.
    reserve_bounds : (lower, upper), optional
        Bounds on the reserve controls, scalars or arrays of shape (n_coordinates,); ±inf for none.
        Default unbounded (OpenSim's CoordinateActuator default).
    reserve_weight : float
        w > 0 multiplying the reserves' sum ``|u|^p`` (1 reproduces OpenSim).
    activation_bounds : (lower, upper)
        Activation bounds, scalars or arrays of shape (n_muscles,), 0 <= lower < upper <= 1;
        default (0, 1).  (OpenSim's Thelen muscles use a minimum activation of 0.01.)
    coordinate_units : sequence of str, optional
        Unit of each coordinate's generalized force for the column names, ``"N m"`` (default) or
        ``"N"``.
    solver_options : dict, optional
        Clarabel settings (e.g. ``tol_feas``), passed through cvxpy.
    epigraph : {"power_cone", "soc"}
        How sum ``|x|^p`` is written when it is neither a plain sum nor a sum of squares of a variable:
        ``"soc"`` (default), cvxpy's ``power`` atom (second-order cones; exact for integer p such
        as 3); ``"power_cone"``, the epigraph t >= ``|x|^p`` as Clarabel's native 3-D power cones.
    fast_path : bool
        Solve each frame's first attempt through cvxpy's parameter tensor applied directly
        (:class:`_ClarabelData`: one sparse product per frame instead of rebuilding the solver's
        matrices; verified against ``problem.get_problem_data`` on the first two frames; a frame
        that does not end 'optimal' is solved again by ``problem.solve``).  ``False`` uses
        ``problem.solve`` for every frame (the constraints' ``dual_value`` are then set).
    retry_options : sequence of dict
        Clarabel settings tried in turn when a frame ends with a solver failure or an inaccurate
        status (default :data:`DEFAULT_RETRY_OPTIONS`); each retry is listed in the frame's
        ``message``.  ``()`` disables retries.

    Attributes
    ----------
    problem : cvxpy.Problem
        The parametrised problem (DPP; ``problem.is_dpp()`` is True).
    constraints : dict of str -> cvxpy.Constraint
        ``"moment_equations"`` (``B a + G u == b``; dual ν, shape (n_coordinates,)),
        ``"activation_lower"`` (``a >= a_lo``) and ``"activation_upper"`` (``a <= a_hi``) (duals
        shape (n_muscles,), >= 0), and, when bounded, ``"reserve_lower"`` / ``"reserve_upper"`` on
        ``u[reserve_lower_index]`` / ``u[reserve_upper_index]``.  cvxpy's convention: the Lagrangian is
        J + ν·(B a + G u - b) + μ_lo·(a_lo - a) + μ_hi·(a - a_hi) + ...
    reserve_coordinates : tuple of str
        Coordinates that have a reserve, in the order of u.

    Examples
    --------
    >>> import numpy as np
    >>> from biomech.muscles import ThelenMuscleSet
    >>> mus = ThelenMuscleSet(["flexor", "extensor", "biarticular"], [1500.0, 2000.0, 800.0],
    ...                       [0.08, 0.1, 0.12], [0.2, 0.25, 0.3], 0.1)
    >>> so = StaticOptimization.from_muscles(mus, ["knee"], criterion="stress", reserve_optimal_force=1.0)
    >>> f = mus.rigid_tendon_forces(mus.tendon_slack_length + mus.optimal_fiber_length, np.zeros(3))
    >>> sol = so.solve_frame([[0.04, -0.05, 0.03]], f.active_force_per_activation, f.passive_force, [20.0])
    >>> sol.status, bool(sol.max_residual < 1e-6)
    ('optimal', True)
    """

    @checked_options
    def __init__(self, muscle_names: Sequence[str], coordinate_names: Sequence[str], max_isometric_force, *,
                 criterion: str = "activation", exponent: float | None = None, pcsa=None,
                 specific_tension: float = SPECIFIC_TENSION, reserve_optimal_force=None, reserve_bounds=None,
                 reserve_weight: float = 1.0, activation_bounds=(0.0, 1.0),
                 coordinate_units: Sequence[str] | None = None, solver_options: dict | None = None,
                 epigraph: str = "soc", retry_options: Sequence[dict] = DEFAULT_RETRY_OPTIONS,
                 fast_path: bool = True):
        import clarabel
        import cvxpy as cp  # cvxpy is imported only inside biomech (DESIGN.md)

        self._cp = cp
        self.muscle_names = tuple(str(s) for s in muscle_names)
        self.coordinate_names = tuple(str(s) for s in coordinate_names)
        n, m = len(self.muscle_names), len(self.coordinate_names)
        if n == 0 or m == 0:
            raise ModelError(f"StaticOptimization: need at least one muscle and one coordinate, got {n} and {m}")
        for label, names in (("muscle", self.muscle_names), ("coordinate", self.coordinate_names)):
            if len(set(names)) != len(names):
                dup = next(s for s in names if names.count(s) > 1)
                raise ModelError(f"StaticOptimization: duplicate {label} name {dup!r}")
        self.n_muscles, self.n_coordinates = n, m

        f0 = self._vector(max_isometric_force, n, "max_isometric_force", self.muscle_names)
        if np.any(~(f0 > 0)):
            j = int(np.flatnonzero(~(f0 > 0))[0])
            raise ModelError(f"muscle {self.muscle_names[j]!r}: max_isometric_force = {f0[j]} must be > 0")
        self.max_isometric_force = f0

        if criterion not in CRITERIA:
            raise UnknownOptionError(f"criterion {criterion!r} is not one of {sorted(CRITERIA)}"
                                     f"{name_hint(str(criterion), sorted(CRITERIA))}")
        self.criterion = criterion
        p = CRITERIA[criterion] if exponent is None else float(exponent)
        if not (math.isfinite(p) and p >= 1.0):
            raise InputError(f"exponent p = {exponent!r} must be a finite number >= 1 (convex criterion)")
        self.exponent = p

        sigma = float(specific_tension)
        if not (math.isfinite(sigma) and sigma > 0):
            raise InputError(f"specific_tension = {specific_tension!r} Pa must be finite and > 0")
        self.specific_tension = sigma
        if pcsa is None:
            self.pcsa = f0 / sigma
        else:
            self.pcsa = self._vector(pcsa, n, "pcsa", self.muscle_names)
            if np.any(~(self.pcsa > 0)):
                j = int(np.flatnonzero(~(self.pcsa > 0))[0])
                raise ModelError(f"muscle {self.muscle_names[j]!r}: pcsa = {self.pcsa[j]} m² must be > 0")
        #: σ PCSA [N]: the force that makes the normalised stress s = 1 (= F0 when pcsa is None).
        self.stress_force_scale = sigma * self.pcsa

        lo, hi = activation_bounds
        self.activation_lower = self._vector(lo, n, "activation_bounds[0]", self.muscle_names)
        self.activation_upper = self._vector(hi, n, "activation_bounds[1]", self.muscle_names)
        bad = ~((self.activation_lower >= 0) & (self.activation_lower < self.activation_upper)
                & (self.activation_upper <= 1))
        if np.any(bad):
            j = int(np.flatnonzero(bad)[0])
            raise ModelError(f"muscle {self.muscle_names[j]!r}: activation bounds ({self.activation_lower[j]}, "
                             f"{self.activation_upper[j]}) must satisfy 0 <= lower < upper <= 1")

        # Reserves.
        if reserve_optimal_force is None:
            r_opt = np.zeros(m)
        else:
            r_opt = self._vector(reserve_optimal_force, m, "reserve_optimal_force", self.coordinate_names)
            if np.any(r_opt < 0):
                i = int(np.flatnonzero(r_opt < 0)[0])
                raise ModelError(f"coordinate {self.coordinate_names[i]!r}: reserve optimal force {r_opt[i]} must be "
                                 ">= 0 (0: no reserve)")
        has = np.flatnonzero(r_opt > 0)
        self.reserve_index = has
        self.reserve_coordinates = tuple(self.coordinate_names[i] for i in has)
        self.reserve_optimal_force = r_opt[has]
        n_r = len(has)
        self.n_reserves = n_r
        self.G = np.zeros((m, n_r))
        self.G[has, np.arange(n_r)] = self.reserve_optimal_force
        if reserve_bounds is None:
            u_lo, u_hi = np.full(n_r, -np.inf), np.full(n_r, np.inf)
        else:
            ulo, uhi = reserve_bounds
            u_lo = self._vector(ulo, m, "reserve_bounds[0]", self.coordinate_names, allow_inf=True)[has]
            u_hi = self._vector(uhi, m, "reserve_bounds[1]", self.coordinate_names, allow_inf=True)[has]
            if np.any(~(u_lo < u_hi)) or np.any(u_lo == np.inf) or np.any(u_hi == -np.inf):
                i = int(np.flatnonzero(~(u_lo < u_hi) | (u_lo == np.inf) | (u_hi == -np.inf))[0])
                raise ModelError(f"coordinate {self.reserve_coordinates[i]!r}: reserve bounds ({u_lo[i]}, {u_hi[i]}) "
                                 "need lower < upper")
        self.reserve_lower, self.reserve_upper = u_lo, u_hi
        w = float(reserve_weight)
        if not (math.isfinite(w) and w > 0):
            raise InputError(f"reserve_weight = {reserve_weight!r} must be finite and > 0")
        self.reserve_weight = w

        units = ["N m"] * m if coordinate_units is None else [str(u) for u in coordinate_units]
        if len(units) != m:
            raise InputError(f"coordinate_units: need {m} units (one per coordinate), got {len(units)}")
        self.coordinate_units = tuple(units)

        if epigraph not in ("power_cone", "soc"):
            raise UnknownOptionError(f"epigraph {epigraph!r} is not one of ['power_cone', 'soc']"
                                     f"{name_hint(str(epigraph), ['power_cone', 'soc'])}")
        self.epigraph = epigraph
        self.solver_options = dict(solver_options or {})
        self.retry_options = tuple(dict(r) for r in retry_options)
        # Clarabel settings that a retry changes are passed explicitly on every solve: cvxpy reuses
        # the Clarabel solver object between solves and would otherwise keep a retry's setting.
        defaults = clarabel.DefaultSettings()
        self._base_options = {key: getattr(defaults, key) for r in self.retry_options for key in r}
        self._base_options.update(self.solver_options)
        self._build(cp)
        self._fast_enabled = bool(fast_path)
        self._fast = None

    # ------------------------------------------------------------------------------------------
    @staticmethod
    def _vector(value, size: int, label: str, names, allow_inf: bool = False) -> np.ndarray:
        arr = np.asarray(value, float)
        if arr.ndim == 0:
            arr = np.full(size, float(arr))
        if arr.shape != (size,):
            raise InputError(f"{label} must be a scalar or have shape ({size},), got shape {arr.shape}")
        bad = np.isnan(arr) if allow_inf else ~np.isfinite(arr)
        if np.any(bad):
            j = int(np.flatnonzero(bad)[0])
            raise InputError(f"{label}: non-finite value {arr[j]} for {names[j]!r}")
        return arr.copy()

    def _build(self, cp) -> None:
        n, m, n_r, p = self.n_muscles, self.n_coordinates, self.n_reserves, self.exponent
        self._B = cp.Parameter((m, n), name="B")
        self._b = cp.Parameter(m, name="b")
        self._a = cp.Variable(n, name="a")
        self._u = cp.Variable(n_r, name="u") if n_r else None
        eq_lhs = self._B @ self._a
        if n_r:
            eq_lhs = eq_lhs + self.G @ self._u
        cons = {
            "moment_equations": eq_lhs == self._b,
            "activation_lower": self._a >= self.activation_lower,
            "activation_upper": self._a <= self.activation_upper,
        }
        self.reserve_lower_index = np.flatnonzero(np.isfinite(self.reserve_lower))
        self.reserve_upper_index = np.flatnonzero(np.isfinite(self.reserve_upper))
        if n_r and self.reserve_lower_index.size:
            cons["reserve_lower"] = self._u[self.reserve_lower_index] >= self.reserve_lower[self.reserve_lower_index]
        if n_r and self.reserve_upper_index.size:
            cons["reserve_upper"] = self._u[self.reserve_upper_index] <= self.reserve_upper[self.reserve_upper_index]

        extra = []
        if self.criterion == "activation":
            self._c = self._d = None
            muscle_term, more = _power_sum(self._a, p, n, True, True, self.epigraph, cp)
        else:
            self._c = cp.Parameter(n, nonneg=True, name="c")
            self._d = cp.Parameter(n, nonneg=True, name="d")
            stress = cp.multiply(self._c, self._a) + self._d
            muscle_term, more = _power_sum(stress, p, n, True, False, self.epigraph, cp)
        extra += more
        objective = muscle_term
        if n_r:
            reserve_term, more = _power_sum(self._u, p, n_r, False, True, self.epigraph, cp)
            extra += more
            objective = objective + self.reserve_weight * reserve_term
        self.constraints = cons
        self.problem = cp.Problem(cp.Minimize(objective), list(cons.values()) + extra)
        if not self.problem.is_dpp():  # pragma: no cover - guards the formulation above
            raise ModelError("StaticOptimization: the problem is not DPP (internal formulation error)")
        self._fallback = None  # least-deficit problem, built on the first infeasible frame

    def _build_fallback(self):
        cp = self._cp
        n, m, n_r = self.n_muscles, self.n_coordinates, self.n_reserves
        a = cp.Variable(n, name="a")
        u = cp.Variable(n_r, name="u") if n_r else None
        r = cp.Variable(m, name="deficit")
        lhs = self._B @ a - self._b
        if n_r:
            lhs = lhs + self.G @ u
        cons = [r == lhs, a >= self.activation_lower, a <= self.activation_upper]
        if n_r and self.reserve_lower_index.size:
            cons.append(u[self.reserve_lower_index] >= self.reserve_lower[self.reserve_lower_index])
        if n_r and self.reserve_upper_index.size:
            cons.append(u[self.reserve_upper_index] <= self.reserve_upper[self.reserve_upper_index])
        obj = cp.sum_squares(r) + 1e-6 * cp.sum_squares(a)
        if n_r:
            obj = obj + 1e-6 * cp.sum_squares(u)
        prob = cp.Problem(cp.Minimize(obj), cons)
        return prob, a, u

    # ------------------------------------------------------------------------------------------
    def objective_value(self, activations, reserve_controls, active_force, passive_force) -> float:
        r"""The criterion J (module docstring) at given activations and reserve controls.

        Parameters
        ----------
        activations : array_like, shape (n_muscles,)
        reserve_controls : array_like, shape (n_reserves,)
        active_force, passive_force : array_like, shape (n_muscles,)
            A and P [N] of the frame (used by the stress criterion).

        Returns
        -------
        float
            J [-].
        """
        a = np.asarray(activations, float)
        u = np.asarray(reserve_controls, float)
        p = self.exponent
        if self.criterion == "activation":
            x = a
        else:
            x = (np.asarray(active_force, float) * a + np.asarray(passive_force, float)) / self.stress_force_scale
        return float(np.sum(np.abs(x) ** p) + self.reserve_weight * np.sum(np.abs(u) ** p))

    def _check_frame(self, R, A, P, tau) -> str:
        """Empty string if the frame's data are usable, otherwise the reason."""
        for label, arr, names in (("moment_arms", R, None), ("active_force", A, self.muscle_names),
                                  ("passive_force", P, self.muscle_names),
                                  ("generalized_forces", tau, self.coordinate_names)):
            bad = ~np.isfinite(arr)
            if np.any(bad):
                idx = np.argwhere(bad)[0]
                if label == "moment_arms":
                    where = f"coordinate {self.coordinate_names[idx[0]]!r}, muscle {self.muscle_names[idx[1]]!r}"
                else:
                    where = f"{names[idx[0]]!r}"
                return f"{label}: non-finite value {arr[tuple(idx)]} ({where})"
        if np.any(A < 0):
            j = int(np.flatnonzero(A < 0)[0])
            return f"active_force: {A[j]} N < 0 for muscle {self.muscle_names[j]!r}"
        if self.criterion == "stress" and np.any(P < 0):
            j = int(np.flatnonzero(P < 0)[0])
            return f"passive_force: {P[j]} N < 0 for muscle {self.muscle_names[j]!r} (stress criterion needs P >= 0)"
        return ""

    def _frame_arrays(self, moment_arms, active_force, passive_force, generalized_forces):
        n, m = self.n_muscles, self.n_coordinates
        R = np.asarray(moment_arms, float)
        A = np.asarray(active_force, float)
        P = np.zeros(n) if passive_force is None else np.asarray(passive_force, float)
        tau = np.asarray(generalized_forces, float)
        for label, arr, shape in (("moment_arms", R, (m, n)), ("active_force", A, (n,)),
                                  ("passive_force", P, (n,)), ("generalized_forces", tau, (m,))):
            if arr.shape != shape:
                raise InputError(f"{label} must have shape {shape} per frame, got {arr.shape}")
        return R, A, P, tau

    def solve_frame(self, moment_arms, active_force, passive_force, generalized_forces) -> FrameSolution:
        r"""Solve one frame.

        Parameters
        ----------
        moment_arms : array_like, shape (n_coordinates, n_muscles)
            R [m, or - for translational coordinates].
        active_force : array_like, shape (n_muscles,)
            A = F0 f_L f_V cos(alpha) [N per unit activation], >= 0
            (:meth:`biomech.muscles.ThelenMuscleSet.rigid_tendon_forces`).
        passive_force : array_like, shape (n_muscles,) or None
            P [N] (None: no passive force).
        generalized_forces : array_like, shape (n_coordinates,)
            tau [N m or N].

        Returns
        -------
        FrameSolution
            Never raises for a numerical failure or bad numbers in the frame; see ``status``.
            After the call, :attr:`constraints` hold the dual values of the last Clarabel run
            of this frame (the chosen one unless a retry did worse than an earlier attempt).

        Raises
        ------
        core.errors.InputError
            An argument of the wrong shape.
        """
        R, A, P, tau = self._frame_arrays(moment_arms, active_force, passive_force, generalized_forces)
        return self._solve(R, A, P, tau)

    def _empty(self, status: str, message: str, elapsed: float = math.nan) -> FrameSolution:
        nan_n, nan_r = np.full(self.n_muscles, np.nan), np.full(self.n_reserves, np.nan)
        return FrameSolution(nan_n, nan_n.copy(), nan_r, nan_r.copy(), np.full(self.n_coordinates, np.nan),
                             status, message, math.nan, elapsed, math.nan, -1)

    def _solve(self, R, A, P, tau) -> FrameSolution:
        reason = self._check_frame(R, A, P, tau)
        if reason:
            return self._empty("invalid_input", reason, 0.0)
        a, u, status, message, elapsed, solver_time, iters = self._attempts(R, A, P, tau)
        if a is None:
            sol = self._empty(status, message or "no solution", elapsed)
            sol.solver_time, sol.iterations = solver_time, iters
            return sol
        forces = A * a + P
        reserve_forces = self.reserve_optimal_force * u
        residual = R @ forces + self.G @ u - tau
        return FrameSolution(a, forces, u, reserve_forces, residual, status, message,
                             self.objective_value(a, u, A, P), elapsed, solver_time, iters)

    def _attempts(self, R, A, P, tau):
        """The attempts of one checked frame (first, retries, least deficit): (a, u, status,
        message, wall time, Clarabel time, iterations), ``a`` and ``u`` None without solution."""
        t0 = time.perf_counter()
        values = {self._B: R * A, self._b: tau - R @ P}  # R diag(A), τ − R P
        if self._c is not None:
            values |= {self._c: A / self.stress_force_scale, self._d: P / self.stress_force_scale}
        fast_ready = self._fast_enabled and self._fast is not None and self._fast.verified >= 2 and self._fast.ok
        if not fast_ready:  # cvxpy's problem is solved or checked against: it reads the parameters
            self._set_parameters(values)
        first = self._run_fast(values if fast_ready else None) if self._fast_enabled else None
        if first is None:
            if fast_ready:
                self._set_parameters(values)
            first = self._run(self.problem, self._base_options)
        best, solver_time, notes = first, first.solver_time, []
        for retry in self.retry_options:
            if _rank(best.status) == 2:
                break
            attempt = self._run(self.problem, {**self._base_options, **retry})
            solver_time += attempt.solver_time if math.isfinite(attempt.solver_time) else 0.0
            notes.append(f"retried with {retry}: {attempt.status}")
            if _rank(attempt.status) > _rank(best.status):
                best = attempt
        status, iters = best.status, best.iterations
        message = best.message if best is first else ""
        if notes:
            first_note = f"first attempt: {first.status}" + (f" ({first.message})" if first.message else "")
            message = "; ".join([first_note] + notes)
        a, u = best.activations, best.reserve_controls
        if status in _SOLUTION_STATUSES and a is not None:
            if status != "optimal":
                message = f"solved to Clarabel's reduced tolerances only; {message}".rstrip("; ")
        elif status in _INFEASIBLE_STATUSES:
            a, u, deficit_message = self._least_deficit(R, tau)
            message = f"{deficit_message}; {message}" if message else deficit_message
        else:
            a = u = None
            if status != "solver_error":
                message = f"solver status {status!r}; {message}".rstrip("; ")
        return a, u, status, message, time.perf_counter() - t0, solver_time, iters

    @staticmethod
    def _set_parameters(values):
        for par, val in values.items():
            par.value = val

    def _run_fast(self, values=None):
        """The frame through :class:`_ClarabelData` (cvxpy's parameter tensor applied directly); None
        where it cannot be used or did not end 'optimal' (the caller then solves with cvxpy).
        ``values`` the parameters' values once the map is verified (else they are set on cvxpy's
        parameters already)."""
        cp = self._cp
        try:
            if self._fast is None:
                variables = [self._a] + ([self._u] if self.n_reserves else [])
                self._fast = _ClarabelData(self.problem, cp, variables)
                self._fast.verified = 1
            elif self._fast.verified < 2:
                self._fast.verify(self.problem, cp)
            if not self._fast.ok:
                self._fast_enabled = False
                return None
            p = None if values is None else self._fast.param_vec(values)
            status, solve_time, iters, values = self._fast.solve(self._base_options, p)
        except Exception:  # an internal API of cvxpy that changed: use problem.solve from now on
            self._fast_enabled = False
            return None
        if status != "optimal":
            return None
        a = values[0]
        u = values[1] if self.n_reserves else np.zeros(0)
        return _Attempt(status, "", solve_time, iters, a, u)

    def _run(self, problem, options) -> _Attempt:
        """Solve ``problem`` with Clarabel and keep a copy of the main problem's solution."""
        cp = self._cp
        status, message = "solver_error", ""
        with warnings.catch_warnings():
            # an inaccurate solution is reported through the status, not as a warning
            warnings.filterwarnings("ignore", message="Solution may be inaccurate")
            try:
                problem.solve(solver=cp.CLARABEL, enforce_dpp=True, **options)
                status = str(problem.status)
            except cp.SolverError as exc:
                message = f"Clarabel failed ({exc})"
        stats = problem.solver_stats
        solver_time = float(stats.solve_time) if stats is not None and stats.solve_time is not None else math.nan
        iters = int(stats.num_iters) if stats is not None and stats.num_iters is not None else -1
        a = u = None
        if problem is self.problem and status in _SOLUTION_STATUSES and self._a.value is not None:
            a = np.array(self._a.value, float)
            u = np.array(self._u.value, float) if self.n_reserves else np.zeros(0)
        return _Attempt(status, message, solver_time, iters, a, u)

    def _least_deficit(self, R, tau):
        """Activations within the bounds that minimise the moment deficit (parameters already set)."""
        cp = self._cp
        if self._fallback is None:
            self._fallback = self._build_fallback()
        prob, a_var, u_var = self._fallback
        run = self._run(prob, self._base_options)
        if run.status not in _SOLUTION_STATUSES or a_var.value is None:
            return None, None, f"infeasible; the least-deficit problem ended {run.status!r} {run.message}".rstrip()
        a = np.clip(np.asarray(a_var.value, float), self.activation_lower, self.activation_upper)
        u = np.asarray(u_var.value, float) if self.n_reserves else np.zeros(0)
        deficit = self._B.value @ a + self.G @ u - self._b.value
        i = int(np.argmax(np.abs(deficit)))
        msg = (f"the muscles{' and reserves' if self.n_reserves else ''} cannot produce the generalized forces; "
               f"activations minimise the deficit, largest {deficit[i]:+.6g} {self.coordinate_units[i]} at "
               f"coordinate {self.coordinate_names[i]!r}")
        return a, u, msg

    # ------------------------------------------------------------------------------------------
    def solve_trial(self, times, moment_arms, active_force, passive_force, generalized_forces) -> pd.DataFrame:
        r"""Solve every frame of a trial, one after another, and tabulate the results.

        Parameters
        ----------
        times : array_like, shape (n_frames,)
            Frame times [s].
        moment_arms : array_like, shape (n_frames, n_coordinates, n_muscles)
            R per frame [m or -].
        active_force : array_like, shape (n_frames, n_muscles)
            A per frame [N per unit activation].
        passive_force : array_like, shape (n_frames, n_muscles) or None
            P per frame [N].
        generalized_forces : array_like, shape (n_frames, n_coordinates)
            tau per frame [N m or N].

        Returns
        -------
        pandas.DataFrame
            One row per frame: ``time [s]``, ``a_<muscle> [-]``, ``F_<muscle> [N]``,
            ``u_<coordinate> [-]`` and ``reserve_<coordinate> [<unit>]`` for each reserve,
            ``max |R F + r - tau| [<unit>]``, ``status``, ``message``, ``objective [-]``,
            ``solve time [s]`` (wall, with cvxpy; the first frame includes the one-off DPP
            compilation), ``solver time [s]`` (Clarabel) and ``iterations``.  ``attrs`` holds the
            formulation (criterion, exponent, σ, reserve rule, solver settings, versions) and a
            count of frames per status.  A failed frame never stops the trial (module docstring).

        Raises
        ------
        core.errors.InputError
            Arrays of inconsistent shapes.
        """
        import clarabel
        import cvxpy

        t = np.asarray(times, float)
        if t.ndim != 1:
            raise InputError(f"times must have shape (n_frames,), got {t.shape}")
        nf, n, m = len(t), self.n_muscles, self.n_coordinates
        R = np.asarray(moment_arms, float)
        A = np.asarray(active_force, float)
        P = np.zeros((nf, n)) if passive_force is None else np.asarray(passive_force, float)
        tau = np.asarray(generalized_forces, float)
        for label, arr, shape in (("moment_arms", R, (nf, m, n)), ("active_force", A, (nf, n)),
                                  ("passive_force", P, (nf, n)), ("generalized_forces", tau, (nf, m))):
            if arr.shape != shape:
                raise InputError(f"{label} must have shape {shape} (n_frames, ...), got {arr.shape}")
        # the frames' data checked all at once; a frame that fails gets its reason from the
        # per-frame check (the same message as solve_frame)
        usable = (np.isfinite(R).all(axis=(1, 2)) & np.isfinite(A).all(axis=1) & np.isfinite(P).all(axis=1)
                  & np.isfinite(tau).all(axis=1) & ~(A < 0).any(axis=1))
        if self.criterion == "stress":
            usable &= ~(P < 0).any(axis=1)
        nr = self.n_reserves
        acts, ctrl = np.full((nf, n), np.nan), np.full((nf, nr), np.nan)
        status, message = [""] * nf, [""] * nf
        elapsed, solver_time = np.zeros(nf), np.full(nf, np.nan)
        iters = np.full(nf, -1, dtype=int)
        for k in range(nf):
            reason = "" if usable[k] else self._check_frame(R[k], A[k], P[k], tau[k])
            if reason:
                status[k], message[k] = "invalid_input", reason
                continue
            a, u, status[k], msg, elapsed[k], solver_time[k], iters[k] = self._attempts(R[k], A[k], P[k], tau[k])
            if a is None:
                message[k] = msg or "no solution"
            else:
                acts[k], ctrl[k], message[k] = a, u, msg
        # forces, residuals and criterion of all frames at once (as solve_frame computes them)
        forces = A * acts + P
        rf = self.reserve_optimal_force * ctrl
        residual = np.einsum("kmn,kn->km", R, forces) + ctrl @ self.G.T - tau
        finite = np.isfinite(residual).all(axis=1)
        max_res = np.where(finite, np.abs(np.where(finite[:, None], residual, 0.0)).max(axis=1, initial=0.0), np.nan)
        x = acts if self.criterion == "activation" else (A * acts + P) / self.stress_force_scale
        p = self.exponent
        objective = np.sum(np.abs(x) ** p, axis=1) + self.reserve_weight * np.sum(np.abs(ctrl) ** p, axis=1)

        unit_set = sorted(set(self.coordinate_units))
        res_unit = unit_set[0] if len(unit_set) == 1 else " or ".join(unit_set)
        cols: dict[str, object] = {"time [s]": t}
        for j, name in enumerate(self.muscle_names):
            cols[f"a_{name} [-]"] = acts[:, j]
        for j, name in enumerate(self.muscle_names):
            cols[f"F_{name} [N]"] = forces[:, j]
        for k, (i, name) in enumerate(zip(self.reserve_index, self.reserve_coordinates)):
            cols[f"u_{name} [-]"] = ctrl[:, k]
            cols[f"reserve_{name} [{self.coordinate_units[i]}]"] = rf[:, k]
        cols[f"max |R F + r - tau| [{res_unit}]"] = max_res
        cols["status"] = status
        cols["message"] = message
        cols["objective [-]"] = objective
        cols["solve time [s]"] = elapsed
        cols["solver time [s]"] = solver_time
        cols["iterations"] = iters
        df = pd.DataFrame(cols)
        counts = df["status"].value_counts()
        df.attrs.update({
            "criterion": self.criterion,
            "exponent": self.exponent,
            "specific_tension [Pa]": self.specific_tension,
            "objective": ("sum a^p" if self.criterion == "activation" else "sum (F/(sigma PCSA))^p")
            + " + w sum |u|^p (OpenSim: every actuator's activation or control to the power p)",
            "reserve_weight": self.reserve_weight,
            "reserve_optimal_force": dict(zip(self.reserve_coordinates, self.reserve_optimal_force.tolist())),
            "solver": "CLARABEL via cvxpy (DPP, parameters updated per frame)",
            "solver_options": dict(self.solver_options),
            "versions": {"cvxpy": cvxpy.__version__, "clarabel": clarabel.__version__},
            "status_counts": {str(k): int(v) for k, v in counts.items()},
        })
        return df

    @classmethod
    def from_muscles(cls, muscles, coordinate_names: Sequence[str], **kwargs) -> StaticOptimization:
        """Build from a :class:`biomech.muscles.ThelenMuscleSet` (names and F0 taken from it)."""
        return cls(muscles.names, coordinate_names, muscles.max_isometric_force, **kwargs)
