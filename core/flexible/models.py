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

SAR antenna unfolding (after Anantharaman & Hiller 1991 and Ambrósio's review)
------------------------------------------------------------------------------
A satellite deploys its synthetic-aperture-radar antenna: a chain of panels, stowed folded
accordion-wise against one face of the bus, unfolds about parallel hinge axes into a straight line
(M. Anantharaman, M. Hiller, Int. J. Numer. Meth. Eng. 32 (1991) 1531–1542; the flexible variant
in Ambrósio's review, its Figs 27–28).  **No public copy of their data was found; every number of**
:data:`SAR_ANTENNA` **is this project's assumption**, chosen to be typical of a small radar
satellite: a 2000 kg bus, three panels of 2 m × 1 m and 25 kg, honeycomb sandwich with
EI = 2·10⁴ N m² (first cantilever frequency of a panel 5.6 Hz, of the deployed 6 m antenna on a
fixed bus 0.62 Hz), 0.5 % modal damping.  The motion is planar (all hinge axes parallel), the bus
floats free (no gravity, no external force), and each hinge's actuator drives its relative angle
by the cycloidal law (:func:`core.drivers.cycloidal`) over the deployment time; the actuator
moment is the driver's Lagrange multiplier, and after the deployment the drivers hold the hinges
(a latched hinge).

:func:`sar_antenna` builds the rigid or the flexible model.  A flexible panel's frame is clamped
at its root hinge (node 0 held); its modes are Craig–Bampton's with the tip hinge's transverse
translation and rotation as the interface (two static constraint modes) plus ``n_modes``
fixed-interface (clamped–clamped) modes.  The panel is axially rigid (no axial coordinate).  The
stowed panels lie on one line (zero thickness); their contact with each other is not
modelled.

:func:`driven_cantilever` is an independent reference for one panel on a fixed base: the exact
Euler–Bernoulli cantilever modes, linearised about the rotating frame (the centrifugal terms
θ̇² are dropped), solved exactly between fine samples of the hub acceleration.
"""

from __future__ import annotations

import numpy as np

from ..drivers import TimeFunction
from ..model import Model, ModelBuilder

__all__ = ["KANE_SPIN_UP", "SAR_ANTENNA", "SIMEON_ROD", "cantilever_roots", "chord_deflection", "driven_cantilever",
           "hub_frame_deflection", "momenta", "panel_tip_deflection", "sar_antenna", "sar_antenna_section",
           "slider_crank_chain", "slider_crank_flexible", "spin_up_angle", "spin_up_beam", "spin_up_chain"]

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
    # θ̇ is the cycloidal rest-to-rest law in the rate: θ is its time integral, which the compiled
    # path evaluates with the same formulas (core.compiled.timefunctions, kind "cycloidal")
    return TimeFunction(_SpinUp(omega_s, T_s, 0), _SpinUp(omega_s, T_s, 1), _SpinUp(omega_s, T_s, 2),
                        f"spin-up to {omega_s:g} rad/s in {T_s:g} s",
                        spec=("cycloidal", float(omega_s), float(T_s), 0.0, True))


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


#: data of the SAR antenna scene -- all assumed (module docstring): bus mass [kg], moment of inertia
#: about the hinge-axis direction [kg m²] and the hinge face's distance from its centre and hinge
#: positions along it [m]; panels: number, hinge-to-hinge length [m], width (along the hinge axis)
#: and sandwich thickness of the homogenised section [m], mass per length [kg/m], bending stiffness
#: [N m²], modal damping ratio; the deployment time [s] of the cycloidal law (every hinge at once)
SAR_ANTENNA = dict(bus_mass=2000.0, bus_inertia=2000.0, bus_face=1.0, hinge_low=-1.0, n_panels=3,
                   panel_length=2.0, panel_width=1.0, panel_thickness=0.03, mass_per_length=12.5, EI=2.0e4,
                   damping_ratio=0.005, deployment_time=10.0)


def sar_antenna_section():
    """The panels' homogenised sandwich section: a 1 m × 30 mm rectangle whose density and modulus
    give :data:`SAR_ANTENNA`'s mass per length and bending stiffness (the skins, the honeycomb core
    and the radiating elements smeared over the section; its fibre stresses are not the skins')."""
    from . import BeamSection

    p = SAR_ANTENNA
    A = p["panel_width"] * p["panel_thickness"]
    Iz = p["panel_width"] * p["panel_thickness"] ** 3 / 12.0
    # the beam's local y is in the plane of the motion: the panel's thickness; local z is along the hinge
    return BeamSection.rectangle(E=p["EI"] / Iz, rho=p["mass_per_length"] / A, width=p["panel_thickness"],
                                 height=p["panel_width"])


def _stowed(n_panels: int):
    """Root hinge, stowed angle and the hinge's travel (from stowed to deployed) of each panel: the
    panels folded accordion-wise along the bus face x = a, the first pointing +y."""
    p = SAR_ANTENNA
    a, y0, L = p["bus_face"], p["hinge_low"], p["panel_length"]
    hinges, angles, travel = [], [], []
    for i in range(n_panels):
        up = i % 2 == 0
        hinges.append((a, y0 if up else y0 + L))
        angles.append(np.pi / 2 if up else -np.pi / 2)
        travel.append(-np.pi / 2 if i == 0 else (np.pi if not up else -np.pi))
    return hinges, angles, travel


def sar_antenna(flexible: bool = True, deployment_time: float | None = None, n_panels: int | None = None,
                n_modes: int = 1, n_elements: int = 8, damping_ratio=None, bus: str = "free") -> Model:
    """The SAR antenna unfolding (module docstring), rigid or flexible panels.

    Bodies ``bus`` (absent with ``bus="fixed"``, when the first hinge is on the ground) and
    ``panel1 …``; joints ``hinge1 …`` with their drivers ``actuator1 …`` (the moment on the
    outboard panel is the driver's reaction ``Mz``); a flexible panel has a node frame
    ``panel<i>.tip`` on its tip hinge and ``2 + n_modes`` modal coordinates.
    """
    from ..drivers import cycloidal
    from ..errors import InputError
    from . import FEModel, craig_bampton, straight_beam

    p = SAR_ANTENNA
    T = p["deployment_time"] if deployment_time is None else deployment_time
    n = p["n_panels"] if n_panels is None else n_panels
    zeta = p["damping_ratio"] if damping_ratio is None else damping_ratio
    if not (isinstance(n, (int, np.integer)) and n >= 1):
        raise InputError(f"sar_antenna: n_panels = {n_panels!r} must be a positive integer")
    if bus not in ("free", "fixed"):
        raise InputError(f"sar_antenna: bus must be 'free' (floating in orbit) or 'fixed' (a ground test), got {bus!r}")
    L, mu = p["panel_length"], p["mass_per_length"]
    kind = "flexible" if flexible else "rigid"
    b = ModelBuilder(2, f"SAR antenna, {n} {kind} panels, {bus} bus", gravity=(0.0, 0.0))
    if bus == "free":
        b.add_body("bus", p["bus_mass"], p["bus_inertia"], (0.0, 0.0))
    if flexible:
        section = sar_antenna_section()
        fe = FEModel.from_beam(straight_beam(L, n_elements, dim=2), section)
        modes = craig_bampton(fe.M, fe.K, fe.dofs(n_elements, [1, 2]), n_modes, fixed_dofs=fe.dofs(0)).orthonormalized()
    outer = "bus" if bus == "free" else "ground"
    for i, (hinge, angle, travel) in enumerate(zip(*_stowed(n))):
        name = f"panel{i + 1}"
        if flexible:
            b.add_flexible_body(name, fe, modes, position=hinge, orientation=angle, damping_ratio=zeta)
            tip = b.add_node_frame(name, n_elements, f"{name}.tip")
        else:
            centre = np.asarray(hinge) + 0.5 * L * np.array([np.cos(angle), np.sin(angle)])
            b.add_body(name, mu * L, mu * L**3 / 12.0, centre, angle)
            tip = name
        b.add_revolute(f"hinge{i + 1}", outer, name, at=hinge)
        b.add_angle_driver(f"actuator{i + 1}", f"hinge{i + 1}", cycloidal(travel, T))
        outer = tip
    return b.build()


def momenta(model: Model, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    r"""Total linear momentum (x, y) [N s] and angular momentum about the global origin [N m s] of a
    planar model, shape ``(n, 3)`` for states ``(n, n_q)`` and ``(n, n_v)``.

    Each is :math:`g(q)^\mathsf{T} M(q)\, v`, the momentum conjugate to a rigid motion of the whole
    model, with :math:`g` the velocity every coordinate takes in that motion: a unit translation
    along x or y (``(1, 0, 0)``, ``(0, 1, 0)`` for a body's frame) or a unit rotation about the origin
    (``(−y, x, 1)``); modal coordinates do not move in either.  Without external forces and moments
    all three are conserved, whatever the joints, drivers and elastic forces inside the model.
    Every extra coordinate is taken as internal like a modal one: for a model whose extra
    coordinates are absolute positions (a series damper's node), the result is not its momentum.
    """
    if model.space.dim != 2:
        raise ValueError("momenta: planar models only")
    q, v = np.atleast_2d(q), np.atleast_2d(v)
    nb = model.n_bodies
    out = np.empty((q.shape[0], 3))
    for k in range(q.shape[0]):
        G = np.zeros((3, model.n_v))
        x, y = q[k, 0:3 * nb:3], q[k, 1:3 * nb:3]
        G[0, 0:3 * nb:3] = 1.0
        G[1, 1:3 * nb:3] = 1.0
        G[2, 0:3 * nb:3], G[2, 1:3 * nb:3], G[2, 2:3 * nb:3] = -y, x, 1.0
        out[k] = G @ (model.M(0.0, q[k]) @ v[k])
    return out


def panel_tip_deflection(model: Model, q: np.ndarray, panel: str) -> np.ndarray:
    """Transverse deflection [m] of a flexible panel's tip node from its root tangent (the panel
    frame's x axis), for states ``(n, n_q)``."""
    q = np.atleast_2d(q)
    tip = model.point_position(q, f"{panel}.tip", (0.0, 0.0))
    root = model.point_position(q, panel, (0.0, 0.0))
    th = q[:, model.q_slice(panel)][:, 2]
    return -np.sin(th) * (tip[:, 0] - root[:, 0]) + np.cos(th) * (tip[:, 1] - root[:, 1])


def cantilever_roots(n: int) -> np.ndarray:
    """β_k L of the clamped–free Euler–Bernoulli beam: the roots of 1 + cos x cosh x = 0."""
    from scipy.optimize import brentq

    f = lambda x: np.cos(x) * np.cosh(x) + 1.0  # noqa: E731
    return np.array([brentq(f, (k + 0.5) * np.pi - 0.6, (k + 0.5) * np.pi + 0.6) for k in range(n)])


def driven_cantilever(angle, t: np.ndarray, length: float, mass_per_length: float, EI: float,
                      damping_ratio: float = 0.0, n_modes: int = 4) -> tuple[np.ndarray, np.ndarray]:
    r"""Hub moment [N m] and tip deflection [m] of a uniform cantilever on a hub whose angle
    θ(t) is prescribed, from the exact Euler–Bernoulli cantilever modes (an independent reference
    for :func:`sar_antenna` with one panel on a fixed bus).

    In the frame turning with the hub, with :math:`w = \sum_k \phi_k(x)\,\eta_k(t)` and the
    centrifugal terms :math:`\dot\theta^2` dropped (linear in the deflection and the hub motion),

    .. math::

        \ddot\eta_k + 2\zeta\omega_k\dot\eta_k + \omega_k^2\eta_k = -\frac{\Gamma_k}{m_k}\,\ddot\theta,
        \qquad M = J\,\ddot\theta + \sum_k \Gamma_k\,\ddot\eta_k,

    :math:`\phi_k = \cosh\beta_k x - \cos\beta_k x - \sigma_k(\sinh\beta_k x - \sin\beta_k x)`,
    :math:`\sigma_k = (\cosh\beta_k L + \cos\beta_k L)/(\sinh\beta_k L + \sin\beta_k L)`,
    :math:`\omega_k = \beta_k^2\sqrt{EI/\mu}`, :math:`m_k = \int_0^L \mu\phi_k^2\,dx`,
    :math:`\Gamma_k = \int_0^L \mu x\phi_k\,dx`, :math:`J = \mu L^3/3` (Meirovitch, *Fundamentals
    of Vibrations*, the cantilever's modes; the base-excitation form of the modal equations).
    The integrals by 96-point Gauss–Legendre quadrature.  The modal equations are solved exactly
    (matrix exponential, :func:`scipy.signal.lsim`) for θ̈ linear between samples of a grid at least
    20 000 steps fine that contains the output times ``t``, which must be evenly spaced; from rest.
    Valid for ``n_modes`` up to about 8 (the hyperbolic terms cancel to e^{β_k L}·eps).
    """
    from scipy.signal import lsim

    if not (isinstance(n_modes, (int, np.integer)) and 1 <= n_modes <= 8):
        raise ValueError(f"driven_cantilever: n_modes = {n_modes!r} must be an integer from 1 to 8")
    t = np.asarray(t, float)
    if t.ndim != 1 or t.size < 2 or not np.allclose(np.diff(t), t[1] - t[0], rtol=1e-9, atol=0.0) or t[1] <= t[0]:
        raise ValueError("driven_cantilever: t must be at least two evenly spaced, increasing times")
    L, mu = float(length), float(mass_per_length)
    beta = cantilever_roots(n_modes) / L
    sigma = (np.cosh(beta * L) + np.cos(beta * L)) / (np.sinh(beta * L) + np.sin(beta * L))

    def phi(k, x):
        bx = beta[k] * x
        return np.cosh(bx) - np.cos(bx) - sigma[k] * (np.sinh(bx) - np.sin(bx))

    xg, wg = np.polynomial.legendre.leggauss(96)  # exact to 1e-15 for these smooth shapes on [0, L]
    xg, wg = 0.5 * L * (xg + 1.0), 0.5 * L * wg
    m = np.array([mu * wg @ phi(k, xg) ** 2 for k in range(n_modes)])
    G = np.array([mu * wg @ (xg * phi(k, xg)) for k in range(n_modes)])
    w = beta**2 * np.sqrt(EI / mu)
    c, k2 = 2.0 * damping_ratio * w, w**2

    n = n_modes
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.diag(k2), -np.diag(c)]])
    B = np.concatenate([np.zeros(n), -G / m])[:, None]
    sub = max(1, int(np.ceil(20000 / (t.size - 1))))
    fine = np.linspace(t[0], t[-1], (t.size - 1) * sub + 1)
    u = np.array([angle(x)[2] for x in fine])
    _, _, x = lsim((A, B, np.eye(2 * n), np.zeros((2 * n, 1))), u, fine, interp=True)
    x = x[::sub]
    eta, etad = x[:, :n].T, x[:, n:].T
    thdd = u[::sub]
    etadd = -c[:, None] * etad - k2[:, None] * eta - (G / m)[:, None] * thdd[None, :]
    moment = mu * L**3 / 3.0 * thdd + G @ etadd
    tip = np.array([phi(k, L) for k in range(n_modes)]) @ eta
    return moment, tip
