"""SimulationResult tables, the CSV/Markdown writer and the figure helpers.

Inputs are closed-form time histories (a point mass turning uniformly on a circle),
so every expected value below is computed independently of the code under test.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest

from core.plot import (
    plot_energy,
    plot_time_history,
    plot_violations,
    plot_work_precision,
    plot_xy_path,
    save_figure,
)
from core.results import SimulationResult, environment_versions, markdown_table, run_metadata, write_table

OMEGA = 2.0  # rad/s
MASS = 3.0  # kg
LENGTH = 0.5  # m


def oscillator(n_t: int = 41, status: str = "finished", with_lam: bool = True) -> SimulationResult:
    """A point on a circle of radius LENGTH turning at OMEGA, as a constrained 2-D mass.

    q = (x, y) = L (cos wt, sin wt), v = L w (-sin wt, cos wt); one constraint
    Phi = (x^2 + y^2 - L^2)/2 with multiplier lam = -m w^2 (centripetal force / L);
    energy = m L^2 w^2 / 2 (constant).
    """
    t = np.linspace(0.0, 2.0, n_t)
    q = LENGTH * np.column_stack([np.cos(OMEGA * t), np.sin(OMEGA * t)])
    v = LENGTH * OMEGA * np.column_stack([-np.sin(OMEGA * t), np.cos(OMEGA * t)])
    kwargs = {}
    if with_lam:
        kwargs["lam"] = np.full((n_t, 1), -MASS * OMEGA**2)
    phi = 0.5 * (np.sum(q**2, axis=1) - LENGTH**2)
    dphi = np.sum(q * v, axis=1)
    energy = 0.5 * MASS * np.sum(v**2, axis=1)
    return SimulationResult(
        t=t,
        q=q,
        v=v,
        status=status,
        message="reached t_end" if status == "finished" else "Newton failed at t=1.0",
        counters={"rhs": 120, "jacobians": 3},
        meta=run_metadata(method="test", system="circle", rtol=1e-6, atol=1e-9, wall_time_s=0.25),
        coordinate_names=["x [m]", "y [m]"],
        velocity_names=["vx [m/s]", "vy [m/s]"],
        constraint_names=["circle"],
        position_violation=np.abs(phi),
        velocity_violation=np.abs(dphi),
        energy=energy,
        reactions={"pivot": -MASS * OMEGA**2 * q},
        reaction_names={"pivot": ["Fx [N]", "Fy [N]"]},
        **kwargs,
    )


# --------------------------------------------------------------------------------------
# SimulationResult
# --------------------------------------------------------------------------------------
def test_tables_carry_time_and_units():
    res = oscillator()
    t = np.linspace(0.0, 2.0, 41)
    coords = res.coordinates()
    assert list(coords.columns) == ["t [s]", "x [m]", "y [m]"]
    np.testing.assert_array_equal(coords["t [s]"], t)
    np.testing.assert_allclose(coords["x [m]"], LENGTH * np.cos(OMEGA * t), rtol=0, atol=1e-15)
    assert list(res.velocities().columns) == ["t [s]", "vx [m/s]", "vy [m/s]"]
    assert list(res.multipliers().columns) == ["t [s]", "circle"]
    viol = res.violations()
    assert list(viol.columns) == ["t [s]", "position violation [m]", "velocity violation [m/s]"]
    assert "units" in viol.attrs
    assert coords.attrs["meta"]["method"] == "test"


def test_violations_of_exact_solution_are_roundoff():
    res = oscillator()
    viol = res.violations()
    eps = np.finfo(float).eps
    assert viol["position violation [m]"].max() <= 4 * eps * LENGTH**2
    assert viol["velocity violation [m/s]"].max() <= 4 * eps * LENGTH**2 * OMEGA


def test_energy_table_matches_closed_form():
    res = oscillator()
    df = res.energy_table()
    e0 = 0.5 * MASS * (LENGTH * OMEGA) ** 2
    np.testing.assert_allclose(df["energy [J]"], e0, rtol=4 * np.finfo(float).eps)
    np.testing.assert_allclose(df["energy drift [J]"], df["energy [J]"] - df["energy [J]"].iloc[0], rtol=0, atol=0)
    np.testing.assert_allclose(df["relative energy drift [-]"], df["energy drift [J]"] / e0, rtol=1e-12, atol=0)
    assert df.attrs["energy scale [J]"] == pytest.approx(e0)


def test_energy_table_with_zero_initial_energy_uses_max_scale():
    t = np.linspace(0, 1, 5)
    energy = np.array([0.0, 1.0, 2.0, 1.0, -4.0])
    res = SimulationResult(t=t, q=np.zeros((5, 1)), v=np.zeros((5, 1)), status="finished", energy=energy)
    df = res.energy_table()
    np.testing.assert_allclose(df["relative energy drift [-]"], energy / 4.0)


def test_summary_energy_drift_from_zero_initial_energy_is_absolute():
    """E0 = 0 (e.g. a pendulum released from its pivot height): the summary gives the absolute drift and
    its scale; a relative drift against the run's own maximum would read 1 whatever the error."""
    t = np.linspace(0, 1, 4)
    res = SimulationResult(t=t, q=np.zeros((4, 1)), v=np.zeros((4, 1)), status="finished",
                           energy=np.array([0.0, 1e-9, -3e-9, 2e-9]))
    row = res.summary().iloc[0]
    assert row["max |energy drift| [J]"] == pytest.approx(3e-9, rel=1e-12)
    assert row["energy scale [J]"] == pytest.approx(3e-9, rel=1e-12)
    assert np.isnan(row["max |relative energy drift| [-]"])
    res = SimulationResult(t=t, q=np.zeros((4, 1)), v=np.zeros((4, 1)), status="finished",
                           energy=np.array([-2.0, -2.0 + 1e-6, -2.0, -2.0 - 4e-6]))
    row = res.summary().iloc[0]
    assert row["max |energy drift| [J]"] == pytest.approx(4e-6, rel=1e-9)
    assert row["max |relative energy drift| [-]"] == pytest.approx(2e-6, rel=1e-9)


