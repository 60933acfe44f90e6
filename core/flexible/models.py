r"""Canonical flexible-body models shared by the tests, the scenes and the documentation.

Spin-up beam (Kane, Ryan & Banerjee 1987)
-----------------------------------------
A uniform cantilever, clamped at the rotation axis, spun in a horizontal plane by a prescribed hub
angle (Kane, Ryan & Banerjee 1987, J. Guidance 10(2):139–151, the spin-up manoeuvre of their
section V):

.. math::

    \theta(t) = \frac{\omega_s}{T_s}\Big[\frac{t^2}{2} + \Big(\frac{T_s}{2\pi}\Big)^2
                \Big(\cos\frac{2\pi t}{T_s} - 1\Big)\Big]\ (t < T_s),\qquad
    \theta(t) = \omega_s\,(t - T_s/2)\ (t \ge T_s),

with L = 10 m, ρA = 1.2 kg/m, EA = 2.8e7 N, EI = 1.4e4 N m², T_s = 15 s, ω_s = 6 rad/s.  The
output is the tip's deflection in the hub frame.

:func:`spin_up_beam` is the floating-frame model (cantilever modes of an Euler–Bernoulli beam,
the frame on the hub).  :func:`spin_up_chain` is an independent, geometrically exact reference
built from rigid bodies only: ``n_links`` uniform rigid links (mass and rotary inertia of their
share of the beam) joined by revolute joints with rotational springs ``EI/ℓ`` and, at the hub,
``2EI/ℓ`` (the Hencky bar chain, whose cantilever tip compliance
:math:`ℓ^3/EI\,[N^2/2 + (N-1)N(2N-1)/6]` equals :math:`L^3/3EI` up to :math:`O(N^{-2})`).  It is
inextensible; its centrifugal stiffening comes from the exact kinematics, not from a
geometric-stiffness matrix.

Slider crank with an elastic connecting rod (Simeon 1996)
---------------------------------------------------------
Simeon's benchmark (B. Simeon, Math. Modelling of Systems 2 (1996) 1–18; the Test Set for IVP
Solvers, problem "crank"): crank 0.15 m driven at Ω = 150 rad/s, steel connecting rod 0.30 m with
an 8 mm × 8 mm section (E = 2e11 Pa, ρ = 7870 kg/m³), slider of mass m₂/2 on the x axis, no
gravity; started (the test set's second initial-value set) with the rod straight and the rigid
mechanism's velocities.  :func:`slider_crank_flexible` makes the rod a flexible body reduced by
Craig–Bampton with the end translations as interface (rigid content removed, so the frame is the
mean axes) and joins it at two node frames; :func:`slider_crank_chain` is the independent,
geometrically exact reference: the rod as a pinned–pinned Hencky chain of rigid links.  The
output is the midpoint's deflection from the chord between the rod's ends,
:func:`chord_deflection`.
"""

from __future__ import annotations

import numpy as np

from ..drivers import TimeFunction
from ..model import Model, ModelBuilder

__all__ = ["KANE_SPIN_UP", "SIMEON_ROD", "chord_deflection", "hub_frame_deflection", "slider_crank_chain",
           "slider_crank_flexible", "spin_up_angle", "spin_up_beam", "spin_up_chain"]

#: data of the spin-up beam (Kane, Ryan & Banerjee 1987, sec. V)
KANE_SPIN_UP = dict(length=10.0, rho=3000.0, area=4e-4, E=7e10, I=2e-7, T_s=15.0, omega_s=6.0)


class _SpinUp:
    """θ, θ̇, θ̈ of the spin-up law (picklable)."""

    def __init__(self, omega_s: float, T_s: float, order: int):
        self.w, self.T, self.order = float(omega_s), float(T_s), order

    def __call__(self, t):
        w, T = self.w, self.T
        c = 2.0 * np.pi / T
        if t < T:
            if self.order == 0:
                return w / T * (t * t / 2.0 + (np.cos(c * t) - 1.0) / c**2)
            if self.order == 1:
                return w / T * (t - np.sin(c * t) / c)
            return w / T * (1.0 - np.cos(c * t))
        return (w * (t - T / 2.0), w, 0.0)[self.order]


def spin_up_angle(omega_s: float = 6.0, T_s: float = 15.0) -> TimeFunction:
    """The hub angle θ(t) [rad] of the spin-up manoeuvre with its exact derivatives."""
    return TimeFunction(_SpinUp(omega_s, T_s, 0), _SpinUp(omega_s, T_s, 1), _SpinUp(omega_s, T_s, 2),
                        f"spin-up to {omega_s:g} rad/s in {T_s:g} s")


