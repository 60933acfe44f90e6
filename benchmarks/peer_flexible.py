r"""Side-by-side benchmark of flexible bodies: mbsuite vs Exudyn (floating frame of reference with modal reduction).

Run as ``python benchmarks/peer_flexible.py [--quick] [--cases ...] [--tools ...] [-o DIR]``
(default output ``benchmarks/out/``).  Exudyn is the optional ``bench`` extra
(``pip install -e '.[bench]'``); without it the peer columns stay empty and the script says so.

What is measured
----------------
Two cases of ``/work/shared/notes/flexible.md``, each built once in mbsuite and once in Exudyn
with **the same reduced component**: mbsuite's FE model (node coordinates, consistent mass and
stiffness ``fe.M``, ``fe.K``) and its mode basis ``modes.T`` are exported to Exudyn, not
recomputed there.

``spin-up`` (notes §3; Kane, Ryan & Banerjee 1987)
    :func:`core.flexible.models.spin_up_beam` with 20 Euler–Bernoulli elements and 4 cantilever
    modes, planar, **without geometric stiffening** (Exudyn's FFRF has none, so like is compared
    with like), hub angle :func:`core.flexible.models.spin_up_angle` (ω_s = 6 rad/s, T_s = 15 s),
    0–8 s.  Without stiffening the first bending mode, softened by −ω², loses its stiffness when the
    hub speed reaches ω₁ = 3.798 rad/s at t* = 8.512 s and the deflection then grows without bound;
    the run stops at 8 s, before that.  Quantity: the tip deflection in the hub frame,
    ``hub_frame_deflection`` (v = (r_tip − r_hub)·e₂(θ)), on a 0.1 s grid (81 times) and at 8 s.
``slider-crank`` (notes §4, set 2: rod straight and undeformed, rigid-body velocities; Simeon 1996)
    :func:`core.flexible.models.slider_crank_flexible` with 8 elements, Craig–Bampton on the end
    translations with 4 fixed-interface modes, rigid content removed (5 modal coordinates, mean
    axes), crank driven at Ω = 150 rad/s, 0–0.1 s.  Quantity: the rod's midpoint deflection from
    the chord, ``chord_deflection`` of the deformed nodes 0, 4, 8 (x̄ + Φ q_f) in the rod's frame
    (the deflection is frame-invariant), on a 0.5 ms grid (201 times) and at 0.1 s.

Exudyn model (``ObjectFFRFreducedOrder``, its C++ FFRF/CMS terms, no user function in the body)
    Exudyn's FFRF body is spatial only, so the planar mbsuite body becomes a spatial Exudyn body
    whose motion is held in the plane: the component is mbsuite's beam as a spatial FE model (the
    same :class:`~core.flexible.BeamSection`, ``straight_beam(..., dim=3)``; its in-plane block of M
    and K equals the planar model's exactly — asserted) with the planar mode basis lifted into the
    (u_x, u_y, θ_z) rows.  Exudyn's ``FEMinterface`` assumes nodes with translations only; a beam has
    nodal rotations too, so the inertia invariants (mass, centre of mass, inertia, ``mPhitTPsi``,
    ``mPhitTPsiTilde``, ``mPsiTildePsi``, ``mPsiTildePsiTilde``, ``mXRefTildePsi``,
    ``mXRefTildePsiTilde``) are computed here, from the same fields mbsuite uses (rigid translations,
    rigid rotations with the nodal rotations, the rotated mode fields, the modes; module
    :mod:`core.flexible.body`), and handed to the object.  Its mass matrix then equals mbsuite's to
    round-off (checked by :func:`check_exudyn_against_mbsuite` at a random state, reported).
    The reference frame is a ``NodeRigidBodyRxyz`` (Tait–Bryan angles; for rotations about z only
    the third angle is the rotation angle); ``CoordinateConstraint``\ s hold z, ψ_x, ψ_y at zero.

    * spin-up: the frame's x, y, z, ψ_x, ψ_y held, ψ_z = θ(t) by a ``CoordinateConstraint`` with
      an offset user function (Exudyn's symbolic user function — an expression tree evaluated in
      C++ — when it accepts the law, else a Python one; the table says which).
    * slider crank: the crank a rigid body (``ObjectRigidBody``, mass and inertia of mbsuite's crank)
      on its pivot, its angle ψ_z = Ω t likewise; the slider a mass point (``MassPoint``, m_rod/2) held
      on the x axis; the crank pin and the wrist pin ``ObjectJointSpherical`` with the in-plane
      axes constrained between the crank / slider and the rod's end nodes
      (``MarkerSuperElementPosition``).

    **Formulation difference (reported, not tuned away).**  Exudyn's reduced-order FFRF equations
    are derived for displacement-based solid elements, nodes with translations only (Zwölfer &
    Gerstmayr 2020, 2021), whose mass matrix has the form M = M_s ⊗ I₃.  For such M, terms bilinear in
    the frame's translational velocity and ω, in that velocity and q̇_f, in ω and q̇_f, and quadratic
    in q̇_f cancel identically, and Exudyn's equations leave them out.  A consistent beam mass matrix
    couples nodal translations and rotations, the terms do not cancel, and Exudyn given the exact
    invariants integrates equations that differ from the Lagrange equations of the same kinetic
    energy (mbsuite's) by exactly them (:func:`_missing_terms`; with them added, Exudyn's forces equal
    mbsuite's to round-off at a random state — the ``checks`` table).  In the spin-up the frame does not
    translate and the cantilever bending modes make the remaining terms vanish in the modal equations:
    they act on the hub's reaction only, the motion is the same.  In the slider crank the rod's frame
    translates and the terms act on the modes.  Their effect on the solution is measured (untimed):
    Exudyn with the terms added as a Python force user function, minus Exudyn as it is, at the same
    step (GeneralizedAlpha, h = 4 µs and 2 µs, Richardson-extrapolated); ``agreement`` compares
    mbsuite with Exudyn's reference plus that effect.

Accuracy and timing protocol (as ``peer_chain.py``)
    * Error = max over the output grid of |v − v_ref| divided by the peak max |v_ref| (relative to
      the peak), each code against **its own** tight reference, so that the error is each code's
      integration error alone; the end-time error is reported too.  mbsuite's reference:
      ``radau-projection`` (spin-up) or ``dop853-projection`` (slider crank) at rtol = atol = 1e-12,
      with a run at 1e-10 as its error estimate.  Exudyn's: ``GeneralizedAlpha`` (ρ∞ = 0.9) at h and
      h/2 (0.1 ms for the spin-up, 1 µs for the slider crank), Richardson-extrapolated (second
      order; the h/2 run's distance from the extrapolated value is its error estimate).  Target
      (``--target-spin-up``, ``--target-slider-crank``): 1e-6 of the peak for the spin-up (2.1e-6 m),
      1e-4 for the slider crank (2.0e-7 m; Exudyn's implicit methods are of second order and reach
      1e-5 at about 10 s a run, the README gives that run).
    * Each tool/solver/option set is a *configuration* whose accuracy knob (step h, a whole number of
      steps per output interval, or tol = rtol = atol) is swept loose → tight (h by 10^(1/4), tol by
      10^(1/2)) until the error meets the target, then the last interval is refined with three
      log-spaced points; the configuration's setting is the **loosest passing setting**.  A
      configuration is abandoned after a run longer than ``--max-run`` s or (before reaching the
      target) ``--prune`` times slower (CPU) than the best passing run of its tool.  Configurations
      within ``--time-within`` (2) times their tool's best screening time are timed: the **median of**
      ``--repeats`` (3) repeats, round-robin over the case's configurations, of the solve alone —
      ``core.simulation.simulate`` (set-up included, output at the grid times) for mbsuite,
      ``mbs.SolveDynamic`` (its ``exudynCPPfast`` module, no solution file, internal sensors on the
      modal coordinates and rates and, in the spin-up, on the frame, written at the grid times) for
      Exudyn.  Model building, Exudyn's ``Assemble`` and the evaluation of the quantity are outside
      the timed region.
    * The compiled (``jit-``) configurations run once, untimed, before the screening: numba compiles
      their kernels (or loads them from its disk cache) at the first call in a process.
    * One process, one thread (``OMP_NUM_THREADS`` etc. = 1 before numpy is imported; Exudyn
      ``numberOfThreads = 1``).  Ratio = mbsuite best median / Exudyn best median, on wall time and
      on process CPU time (``time.process_time``: the steadier figure on a shared machine).

Configurations
    mbsuite: the numpy ``radau-projection`` and ``dop853-projection`` and the compiled
    ``jit-dop853``, ``jit-dop853-projection``, ``jit-radau`` and ``jit-radau-projection``.  Both
    flexible bodies have the inertia of the deformed body, which the compiled integrators take as a
    mass group (its mass matrix M(q_f) rebuilt from the inertia invariants at every evaluation,
    :mod:`core.flexible.compiled`).  ``--methods`` takes any registered method.
    Exudyn (``--exudyn-set full``): ``GeneralizedAlpha`` (ρ∞ = 0.9, Exudyn's default, and 0.5) and
    ``TrapezoidalIndex2`` with modified Newton and ``EXUdense`` (Exudyn's defaults), the same with
    ``EigenSparse``, and GeneralizedAlpha ρ∞ = 0.9 and TrapezoidalIndex2 with full Newton, fixed step;
    ``basic``: the first three.  The explicit ``DOPRI5``, ``ODE23`` (adaptive), ``RK67`` and ``RK44``
    (fixed step) are probed and listed as unavailable with the reason: in the spin-up Exudyn's explicit
    solvers eliminate the coordinate constraints to ground as fixed coordinates and ignore the offset
    user function of the drive (the hub stays at ψ_z = 0 in the probe: a wrong answer, not a slow
    one); in the slider crank they refuse the joints (``ModelError``).

Agreement between the two codes (``agreement`` table)
    The two references against each other (max |v_mbsuite − v_Exudyn| over the grid, absolute and
    relative to the peak, and at the end time); for the slider crank also mbsuite against Exudyn's
    reference plus the effect of the missing terms.

Outputs (CSV + Markdown via ``core.results.write_table``): ``peer_flexible_summary`` (per case and
tool: best configuration, setting, errors, median wall and CPU time, ratios, processor),
``peer_flexible_configs`` (every configuration), ``peer_flexible_sweep`` (every screening run),
``peer_flexible_references``, ``peer_flexible_agreement``, ``peer_flexible_checks``, and the log
``peer_flexible_log.txt``.

References
----------
T. R. Kane, R. R. Ryan, A. K. Banerjee, J. Guidance 10(2):139–151, 1987 (spin-up).  B. Simeon,
Math. Modelling of Systems 2 (1996) 1–18 (slider crank).  J. Gerstmayr, Multibody Syst. Dyn. 60
(2024) 533–561 (Exudyn); A. Zwölfer, J. Gerstmayr, "A concise nodal-based derivation of the floating
frame of reference formulation for displacement-based solid finite elements", Multibody Syst. Dyn.
(2020), doi:10.1007/s11044-019-09716-x, and "The nodal-based floating frame of reference formulation
with modal reduction", Acta Mech. (2021) (Exudyn's ``ObjectFFRFreducedOrder``);
Exudyn 1.13 documentation, items ``ObjectFFRFreducedOrder``, ``ObjectConnectorCoordinate``,
``ObjectJointSpherical``, ``MarkerSuperElementPosition``; ``exudyn.FEM.ObjectFFRFreducedOrderInterface``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS",
             "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import io  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from contextlib import redirect_stdout  # noqa: E402
from dataclasses import dataclass, field, replace  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Callable  # noqa: E402

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import scipy.sparse as sp  # noqa: E402

_HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(_HERE.parent))
sys.path.insert(0, str(_HERE))

import _exudyn_chain as exc  # noqa: E402
from core.flexible import FEModel, straight_beam  # noqa: E402
from core.flexible.models import (KANE_SPIN_UP, SIMEON_ROD, chord_deflection, hub_frame_deflection,  # noqa: E402
                                  slider_crank_flexible, spin_up_angle, spin_up_beam)
from core.integrators import METHODS, simulate  # noqa: E402
from core.results import write_table  # noqa: E402

EXUDYN_MISSING = "Exudyn not installed: peer columns empty"
UNAVAILABLE = "unavailable: "
TOOLS = ("mbsuite", "exudyn")
MBSUITE_METHODS = ("radau-projection", "dop853-projection", "jit-dop853", "jit-dop853-projection", "jit-radau",
                   "jit-radau-projection")
LIFT_2D_TO_3D = np.array([0, 1, 5])  # planar (u_x, u_y, θ_z) → spatial (u_x, u_y, u_z, θ_x, θ_y, θ_z)


# ------------------------------------------------------------------------------------------
# the cases: mbsuite models and the quantity
# ------------------------------------------------------------------------------------------


@dataclass
class Case:
    """One benchmark case: the mbsuite model, its flexible body's component, the output grid and the target."""

    name: str
    title: str
    model: object
    t_end: float
    grid: np.ndarray
    target: float  # relative to the peak
    quantity: str
    fe2: FEModel = None  # the planar component (rebuilt from the body's beam data)
    T2: np.ndarray = None  # the planar mode basis (modes.T), rows (u_x, u_y, θ_z) per node
    body: object = None  # the flexible body's record in the model


