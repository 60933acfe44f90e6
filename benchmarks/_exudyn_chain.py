r"""Exudyn models of the N-link whip chain (``core_benchmarks.md`` §1) and the grid of Exudyn solver configurations.

Exudyn (J. Gerstmayr, University of Innsbruck; ``pip install exudyn``, the optional ``bench`` extra)
is the C++ peer the speed targets are measured against.  This module builds the same mechanism
three ways and runs every Exudyn solver configuration that could be the peer's fastest on it.

Formulations
------------
``"redundant"``  (absolute / redundant coordinates, index 3)
    N ``NodeRigidBody2D`` + ``ObjectRigidBody2D`` (x, y, φ per link; mass m = 1/N kg,
    J = m L²/12), ``ObjectJointRevolute2D`` between ``MarkerBodyPosition`` markers at the joint
    points (link 1 to an ``ObjectGround`` marker at the origin), gravity by
    ``LoadMassProportional``.  3N coordinates, 2N algebraic equations
    ``M q̈ + Φ_qᵀ λ = Q``, ``Φ(q) = 0``.
``"minimal"``  (minimal / joint coordinates)
    One ``ObjectKinematicTree`` on a ``NodeGenericODE2`` with N relative joint angles ψ
    (``JointType.RevoluteZ``), link k's joint at (L, 0, 0) in link k−1's frame, centre of mass at
    (L/2, 0, 0), inertia diag(J, J, J) (only the z entry enters the planar motion), gravity
    (0, −9.81, 0).  An ODE ``M(ψ) ψ̈ = f(ψ, ψ̇)`` with a dense, configuration-dependent N×N mass
    matrix.
``"penalty"``  (the stiff variant)
    As ``"redundant"`` but every revolute joint (the ground pivot included) is replaced by an
    ``ObjectConnectorCartesianSpringDamper`` with stiffness (k, k, k) [N/m] and zero damping
    between the same two points: the unconstrained stiff ODE ``M q̈ = Q − k Φ_qᵀ Φ`` in 3N
    coordinates with constant block-diagonal M.

The tip (free end of link N) is ``r_N + (L/2)(cos φ_N, sin φ_N)`` in absolute coordinates and
``Σ_k L (cos θ_k, sin θ_k)`` with ``θ_k = Σ_{j≤k} ψ_j`` in joint coordinates ψ.

Solver configurations (:func:`solver_configurations`)
-----------------------------------------------------
Every member of ``exu.DynamicSolverType`` is tried on every formulation; a member is *implicit*
when its enum description says "implicit solver" (Exudyn 1.13: ``GeneralizedAlpha``,
``TrapezoidalIndex2``), otherwise *explicit*.  A short probe solve (:func:`probe_solver`)
decides whether the pair runs at all; a pair Exudyn refuses (``ModelError`` — e.g. explicit
solvers with the joints of ``"redundant"`` —, ``NotImplementedFeatureError`` — e.g. ``DVERK6``
— or ``ExudynValueError``) becomes a single configuration recorded as unavailable with Exudyn's
message, never silently dropped.  For the explicit solvers the probe also asks Exudyn
(``MainSolverExplicit.HasAutomaticStepSizeControl``) whether the method has an embedded error
estimate.

Explicit solvers (``SimulationSettings.timeIntegration.explicit``, called
``explicitIntegration`` up to Exudyn 1.11), the full product of

* step control: fixed step h (``automaticStepSize = False``, ``numberOfSteps = 1/h``) and, for
  the methods with error control (ODE23, DOPRI5), adaptive (``automaticStepSize = True``,
  ``relativeTolerance = absoluteTolerance = tol``, largest step ``t_end/10``, Exudyn's default
  ``stepSizeSafety`` = 0.9, ``stepSizeMaxIncrease`` = 2, ``initialStepSize`` = 0 = the largest step).
  For these methods the probe also checks that ``automaticStepSize = False`` really gives fixed
  steps (2 steps of 50 ms at rtol = atol = 1e-8 must take 2 steps without rejections); when it
  does not — the method then still controls its step with the tolerances and h is only the
  largest step, i.e. the adaptive mode again — the fixed-step mode is recorded as unavailable with
  the probe's step counts;
* ``computeEndOfStepAccelerations`` (EOSA) on (Exudyn's default: one more right-hand side per
  step) / off (the last stage's accelerations are re-used; the state is the same);
* ``computeMassMatrixInversePerBody`` off (default: one factorisation of the system mass matrix)
  / on (each body's mass matrix inverted separately — valid here: no body shares a node; the
  kinematic tree is one body);
* ``linearSolver.solverType`` for the mass-matrix solve: ``EXUdense`` (default), ``EigenDense``
  (partial-pivot LU), ``EigenSparse`` (sparse LU), ``EigenSparseSymmetric`` (sparse LDLᵀ; the
  mass matrix is symmetric positive definite).

``useLieGroupIntegration`` is left at its default (True): it acts on Lie-group nodes only and
none of the three models has one (``NodeRigidBody2D``, ``NodeGenericODE2``).
``eliminateConstraints`` (default True) only removes ``CoordinateConstraint``\ s to ground; with
the ``ObjectJointRevolute2D`` joints of ``"redundant"`` Exudyn's explicit solvers stop with a
``ModelError``.  The only other explicit option on that formulation, ``eliminateConstraints =
False``, makes Exudyn *ignore* the joints (it warns "explicit INTEGRATOR WILL IGNORE
CONSTRAINTS"); it is run once per explicit method as a configuration of its own, so that the
tables show what it returns.

Implicit solvers (Newton settings at Exudyn's defaults: ``relativeTolerance`` = 1e-8,
``absoluteTolerance`` = 1e-10, ``maxIterations`` = 25, ``maxModifiedNewtonIterations`` = 8,
``maxModifiedNewtonRestartIterations`` = 7, ``modifiedNewtonContractivity`` = 0.5; step
reduction after Newton failure on, ``adaptiveStep`` = True), fixed step h, the product of

* method: ``GeneralizedAlpha`` (index-3 position constraints) with spectral radius
  ρ∞ ∈ {0.99, 0.9 (default), 0.5, 0}, plus ρ∞ = 1 on the unconstrained formulations
  (``"minimal"``, ``"penalty"``; Exudyn requires ρ∞ < 1 with index-3 constraints), and
  ``TrapezoidalIndex2`` (Newmark β = 1/4, γ = 1/2 with velocity-level, index-2 constraints).
  ``GeneralizedAlpha`` with ``useIndex2Constraints`` alone is tried too (Exudyn requires
  ``useNewmark`` with it); with both flags it *is* ``TrapezoidalIndex2`` (``exudyn.solver``
  sets exactly these two flags for it) and is not repeated;
* Newton: modified (default: the Jacobian is kept across steps and updated when the contraction
  is poor), modified with a Jacobian update every step (``modifiedNewtonJacUpdatePerStep``),
  full (``useModifiedNewton = False``: a Jacobian per iteration);
* ``linearSolver.solverType``: ``EXUdense`` (default), ``EigenDense``, ``EigenSparse``,
  ``EigenSparseSymmetric``.

All runs: ``numberOfThreads = 1``, no solution file, no sensors, no console output, the mass
matrix reused when constant (``reuseConstantMassMatrix``, default).  Timing is of
``mbs.SolveDynamic`` alone (model build, ``Assemble`` and the probe excluded); Exudyn is imported
in its ``exudynCPPfast`` flavour (no range checks, AVX2) when the CPU supports it.  A run counts
as successful when ``SolveDynamic`` returns True without raising, the solver reached t_end and
the tip is finite (Exudyn's explicit solvers report success for runs that overflow to ±inf or
NaN; the caller judges the error).

References
----------
J. Gerstmayr, "Exudyn -- a C++-based Python package for flexible multibody systems",
Multibody Syst. Dyn. 60 (2024) 533–561.  Exudyn 1.13 documentation (and the docstrings of the
installed package, ``exudyn/__init__.pyi``): items ``ObjectRigidBody2D``,
``ObjectJointRevolute2D``, ``ObjectKinematicTree``, ``ObjectConnectorCartesianSpringDamper``;
``DynamicSolverType``, ``LinearSolverType``; ``SimulationSettings.timeIntegration``
(``explicit``, ``generalizedAlpha``, ``newton``).  M. Arnold, O. Brüls, "Convergence of the
generalized-α scheme for constrained mechanical systems", Multibody Syst. Dyn. 18 (2007) 185–202.
"""

