"""Creep force laws: limits, symmetries, Kalker table interpolation, registry, bad input.

Oracles: Kalker's linear theory (the common small-creepage limit), Coulomb saturation mu N at
large creepage, odd symmetry of friction forces, the tabulated Kalker coefficients themselves,
and closed-form integrals of Kalker's simplified theory for FASTSIM.
"""

import numpy as np
import pandas as pd
import pytest

from core.errors import InputError, NameTakenError, UnknownNameError
from railway.contact.creep import (
    CREEP_MODELS,
    CreepModel,
    Fastsim,
    KalkerLinear,
    Polach2000,
    Polach2005,
    _asymptote_small_a,
    _asymptote_small_b,
    creep_forces,
    get_creep_model,
    kalker_coefficients,
    kalker_table,
    kalker_table_path,
    register_creep_model,
)
from railway.contact.creep_curve import creep_curve, plot_creep_curve

# a typical tread contact: N = 100 kN, a = 6 mm (rolling), b = 4 mm, steel
N0, A0, B0, G0, NU0, MU0 = 1e5, 6e-3, 4e-3, 8.1e10, 0.28, 0.3
ALL = sorted(CREEP_MODELS)


def _lin(xi, eta, phi, a=A0, b=B0, nu=NU0):
    return KalkerLinear()(xi, eta, phi, N0, a, b, G0, nu, MU0)


# ----------------------------------------------------------------------------- Kalker table

def test_table_nodes_reproduced_exactly():
    df = pd.read_csv(kalker_table_path())
    ratio = np.where(df["branch"] == "a/b<=1", df["g"], 1.0 / df["g"])
    C = np.stack(kalker_coefficients(ratio, df["nu"].to_numpy()))
    ref = df[["C11", "C22", "C23", "C33"]].to_numpy().T
    np.testing.assert_allclose(C, ref, rtol=1e-13)


def test_interpolation_linear_in_g_and_lagrange_in_nu():
    t = kalker_table()["a/b<=1"]
    # midway between g = 0.4 and 0.5 at a tabulated nu: arithmetic mean of the rows
    C = np.stack(kalker_coefficients(0.45, 0.25))[:, 0]
    ref = [0.5 * (t[c][3, 1] + t[c][4, 1]) for c in ("C11", "C22", "C23", "C33")]
    np.testing.assert_allclose(C, ref, rtol=1e-13)
    # at a tabulated g, 1/C is the quadratic through the three nu nodes
    nu = np.array([0.1, 0.3, 0.45])
    for k, c in enumerate(("C11", "C22", "C23", "C33")):
        coef = np.polyfit([0.0, 0.25, 0.5], 1.0 / t[c][6], 2)
        np.testing.assert_allclose(kalker_coefficients(0.7, nu)[k], 1.0 / np.polyval(coef, nu), rtol=1e-12)


def test_branches_meet_at_circular_contact():
    lo = np.stack(kalker_coefficients(1.0 - 1e-12, [0.0, 0.3, 0.5]))
    hi = np.stack(kalker_coefficients(1.0 + 1e-12, [0.0, 0.3, 0.5]))
    np.testing.assert_allclose(lo, hi, rtol=1e-10)


@pytest.mark.parametrize("branch, asym", [("a/b<=1", _asymptote_small_a), ("a/b>1", _asymptote_small_b)])
def test_asymptotes_join_table_at_g_0p1(branch, asym):
    """Kalker's g -> 0 asymptotes against his own table row g = 0.1.

    The asymptotes are leading-order in g, so they miss the g = 0.1 row by a few percent.
    Stated tolerance: C11, C22 within 5 %, C23 within 7 % (measured worst: C23, a << b,
    nu = 0.5: -6.0 %).  The default ``join="scaled"`` removes the jump (tested below).
    """
    t = kalker_table()[branch]
    for j, nu in enumerate((0.0, 0.25, 0.5)):
        Ca = asym(np.array([0.1]), nu)
        for k, (c, tol) in enumerate((("C11", 0.05), ("C22", 0.05), ("C23", 0.07))):
            assert abs(Ca[k][0] / t[c][0, j] - 1.0) <= tol, (branch, nu, c)