def _component(model):
    """The flexible body's FE model and mode basis as mbsuite uses them (``modes.T`` and the beam's ``fe.M``, ``fe.K``)."""
    rec = model.flexible[0]
    d = rec.data
    mesh, section, theory = d.beam
    fe = FEModel.from_beam(mesh, section, theory)
    T = np.asarray(d.T, float)
    # the body's reduced mass is exactly Tᵀ M T of this FE model (the component as mbsuite built it)
    Mr = T.T @ (fe.M @ T)
    assert np.allclose(Mr, d.gram[-d.n_modes:, -d.n_modes:], rtol=1e-12, atol=1e-12 * np.abs(Mr).max())
    return rec, fe, T


def spin_up_case(target: float) -> Case:
    model = spin_up_beam(n_elements=20, n_modes=4, geometric_stiffening=False)
    rec, fe, T = _component(model)
    return Case("spin-up", "spin-up beam, 20 elements, 4 cantilever modes, no stiffening, 0-8 s", model, 8.0,
                np.round(np.linspace(0.0, 8.0, 81), 12), target, "tip deflection in the hub frame [m]", fe, T, rec)


def slider_crank_case(target: float) -> Case:
    model = slider_crank_flexible(n_elements=8, n_modes=4)
    rec, fe, T = _component(model)
    return Case("slider-crank", "slider crank, rod 8 elements, Craig-Bampton 1+4 modes (mean axes), set 2, 0-0.1 s",
                model, 0.1, np.round(np.linspace(0.0, 0.1, 201), 12), target,
                "midpoint deflection from the chord [m]", fe, T, rec)