from __future__ import annotations

import io
import sys
import time
from contextlib import redirect_stdout
from dataclasses import dataclass, replace

import numpy as np

G_EARTH = 9.81
FORMULATIONS = ("redundant", "minimal", "penalty")
LINEAR_SOLVERS = ("EXUdense", "EigenDense", "EigenSparse", "EigenSparseSymmetric")
NEWTON_MODES = ("modified", "modified, Jacobian every step", "full")
SPECTRAL_RADII = (0.99, 0.9, 0.5, 0.0)  # + 1.0 where there are no index-3 constraints
EOSA_DEFAULT = True  # Exudyn's default of explicit.computeEndOfStepAccelerations


def load_exudyn():
    """Import Exudyn (fast module when available); returns the module or None when not installed."""
    if "exudyn" not in sys.modules:
        sys.exudynFast = True  # peer's fastest build: exudynCPPfast (falls back when no AVX2)
    try:
        with redirect_stdout(io.StringIO()):
            import exudyn  # noqa: F401
    except ImportError:
        return None
    return sys.modules["exudyn"]


@dataclass
class ExudynChain:
    """A built and assembled Exudyn chain model (see the module docstring)."""

    exu: object
    SC: object
    mbs: object
    n: int
    formulation: str
    L: float
    stiff_k: float | None = None

    def tip(self) -> np.ndarray:
        """Tip position (x, y) [m] from the current (end-of-run) coordinates."""
        exu = self.exu
        u = np.asarray(self.mbs.systemData.GetODE2Coordinates(configuration=exu.ConfigurationType.Current))
        n, L = self.n, self.L
        if self.formulation == "minimal":
            th = np.cumsum(u[:n])
            return L * np.array([np.cos(th).sum(), np.sin(th).sum()])
        x = (n - 0.5) * L + u[3 * (n - 1)]
        y = u[3 * (n - 1) + 1]
        phi = u[3 * (n - 1) + 2]
        return np.array([x + 0.5 * L * np.cos(phi), y + 0.5 * L * np.sin(phi)])