def spin_up_beam(n_elements: int = 20, n_modes: int = 4, geometric_stiffening: bool | str = True,
                 omega_s: float = 6.0, T_s: float = 15.0, dimension: int = 2) -> Model:
    """The spin-up beam as one flexible body with cantilever modes (module docstring).

    The frame sits on the hub (node 0, held when the modes are computed); a node frame ``beam.tip``
    is on the last node.  ``dimension=3`` builds the same beam as a spatial body spinning about z,
    with its out-of-plane modes among the ``n_modes``.
    """
    from . import BeamSection, FEModel, straight_beam
    from .reduction import normal_mode_component

    k = KANE_SPIN_UP
    section = BeamSection(E=k["E"], rho=k["rho"], A=k["area"], Iz=k["I"],
                          **({} if dimension == 2 else dict(Iy=k["I"], J=2 * k["I"])))
    fe = FEModel.from_beam(straight_beam(k["length"], n_elements, dim=dimension), section)
    modes = normal_mode_component(fe.M, fe.K, n_modes, fixed_dofs=fe.dofs(0))
    b = ModelBuilder(dimension, "spin-up beam", gravity=np.zeros(dimension))
    b.add_flexible_body("beam", fe, modes, geometric_stiffening=geometric_stiffening)
    b.add_node_frame("beam", n_elements, "beam.tip")
    if dimension == 2:
        b.add_revolute("hub", "ground", "beam", at=(0.0, 0.0))
    else:
        b.add_revolute("hub", "ground", "beam", at=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0))
    b.add_angle_driver("spin", "hub", spin_up_angle(omega_s, T_s))
    return b.build()


def spin_up_chain(n_links: int = 20, omega_s: float = 6.0, T_s: float = 15.0) -> Model:
    """The geometrically exact rigid-link reference of the spin-up beam (module docstring); the
    last link's end is the tip (body ``link{n}``, local point ``(ℓ/2, 0)``)."""
    k = KANE_SPIN_UP
    L, rhoA, EI = k["length"], k["rho"] * k["area"], k["E"] * k["I"]
    ell = L / n_links
    m = rhoA * ell
    b = ModelBuilder(2, f"spin-up chain ({n_links} links)", gravity=(0.0, 0.0))
    b.add_body("hub", 0.0, 0.0, (0.0, 0.0))
    b.add_revolute("hub pivot", "ground", "hub", at=(0.0, 0.0))
    b.add_angle_driver("spin", "hub pivot", spin_up_angle(omega_s, T_s))
    prev = "hub"
    for i in range(n_links):
        name = f"link{i + 1}"
        b.add_body(name, m, m * ell**2 / 12.0, ((i + 0.5) * ell, 0.0))
        b.add_revolute(f"joint{i + 1}", prev, name, at=(i * ell, 0.0))
        b.add_rotational_spring_damper(f"spring{i + 1}", prev, name, (2.0 if i == 0 else 1.0) * EI / ell)
        prev = name
    return b.build()


def hub_frame_deflection(tip: np.ndarray, theta: np.ndarray, length: float) -> tuple[np.ndarray, np.ndarray]:
    """Tip deflection in the hub frame: transverse ``v = r·e₂(θ)`` and axial ``u = r·e₁(θ) − L`` [m]
    for tip positions ``(n, 2)`` (the hub on the axis) and hub angles ``(n,)``."""
    c, s = np.cos(theta), np.sin(theta)
    return -s * tip[:, 0] + c * tip[:, 1], c * tip[:, 0] + s * tip[:, 1] - length


#: Simeon's slider crank (Simeon 1996; Test Set for IVP Solvers "crank")
SIMEON_ROD = dict(l1=0.15, l2=0.30, m1=0.36, J1=0.002727, E=2.0e11, nu=0.3, rho=7870.0, width=0.008,
                  height=0.008, omega=150.0)


def _rigid_start(p):
    """Rigid slider crank at crank angle 0: crank pin A, wrist pin B, rod rate (Simeon's set 2)."""
    l1, l2, w1 = p["l1"], p["l2"], p["omega"]
    return np.array([l1, 0.0]), np.array([l1 + l2, 0.0]), np.array([0.0, l1 * w1]), -l1 * w1 / l2


def _crank_and_slider(b, p, slider_mass, A, B, vA):
    b.add_body("crank", p["m1"], p["J1"] - p["m1"] * (p["l1"] / 2) ** 2, A / 2, velocity=vA / 2,
               angular_velocity=p["omega"])
    b.add_body("slider", slider_mass, 0.0, B)
    b.add_revolute("crank pivot", "ground", "crank", (0.0, 0.0))
    b.add_translational("slider guide", "ground", "slider", B, (1.0, 0.0))
    from ..drivers import ramp

    b.add_angle_driver("crank drive", "crank pivot", ramp(p["omega"]))