def quantity_from_modes(case: Case, t: np.ndarray, frame: np.ndarray, qf: np.ndarray) -> np.ndarray:
    """The case's quantity from the frame coordinates (x, y, θ) (n, 3) and modal coordinates (n, m).

    spin-up: ``hub_frame_deflection`` of the tip r + A(θ)(x̄_tip + Φ_tip q_f) with the hub angle of the
    law at t; slider crank: ``chord_deflection`` of nodes 0, N/2, N at x̄ + Φ q_f in the rod frame.
    """
    X = np.asarray(case.fe2.nodes, float)
    N = X.shape[0]

    def node(i):  # (n, 2) deformed position of node i in the frame
        return X[i][None, :] + qf @ case.T2[3 * i:3 * i + 2].T

    if case.name == "spin-up":
        loc = node(N - 1)
        c, s = np.cos(frame[:, 2]), np.sin(frame[:, 2])
        tip = frame[:, :2] + np.stack([c * loc[:, 0] - s * loc[:, 1], s * loc[:, 0] + c * loc[:, 1]], 1)
        theta = np.array([spin_up_angle()(ti)[0] for ti in t])
        return hub_frame_deflection(tip, theta, KANE_SPIN_UP["length"])[0]
    return chord_deflection(node(0), node((N - 1) // 2), node(N - 1))


def mbsuite_quantity(case: Case, t: np.ndarray, q: np.ndarray) -> np.ndarray:
    rec = case.body
    return quantity_from_modes(case, t, q[:, rec.qi[:3]], q[:, rec.qi[3:]])


# ------------------------------------------------------------------------------------------
# export of the component to Exudyn
# ------------------------------------------------------------------------------------------


def spatial_component(case: Case) -> tuple[FEModel, np.ndarray]:
    """The planar component as a spatial beam FE model (same section and mesh) and the lifted mode basis.

    Asserts that the spatial model's (u_x, u_y, θ_z) block of M and K is the planar M and K.
    """
    mesh, section, theory = case.body.data.beam
    X = np.asarray(mesh.nodes, float)
    N = X.shape[0]
    mesh3 = straight_beam(float(np.linalg.norm(X[-1] - X[0])), mesh.elements.shape[0], dim=3)
    assert np.allclose(mesh3.nodes[:, :2], X) and not np.any(mesh3.nodes[:, 2])
    fe3 = FEModel.from_beam(mesh3, section, theory)
    rows = (6 * np.arange(N)[:, None] + LIFT_2D_TO_3D[None, :]).ravel()
    for name in ("M", "K"):
        A3, A2 = getattr(fe3, name).toarray(), getattr(case.fe2, name).toarray()
        assert np.array_equal(A3[np.ix_(rows, rows)], A2), f"spatial and planar {name} differ in the plane"
    T3 = np.zeros((6 * N, case.T2.shape[1]))
    T3[rows] = case.T2
    return fe3, T3


def ffrf_invariants(fe3: FEModel, T3: np.ndarray) -> dict:
    """Exudyn's ``ObjectFFRFreducedOrder`` data for a component with 6 degrees of freedom per node.

    With M the FE mass matrix and, on the nodal vector (u, θ) of every node, Φ_t the rigid translations,
    R the rigid rotations (e_j × x̄ on the translations, e_j on the nodal rotations), G_k the rotated
    mode k (e_j × φ_k, e_j × ψ_k) and Ψ the modes: Exudyn's x̃_ref is −R and Ψ̃ = −[G_1 … G_m], so
    mass = (Φ_tᵀ M Φ_t)₁₁, inertia = Rᵀ M R, mPhitTPsi = Φ_tᵀ M Ψ, mPhitTPsiTilde = −Φ_tᵀ M G,
    mPsiTildePsi = −Gᵀ M Ψ, mPsiTildePsiTilde = Gᵀ M G, mXRefTildePsi = −Rᵀ M Ψ,
    mXRefTildePsiTilde = Rᵀ M G and the centre of mass from Φ_tᵀ M R = −skew(m c) (what
    ``exudyn.FEM.ObjectFFRFreducedOrderInterface`` computes for translation-only nodes, and mbsuite's
    matrix W of :mod:`core.flexible.body`).
    """
    X = np.asarray(fe3.nodes, float)
    N, m = X.shape[0], T3.shape[1]
    M = sp.csr_matrix(fe3.M)
    E = np.eye(3)
    tr = (6 * np.arange(N)[:, None] + np.arange(3)).ravel()
    ro = tr + 3
    Rt, Rr, G = np.zeros((6 * N, 3)), np.zeros((6 * N, 3)), np.zeros((6 * N, 3 * m))
    for j in range(3):
        Rt[tr[j::3], j] = 1.0
        Rr[tr, j] = np.cross(E[j], X).ravel()
        Rr[ro[j::3], j] = 1.0
        for k in range(m):
            G[tr, 3 * k + j] = np.cross(E[j], T3[tr, k].reshape(N, 3)).ravel()
            G[ro, 3 * k + j] = np.cross(E[j], T3[ro, k].reshape(N, 3)).ravel()
    MRt, MRr, MG, MT = M @ Rt, M @ Rr, M @ G, M @ T3
    mass = float(Rt[:, 0] @ MRt[:, 0])
    assert np.allclose(Rt.T @ MRt, mass * np.eye(3), rtol=1e-12, atol=1e-12 * mass)
    C = Rt.T @ MRr  # = -skew(m c)
    mc = -np.array([C[2, 1] - C[1, 2], C[0, 2] - C[2, 0], C[1, 0] - C[0, 1]]) / 2.0
    Mff, Kff = T3.T @ MT, T3.T @ (sp.csr_matrix(fe3.K) @ T3)
    return dict(mass=mass, centerOfMass=mc / mass, inertia=Rr.T @ MRr, Mff=0.5 * (Mff + Mff.T),
                Kff=0.5 * (Kff + Kff.T), mPhitTPsi=Rt.T @ MT, mPhitTPsiTilde=-(Rt.T @ MG), mPsiTildePsi=-(G.T @ MT),
                mPsiTildePsiTilde=G.T @ MG, mXRefTildePsi=-(Rr.T @ MT), mXRefTildePsiTilde=Rr.T @ MG,
                modeBasis=T3[tr], referencePositions=X.ravel())


def _missing_terms(inv: dict, A: np.ndarray, Rdot: np.ndarray, w: np.ndarray, qfd: np.ndarray, G: np.ndarray):
    """The generalized forces (right-hand side, Exudyn's coordinate order: frame translation, rotation
    parameters, modes) that Exudyn's reduced-order FFRF equations omit for a component whose mass
    matrix is not of the form M_s ⊗ I₃ (module docstring).  With S_k = Φ_tᵀ M ψ_k, P_k = Φ_tᵀ M Ψ̃_k
    (``mPhitTPsiTilde`` block k), B_k = −(``mPsiTildePsi`` block k) = G_kᵀ M Ψ (3 × m), V̄ = Aᵀ ṙ and ω̄
    in body axes:

        translation  −A Σ_k q̇_k (ω̄ × S_k + P_k ω̄)
        rotation     −Gᵀ Σ_k q̇_k (V̄ × S_k − P_kᵀ V̄ + B_k q̇)
        mode k       S_k · (ω̄ × V̄) − (P_k ω̄) · V̄ + Σ_j q̇_j (B_jᵀ ω̄)_k + ω̄ᵀ B_k q̇

    Each vanishes when P_k = skew(S_k) and B_j[:, k] = −B_k[:, j], which holds for M = M_s ⊗ I₃
    (nodes with translations only, consistent solid or lumped masses: what Exudyn's equations assume);
    the translation–rotation coupling of a consistent beam mass matrix breaks both.  These are the
    differences of the Lagrange equations of T = ½ wᵀ M w (mbsuite's, :mod:`core.flexible.body`) from
    Exudyn's ``ObjectFFRFreducedOrder`` terms given the same invariants (checked to round-off by
    :func:`check_exudyn_against_mbsuite`)."""
    S = inv["mPhitTPsi"]
    m = S.shape[1]
    P3 = inv["mPhitTPsiTilde"].reshape(3, m, 3)  # P3[:, k, :] = P_k
    B3 = -inv["mPsiTildePsi"].reshape(m, 3, m)  # B3[k] = B_k
    V = A.T @ Rdot
    Sq = S @ qfd
    Pq = np.einsum("ikj,k->ij", P3, qfd)  # Σ_k q̇_k P_k
    Bq = np.einsum("kij,k->ij", B3, qfd)  # Σ_k q̇_k B_k
    ft = np.cross(w, Sq) + Pq @ w
    fr = np.cross(V, Sq) - Pq.T @ V + Bq @ qfd
    fm = S.T @ np.cross(w, V) - np.einsum("ikj,j,i->k", P3, w, V) + Bq.T @ w + np.einsum("i,kij,j->k", w, B3, qfd)
    return np.concatenate([-A @ ft, -G.T @ fr, fm])


# ------------------------------------------------------------------------------------------
# Exudyn models
# ------------------------------------------------------------------------------------------


@dataclass
class ExudynModel:
    """A built and assembled Exudyn model of a case (module docstring)."""

    exu: object
    SC: object
    mbs: object
    case: Case
    n_frame: object  # the flexible body's rigid-body node (Rxyz)
    n_modes: object  # its NodeGenericODE2 (modal coordinates)
    o_body: object
    s_modes: object = None  # sensors: modal coordinates and rates, frame coordinates
    s_modes_t: object = None
    s_frame: object = None
    drive: str = ""  # how the prescribed angle is given (symbolic / Python user function)
    keep: list = field(default_factory=list)  # symbolic user functions must stay alive
    inv: dict = field(default_factory=dict)
    frame_ref: np.ndarray = field(default_factory=lambda: np.zeros(3))


def _add_ffrf(mbs, ii, exu, inv, position, velocity=(0.0, 0.0, 0.0), omega_z=0.0):
    m = inv["Mff"].shape[0]
    n_frame = mbs.AddNode(ii.NodeRigidBodyRxyz(referenceCoordinates=list(position) + [0.0, 0.0, 0.0],
                                               initialVelocities=list(velocity) + [0.0, 0.0, omega_z]))
    n_modes = mbs.AddNode(ii.NodeGenericODE2(numberOfODE2Coordinates=m, referenceCoordinates=[0.0] * m,
                                             initialCoordinates=[0.0] * m, initialCoordinates_t=[0.0] * m))
    Mc, Kc = exu.MatrixContainer(), exu.MatrixContainer()
    Mc.SetWithDenseMatrix(inv["Mff"], useDenseMatrix=False)
    Kc.SetWithDenseMatrix(inv["Kff"], useDenseMatrix=False)
    keys = ("mPsiTildePsi", "mPsiTildePsiTilde", "mPhitTPsi", "mPhitTPsiTilde", "mXRefTildePsi", "mXRefTildePsiTilde")
    o = mbs.AddObject(ii.ObjectFFRFreducedOrder(
        nodeNumbers=[n_frame, n_modes], massMatrixReduced=Mc, stiffnessMatrixReduced=Kc,
        modeBasis=inv["modeBasis"], referencePositions=inv["referencePositions"], mass=inv["mass"],
        inertia=inv["inertia"], centerOfMass=list(inv["centerOfMass"]), **{k: inv[k] for k in keys},
        visualization=ii.VObjectFFRFreducedOrder(show=False)))
    return n_frame, n_modes, o


def _hold(mbs, ii, node, coords, ground_marker):
    """CoordinateConstraints holding the node's coordinates ``coords`` at their reference values."""
    out = []
    for c in coords:
        mk = mbs.AddMarker(ii.MarkerNodeCoordinate(nodeNumber=node, coordinate=c))
        out.append(mbs.AddObject(ii.CoordinateConstraint(markerNumbers=[ground_marker, mk],
                                                         visualization=ii.VCoordinateConstraint(show=False))))
    return out


def _drive(mbs, exu, ii, node, coord, ground_marker, laws):
    """ψ_z of ``node`` = θ(t): a CoordinateConstraint whose offset and offset rate (for the index-2 solvers)
    are user functions, symbolic (an expression tree evaluated in C++) when Exudyn records them, else Python.

    ``laws`` = ((θ, θ̇) symbolic, (θ, θ̇) Python)."""
    (sym_f, sym_ft), (py_f, py_ft) = laws
    mk = mbs.AddMarker(ii.MarkerNodeCoordinate(nodeNumber=node, coordinate=coord))
    co = mbs.AddObject(ii.CoordinateConstraint(markerNumbers=[ground_marker, mk], offsetUserFunction=py_f,
                                               offsetUserFunction_t=py_ft,
                                               visualization=ii.VCoordinateConstraint(show=False)))
    try:
        from exudyn.advancedUtilities import CreateSymbolicUserFunction

        kept = []
        with redirect_stdout(io.StringIO()):
            for name, f in (("offsetUserFunction", sym_f), ("offsetUserFunction_t", sym_ft)):
                sym = CreateSymbolicUserFunction(mbs, f, name, co)
                mbs.SetObjectParameter(co, name, sym)
                kept.append(sym)
        return co, "symbolic user function", kept
    except Exception as exc:  # older Exudyn or an expression it cannot record: keep the Python functions
        mbs.SetObjectParameter(co, "offsetUserFunction", py_f)
        mbs.SetObjectParameter(co, "offsetUserFunction_t", py_ft)
        return co, f"Python user function (symbolic refused: {type(exc).__name__}: {str(exc)[:80]})", []


def _sensors(xm: ExudynModel, ii, with_frame: bool):
    mbs, exu = xm.mbs, xm.exu
    xm.s_modes = mbs.AddSensor(ii.SensorNode(nodeNumber=xm.n_modes, storeInternal=True, writeToFile=False,
                                             outputVariableType=exu.OutputVariableType.Coordinates))
    xm.s_modes_t = mbs.AddSensor(ii.SensorNode(nodeNumber=xm.n_modes, storeInternal=True, writeToFile=False,
                                               outputVariableType=exu.OutputVariableType.Coordinates_t))
    if with_frame:
        xm.s_frame = mbs.AddSensor(ii.SensorNode(nodeNumber=xm.n_frame, storeInternal=True, writeToFile=False,
                                                 outputVariableType=exu.OutputVariableType.Coordinates))


def build_exudyn(case: Case, missing_terms: bool = False) -> ExudynModel:
    """Build and assemble the case in Exudyn (module docstring).  ``missing_terms`` adds the terms of
    :func:`_missing_terms` as a Python force user function on the flexible body (cross-check only)."""
    exu = exc.load_exudyn()
    if exu is None:
        raise ImportError("exudyn is not installed (pip install 'mbsuite[bench]')")
    import exudyn.itemInterface as ii

    fe3, T3 = spatial_component(case)
    inv = ffrf_invariants(fe3, T3)
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    n_ground = mbs.AddNode(ii.NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
    m_ground = mbs.AddMarker(ii.MarkerNodeCoordinate(nodeNumber=n_ground, coordinate=0))
    keep = []
    if case.name == "spin-up":
        k = KANE_SPIN_UP
        if case.t_end > k["T_s"]:
            raise ValueError("the closed-form spin-up law used in Exudyn is that of t < T_s")
        w_s, T_s = k["omega_s"], k["T_s"]
        c = 2.0 * np.pi / T_s
        import math

        esym = exu.symbolic

        def law_sym(mbs, t, itemNumber, lOffset):
            return w_s / T_s * (t * t / 2.0 + (esym.cos(c * t) - 1.0) / c**2)

        def law_sym_t(mbs, t, itemNumber, lOffset):
            return w_s / T_s * (t - esym.sin(c * t) / c)

        def law_py(mbs, t, itemNumber, lOffset):
            return w_s / T_s * (t * t / 2.0 + (math.cos(c * t) - 1.0) / c**2)

        def law_py_t(mbs, t, itemNumber, lOffset):
            return w_s / T_s * (t - math.sin(c * t) / c)

        laws = ((law_sym, law_sym_t), (law_py, law_py_t))
        n_frame, n_modes, o = _add_ffrf(mbs, ii, exu, inv, (0.0, 0.0, 0.0))
        _hold(mbs, ii, n_frame, range(5), m_ground)
        _, drive, kept = _drive(mbs, exu, ii, n_frame, 5, m_ground, laws)
        keep += kept
        frame_ref = np.zeros(3)
    elif case.name == "slider-crank":
        p = SIMEON_ROD
        l1, l2, w = p["l1"], p["l2"], p["omega"]
        A, B = np.array([l1, 0.0, 0.0]), np.array([l1 + l2, 0.0, 0.0])

        def law(mbs, t, itemNumber, lOffset):
            return w * t

        def law_t(mbs, t, itemNumber, lOffset):
            return w + 0.0 * t  # an expression in t, so that Exudyn can record it symbolically

        laws = ((law, law_t), (law, law_t))
        # crank on its pivot: node at the pivot, centre of mass at l1/2, inertia J1 about the pivot
        n_crank = mbs.AddNode(ii.NodeRigidBodyRxyz(referenceCoordinates=[0.0] * 6,
                                                   initialVelocities=[0.0] * 5 + [w]))
        J1 = p["J1"]
        o_crank = mbs.AddObject(ii.ObjectRigidBody(nodeNumber=n_crank, mass=p["m1"],
                                                   inertia=[1e-3 * J1, J1, J1, 0.0, 0.0, 0.0],
                                                   centerOfMass=[l1 / 2, 0.0, 0.0],
                                                   visualization=ii.VObjectRigidBody(show=False)))
        _hold(mbs, ii, n_crank, range(5), m_ground)
        _, drive, kept = _drive(mbs, exu, ii, n_crank, 5, m_ground, laws)
        keep += kept
        w2 = -l1 * w / l2
        n_frame, n_modes, o = _add_ffrf(mbs, ii, exu, inv, A, velocity=(0.0, l1 * w, 0.0), omega_z=w2)
        _hold(mbs, ii, n_frame, (2, 3, 4), m_ground)
        m_rod = p["rho"] * case.body.data.beam[1].A * l2
        n_slider = mbs.AddNode(ii.NodePoint(referenceCoordinates=list(B)))
        o_slider = mbs.AddObject(ii.MassPoint(nodeNumber=n_slider, mass=m_rod / 2,
                                              visualization=ii.VMassPoint(show=False)))
        _hold(mbs, ii, n_slider, (1, 2), m_ground)
        N = fe3.nodes.shape[0]
        m_pin = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=o_crank, localPosition=[l1, 0.0, 0.0]))
        m_rod_a = mbs.AddMarker(ii.MarkerSuperElementPosition(bodyNumber=o, meshNodeNumbers=[0], weightingFactors=[1.0]))
        m_rod_b = mbs.AddMarker(ii.MarkerSuperElementPosition(bodyNumber=o, meshNodeNumbers=[N - 1],
                                                              weightingFactors=[1.0]))
        m_sl = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=o_slider, localPosition=[0.0, 0.0, 0.0]))
        for pair in ([m_pin, m_rod_a], [m_rod_b, m_sl]):
            mbs.AddObject(ii.ObjectJointSpherical(markerNumbers=pair, constrainedAxes=[1, 1, 0],
                                                  visualization=ii.VObjectJointSpherical(show=False)))
        frame_ref = np.array([A[0], A[1], 0.0])
    else:
        raise ValueError(f"unknown case {case.name!r}")
    xm = ExudynModel(exu, SC, mbs, case, n_frame, n_modes, o, drive=drive, keep=keep, inv=inv, frame_ref=frame_ref)
    if missing_terms:
        import math

        def uf_force(mbs, t, itemIndex, q, q_t):
            # Exudyn's Tait-Bryan (xyz) frame: A = A_x A_y A_z, local G (exudyn.rigidBodyUtilities.RotXYZ2GLocal)
            c0, s0, c1, s1 = math.cos(q[3]), math.sin(q[3]), math.cos(q[4]), math.sin(q[4])
            c2, s2 = math.cos(q[5]), math.sin(q[5])
            A3 = np.array([[c1 * c2, -c1 * s2, s1], [s0 * s1 * c2 + c0 * s2, -s0 * s1 * s2 + c0 * c2, -s0 * c1],
                           [-c0 * s1 * c2 + s0 * s2, c0 * s1 * s2 + s0 * c2, c0 * c1]])
            G = np.array([[c1 * c2, s2, 0.0], [-c1 * s2, c2, 0.0], [s1, 0.0, 1.0]])
            q_t = np.asarray(q_t)
            return _missing_terms(inv, A3, q_t[:3], G @ q_t[3:6], q_t[6:], G)

        mbs.SetObjectParameter(o, "forceUserFunction", uf_force)
        xm.keep.append(uf_force)
    _sensors(xm, ii, with_frame=case.name == "spin-up")
    with redirect_stdout(io.StringIO()):
        mbs.Assemble()
    return xm