@pytest.mark.parametrize("ratio_at, sign", [(0.1, 1), (10.0, -1)])
def test_scaled_join_is_continuous_and_keeps_asymptotic_shape(ratio_at, sign):
    nu = np.array([0.0, 0.27, 0.5])
    eps = 1e-9
    inside = np.stack(kalker_coefficients(ratio_at * (1 + sign * eps), nu))
    outside = np.stack(kalker_coefficients(ratio_at * (1 - sign * eps), nu))
    np.testing.assert_allclose(outside, inside, rtol=1e-6)
    # deep in the asymptotic range scaled/raw is the constant junction factor
    g = np.array([0.05, 0.01, 1e-3])
    r = g if sign > 0 else 1.0 / g
    for n in nu:
        s = np.stack(kalker_coefficients(r, n, join="scaled"))[:3]
        w = np.stack(kalker_coefficients(r, n, join="raw"))[:3]
        q = s / w
        np.testing.assert_allclose(q, q[:, :1] * np.ones((1, 3)), rtol=1e-12)


# ----------------------------------------------------------------------------- small creepage

CASES = {  # creepages small enough that beta = F_lin/(mu N) ~ 1e-4: nonlinear terms < 1e-4 relative
    "xi": (2e-7, 0.0, 0.0),
    "eta": (0.0, -2e-7, 0.0),
    "phi": (0.0, 0.0, 1e-4),
    "eta+phi same sign": (0.0, 1e-7, 2e-5),
    "eta+phi opposite": (0.0, 1e-7, -5e-5),
}


#: laws checked against Kalker's linear theory at small creepage (FASTSIM: against the simplified
#: theory it discretises, test_fastsim_small_creepage_against_simplified_theory)
SMALL_CREEPAGE_MODELS = ["kalker_linear", "shen_hedrick_elkins", "polach2000", "polach2005"]


@pytest.mark.parametrize("model", SMALL_CREEPAGE_MODELS)
@pytest.mark.parametrize("case", sorted(CASES))
def test_small_creepage_limit_is_kalker_linear(model, case):
    xi, eta, phi = CASES[case]
    ref = _lin(xi, eta, phi)
    f = creep_forces(model, xi, eta, phi, N0, A0, B0, G0, NU0, MU0)
    scale = max(np.hypot(ref.Fx[0], ref.Fy[0]), 1e-300)
    for comp in ("Fx", "Fy"):
        assert abs(getattr(f, comp)[0] - getattr(ref, comp)[0]) <= 1e-4 * scale, comp
    assert f.Mz[0] == pytest.approx(ref.Mz[0], rel=1e-4, abs=1e-300)


def test_polach_spin_term_sign():
    """The trap of the notes: Polach's F_yS must tend to -G c^3 C23 phi (same sign as Kalker)."""
    phi = np.array([1e-5, -1e-5])
    f = Polach2000()(0.0, 0.0, phi, N0, A0, B0, G0, NU0, MU0)
    C23 = kalker_coefficients(A0 / B0, NU0)[2]
    np.testing.assert_allclose(f.Fy, -G0 * (A0 * B0) ** 1.5 * C23 * phi, rtol=1e-6)
    assert np.all(np.sign(f.Fy) == -np.sign(phi))


def test_polach2005_initial_slope_and_reduction_to_2000():
    kA, kS = 0.8, 0.3
    xi = 1e-7
    f = Polach2005(k_A=kA, k_S=kS)(xi, 0.0, 0.0, N0, A0, B0, G0, NU0, MU0)
    # F ~ (2 N mu/pi)(k_A + k_S) eps  ->  (k_A + k_S)/2 times the Kalker slope
    assert f.Fx[0] == pytest.approx(0.5 * (kA + kS) * _lin(xi, 0, 0).Fx[0], rel=1e-5)
    rng = np.random.default_rng(3)
    c = rng.normal(size=(3, 40)) * np.array([[3e-3], [3e-3], [0.5]])
    f0 = Polach2000()(*c, N0, A0, B0, G0, NU0, MU0)
    f1 = Polach2005()(*c, N0, A0, B0, G0, NU0, MU0)
    for u, v in zip(f0, f1):
        np.testing.assert_array_equal(u, v)