def build_chain(n: int, formulation: str = "redundant", stiff_k: float | None = None,
                total_length: float = 1.0, total_mass: float = 1.0, gravity: float = G_EARTH) -> ExudynChain:
    """Build and assemble the chain in Exudyn.

    Parameters
    ----------
    n : int
        Number of links N.
    formulation : {'redundant', 'minimal', 'penalty'}
    stiff_k : float, optional
        Joint spring stiffness k [N/m] (``'penalty'`` only, required there).

    Returns
    -------
    ExudynChain

    Raises
    ------
    ImportError
        If Exudyn is not installed.
    ValueError
        On an unknown formulation or a missing ``stiff_k``.
    """
    exu = load_exudyn()
    if exu is None:
        raise ImportError("exudyn is not installed (pip install 'mbsuite[bench]')")
    import exudyn.itemInterface as ii

    if formulation not in ("redundant", "minimal", "penalty"):
        raise ValueError(f"build_chain: unknown formulation {formulation!r}")
    if formulation == "penalty" and not (stiff_k and stiff_k > 0):
        raise ValueError(f"build_chain: the penalty chain needs stiff_k > 0, got {stiff_k}")
    L, m = total_length / n, total_mass / n
    J = m * L * L / 12.0
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    if formulation == "minimal":
        node = mbs.AddNode(ii.NodeGenericODE2(referenceCoordinates=[0.0] * n, initialCoordinates=[0.0] * n,
                                              initialCoordinates_t=[0.0] * n, numberOfODE2Coordinates=n))
        offsets = exu.Vector3DList([[0.0, 0.0, 0.0]] + [[L, 0.0, 0.0]] * (n - 1))
        rots = exu.Matrix3DList([np.eye(3)] * n)
        inert = exu.Matrix3DList([np.diag([J, J, J])] * n)
        coms = exu.Vector3DList([[0.5 * L, 0.0, 0.0]] * n)
        mbs.AddObject(ii.ObjectKinematicTree(nodeNumber=node, gravity=[0.0, -gravity, 0.0],
                                             jointTypes=[exu.JointType.RevoluteZ] * n,
                                             linkParents=list(range(-1, n - 1)),
                                             jointTransformations=rots, jointOffsets=offsets,
                                             linkInertiasCOM=inert, linkCOMs=coms, linkMasses=[m] * n,
                                             visualization=ii.VObjectKinematicTree(show=False)))
    else:
        ground = mbs.AddObject(ii.ObjectGround(referencePosition=[0.0, 0.0, 0.0]))
        prev_marker = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0]))
        for k in range(n):
            nd = mbs.AddNode(ii.NodeRigidBody2D(referenceCoordinates=[(k + 0.5) * L, 0.0, 0.0],
                                                initialCoordinates=[0.0, 0.0, 0.0],
                                                initialVelocities=[0.0, 0.0, 0.0]))
            body = mbs.AddObject(ii.ObjectRigidBody2D(physicsMass=m, physicsInertia=J, nodeNumber=nd,
                                                      visualization=ii.VObjectRigidBody2D(show=False)))
            m_left = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=body, localPosition=[-0.5 * L, 0.0, 0.0]))
            m_mass = mbs.AddMarker(ii.MarkerBodyMass(bodyNumber=body))
            mbs.AddLoad(ii.LoadMassProportional(markerNumber=m_mass, loadVector=[0.0, -gravity, 0.0]))
            if formulation == "redundant":
                mbs.AddObject(ii.ObjectJointRevolute2D(markerNumbers=[prev_marker, m_left],
                                                       visualization=ii.VObjectJointRevolute2D(show=False)))
            else:
                kk = float(stiff_k)
                mbs.AddObject(ii.ObjectConnectorCartesianSpringDamper(
                    markerNumbers=[prev_marker, m_left], stiffness=[kk, kk, kk], damping=[0.0, 0.0, 0.0],
                    visualization=ii.VObjectConnectorCartesianSpringDamper(show=False)))
            prev_marker = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=body, localPosition=[0.5 * L, 0.0, 0.0]))
    with redirect_stdout(io.StringIO()):
        mbs.Assemble()
    return ExudynChain(exu, SC, mbs, n, formulation, L, stiff_k)