@dataclass
class ExudynRun:
    """One Exudyn solve: the sampled states and the timing."""

    t: np.ndarray
    frame: np.ndarray  # (n, 3): x, y, ψ_z of the flexible body's frame
    qf: np.ndarray
    qf_t: np.ndarray
    wall: float
    cpu: float
    ok: bool
    message: str
    steps: int = -1
    jacobians: int = -1
    rejected: int = -1
    unavailable: bool = False


def exudyn_solve(xm: ExudynModel, opts, h: float | None = None, tol: float | None = None,
                 write_period: float | None = None, t_end: float | None = None) -> ExudynRun:
    """Run one Exudyn dynamic solve of ``xm`` from its initial state, timing ``mbs.SolveDynamic`` alone.

    Sensors write at the grid spacing (``write_period``: 0 = every step).  A run counts as failed when
    Exudyn raises or returns False, stops before t_end or leaves non-finite coordinates; ``unavailable``
    when it refuses the configuration (``ModelError``, ``NotImplementedFeatureError``, ``ExudynValueError``).
    """
    exu, mbs, case = xm.exu, xm.mbs, xm.case
    t_end = case.t_end if t_end is None else t_end
    st = exc._settings(exu, opts, h, tol, t_end)
    st.solution.sensors.active = True
    st.solution.sensors.writePeriod = float(case.grid[1] - case.grid[0]) if write_period is None else write_period
    cfg = exu.ConfigurationType
    mbs.systemData.SetODE2Coordinates(mbs.systemData.GetODE2Coordinates(configuration=cfg.Initial),
                                      configuration=cfg.Current)
    mbs.systemData.SetODE2Coordinates_t(mbs.systemData.GetODE2Coordinates_t(configuration=cfg.Initial),
                                        configuration=cfg.Current)
    mbs.sys.pop("dynamicSolver", None)
    stype = getattr(exu.DynamicSolverType, opts.solver)
    refused = tuple(getattr(exu, n) for n in ("ModelError", "NotImplementedFeatureError", "ExudynValueError")
                    if hasattr(exu, n))
    buf = io.StringIO()
    unavailable = False
    with redirect_stdout(buf):
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            ok, msg = bool(mbs.SolveDynamic(st, solverType=stype)), ""
        except Exception as exc_:  # Exudyn raises on Newton failures and on refused models
            ok, msg = False, f"{type(exc_).__name__}: {exc_}"
            unavailable = isinstance(exc_, refused)
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
    if ok and not abs(t_reached - t_end) <= 1e-9 * max(1.0, t_end):
        ok, msg = False, msg or f"stopped at t = {t_reached:.6g} s"
    out = buf.getvalue().strip()
    if not msg and out:
        msg = out.replace("\n", " | ")[-200:]
    try:
        dq = np.atleast_2d(np.asarray(mbs.GetSensorStoredData(xm.s_modes)))
        dqt = np.atleast_2d(np.asarray(mbs.GetSensorStoredData(xm.s_modes_t)))
        t = dq[:, 0]
        frame = np.tile(xm.frame_ref, (len(t), 1))
        if xm.s_frame is not None:
            df = np.atleast_2d(np.asarray(mbs.GetSensorStoredData(xm.s_frame)))
            frame = frame + df[:, [1, 2, 6]]
        qf, qf_t = dq[:, 1:], dqt[:, 1:]
    except Exception as exc_:
        t, frame, qf, qf_t = np.zeros(0), np.zeros((0, 3)), np.zeros((0, 0)), np.zeros((0, 0))
        ok, msg = False, msg or f"no sensor data ({exc_})"
    if ok and not np.all(np.isfinite(qf)):
        ok, msg = False, "non-finite modal coordinates"
    return ExudynRun(t, frame, qf, qf_t, wall, cpu, ok, msg, steps, jac, rej, unavailable)