def _gfm_table(text: str) -> tuple[list[str], list[list[str]]]:
    """Header cells and body rows of the one GitHub-flavoured Markdown table in ``text``, as a GFM
    parser (markdown-it-py, CommonMark + the table extension) reads them."""
    from markdown_it import MarkdownIt

    tokens = MarkdownIt("commonmark").enable("table").parse(text)
    assert sum(tok.type == "table_open" for tok in tokens) == 1, "the text is not one Markdown table"
    header, rows, cell = [], [], None
    for tok in tokens:
        if tok.type == "tr_open":
            rows.append([])
        elif tok.type in ("th_open", "td_open"):
            cell = tok.type
        elif tok.type == "inline" and cell is not None:
            rows[-1].append(tok.content)
            cell = None
    header, body = rows[0], rows[1:]
    return header, body


def test_markdown_tables_render_with_pipes_in_headers_cells_and_index(tmp_path):
    """Headers such as "max |Φ| [m]" and cells holding "|" must not split cells: every row of the
    written .md parses, with a GFM parser, into exactly the DataFrame's columns, with the text unchanged."""
    df = pd.DataFrame({"max |Φ| [m]": [1.5e-10, 2.0], "status": ["finished", "a | b\nnext line"],
                       "note": ["|x|", "already \\| escaped"]},
                      index=pd.Index(["run |1|", "run 2"], name="case |k|"))
    paths = write_table(df, tmp_path, "pipes")
    header, body = _gfm_table(paths["md"].read_text())
    assert header == ["case |k|", "max |Φ| [m]", "status", "note"]
    assert len(body) == 2 and all(len(r) == 4 for r in body)
    assert body[0][0] == "run |1|" and body[0][3] == "|x|"
    assert body[1][2] == "a | b next line" and body[1][3] == "already | escaped"
    assert float(body[0][1]) == pytest.approx(1.5e-10)
    # the CSV keeps the text as it is
    assert pd.read_csv(paths["csv"])["status"].iloc[1] == "a | b\nnext line"
    # the same function serves printed tables
    header, _ = _gfm_table(markdown_table(df.reset_index()))
    assert header[1] == "max |Φ| [m]"


def test_simulation_summary_table_renders(tmp_path):
    """The summary of a real run (its headers hold |·|) written by write_table parses as a table."""
    from core import models
    from core.integrators import simulate

    res = simulate(models.simple_pendulum(), (0.0, 0.2), "rk45-projection", n_output=5)
    summ = res.summary()
    header, body = _gfm_table(write_table(summ, tmp_path, "summary")["md"].read_text())
    assert header == list(summ.columns) and len(body) == 1 and len(body[0]) == len(header)