@pytest.mark.parametrize("n", [20, 40, 80])
def test_fastsim_small_creepage_against_simplified_theory(n):
    """FASTSIM's linear limit in closed form (Kalker's simplified theory on the ellipse).

    Fx = -(8 a^2 b/3) xi/L1 = -G c^2 C11 xi, Fy = -G c^2 C22 eta - G c^3 C23 phi (by the choice of
    L1, L2, L3);  Mz = (pi a^3 b/4) eta/L2 - (8 a^2 b^3/15) phi/L3.
    The element-centre (midpoint) quadrature is second order: tolerance 4 n^-2 (the error
    constants of the midpoint rule for these smooth integrands are O(1)); the order itself is
    checked in :func:`test_fastsim_converges_second_order`.
    """
    C11, C22, C23, _ = kalker_coefficients(A0 / B0, NU0)
    L2 = 8 * A0 / (3 * G0 * C22)
    L3 = np.pi * A0 * np.sqrt(A0 / B0) / (4 * G0 * C23)
    fs = Fastsim(n_x=n, n_y=n)
    tol = 4.0 / n**2
    for xi, eta, phi in ((1e-7, 0, 0), (0, 1e-7, 0), (0, 0, 1e-5)):
        f = fs(xi, eta, phi, N0, A0, B0, G0, NU0, MU0)
        ref = _lin(xi, eta, phi)
        Mz = np.pi * A0**3 * B0 / 4 * eta / L2 - 8 * A0**2 * B0**3 / 15 * phi / L3
        scale = np.hypot(ref.Fx[0], ref.Fy[0])
        assert abs(f.Fx[0] - ref.Fx[0]) <= tol * scale
        assert abs(f.Fy[0] - ref.Fy[0]) <= tol * scale
        if Mz != 0:
            assert f.Mz[0] == pytest.approx(Mz, rel=tol)
        else:
            assert abs(f.Mz[0]) <= 1e-12 * scale * A0


def test_fastsim_converges_second_order():
    def err(n):
        f = Fastsim(n_x=n, n_y=n)(0.0, 0.0, 1e-5, N0, A0, B0, G0, NU0, MU0)
        return abs(f.Fy[0] / _lin(0.0, 0.0, 1e-5).Fy[0] - 1.0)

    e20, e40, e80 = err(20), err(40), err(80)
    assert e40 / e20 < 0.3 and e80 / e40 < 0.3  # 0.25 for second order


# ----------------------------------------------------------------------------- large creepage

SATURATION_CASES = [
    ("shen_hedrick_elkins", 1e-14),     # exactly mu N for beta >= 3
    ("polach2000", 1e-6),               # deficit (4/(3 pi)) eps^-3, eps ~ 1e4 here
    ("polach2005", 1e-6),
    ("fastsim", 5e-3),                  # sum of the discretised parabolic bound, 40 x 40 grid
]


@pytest.mark.parametrize("model, tol", SATURATION_CASES)
@pytest.mark.parametrize("direction", [(1.0, 0.0), (0.0, -1.0), (0.6, 0.8)])
def test_large_creepage_saturates_at_mu_N(model, tol, direction):
    s = 0.5
    f = creep_forces(model, s * direction[0], s * direction[1], 0.0, N0, A0, B0, G0, NU0, MU0)
    FR = np.hypot(f.Fx[0], f.Fy[0])
    assert FR == pytest.approx(MU0 * N0, rel=tol)
    # and the force opposes the creepage (dissipates); Polach's law makes it exactly antiparallel,
    # SHE keeps the direction of the anisotropic Kalker force (C11 != C22), FASTSIM nearly so
    power = np.dot([f.Fx[0], f.Fy[0]], direction)
    assert power < 0
    if model.startswith("polach"):
        assert power == pytest.approx(-FR, rel=1e-12)