def slider_crank_flexible(n_elements: int = 8, n_modes: int = 4, theory: str = "euler-bernoulli",
                          geometric_stiffening: bool | str = False, damping_ratio=0.0, frame: str = "mean axes") -> Model:
    """Simeon's slider crank with the rod a flexible body (module docstring): ``n_elements`` beam
    elements, Craig–Bampton with the two end nodes' translations as interface and ``n_modes``
    fixed-interface modes, rigid-body content removed (``1 + n_modes`` modal coordinates).  Node
    frames ``rod.A`` (crank pin), ``rod.mid`` and ``rod.B`` (wrist pin)."""
    from . import BeamSection, FEModel, craig_bampton, straight_beam

    if n_elements % 2:
        raise ValueError("slider_crank_flexible: n_elements must be even (a node at mid-length)")
    p = SIMEON_ROD
    section = BeamSection.rectangle(E=p["E"], rho=p["rho"], width=p["height"], height=p["width"], nu=p["nu"])
    fe = FEModel.from_beam(straight_beam(p["l2"], n_elements, dim=2), section, theory)
    if frame == "mean axes":
        interface = np.concatenate([fe.dofs(0, [0, 1]), fe.dofs(n_elements, [0, 1])])
        modes = craig_bampton(fe.M, fe.K, interface, n_modes).orthonormalized(drop_rigid=True)
    elif frame == "chord":  # Simeon's frame: origin at the crank pin, x axis through the wrist pin
        held = np.concatenate([fe.dofs(0, [0, 1]), fe.dofs(n_elements, [1])])
        modes = craig_bampton(fe.M, fe.K, fe.dofs(n_elements, [0]), n_modes, fixed_dofs=held).orthonormalized()
    else:
        raise ValueError(f"slider_crank_flexible: frame must be 'mean axes' or 'chord', got {frame!r}")
    A, B, vA, w2 = _rigid_start(p)
    b = ModelBuilder(2, "flexible slider crank", gravity=(0.0, 0.0))
    m_rod = p["rho"] * section.A * p["l2"]
    _crank_and_slider(b, p, m_rod / 2, A, B, vA)
    b.add_flexible_body("rod", fe, modes, position=A, velocity=vA, angular_velocity=w2,
                        geometric_stiffening=geometric_stiffening, damping_ratio=damping_ratio)
    b.add_node_frame("rod", 0, "rod.A")
    b.add_node_frame("rod", n_elements // 2, "rod.mid")
    b.add_node_frame("rod", n_elements, "rod.B")
    b.add_revolute("crank pin", "crank", "rod.A", A)
    b.add_revolute("wrist pin", "rod.B", "slider", B)
    return b.build()


def slider_crank_chain(n_links: int = 16) -> Model:
    """Simeon's slider crank with the rod a pinned–pinned Hencky chain: ``n_links`` (even) rigid links
    with their share of the rod's mass and rotary inertia, rotational springs ``EI/ℓ`` at the
    ``n_links − 1`` inner joints; the midpoint is the joint ``mid`` between links ``n/2`` and
    ``n/2 + 1`` (the end of link ``rod{n/2}``)."""
    if n_links % 2:
        raise ValueError("slider_crank_chain: n_links must be even (a joint at mid-length)")
    p = SIMEON_ROD
    A, B, vA, w2 = _rigid_start(p)
    area = p["width"] * p["height"]
    EI = p["E"] * p["width"] * p["height"] ** 3 / 12.0
    ell = p["l2"] / n_links
    m = p["rho"] * area * ell
    b = ModelBuilder(2, f"slider crank, rod of {n_links} rigid links", gravity=(0.0, 0.0))
    _crank_and_slider(b, p, p["rho"] * area * p["l2"] / 2, A, B, vA)
    prev = "crank"
    for i in range(n_links):
        name = f"rod{i + 1}"
        x = A[0] + (i + 0.5) * ell
        b.add_body(name, m, m * ell**2 / 12.0, (x, 0.0), velocity=(0.0, vA[1] + w2 * (x - A[0])),
                   angular_velocity=w2)
        b.add_revolute("crank pin" if i == 0 else f"rod joint {i}", prev, name, (A[0] + i * ell, 0.0))
        if i > 0:
            b.add_rotational_spring_damper(f"rod spring {i}", prev, name, EI / ell)
        prev = name
    b.add_revolute("wrist pin", prev, "slider", B)
    return b.build()


def chord_deflection(a: np.ndarray, mid: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Deflection [m] of ``mid`` from the chord ``a``–``b`` (positive along the chord turned by +90°),
    for positions of shape (n, 2): ``(mid − (a + b)/2) · R e``, ``e = (b − a)/|b − a|``."""
    e = (b - a) / np.linalg.norm(b - a, axis=1, keepdims=True)
    n = np.stack([-e[:, 1], e[:, 0]], 1)
    return np.einsum("ni,ni->n", mid - 0.5 * (a + b), n)