# ------------------------------------------------------------------------------------------
# mbsuite runs
# ------------------------------------------------------------------------------------------


@dataclass
class MbsuiteRun:
    t: np.ndarray
    q: np.ndarray
    wall: float
    cpu: float
    ok: bool
    message: str
    info: str = ""
    unavailable: bool = False


def mbsuite_solve(case: Case, method: str, setting: float, fixed: bool) -> MbsuiteRun:
    """``simulate`` of the case's model with ``method`` (h = setting, or rtol = atol = setting), output at
    the grid times; the solve alone is timed (the model is built beforehand)."""
    kw = dict(h=setting) if fixed else dict(rtol=setting, atol=setting)
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = simulate(case.model, (0.0, case.t_end), method, t_eval=case.grid, compute_multipliers=False, **kw)
    except Exception as exc_:  # a refusal (ModelError naming the reason) or a crash: a failed run with its message
        from core.errors import ModelError, NotCompilable

        return MbsuiteRun(np.zeros(0), np.zeros((0, 0)), time.perf_counter() - t0, time.process_time() - c0, False,
                          f"{type(exc_).__name__}: {exc_}", unavailable=isinstance(exc_, (ModelError, NotCompilable)))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    ok = res.success and abs(res.t[-1] - case.t_end) < 1e-12 and len(res.t) == len(case.grid)
    c = res.counters
    info = f"steps={c['n_steps']} rhs={c['n_rhs']} fact={c['n_factor']}"
    return MbsuiteRun(np.asarray(res.t), np.asarray(res.q), wall, cpu, ok, "" if ok else res.message, info)


# ------------------------------------------------------------------------------------------
# the two formulations at one state
# ------------------------------------------------------------------------------------------


def check_exudyn_against_mbsuite(xm: ExudynModel, seed: int = 1) -> dict:
    """Mass matrix and forces of the flexible body in Exudyn against mbsuite's at a random state.

    The frame at (x, y, ψ_z), velocities (ẋ, ẏ, ω_z), modal coordinates and rates random; the in-plane
    rows and columns (x, y, ψ_z, q_f) of Exudyn's system mass matrix and of its ODE2 right-hand side
    (the flexible body's rows; no gravity, no constraint forces) against
    :meth:`core.flexible.body.FlexibleBodyData.mass_and_forces`.  Returns the largest differences
    relative to the largest entry: mass matrix, forces as Exudyn computes them, forces with
    :func:`_missing_terms` added, and the modal forces alone with the frame not translating (ṙ = 0,
    as the spin-up's hub), relative to the largest modal force.
    """
    exu, mbs, case = xm.exu, xm.mbs, xm.case
    data = case.body.data
    m = data.n_modes
    rng = np.random.default_rng(seed)
    scale = np.abs(case.T2).max()
    qf = rng.normal(size=m) * 0.01 / scale
    qfd = rng.normal(size=m) * 1.0 / scale
    x, y, th, xd, yd, w = 0.3, -0.2, 0.7, 0.5, -1.0, 2.0
    u0 = np.asarray(mbs.systemData.GetODE2Coordinates(configuration=exu.ConfigurationType.Initial))
    v0 = np.asarray(mbs.systemData.GetODE2Coordinates_t(configuration=exu.ConfigurationType.Initial))
    i_f, i_m = mbs.GetNodeODE2Index(xm.n_frame), mbs.GetNodeODE2Index(xm.n_modes)
    u, v = u0.copy(), v0.copy()
    u[i_f:i_f + 6] = [x, y, 0.0, 0.0, 0.0, th]
    v[i_f:i_f + 6] = [xd, yd, 0.0, 0.0, 0.0, w]
    u[i_m:i_m + m], v[i_m:i_m + m] = qf, qfd
    solver = exu.MainSolverImplicitSecondOrder()
    st = exu.SimulationSettings()
    st.timeIntegration.verboseMode = 0
    st.solution.sensors.active = False
    rows = np.r_[i_f, i_f + 1, i_f + 5, i_m + np.arange(m)]
    A2 = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    A3 = np.eye(3)
    A3[:2, :2] = A2
    out = {}
    for still in (False, True):  # the frame translating, and not (ṙ = 0, as the spin-up's hub)
        rd = np.zeros(2) if still else np.array([xd, yd])
        v[i_f:i_f + 2] = rd
        with redirect_stdout(io.StringIO()):
            solver.InitializeSolver(mbs, st)
            mbs.systemData.SetODE2Coordinates(list(u))
            mbs.systemData.SetODE2Coordinates_t(list(v))
            solver.ComputeMassMatrix(mbs)
            Mx = np.asarray(solver.GetSystemMassMatrix())
            solver.ComputeODE2RHS(mbs)
            fx = np.asarray(solver.GetSystemResidual())[:len(u)]
            solver.FinalizeSolver(mbs, st)
        mbs.sys.pop("dynamicSolver", None)
        Mb, rhs = data.mass_and_forces(A2, rd, np.array([w]), qf, qfd, np.zeros(2))
        corr = _missing_terms(xm.inv, A3, np.r_[rd, 0.0], np.array([0.0, 0.0, w]), qfd, np.eye(3))
        corr = corr[[0, 1, 5] + list(6 + np.arange(m))]
        if still:
            modal = slice(3, None)
            out["modal forces, frame not translating"] = float(np.abs(fx[rows][modal] - rhs[modal]).max()
                                                               / np.abs(rhs[modal]).max())
        else:
            scale_f = np.abs(rhs).max()
            out.update({"mass matrix": float(np.abs(Mx[np.ix_(rows, rows)] - Mb).max() / np.abs(Mb).max()),
                        "forces": float(np.abs(fx[rows] - rhs).max() / scale_f),
                        "forces + missing terms": float(np.abs(fx[rows] + corr - rhs).max() / scale_f)})
    mbs.systemData.SetODE2Coordinates(list(u0))  # back to the initial state
    mbs.systemData.SetODE2Coordinates_t(list(v0))
    return out


# ------------------------------------------------------------------------------------------
# configurations
# ------------------------------------------------------------------------------------------


@dataclass
class Config:
    """One tool + solver + options with an accuracy knob to sweep (``peer_chain.Config``)."""

    tool: str
    label: str
    knob: str  # "h" or "tol"
    run: Callable  # setting -> (t, v, wall, cpu, ok, info, unavailable)
    loosest: float
    tightest: float
    sweep: list = field(default_factory=list)
    chosen: tuple | None = None  # (setting, error, screening cpu)
    times: list = field(default_factory=list)
    cpu_times: list = field(default_factory=list)
    note: str = ""


def _grid(cfg: Config, dt: float) -> list[float]:
    """Loose → tight settings: h by 10^(1/4) (a whole number of steps per output interval dt), tol by 10^(1/2)."""
    f = 10 ** (-0.25) if cfg.knob == "h" else 10 ** (-0.5)
    vals, x = [], cfg.loosest
    while x >= cfg.tightest * (1 - 1e-9):
        s = _round_setting(cfg.knob, x, dt)
        if s not in vals:
            vals.append(s)
        x *= f
    return vals


def _round_setting(knob: str, x: float, dt: float) -> float:
    if knob == "h":
        return dt / max(1, round(dt / x))
    return float(f"{x:.3g}")