@dataclass(frozen=True)
class SolverOptions:
    """One Exudyn solver configuration (see the module docstring for what each option does).

    Parameters
    ----------
    solver : str
        Name of an ``exu.DynamicSolverType`` member.
    adaptive : bool
        Automatic step-size control (``automaticStepSize``; explicit methods with error control);
        the accuracy knob is then rtol = atol, otherwise the step h.
    eosa : bool
        ``explicit.computeEndOfStepAccelerations``.
    per_body : bool
        ``explicit.computeMassMatrixInversePerBody``.
    eliminate_constraints : bool
        ``explicit.eliminateConstraints`` (False: the explicit solver ignores the constraints).
    linear_solver : str
        ``linearSolver.solverType`` (a ``exu.LinearSolverType`` name).
    newton : str
        One of :data:`NEWTON_MODES` (implicit solvers).
    spectral_radius : float
        ``generalizedAlpha.spectralRadius`` ρ∞ (``GeneralizedAlpha``).
    index2 : bool
        ``generalizedAlpha.useIndex2Constraints`` (``GeneralizedAlpha``).
    implicit : bool
        Whether ``solver`` is an implicit method (only used for the label and the option set).
    unavailable : str
        Non-empty: Exudyn refused this configuration (its message); it is not run.
    """

    solver: str
    adaptive: bool = False
    eosa: bool = EOSA_DEFAULT
    per_body: bool = False
    eliminate_constraints: bool = True
    linear_solver: str = "EXUdense"
    newton: str = "modified"
    spectral_radius: float = 0.9
    index2: bool = False
    implicit: bool = False
    unavailable: str = ""

    @property
    def knob(self) -> str:
        """``'tol'`` for adaptive step control, else ``'h'``."""
        return "tol" if self.adaptive else "h"

    def label(self) -> str:
        """Short human-readable description (unique within one formulation)."""
        if self.implicit:
            s = self.solver
            if self.solver == "GeneralizedAlpha":
                s += ", index-2 constraints" if self.index2 else f" rho={self.spectral_radius:g}"
            return s if self.unavailable else f"{s}, {self.newton} Newton, {self.linear_solver}"
        if self.unavailable:
            return f"{self.solver} {'adaptive' if self.adaptive else 'fixed h'}"
        s = f"{self.solver} {'adaptive' if self.adaptive else 'fixed h'}"
        if not self.eliminate_constraints:
            return s + ", eliminateConstraints off (joints ignored)"
        return (f"{s}, EOSA {'on' if self.eosa else 'off'}, M-inverse per body {'on' if self.per_body else 'off'}, "
                f"{self.linear_solver}")