def test_reactions_summary_final_state_and_frame():
    res = oscillator()
    reac = res.reactions_table("pivot")
    assert list(reac.columns) == ["t [s]", "Fx [N]", "Fy [N]"]
    np.testing.assert_allclose(np.hypot(reac["Fx [N]"], reac["Fy [N]"]), MASS * OMEGA**2 * LENGTH, rtol=1e-14)
    with pytest.raises(ValueError, match="'hinge'.*pivot"):
        res.reactions_table("hinge")

    summary = res.summary()
    assert len(summary) == 1
    row = summary.iloc[0]
    assert row["status"] == "finished" and row["method"] == "test" and row["n rhs"] == 120
    assert row["versions.numpy"] == np.__version__
    assert row["final position violation [m]"] == res.position_violation[-1]

    fs = res.final_state()
    assert fs.t == 2.0
    np.testing.assert_array_equal(fs.q, res.q[-1])
    fs.q[0] = 99.0  # a copy: the result is untouched
    assert res.q[-1, 0] != 99.0

    frame = res.to_frame()
    assert frame.columns[0] == "t [s]"
    assert {"x [m]", "vy [m/s]", "circle", "position violation [m]", "energy [J]"} <= set(frame.columns)
    assert len(frame) == res.n_t


def test_status_success_and_immutability():
    assert oscillator().success
    failed = oscillator(status="failed")
    assert not failed.success and "Newton" in failed.summary().iloc[0]["message"]
    res = oscillator()
    with pytest.raises(ValueError, match="read-only"):
        res.q[0, 0] = 1.0
    with pytest.raises(AttributeError):
        res.status = "failed"


def test_defaults_for_unconstrained_system():
    t = np.linspace(0, 1, 3)
    res = SimulationResult(t=t, q=np.zeros((3, 2)), v=np.ones((3, 2)), status="finished")
    assert res.coordinate_names == ["q[0]", "q[1]"]
    assert res.constraint_names == []
    np.testing.assert_array_equal(res.violations()["position violation [m]"], 0.0)
    assert set(res.meta["versions"]) >= {"numpy", "scipy", "mbsuite"}
    with pytest.raises(ValueError, match="multipliers"):
        res.multipliers()
    with pytest.raises(ValueError, match="energy"):
        res.energy_table()


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"status": "done"}, "status"),
        ({"t": np.array([0.0, 2.0, 1.0])}, r"strictly increasing: t\[1\]"),
        ({"q": np.zeros((2, 2))}, r"q has 2 rows but t has 3"),
        ({"v": np.zeros(3)}, r"v must be 2-D"),
        ({"lam": np.zeros((4, 1))}, r"lam has 4 rows"),
        ({"coordinate_names": ["a"]}, r"coordinate_names has 1 names for 2"),
        ({"coordinate_names": ["a", "a"]}, "duplicate"),
        ({"position_violation": None}, "position_violation is required"),
        ({"velocity_violation": np.zeros(4)}, r"velocity_violation has shape \(4,\)"),
        ({"energy": np.zeros((3, 1))}, "energy must be 1-D"),
        ({"counters": {"rhs": -1}}, r"counters\['rhs'\]"),
        ({"reactions": {"j": np.zeros((2, 2))}}, r"reactions\['j'\] has 2 rows"),
        ({"reactions": {"j": np.zeros((3, 2))}, "reaction_names": {"j": ["Fx [N]"]}}, "1 names for 2"),
        ({"reaction_names": {"k": ["Fx [N]"]}}, "without reactions"),
    ],
)
def test_validation_messages(change, message):
    kwargs = dict(
        t=np.array([0.0, 1.0, 2.0]),
        q=np.zeros((3, 2)),
        v=np.zeros((3, 2)),
        status="finished",
        lam=np.zeros((3, 1)),
        position_violation=np.zeros(3),
        velocity_violation=np.zeros(3),
    )
    kwargs.update(change)
    with pytest.raises(ValueError, match=message):
        SimulationResult(**kwargs)


def test_run_metadata_and_versions():
    meta = run_metadata(method="HHT", system="m", rtol=None, atol=None, h=1e-3, alpha=-0.1)
    assert meta["h"] == 1e-3 and meta["alpha"] == -0.1
    assert meta["versions"] == environment_versions()


def test_simulate_writes_the_metadata_of_run_metadata():
    """One definition of the metadata keys: a simulated result carries exactly run_metadata's keys
    (plus the entries simulate adds) with the run's values."""
    from core.models import simple_pendulum
    from core.simulation import simulate

    res = simulate(simple_pendulum(bob="rod"), (0.0, 0.1), "rk45", rtol=1e-5, atol=1e-7, n_output=3)
    ref = run_metadata(method="rk45", system=res.meta["system"], rtol=1e-5, atol=1e-7, h=None, wall_time_s=0.0)
    assert set(ref) <= set(res.meta)
    assert set(res.meta) - set(ref) == {"total_time_s", "t_end_reached", "max_invariant_violation"}
    assert res.meta["method"] == "rk45" and res.meta["rtol"] == 1e-5 and res.meta["t_end_reached"] == 0.1
    assert res.meta["versions"] == environment_versions()