def mbsuite_configs(case: Case, methods) -> list[Config]:
    out = []
    # the explicit method first on the slider crank (its implicit runs are slower there), so that pruning bites early
    if case.name == "slider-crank":
        methods = sorted(methods, key=lambda m: m != "dop853-projection")
    for name in methods:
        cls = METHODS[name]
        fixed = bool(cls.fixed_step)

        def run(s, name=name, fixed=fixed):
            r = mbsuite_solve(case, name, s, fixed)
            v = mbsuite_quantity(case, r.t, r.q) if r.ok else np.full(len(case.grid), np.nan)
            info = r.info if r.ok else r.message
            return r.t, v, r.wall, r.cpu, r.ok, (UNAVAILABLE + info) if r.unavailable else info, r.unavailable

        if fixed:
            out.append(Config("mbsuite", name, "h", run, 1e-2 if case.name == "spin-up" else 1e-4,
                              1e-6 if case.name == "spin-up" else 1e-8))
        else:
            out.append(Config("mbsuite", name, "tol", run, 1e-3, 1e-12))
    return out


def exudyn_option_sets(case: Case, quick: bool) -> list:
    """The Exudyn configurations of the case (module docstring), most promising first."""
    imp = [exc.SolverOptions("GeneralizedAlpha", implicit=True, spectral_radius=0.9),
           exc.SolverOptions("TrapezoidalIndex2", implicit=True),
           exc.SolverOptions("GeneralizedAlpha", implicit=True, spectral_radius=0.5)]
    out = list(imp)
    if not quick:
        out += [replace(o, linear_solver="EigenSparse") for o in imp]
        out += [replace(imp[0], newton="full"), replace(imp[1], newton="full")]
    expl = [exc.SolverOptions("DOPRI5", adaptive=True, eosa=False), exc.SolverOptions("RK67", eosa=False),
            exc.SolverOptions("RK44", eosa=False), exc.SolverOptions("ODE23", adaptive=True, eosa=False)]
    return out + expl


def probe_exudyn(xm: ExudynModel, opts) -> str:
    """'' when Exudyn runs ``opts`` on the model and moves it as prescribed, else why not (a short run:
    0.5 s of the spin-up, 5 ms of the slider crank).  Exudyn's explicit solvers eliminate coordinate
    constraints to ground as fixed coordinates: a constraint whose offset is a user function (the
    prescribed hub or crank angle) is then held at its reference value instead of following the law,
    which the probe detects from the frame (spin-up) or the modal response."""
    t_p = 0.5 if xm.case.name == "spin-up" else 5e-3
    h = 1e-3 if xm.case.name == "spin-up" else 1e-5
    r = exudyn_solve(xm, opts, h=None if opts.adaptive else h, tol=1e-8 if opts.adaptive else None,
                     write_period=0.0, t_end=t_p)
    if r.unavailable:
        return r.message
    if not r.ok:
        return ""  # a step-size question: left to the sweep
    if xm.case.name == "spin-up":
        theta = spin_up_angle()(t_p)[0]
        if abs(r.frame[-1, 2] - theta) > 1e-3 * abs(theta):
            return (f"{opts.solver}: the hub does not follow the prescribed angle (probe: psi_z({t_p:g} s) = "
                    f"{r.frame[-1, 2]:.3g} rad, law {theta:.3g} rad): Exudyn's explicit solvers eliminate the "
                    "CoordinateConstraint to ground as a fixed coordinate and ignore its offset user function")
    elif not opts.implicit and not np.any(np.abs(r.qf[-1]) > 0):
        return f"{opts.solver}: the rod does not deform in the probe (the crank drive was eliminated as fixed)"
    return ""


def exudyn_configs(case: Case, xm: ExudynModel, quick: bool, log) -> list[Config]:
    out = []
    dt = float(case.grid[1] - case.grid[0])
    for opts in exudyn_option_sets(case, quick):
        why = probe_exudyn(xm, opts)

        def run(s, opts=opts):
            r = exudyn_solve(xm, opts, **({"h": s} if opts.knob == "h" else {"tol": s}))
            ok = r.ok and len(r.t) == len(case.grid) and np.allclose(r.t, case.grid, atol=1e-9 * case.t_end)
            msg = r.message
            if r.ok and not ok:
                msg = f"sensor times off the output grid ({len(r.t)} samples)"
            v = quantity_from_modes(case, r.t, r.frame, r.qf) if ok else np.full(len(case.grid), np.nan)
            info = f"steps={r.steps} jac={r.jacobians} rejected={r.rejected} {msg}".strip()
            return r.t, v, r.wall, r.cpu, ok, (UNAVAILABLE + info) if r.unavailable else info, r.unavailable

        if opts.knob == "h":
            lo, hi = (1e-2, 1e-6) if case.name == "spin-up" else (1e-4, 1e-8)
            lo = min(lo, dt)
        else:
            lo, hi = 1e-3, 1e-12
        cfg = Config("exudyn", opts.label(), opts.knob, run, lo, hi)
        if why:
            cfg.note = UNAVAILABLE + why
        out.append(cfg)
    return out


# ------------------------------------------------------------------------------------------
# search and timing (peer_chain.py's protocol, error relative to the peak of the reference)
# ------------------------------------------------------------------------------------------


def _errors(v: np.ndarray, ref: np.ndarray) -> tuple[float, float]:
    """(max over the grid, at the end time) of |v − ref| relative to the peak max |ref|."""
    peak = float(np.max(np.abs(ref)))
    return float(np.max(np.abs(v - ref))) / peak, float(abs(v[-1] - ref[-1])) / peak


def screen(cfg: Config, ref: np.ndarray, case: Case, max_run: float, budget: float, log) -> None:
    """Sweep cfg's knob loose → tight; cfg.chosen = the loosest setting whose error meets the case's target."""
    dt = float(case.grid[1] - case.grid[0])

    def one(s):
        t, v, wall, cpu, ok, info, unavailable = cfg.run(s)
        err, err_end = _errors(v, ref) if ok else (np.nan, np.nan)
        cfg.sweep.append(dict(setting=s, err=err, err_end=err_end, wall=wall, cpu=cpu, ok=ok, info=info))
        log(f"    {cfg.tool:8s} {cfg.label:62s} {cfg.knob}={s:<10.4g} err={err:<10.3g} wall={wall:8.4f}s "
            f"cpu={cpu:8.4f}s {'' if ok else 'FAILED ' + info[:100]}")
        return err, wall, cpu, ok, unavailable

    if cfg.note.startswith(UNAVAILABLE):
        log(f"    {cfg.tool:8s} {cfg.label:62s} {cfg.note[:160]}")
        return
    grid = _grid(cfg, dt)
    prev = None
    for s in grid:
        err, wall, cpu, ok, unavailable = one(s)
        if unavailable:  # refused at run time: no other setting helps
            cfg.note = cfg.sweep[-1]["info"]
            return
        if ok and err <= case.target:
            cfg.chosen = (s, err, cpu)
            break
        if wall > max_run or cpu > budget:
            cfg.note = (f"abandoned: a run took {wall:.3g} s wall / {cpu:.3g} s cpu (limits {max_run:.3g} s wall, "
                        f"{budget:.3g} s cpu) with error {err:.3g} of the peak")
            return
        prev = s
    if cfg.chosen is None:
        cfg.note = cfg.note or f"no setting down to {cfg.knob}={grid[-1]:.3g} reached {case.target:g} of the peak"
        return
    if prev is None:
        return
    lo, hi = prev, cfg.chosen[0]
    for frac in (0.25, 0.5, 0.75):
        s = _round_setting(cfg.knob, float(np.exp(np.log(lo) + frac * (np.log(hi) - np.log(lo)))), dt)
        if s in (lo, hi) or any(r["setting"] == s for r in cfg.sweep):
            continue
        err, wall, cpu, ok, _ = one(s)
        if ok and err <= case.target:
            cfg.chosen = (s, err, cpu)
            break


def run_case(case: Case, refs: dict, configs: list[Config], args, log) -> None:
    # one untimed run of each compiled configuration first: numba compiles its kernels (or loads them
    # from its disk cache) at the first call in a process, a one-off cost like building Exudyn's C++
    for cfg in configs:
        if cfg.tool == "mbsuite" and cfg.label.startswith("jit-") and not cfg.note.startswith(UNAVAILABLE):
            w0 = time.perf_counter()
            cfg.run(cfg.loosest)
            log(f"    warm-up of {cfg.label} (compilation or cache load, not timed): {time.perf_counter() - w0:.3g} s")
    log(f"\n=== {case.name}: screening ({len(configs)} configurations, target {case.target:g} of the peak) ===")
    best = {}
    for cfg in configs:
        b = best.get(cfg.tool, np.inf)
        screen(cfg, refs[cfg.tool], case, args.max_run, args.prune * b if np.isfinite(b) else np.inf, log)
        if cfg.chosen is not None:
            best[cfg.tool] = min(b, cfg.chosen[2])
    chosen = [c for c in configs if c.chosen is not None and c.chosen[2] <= args.time_within * best[c.tool]]
    for c in configs:
        if c.chosen is not None and c not in chosen:
            c.note = (f"not re-timed: screening CPU {c.chosen[2]:.3g} s > {args.time_within:g} x the best of its tool "
                      f"({best[c.tool]:.3g} s)")
    log(f"=== {case.name}: timing {len(chosen)} configurations x {args.repeats} repeats (round-robin) ===")
    for _ in range(args.repeats):
        for cfg in chosen:
            _, _, wall, cpu, ok, _, _ = cfg.run(cfg.chosen[0])
            cfg.times.append(wall if ok else np.nan)
            cfg.cpu_times.append(cpu if ok else np.nan)