def solver_types(exu) -> list[tuple[str, bool]]:
    """All ``exu.DynamicSolverType`` members as ``(name, implicit)``, in enum order.

    A member is implicit when its enum description contains "implicit solver".
    """
    desc = {}
    for line in (exu.DynamicSolverType.__doc__ or "").splitlines():
        name, sep, text = line.strip().partition(" : ")
        if sep:
            desc[name] = text.lower()
    members = sorted(exu.DynamicSolverType.__members__.items(), key=lambda kv: int(kv[1].value))
    return [(name, "implicit solver" in desc.get(name, "")) for name, _ in members]


@dataclass
class ProbeResult:
    """What a short trial solve tells about one solver method on one formulation."""

    available: bool
    message: str
    adaptive_capable: bool = False
    order: int = -1
    stages: int = -1
    fixed_step_message: str = ""  # non-empty: automaticStepSize = False is not honoured (why)


def probe_solver(chain: ExudynChain, opts: SolverOptions) -> ProbeResult:
    """Run ``opts`` (fixed h = 1 ms) over 5 ms of motion; report refusal and, for explicit methods, capabilities.

    Exudyn refuses a configuration by raising ``ModelError``, ``NotImplementedFeatureError`` or
    ``ExudynValueError``; other failures (e.g. a Newton failure) are step-size questions and left
    to the sweep.  For explicit methods ``MainSolverExplicit`` is asked whether it has automatic
    step-size control (``HasAutomaticStepSizeControl``), and for its order and number of stages.
    """
    exu = chain.exu
    r = solve(chain, replace(opts, adaptive=False), h=1e-3, t_end=5e-3)
    if r.unavailable:
        return ProbeResult(False, r.message)
    out = ProbeResult(True, "")
    if not opts.implicit:
        st = _settings(exu, replace(opts, adaptive=False), h=1e-3, tol=None, t_end=5e-3)
        st.timeIntegration.automaticStepSize = True
        st.timeIntegration.solverType = getattr(exu.DynamicSolverType, opts.solver)
        ms = exu.MainSolverExplicit()
        try:
            with redirect_stdout(io.StringIO()):
                ms.InitializeSolver(chain.mbs, st)
                out.adaptive_capable = bool(ms.HasAutomaticStepSizeControl(chain.mbs, st))
                out.order, out.stages = int(ms.GetMethodOrder()), int(ms.GetNumberOfStages())
                ms.FinalizeSolver(chain.mbs, st)
        except Exception as exc:  # capability query failed: treat as fixed-step only, say why
            out.message = f"capability query failed: {type(exc).__name__}: {exc}"
        if out.adaptive_capable:
            # does automaticStepSize = False give fixed steps?  2 steps of 50 ms at rtol = atol = 1e-8
            # (Exudyn's default tolerances): far too long a step for that tolerance on either model, so
            # a method that still controls its step rejects steps or takes more of them.  (Tighter
            # tolerances make the probe itself slow: at k = 1e8, DOPRI5 at 1e-10 runs for many minutes.)
            n_fixed, h_probe = 2, 0.05
            r = solve(chain, replace(opts, adaptive=False), h=h_probe, tol=1e-8, t_end=n_fixed * h_probe)
            if r.rejected > 0 or r.steps > n_fixed + 1:
                out.fixed_step_message = (
                    f"automaticStepSize=False is not honoured by {opts.solver}: asked for {n_fixed} fixed steps of "
                    f"{h_probe * 1e3:g} ms at rtol=atol=1e-8, it took {r.steps} steps with {r.rejected} rejected "
                    f"(step-size control stays on with the tolerances; h is only the largest step)")
    return out