def test_polach2005_falling_friction_limit():
    A, B, V = 0.4, 0.6, 20.0
    model = Polach2005(k_A=0.9, k_S=0.4, A=A, B=B, speed=V)
    s = np.array([0.05, 0.2, 0.8])
    f = model(-s, 0.0, 0.0, N0, A0, B0, G0, NU0, MU0)
    mu_w = MU0 * ((1 - A) * np.exp(-B * V * s) + A)
    # F = (2 N mu/pi)[k_A eps/(1+(k_A eps)^2) + arctan(k_S eps)] -> mu(w) N, deficit ~ 1/(k_S eps)
    eps = np.pi * G0 * A0 * B0 * kalker_coefficients(A0 / B0, NU0)[0] * s / (4 * N0 * mu_w)
    np.testing.assert_allclose(f.Fx, mu_w * N0, rtol=2.0 / (np.pi * 0.4 * eps.min()))
    assert np.all(np.diff(f.Fx) < 0)  # falling friction: the force decreases with slip


def test_saturated_models_never_exceed_mu_N():
    rng = np.random.default_rng(11)
    c = rng.normal(size=(2, 500)) * 0.01
    for model in ("shen_hedrick_elkins", "fastsim"):
        f = creep_forces(model, c[0], c[1], 0.0, N0, A0, B0, G0, NU0, MU0)
        assert np.all(np.hypot(f.Fx, f.Fy) <= MU0 * N0 * (1 + 5e-3)), model
    f = creep_forces("polach2000", c[0], c[1], 0.0, N0, A0, B0, G0, NU0, MU0)
    assert np.all(np.hypot(f.Fx, f.Fy) <= MU0 * N0 * (1 + 1e-12))


# ----------------------------------------------------------------------------- symmetry