# --------------------------------------------------------------------------------------
# write_table
# --------------------------------------------------------------------------------------
def test_write_table_round_trip(tmp_path):
    rng = np.random.default_rng(7)
    df = pd.DataFrame({"t [s]": np.linspace(0, 1, 6), "Fx [N]": rng.standard_normal(6), "name": list("abcdef")})
    paths = write_table(df, tmp_path / "sub", "forces")
    assert paths == {"csv": tmp_path / "sub" / "forces.csv", "md": tmp_path / "sub" / "forces.md"}
    # pandas >= 3 reads the shortest repr back exactly by default; pandas 2 needs round_trip.
    kw = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}
    back = pd.read_csv(paths["csv"], **kw)
    pd.testing.assert_frame_equal(back, df, check_exact=True, check_dtype=False)
    md = paths["md"].read_text().splitlines()
    assert md[0].startswith("|") and "Fx [N]" in md[0] and "t [s]" in md[0]
    assert len(md) == 2 + len(df)
    assert f"{df['Fx [N]'].iloc[1]:.6g}" in md[3]


def test_write_table_keeps_named_index_and_rejects_bad_stems(tmp_path):
    df = pd.DataFrame({"k [N/m]": [1.0, 2.0]}, index=pd.Index(["front", "rear"], name="spring"))
    paths = write_table(df, tmp_path, "springs")
    assert paths["csv"].read_text().splitlines()[0] == "spring,k [N/m]"
    for stem in ["", "../x", "a/b", "x."]:
        with pytest.raises(ValueError, match="stem"):
            write_table(df, tmp_path, stem)
    with pytest.raises(TypeError, match="DataFrame"):
        write_table({"a": 1}, tmp_path, "x")


# --------------------------------------------------------------------------------------
# Figures: check the artists' data, not pixels
# --------------------------------------------------------------------------------------
def test_plot_time_history_and_save(tmp_path):
    from matplotlib.figure import Figure

    res = oscillator()
    fig = plot_time_history(res.coordinates(), ["x [m]", "y [m]"])
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    lines = ax.get_lines()
    assert [ln.get_label() for ln in lines] == ["x [m]", "y [m]"]
    np.testing.assert_array_equal(lines[1].get_ydata(), res.q[:, 1])
    assert ax.get_xlabel() == "t [s]"
    path = save_figure(fig, tmp_path / "figs", "coords")
    assert path == tmp_path / "figs" / "coords.png"
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError, match="nope"):
        plot_time_history(res.coordinates(), "nope")


def test_plot_on_given_axes_returns_its_figure():
    from matplotlib.figure import Figure

    fig = Figure()
    ax = fig.add_subplot()
    assert plot_xy_path(oscillator().coordinates(), "x [m]", "y [m]", ax=ax) is fig
    np.testing.assert_array_equal(ax.get_lines()[0].get_xdata(), oscillator().q[:, 0])


def test_plot_violations_energy():
    t = oscillator().t
    res = dataclasses.replace(
        oscillator(),
        position_violation=np.where(t > 0, 1e-12 * t**2, 0.0),
        velocity_violation=1e-9 * (1 + t),
    )
    fig = plot_violations(res)
    ax = fig.axes[0]
    assert ax.get_yscale() == "log"
    y = ax.get_lines()[0].get_ydata()
    pos = res.position_violation
    np.testing.assert_array_equal(np.isnan(y), pos == 0)
    np.testing.assert_array_equal(y[pos > 0], pos[pos > 0])

    zero = SimulationResult(t=np.arange(3.0), q=np.zeros((3, 1)), v=np.zeros((3, 1)), status="finished")
    assert plot_violations(zero).axes[0].get_yscale() == "linear"

    e_line = plot_energy(res).axes[0].get_lines()[0]
    np.testing.assert_allclose(e_line.get_ydata(), res.energy_table()["relative energy drift [-]"])


def test_plot_work_precision():
    df = pd.DataFrame(
        {
            "method": ["A", "A", "A", "B", "B"],
            "error": [1e-3, 1e-6, 1e-4, 1e-2, 1e-5],
            "time [s]": [0.1, 1.0, 0.3, 0.05, 0.4],
        }
    )
    ax = plot_work_precision(df, "time [s]", "error", "method").axes[0]
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    assert set(lines) == {"A", "B"}
    np.testing.assert_array_equal(lines["A"].get_xdata(), [1e-3, 1e-4, 1e-6])
    np.testing.assert_array_equal(lines["A"].get_ydata(), [0.1, 0.3, 1.0])
    bad = df.assign(error=[0.0, 1, 1, 1, 1])
    with pytest.raises(ValueError, match="non-positive"):
        plot_work_precision(bad, "time [s]", "error", "method")