# ------------------------------------------------------------------------------------------
# references and agreement
# ------------------------------------------------------------------------------------------

#: mbsuite's reference per case: (method, rtol = atol) and a looser run for its error estimate
MBSUITE_REFS = {"spin-up": ("radau-projection", 1e-12, 1e-10), "slider-crank": ("dop853-projection", 1e-12, 1e-10)}
#: Exudyn's reference per case: GeneralizedAlpha (ρ∞ = 0.9) at h and h/2, Richardson-extrapolated
EXUDYN_REF_H = {"spin-up": 1e-4, "slider-crank": 1e-6}


def mbsuite_reference(case: Case, quick: bool, log) -> tuple[np.ndarray, list[dict]]:
    method, tol, check = MBSUITE_REFS[case.name]
    if quick:
        tol, check = 1e-9, 1e-8
    rows, vs = [], []
    for s in (tol, check):
        r = mbsuite_solve(case, method, s, False)
        if not r.ok:
            raise RuntimeError(f"mbsuite reference of {case.name} ({method}, tol {s:g}) failed: {r.message}")
        vs.append(mbsuite_quantity(case, r.t, r.q))
        rows.append(dict(case=case.name, tool="mbsuite", run=f"{method} rtol=atol={s:g}", wall=r.wall, info=r.info))
    peak = np.max(np.abs(vs[0]))
    rows[0].update({"peak |v| [m]": peak, "v(t_end) [m]": vs[0][-1], "role": "reference"})
    rows[1].update({"peak |v| [m]": np.max(np.abs(vs[1])), "v(t_end) [m]": vs[1][-1], "role": "error estimate",
                    "max |v - reference| / peak": np.max(np.abs(vs[1] - vs[0])) / peak})
    log(f"  mbsuite reference {method} rtol=atol={tol:g}: peak {peak:.9g} m, v(t_end) {vs[0][-1]:.9g} m, "
        f"{rows[0]['wall']:.2f} s; the run at {check:g} is within {rows[1]['max |v - reference| / peak']:.2e} of the peak")
    return vs[0], rows


def exudyn_richardson(case: Case, xm: ExudynModel, h: float, label: str) -> tuple[np.ndarray, list[dict]]:
    """GeneralizedAlpha (ρ∞ = 0.9) at h and h/2 (whole steps per output interval) and the Richardson value
    v_R = v_{h/2} + (v_{h/2} − v_h)/3 (second order)."""
    dt = float(case.grid[1] - case.grid[0])
    h = _round_setting("h", h, dt)
    opts = exc.SolverOptions("GeneralizedAlpha", implicit=True, spectral_radius=0.9)
    vs, rows = [], []
    for hh in (h, h / 2):
        r = exudyn_solve(xm, opts, h=hh)
        if not r.ok:
            raise RuntimeError(f"Exudyn reference of {case.name} (h = {hh:g}) failed: {r.message}")
        vs.append(quantity_from_modes(case, r.t, r.frame, r.qf))
        rows.append(dict(case=case.name, tool="exudyn", run=f"{label}GeneralizedAlpha rho=0.9 h={hh:.4g}", wall=r.wall,
                         info=f"steps={r.steps} jac={r.jacobians}", **{"peak |v| [m]": np.max(np.abs(vs[-1])),
                                                                        "v(t_end) [m]": vs[-1][-1]}))
    vR = vs[1] + (vs[1] - vs[0]) / 3.0
    peak = np.max(np.abs(vR))
    rows[0].update({"role": "Richardson input", "max |v - reference| / peak": np.max(np.abs(vs[0] - vR)) / peak})
    rows[1].update({"role": "Richardson input (its difference from the extrapolated value estimates its error)",
                    "max |v - reference| / peak": np.max(np.abs(vs[1] - vR)) / peak})
    rows.append(dict(case=case.name, tool="exudyn", run=f"{label}Richardson of h={h:.4g} and h/2", wall=np.nan,
                     role="reference", **{"peak |v| [m]": peak, "v(t_end) [m]": vR[-1]}))
    return vR, rows


#: steps of the cross-check runs with the missing terms (h and h/2; Python force user function, ~0.5 ms a step)
CROSS_CHECK_H = 4e-6


def missing_terms_effect(case: Case, xm: ExudynModel, h: float) -> tuple[np.ndarray, list[dict]]:
    """Δv = v(Exudyn with :func:`_missing_terms` as a force user function) − v(Exudyn), both with
    GeneralizedAlpha (ρ∞ = 0.9) at the same step, at h and h/2, Richardson-extrapolated: the effect of the
    terms on Exudyn's solution (most of the discretization error cancels in the difference)."""
    xc = build_exudyn(case, missing_terms=True)
    dt = float(case.grid[1] - case.grid[0])
    h = _round_setting("h", h, dt)
    opts = exc.SolverOptions("GeneralizedAlpha", implicit=True, spectral_radius=0.9)
    deltas, rows = [], []
    for hh in (h, h / 2):
        vv = []
        for model, what in ((xm, "Exudyn"), (xc, "Exudyn with the missing terms (Python force user function)")):
            r = exudyn_solve(model, opts, h=hh)
            if not r.ok:
                raise RuntimeError(f"cross-check run {what} of {case.name} (h = {hh:g}) failed: {r.message}")
            vv.append(quantity_from_modes(case, r.t, r.frame, r.qf))
            rows.append(dict(case=case.name, tool="exudyn", run=f"{what}, GeneralizedAlpha rho=0.9 h={hh:.4g}",
                             wall=r.wall, info=f"steps={r.steps} jac={r.jacobians}", role="cross-check",
                             **{"peak |v| [m]": np.max(np.abs(vv[-1])), "v(t_end) [m]": vv[-1][-1]}))
        deltas.append(vv[1] - vv[0])
    dR = deltas[1] + (deltas[1] - deltas[0]) / 3.0
    rows.append(dict(case=case.name, tool="exudyn", run=f"effect of the missing terms, Richardson of h={h:.4g} and h/2",
                     wall=np.nan, role="cross-check: max |effect| [m] in 'peak', change from h to h/2 relative to "
                     "the peak in the last column", **{"peak |v| [m]": np.max(np.abs(dR)), "v(t_end) [m]": dR[-1],
                                                        "max |v - reference| / peak": np.max(np.abs(deltas[1] - deltas[0]))
                                                        / np.max(np.abs(vv[0]))}))
    return dR, rows


def agreement_rows(case: Case, v_mb: np.ndarray, v_ex: np.ndarray, extra: dict) -> list[dict]:
    """The two codes' references against each other (and against the extra runs)."""
    peak = float(np.max(np.abs(v_mb)))
    rows = []
    pairs = [("mbsuite reference", v_mb, "Exudyn reference", v_ex)] + \
            [("mbsuite reference", v_mb, k, v) for k, v in extra.items()] + \
            [("Exudyn reference", v_ex, k, v) for k, v in extra.items()]
    for a, va, b, vb in pairs:
        d = np.abs(va - vb)
        rows.append({"case": case.name, "compared": f"{a} vs {b}", "peak |v| [m]": peak,
                     "max |difference| [m]": float(d.max()), "max |difference| / peak": float(d.max()) / peak,
                     "at t [s]": float(case.grid[int(np.argmax(d))]), "|difference| at t_end [m]": float(d[-1])})
    return rows