def solver_configurations(chain: ExudynChain) -> list[SolverOptions]:
    """Every Exudyn configuration to try on ``chain`` (see the module docstring), after the probes.

    Each *method* (an explicit solver type and step control; an implicit solver type with its
    ρ∞ / constraint-index choice) is probed once with default options; a refused method appears
    once, with ``unavailable`` set to Exudyn's message, an accepted one with every combination of
    its speed options.

    Returns
    -------
    list of SolverOptions
    """
    exu = chain.exu
    constrained = chain.formulation == "redundant"
    out: list[SolverOptions] = []
    for name, implicit in solver_types(exu):
        if implicit:
            if name == "GeneralizedAlpha":
                rhos = SPECTRAL_RADII + (() if constrained else (1.0,))
                methods = [SolverOptions(name, implicit=True, spectral_radius=r) for r in rhos]
                methods.append(SolverOptions(name, implicit=True, index2=True))
            else:
                methods = [SolverOptions(name, implicit=True)]
            for m in methods:
                pr = probe_solver(chain, m)
                if not pr.available:
                    out.append(replace(m, unavailable=pr.message))
                    continue
                out += [replace(m, newton=nt, linear_solver=lin) for nt in NEWTON_MODES for lin in LINEAR_SOLVERS]
            continue
        base = SolverOptions(name)
        pr = probe_solver(chain, base)
        if not pr.available:
            # one row per step-control mode with Exudyn's message; on the jointed formulation also
            # the one option that makes an explicit solver run anyway (it ignores the joints)
            for ad in [False] + ([True] if name in _adaptive_by_doc(exu) else []):
                out.append(replace(base, adaptive=ad, unavailable=pr.message))
                if constrained and "constraint" in pr.message.lower():
                    out.append(replace(base, adaptive=ad, eliminate_constraints=False))
            continue
        for ad in [False] + ([True] if pr.adaptive_capable else []):
            if not ad and pr.fixed_step_message:
                out.append(replace(base, unavailable=pr.fixed_step_message))
                continue
            out += [replace(base, adaptive=ad, eosa=eosa, per_body=pb, linear_solver=lin)
                    for eosa in (False, True) for pb in (True, False) for lin in LINEAR_SOLVERS]
    return out


def _adaptive_by_doc(exu) -> set[str]:
    """Solver types whose enum description promises automatic step-size selection."""
    names = set()
    for line in (exu.DynamicSolverType.__doc__ or "").splitlines():
        name, sep, text = line.strip().partition(" : ")
        if sep and ("automatic step size" in text.lower() or "adaptive step" in text.lower()):
            names.add(name)
    return names


@dataclass
class ExudynRun:
    """Outcome of one timed Exudyn solve."""

    tip: np.ndarray
    wall_s: float
    cpu_s: float
    success: bool
    steps: int
    message: str
    unavailable: bool = False  # Exudyn refused the configuration (model / not implemented / invalid value)
    jacobians: int = -1
    rejected: int = -1


def _settings(exu, opts: SolverOptions, h: float | None, tol: float | None, t_end: float):
    """``exu.SimulationSettings`` for one run of ``opts`` (see the module docstring)."""
    st = exu.SimulationSettings()
    ti = st.timeIntegration
    ti.startTime = 0.0
    ti.endTime = t_end
    if opts.adaptive:
        if tol is None:
            raise ValueError(f"solve: adaptive {opts.solver} needs tol")
        ti.automaticStepSize = True
        ti.numberOfSteps = max(1, int(round(t_end / (h if h else t_end / 10))))
        ti.relativeTolerance = float(tol)
        ti.absoluteTolerance = float(tol)
    else:
        if h is None:
            raise ValueError(f"solve: the fixed-step solver {opts.solver} needs h")
        ti.automaticStepSize = False
        ti.numberOfSteps = max(1, int(round(t_end / h)))
        if tol is not None:  # only used by probe_solver's check that the fixed step is honoured
            ti.relativeTolerance = float(tol)
            ti.absoluteTolerance = float(tol)
    ti.verboseMode = 0
    ex = ti.explicit
    ex.computeEndOfStepAccelerations = opts.eosa
    ex.computeMassMatrixInversePerBody = opts.per_body
    ex.eliminateConstraints = opts.eliminate_constraints
    ga = ti.generalizedAlpha
    ga.spectralRadius = opts.spectral_radius
    ga.useIndex2Constraints = opts.index2
    ga.useNewmark = False  # TrapezoidalIndex2 sets useNewmark and useIndex2Constraints itself
    ti.newton.useModifiedNewton = opts.newton != "full"
    ti.newton.modifiedNewtonJacUpdatePerStep = opts.newton == "modified, Jacobian every step"
    st.linearSolver.solverType = getattr(exu.LinearSolverType, opts.linear_solver)
    st.solution.file.write = False
    st.solution.sensors.active = False
    st.show.computationTime = False
    st.show.statistics = False
    st.show.globalTimers = False
    st.parallel.numberOfThreads = 1
    return st