@pytest.mark.parametrize("model", ALL)
def test_odd_in_creepage_and_mirror_symmetric(model):
    rng = np.random.default_rng(5)
    xi, eta = rng.normal(size=(2, 30)) * 4e-3
    phi = rng.normal(size=30) * 0.8
    m = get_creep_model(model)
    f = m(xi, eta, phi, N0, A0, B0, G0, NU0, MU0)
    g = m(-xi, -eta, -phi, N0, A0, B0, G0, NU0, MU0)
    for u, v in zip(f, g):
        np.testing.assert_allclose(v, -u, rtol=1e-12, atol=1e-9)
    # mirror about the x-z plane (y -> -y): eta, phi change sign, Fx stays, Fy and Mz flip
    h = m(xi, -eta, -phi, N0, A0, B0, G0, NU0, MU0)
    np.testing.assert_allclose(h.Fx, f.Fx, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(h.Fy, -f.Fy, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(h.Mz, -f.Mz, rtol=1e-12, atol=1e-9)


def test_fastsim_batch_equals_serial():
    rng = np.random.default_rng(2)
    n = 12
    xi, eta = rng.normal(size=(2, n)) * 3e-3
    phi = rng.normal(size=n)
    N = rng.uniform(2e4, 1.2e5, n)
    a = rng.uniform(2e-3, 9e-3, n)
    b = rng.uniform(2e-3, 9e-3, n)
    fs = Fastsim(n_x=25, n_y=25)
    batch = fs(xi, eta, phi, N, a, b, G0, NU0, MU0)
    for i in range(n):
        one = fs(xi[i], eta[i], phi[i], N[i], a[i], b[i], G0, NU0, MU0)
        for u, v in zip(batch, one):
            assert u[i] == v[0]


def test_zero_load_gives_zero_forces():
    f = creep_forces("polach2000", [0.01, 0.01], 0.0, 0.0, [0.0, N0], [0.0, A0], [0.0, B0], G0, NU0, MU0)
    assert f.Fx[0] == 0 and f.Fy[0] == 0 and f.Mz[0] == 0 and f.Fx[1] < 0


# ----------------------------------------------------------------------------- interface

def test_registry_names_aliases_classes_and_user_models():
    assert {"kalker_linear", "polach2000", "polach2005", "shen_hedrick_elkins", "fastsim"} <= set(CREEP_MODELS)
    assert isinstance(get_creep_model("SHE"), CREEP_MODELS["shen_hedrick_elkins"])
    assert isinstance(get_creep_model("Polach-2005", k_A=0.5, k_S=0.1), Polach2005)
    inst = Polach2000()
    assert get_creep_model(inst) is inst

    class Coulomb(CreepModel):
        def _forces(self, xi, eta, phi, N, a, b, G, nu, mu):
            s = np.hypot(xi, eta)
            with np.errstate(invalid="ignore"):
                return (np.where(s > 0, -mu * N * xi / s, 0.0), np.where(s > 0, -mu * N * eta / s, 0.0),
                        np.zeros_like(xi))

    register_creep_model("test_coulomb", Coulomb)
    try:
        f = creep_forces("test_coulomb", 0.1, 0.0, 0.0, N0, A0, B0, G0, NU0, MU0)
        assert f.Fx[0] == pytest.approx(-MU0 * N0)
    finally:
        CREEP_MODELS.unregister("test_coulomb")
    assert "test_coulomb" not in CREEP_MODELS
    with pytest.raises(ValueError, match="unknown creep model 'nope'"):
        get_creep_model("nope")


def test_unknown_or_taken_names_raise_the_registry_errors():
    # the registry is core.registry.Registry: an unknown name raises UnknownNameError listing the
    # registered laws (it was a plain ValueError; a taken name raised TypeError from formatting
    # the registered class with float())
    with pytest.raises(UnknownNameError, match="unknown creep model 'nope'; registered: kalker_linear, "
                                               "shen_hedrick_elkins, polach2000, polach2005, fastsim"):
        get_creep_model("nope")
    with pytest.raises(UnknownNameError, match="given as 'No-Pe'"):
        get_creep_model("No-Pe")

    class Other(CreepModel):
        pass

    with pytest.raises(NameTakenError, match="'polach2000' is taken by railway.contact.creep.Polach2000"):
        register_creep_model("polach2000", Other)
    assert CREEP_MODELS["polach2000"] is Polach2000
    assert register_creep_model("polach2000", Polach2000) is Polach2000  # same class again: no-op
    with pytest.raises(TypeError, match="CreepModel subclasses"):
        register_creep_model("not_a_law", int)
    assert "not_a_law" not in CREEP_MODELS
    with pytest.raises(InputError, match="parameters \\['join'\\] given with a model instance"):
        get_creep_model(Polach2000(), join="raw")
    with pytest.raises(InputError, match="must be a name, a CreepModel class or instance, got 3.0"):
        get_creep_model(3.0)


@pytest.mark.parametrize("model", ALL)
@pytest.mark.parametrize("kwargs, match", [
    (dict(normal_force=-5.0), "normal_force must be >= 0, got -5.0 at index 0"),
    (dict(xi=np.nan), "xi must be finite, got nan at index 0"),
    (dict(eta=[0.0, np.nan]), "eta must be finite, got nan at index 1"),
    (dict(phi=np.nan), "phi must be finite, got nan at index 0"),
    (dict(phi=[0.0, np.inf]), "phi must be finite, got inf at index 1"),
    (dict(nu=0.7), "Poisson ratio nu must lie in \\[0, 0.5\\], got 0.7"),
    (dict(nu=-0.01), "Poisson ratio nu must lie in \\[0, 0.5\\], got -0.01"),
    (dict(mu=0.0), "friction coefficient mu must be > 0, got 0.0"),
    (dict(mu=-0.2), "friction coefficient mu must be > 0, got -0.2"),
    (dict(G=0.0), "shear modulus G must be > 0, got 0.0"),
    (dict(a=0.0), "needs semi-axes a, b > 0"),
])
def test_bad_input_names_the_value(model, kwargs, match):
    args = dict(xi=1e-3, eta=0.0, phi=0.0, normal_force=N0, a=A0, b=B0, G=G0, nu=NU0, mu=MU0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        get_creep_model(model)(**args)


def test_kalker_table_comes_from_the_project_data_folder():
    from core.paths import data_path

    assert kalker_table_path() == data_path("railway", "kalker_coefficients.csv")


def test_polach2005_parameter_checks():
    with pytest.raises(ValueError, match="k_A=0.3, k_S=0.5"):
        Polach2005(k_A=0.3, k_S=0.5)
    with pytest.raises(ValueError, match="A must lie in \\(0, 1\\], got 1.5"):
        Polach2005(A=1.5)


# ----------------------------------------------------------------------------- creep curve

def test_creep_curve_table_and_figure(tmp_path):
    df = creep_curve(["kalker_linear", "polach2000", "fastsim"], "xi", np.linspace(-0.01, 0.01, 21),
                     normal_force=N0, a=A0, b=B0, G=G0, nu=NU0, mu=MU0, eta=1e-3)
    assert len(df) == 63
    assert {"model", "xi [-]", "eta [-]", "phi [1/m]", "Fx [N]", "Fy [N]", "Mz [N m]"} <= set(df.columns)
    assert np.all(df["eta [-]"] == 1e-3)
    pol = df[df["model"] == "polach2000"]
    assert np.all(np.hypot(pol["Fx [N]"], pol["Fy [N]"]) <= MU0 * N0 * (1 + 1e-12))
    fig = plot_creep_curve(df)
    out = tmp_path / "curve.png"
    fig.savefig(out)
    assert out.stat().st_size > 1000


def test_creep_curve_from_curvatures_uses_hertz():
    from core.contact_laws import hertz_from_load

    E, nu = 2.1e11, 0.3
    A, B = 1 / (2 * 0.46), 1 / (2 * 0.3)
    df = creep_curve("polach2000", "eta", [1e-3], normal_force=N0, A=A, B=B, E=E, nu=nu, mu=MU0)
    h = hertz_from_load(N0, A, B, E, nu, E, nu)
    assert df["a [m]"].iloc[0] == pytest.approx(h.a[0], rel=1e-14)
    assert df["b [m]"].iloc[0] == pytest.approx(h.b[0], rel=1e-14)
    assert df["G [Pa]"].iloc[0] == pytest.approx(E / 2.6, rel=1e-14)


@pytest.mark.parametrize("model", ["shen_hedrick_elkins", "polach2000", "polach2005"])
def test_spin_moment_bounded_by_linear_moment(model):
    # sweep eta through the zero of the linear lateral force, eta = -C23 c phi / C22, where a
    # moment scaled by |F|/|F_lin| would blow up
    phi = 0.5
    eta = np.linspace(-0.01, 0.01, 2001)
    f = creep_forces(model, 0.0, eta, phi, N0, A0, B0, G0, NU0, MU0)
    ref = _lin(0.0, eta, phi)
    assert np.all(np.abs(f.Mz) <= np.abs(ref.Mz) * (1 + 1e-12))


def test_cli_creep_curve(tmp_path, capsys):
    import argparse

    from railway.cli.creep_curve import add_creep_curve_parser

    parser = argparse.ArgumentParser()
    rail = parser.add_subparsers().add_parser("railway").add_subparsers()
    add_creep_curve_parser(rail)
    args = parser.parse_args(["railway", "creep-curve", "--model", "polach2000", "--model", "she",
                              "--creepage", "phi", "--n", "11", "--load-kN", "80", "-o", str(tmp_path)])
    assert args.func(args) == 0
    df = pd.read_csv(tmp_path / "creep_curve.csv")
    assert len(df) == 22 and df["N [N]"].iloc[0] == 80e3
    assert (tmp_path / "creep_curve.md").is_file() and (tmp_path / "creep_curve.png").is_file()
    assert "polach2000" in capsys.readouterr().out
    bad = parser.parse_args(["railway", "creep-curve", "--mu", "-0.1", "-o", str(tmp_path)])
    with pytest.raises(SystemExit) as exc:
        bad.func(bad)
    assert exc.value.code == 2
    # issue 21: the option is checked against its plausible range before the model sees it
    assert "--mu -0.1: the wheel-rail friction coefficient must lie in 0.01 ... 1" in capsys.readouterr().err


def test_every_registered_creep_law_is_in_the_property_lists():
    """A new creep law cannot skip the property tests: every registered law is in the small-creepage
    list (or is FASTSIM, checked against the simplified theory), in the saturation list (or is
    Kalker's linear law, unsaturated by definition) and in the symmetry test (ALL)."""
    registered = set(CREEP_MODELS)
    assert registered <= set(SMALL_CREEPAGE_MODELS) | {"fastsim"}
    assert registered <= {m for m, _ in SATURATION_CASES} | {"kalker_linear"}
    assert registered == set(ALL)