# ------------------------------------------------------------------------------------------
# main
# ------------------------------------------------------------------------------------------


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--quick", action="store_true",
                   help="smoke: the spin-up only, 3 implicit Exudyn configurations, looser references, 1 repeat")
    p.add_argument("-o", "--out", default=str(_HERE / "out"), help="output folder (default benchmarks/out)")
    p.add_argument("--cases", default=None, help="comma list of spin-up, slider-crank (default both; --quick: spin-up)")
    p.add_argument("--tools", default=",".join(TOOLS), help="comma list of mbsuite, exudyn (default both)")
    p.add_argument("--methods", default=",".join(MBSUITE_METHODS),
                   help=f"comma list of mbsuite methods (default {','.join(MBSUITE_METHODS)})")
    p.add_argument("--target-spin-up", type=float, default=1e-6, help="error target, relative to the peak (1e-6)")
    p.add_argument("--target-slider-crank", type=float, default=1e-4,
                   help="error target, relative to the peak (1e-4; 1e-5 and below take much longer, README)")
    p.add_argument("--repeats", type=int, default=None, help="timed repeats per configuration (default 3)")
    p.add_argument("--max-run", type=float, default=None, help="abandon a configuration after a run longer than this [s]")
    p.add_argument("--prune", type=float, default=3.0,
                   help="abandon a configuration after a run (not yet at the target) taking more CPU than this factor "
                        "x the best passing CPU time of its tool")
    p.add_argument("--time-within", type=float, default=2.0,
                   help="re-time only configurations whose screening CPU time is within this factor of their tool's best")
    p.add_argument("--no-cross-check", action="store_true",
                   help="skip the untimed Exudyn runs with the missing terms added (slider crank, ~40 s)")
    p.add_argument("--exudyn-set", choices=("full", "basic"), default="full",
                   help="Exudyn configurations: full (every option set of the module docstring) or basic (each "
                        "method with Exudyn's default options)")
    args = p.parse_args(argv)
    tools = [t.strip() for t in args.tools.split(",") if t.strip()]
    if not tools or any(t not in TOOLS for t in tools):
        p.error(f"--tools: choose from {', '.join(TOOLS)}, got {args.tools!r}")
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        p.error(f"--methods: unknown {unknown}; registered: {', '.join(sorted(METHODS))}")
    args.repeats = args.repeats or (1 if args.quick else 3)
    args.max_run = args.max_run or (10.0 if args.quick else 60.0)
    cases = [c.strip() for c in (args.cases or ("spin-up" if args.quick else "spin-up,slider-crank")).split(",")]
    out = Path(args.out)
    lines: list[str] = []

    def log(s=""):
        print(s, flush=True)
        lines.append(s)

    have_exudyn = exc.load_exudyn() is not None
    import scipy
    from _host import cpu_model, host_line

    processor = cpu_model()
    log(f"peer_flexible: python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
        f"exudyn {sys.modules['exudyn'].__version__ if have_exudyn else '-'}, "
        f"machine {platform.machine()} ({os.cpu_count()} cores), {processor}, "
        f"load average at start {os.getloadavg()[0]:.2f}")
    log(f"host: {host_line()}")
    from _calibration import calibrate, calibration_line, with_calibration

    cal = calibrate()
    log(calibration_line(cal))
    if not have_exudyn:
        log(EXUDYN_MISSING)
    run_exudyn = have_exudyn and "exudyn" in tools
    ref_rows, sweep_rows, cfg_rows, summ_rows, agree_rows, check_rows = [], [], [], [], [], []

    def write_all():
        write_table(with_calibration(pd.DataFrame(summ_rows), cal, ["median wall [s]"]) if summ_rows else pd.DataFrame(),
                    out, "peer_flexible_summary")
        write_table(pd.DataFrame(cfg_rows), out, "peer_flexible_configs")
        write_table(pd.DataFrame(sweep_rows), out, "peer_flexible_sweep")
        write_table(pd.DataFrame(ref_rows), out, "peer_flexible_references", floatfmt=".10g")
        write_table(pd.DataFrame(agree_rows), out, "peer_flexible_agreement", floatfmt=".4g")
        write_table(pd.DataFrame(check_rows), out, "peer_flexible_checks", floatfmt=".3g")
        (out / "peer_flexible_log.txt").write_text("\n".join(lines) + "\n")

    makers = {"spin-up": (spin_up_case, args.target_spin_up), "slider-crank": (slider_crank_case, args.target_slider_crank)}
    for name in cases:
        if name not in makers:
            raise SystemExit(f"unknown case {name!r}: use spin-up, slider-crank")
        maker, target = makers[name]
        case = maker(target)
        log(f"\n##### {case.title}; quantity: {case.quantity}; target {target:g} of the peak")
        log(f"  modes [Hz]: {', '.join(f'{f:.4g}' for f in case.body.data.frequencies)}")
        refs, xm = {}, None
        if run_exudyn:
            t0 = time.perf_counter()
            xm = build_exudyn(case)
            chk = check_exudyn_against_mbsuite(xm)
            check_rows.append({"case": case.name, "Exudyn drive": xm.drive, **{f"max rel. difference: {k}": v
                                                                             for k, v in chk.items()}})
            log(f"  Exudyn model built in {time.perf_counter() - t0:.2f} s (drive: {xm.drive}); at a random state "
                f"against mbsuite: mass matrix {chk['mass matrix']:.2e}, forces {chk['forces']:.2e}, forces with "
                f"the missing terms {chk['forces + missing terms']:.2e}, modal forces with the frame not translating "
                f"{chk['modal forces, frame not translating']:.2e} (relative to the largest entry)")
        log("  references:")
        v_mb, rows = mbsuite_reference(case, args.quick, log)
        ref_rows += rows
        refs["mbsuite"] = v_mb
        if run_exudyn:
            h_ref = EXUDYN_REF_H[case.name] * (10.0 if args.quick else 1.0)
            v_ex, rows = exudyn_richardson(case, xm, h_ref, "")
            ref_rows += rows
            refs["exudyn"] = v_ex
            log(f"  Exudyn reference: Richardson of GeneralizedAlpha at h = {rows[0]['run'].split('h=')[1]} and h/2: "
                f"peak {np.max(np.abs(v_ex)):.9g} m, v(t_end) {v_ex[-1]:.9g} m; the h/2 run is within "
                f"{rows[1]['max |v - reference| / peak']:.2e} of the peak")
            extra = {}
            if case.name == "slider-crank" and not args.no_cross_check:
                delta, rows = missing_terms_effect(case, xm, CROSS_CHECK_H)
                ref_rows += rows
                extra["Exudyn reference + effect of the missing terms"] = v_ex + delta
                log(f"  effect of the missing terms on Exudyn's solution: up to {np.max(np.abs(delta)):.3g} m "
                    f"({np.max(np.abs(delta)) / np.max(np.abs(v_ex)):.2e} of the peak)")
            agree_rows += agreement_rows(case, v_mb, v_ex, extra)
            for r in agree_rows[-(1 + 2 * len(extra)):]:
                log(f"  agreement: {r['compared']}: max {r['max |difference| [m]']:.3g} m "
                    f"({r['max |difference| / peak']:.2e} of the peak) at t = {r['at t [s]']:.4g} s; "
                    f"at t_end {r['|difference| at t_end [m]']:.3g} m")
        configs = []
        if "mbsuite" in tools:
            configs += mbsuite_configs(case, methods)
        if run_exudyn:
            configs += exudyn_configs(case, xm, args.quick or args.exudyn_set == "basic", log)
        run_case(case, refs, configs, args, log)
        for cfg in configs:
            for r in cfg.sweep:
                sweep_rows.append({"case": case.name, "tool": cfg.tool, "configuration": cfg.label, "knob": cfg.knob,
                                   "setting": r["setting"], "max error / peak": r["err"], "end error / peak": r["err_end"],
                                   "wall [s]": r["wall"], "cpu [s]": r["cpu"], "ok": r["ok"], "info": r["info"]})
            med = float(np.nanmedian(cfg.times)) if cfg.times and np.any(np.isfinite(cfg.times)) else np.nan
            medc = float(np.nanmedian(cfg.cpu_times)) if cfg.cpu_times and np.any(np.isfinite(cfg.cpu_times)) else np.nan
            chosen_row = next((r for r in cfg.sweep if cfg.chosen and r["setting"] == cfg.chosen[0]), None)
            cfg_rows.append({"case": case.name, "tool": cfg.tool, "configuration": cfg.label,
                             "setting": f"{cfg.knob}={cfg.chosen[0]:.4g}" if cfg.chosen else "",
                             "max error / peak": cfg.chosen[1] if cfg.chosen else np.nan,
                             "end error / peak": chosen_row["err_end"] if chosen_row else np.nan,
                             "median wall [s]": med, "median cpu [s]": medc, "repeats": len(cfg.times),
                             "info": chosen_row["info"] if chosen_row else "", "note": cfg.note})
        case_df = pd.DataFrame([r for r in cfg_rows if r["case"] == case.name])
        bests = {}
        for tool in TOOLS:
            sub = case_df[(case_df.tool == tool) & case_df["median wall [s]"].notna()] if tool in tools else []
            bests[tool] = sub.loc[sub["median wall [s]"].idxmin()] if len(sub) else None
        ex = bests["exudyn"]
        for tool in tools:
            b = bests[tool]
            row = {"case": case.name, "tool": tool, "target (error / peak)": target}
            if b is None:
                row.update({"best configuration": EXUDYN_MISSING if (tool == "exudyn" and not have_exudyn)
                            else f"none reached {target:g}", "setting": "", "max error / peak": np.nan,
                            "end error / peak": np.nan, "median wall [s]": np.nan, "median cpu [s]": np.nan})
            else:
                row.update({k: b[k] for k in ("setting", "max error / peak", "end error / peak", "median wall [s]",
                                               "median cpu [s]")})
                row["best configuration"] = b["configuration"]
            row["ratio mbsuite/Exudyn, wall [-]"] = (row["median wall [s]"] / ex["median wall [s]"]
                                                     if ex is not None and tool == "mbsuite" else np.nan)
            row["ratio mbsuite/Exudyn, cpu [-]"] = (row["median cpu [s]"] / ex["median cpu [s]"]
                                                    if ex is not None and tool == "mbsuite" else np.nan)
            row["processor"] = processor
            summ_rows.append(row)
        write_all()

    summary = with_calibration(pd.DataFrame(summ_rows), cal, ["median wall [s]"]) if summ_rows else pd.DataFrame()
    log("\n## Summary (time for the quantity's error over the output grid to reach the target, relative to the peak; "
        "ratio = mbsuite median / Exudyn median)")
    if not have_exudyn:
        log(EXUDYN_MISSING)
    if len(summary):
        log(summary.to_markdown(index=False, floatfmt=".4g"))
    log("\n## Per configuration")
    log(pd.DataFrame(cfg_rows).to_markdown(index=False, floatfmt=".4g"))
    log("\n## References")
    log(pd.DataFrame(ref_rows).to_markdown(index=False, floatfmt=".10g"))
    if agree_rows:
        log("\n## Agreement between the two codes")
        log(pd.DataFrame(agree_rows).to_markdown(index=False, floatfmt=".4g"))
        log("\n## Exudyn's flexible body against mbsuite's at a random state")
        log(pd.DataFrame(check_rows).to_markdown(index=False, floatfmt=".3g"))
    log(f"\nload average at end {os.getloadavg()[0]:.2f}")
    write_all()
    log(f"tables written to {out}/peer_flexible_*.csv|.md")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