def solve(chain: ExudynChain, solver: SolverOptions | str, h: float | None = None, tol: float | None = None,
          t_end: float = 1.0) -> ExudynRun:
    """Run one Exudyn dynamic solve from the initial state and time ``mbs.SolveDynamic`` alone.

    Parameters
    ----------
    chain : ExudynChain
    solver : SolverOptions or str
        The configuration; a plain ``exu.DynamicSolverType`` name means its default options,
        adaptive when ``tol`` is given.
    h : float, optional
        Step size [s] (fixed step; for adaptive runs the largest step, default ``t_end/10``).
    tol : float, optional
        Relative = absolute tolerance (adaptive runs).
    t_end : float
        End time [s].

    Returns
    -------
    ExudynRun
        ``success`` is False when Exudyn raised, returned False, stopped before ``t_end`` or left
        a non-finite tip; ``unavailable`` when it refused the configuration outright.
    """
    exu = chain.exu
    opts = solver if isinstance(solver, SolverOptions) else SolverOptions(solver, adaptive=tol is not None)
    if opts.unavailable:
        return ExudynRun(np.full(2, np.nan), 0.0, 0.0, False, 0, opts.unavailable, unavailable=True)
    st = _settings(exu, opts, h, tol, t_end)
    mbs = chain.mbs
    # reset to the initial state; drop the previous run's solver so that its counters are not reported
    mbs.systemData.SetODE2Coordinates(mbs.systemData.GetODE2Coordinates(configuration=exu.ConfigurationType.Initial),
                                      configuration=exu.ConfigurationType.Current)
    mbs.sys.pop("dynamicSolver", None)
    stype = getattr(exu.DynamicSolverType, opts.solver)
    refused = tuple(getattr(exu, n) for n in ("ModelError", "NotImplementedFeatureError", "ExudynValueError")
                    if hasattr(exu, n))
    buf = io.StringIO()
    unavailable = False
    with redirect_stdout(buf):
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            ok = bool(mbs.SolveDynamic(st, solverType=stype))
            msg = ""
        except Exception as exc:  # Exudyn raises on Newton / linear-solver failure and on refused models
            ok, msg = False, f"{type(exc).__name__}: {exc}"
            unavailable = isinstance(exc, refused)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    steps = jac = rej = -1
    t_reached = np.nan
    ds = mbs.sys.get("dynamicSolver")
    if ds is not None:
        try:
            it = ds.it
            steps, t_reached = int(it.currentStepIndex), float(it.currentTime)
            jac, rej = int(it.newtonJacobiCount), int(it.rejectedAutomaticStepSizeSteps)
        except Exception:
            pass
    tip = chain.tip()
    if ok and not (abs(t_reached - t_end) <= 1e-9 * max(1.0, t_end)):
        ok, msg = False, msg or f"stopped at t = {t_reached:.6g} s"
    if not np.all(np.isfinite(tip)):
        ok = False
        msg = msg or "non-finite tip"
    out = buf.getvalue().strip()
    if not msg and out:
        msg = out.replace("\n", " | ")[-200:]
    return ExudynRun(tip, wall, cpu, ok, steps, msg, unavailable=unavailable, jacobians=jac, rejected=rej)
