r"""Exudyn models of the N-link whip chain (``core_benchmarks.md`` §1) for the side-by-side benchmark.

Exudyn (J. Gerstmayr, University of Innsbruck; ``pip install exudyn``, the optional ``bench`` extra)
is the C++ peer the speed targets are measured against.  This module builds the same mechanism
three ways and times Exudyn's own solvers on it:

``"redundant"``  (absolute / redundant coordinates, index 3)
    N ``NodeRigidBody2D`` + ``ObjectRigidBody2D`` (x, y, φ per link; mass m = 1/N kg,
    J = m L²/12), ``ObjectJointRevolute2D`` between ``MarkerBodyPosition`` markers at the joint
    points (link 1 to an ``ObjectGround`` marker at the origin), gravity by
    ``LoadMassProportional``.  3N coordinates, 2N algebraic equations.  Solved with Exudyn's
    generalized-α (``DynamicSolverType.GeneralizedAlpha``, index-3 position constraints, or
    ``useIndex2Constraints``) with fixed step h and its default Newton / step-cut settings.
``"minimal"``  (minimal / joint coordinates)
    One ``ObjectKinematicTree`` on a ``NodeGenericODE2`` with N relative joint angles
    (``JointType.RevoluteZ``), link k's joint at (L, 0, 0) in link k−1's frame, centre of mass at
    (L/2, 0, 0), inertia diag(J, J, J) (only the z entry enters the planar motion), gravity
    (0, −9.81, 0).  An ODE with a dense N×N mass matrix, solved with Exudyn's explicit
    Runge–Kutta schemes: ``DOPRI5`` (adaptive, tolerance sweep) or ``RK44`` (fixed h).
``"penalty"``  (the stiff variant)
    As ``"redundant"`` but every revolute joint (the ground pivot included) is replaced by an
    ``ObjectConnectorCartesianSpringDamper`` with stiffness (k, k, k) [N/m] between the same two
    points: an unconstrained stiff ODE in 3N coordinates.  Solved with generalized-α (fixed h)
    or DOPRI5 (adaptive).

The tip (free end of link N) is ``r_N + (L/2)(cos φ_N, sin φ_N)`` in absolute coordinates and
``Σ_k L (cos θ_k, sin θ_k)`` with ``θ_k = Σ_{j≤k} ψ_j`` in joint coordinates ψ.

Timing is of ``mbs.SolveDynamic`` alone (model build and ``Assemble`` excluded), with solution
files and sensors off; Exudyn is imported in its ``exudynCPPfast`` flavour (no range checks, AVX2)
when the CPU supports it, i.e. the peer's fastest configuration, and runs on one thread.

References
----------
J. Gerstmayr, "Exudyn -- a C++-based Python package for flexible multibody systems",
Multibody Syst. Dyn. 60 (2024) 533–561.  Exudyn 1.13 documentation: items ``ObjectRigidBody2D``,
``ObjectJointRevolute2D``, ``ObjectKinematicTree``, ``ObjectConnectorCartesianSpringDamper``;
``SimulationSettings.timeIntegration`` (``generalizedAlpha``, ``explicitIntegration``).
"""

from __future__ import annotations

import io
import sys
import time
from contextlib import redirect_stdout
from dataclasses import dataclass

import numpy as np

G_EARTH = 9.81


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


@dataclass
class ExudynRun:
    """Outcome of one timed Exudyn solve."""

    tip: np.ndarray
    wall_s: float
    cpu_s: float
    success: bool
    steps: int
    message: str


def solve(chain: ExudynChain, solver: str, h: float | None = None, tol: float | None = None,
          t_end: float = 1.0, sparse: bool = False, index2: bool = False, spectral_radius: float = 0.9) -> ExudynRun:
    """Run one Exudyn dynamic solve from the initial state and time ``mbs.SolveDynamic`` alone.

    Parameters
    ----------
    chain : ExudynChain
    solver : str
        Name of an ``exu.DynamicSolverType`` (``'GeneralizedAlpha'``, ``'DOPRI5'``, ``'RK44'``, ...).
    h : float, optional
        Step size [s] (fixed-step solvers; for DOPRI5 the largest step, default ``t_end/10``).
    tol : float, optional
        Relative = absolute tolerance of the adaptive explicit solvers (DOPRI5, ODE23).
    sparse : bool
        Use the EigenSparse linear solver instead of the default dense one (implicit solvers).
    index2 : bool
        Generalized-α with velocity-level (index-2) constraints.
    spectral_radius : float
        Generalized-α ρ∞ (Exudyn default 0.9).
    """
    exu = chain.exu
    st = exu.SimulationSettings()
    ti = st.timeIntegration
    ti.endTime = t_end
    adaptive = solver in ("DOPRI5", "ODE23")
    if adaptive:
        ti.automaticStepSize = True
        ti.numberOfSteps = max(1, int(round(t_end / (h if h else t_end / 10))))
        ti.relativeTolerance = float(tol)
        ti.absoluteTolerance = float(tol)
    else:
        if h is None:
            raise ValueError(f"solve: the fixed-step solver {solver} needs h")
        ti.numberOfSteps = int(round(t_end / h))
    ti.verboseMode = 0
    ti.generalizedAlpha.spectralRadius = spectral_radius
    ti.generalizedAlpha.useIndex2Constraints = index2
    ti.generalizedAlpha.useNewmark = index2  # Exudyn requires Newmark/trapezoidal for index-2
    st.solutionSettings.writeSolutionToFile = False
    st.solutionSettings.sensorsWritePeriod = t_end
    st.displayComputationTime = False
    st.displayStatistics = False
    st.parallel.numberOfThreads = 1
    if sparse:
        st.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    # reset to the initial state
    mbs = chain.mbs
    mbs.systemData.SetODE2Coordinates(mbs.systemData.GetODE2Coordinates(configuration=exu.ConfigurationType.Initial),
                                      configuration=exu.ConfigurationType.Current)
    stype = getattr(exu.DynamicSolverType, solver)
    buf = io.StringIO()
    with redirect_stdout(buf):
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            ok = bool(mbs.SolveDynamic(st, solverType=stype))
            msg = ""
        except Exception as exc:  # Exudyn raises on Newton / linear-solver failure
            ok, msg = False, f"{type(exc).__name__}: {exc}"
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    steps = -1
    try:
        ds = mbs.sys["dynamicSolver"]
        steps = int(ds.it.currentStepIndex)
    except Exception:
        pass
    tip = chain.tip()
    if not np.all(np.isfinite(tip)):
        ok = False
    return ExudynRun(tip, wall, cpu, ok, steps, msg or buf.getvalue().strip()[-200:])
