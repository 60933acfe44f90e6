"""Report files: the figures and tables the scenes write follow the rules of :mod:`core.plot`.

Figures: a title naming the scene or system and, for a run, the integrator (and saying when the
run finished with warnings or failed); a unit in brackets on every axis label (``[-]`` when
dimensionless); no panel of round-off noise drawn as if it were a signal (it must say "round-off",
"exactly zero" or "constant" in its title, and its y-range must be floored).

Tables: every column carries a unit in brackets, except text and flag columns and the numeric
columns whose unit is given row by row in a ``unit`` / ``<name> unit`` text column; within the
files of one scene a quantity never appears in two units, and all lengths (forces, moduli) share
one unit.

The fast scenes run here; the others (tens of seconds to minutes) run with ``pytest --runslow``.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from core import plot
from core.benchmarks.report import (
    REPORT_COLUMNS,
    fastest_to_tolerance,
    report_table,
    work_precision_figure,
)
from core.results import SimulationResult, run_metadata
from core.scenes import all_scenes, run_scene

EPS = np.finfo(float).eps
UNIT_RE = re.compile(r"^(?P<name>.*?)\s*\[(?P<unit>[^\[\]]+)\]$")
BRACKET_RE = re.compile(r"\[[^\[\]]+\]")
MARKS = ("round-off", "exactly zero", "constant")
#: Values below this (absolute, SI-sized models) can only be rounding noise: the panel must say so.
NOISE_ABS = 1e-13
#: Units of one dimension: a scene's files use one of each set.
DIMENSIONS = {
    "length": {"m", "mm", "um", "µm", "cm", "km"},
    "force": {"N", "kN", "MN"},
    "moment": {"N m", "kN m", "N mm"},
    "modulus": {"Pa", "kPa", "MPa", "GPa"},
}

FAST_SCENES = ["slider-crank", "railway-creep-curves"]
SLOW_SCENES = ["pendulum", "n-link-chain", "four-bar-modes", "bouncing-ball", "andrews", "work-precision",
               "railway-contact-geometry", "railway-two-point-contact"]


def _no_progress(iterable, **kwargs):
    return iterable


# ---------------------------------------------------------------------------------------------
# checkers
# ---------------------------------------------------------------------------------------------
def _titles(fig) -> list[str]:
    texts = [fig.get_suptitle()]
    for ax in fig.axes:
        texts += [ax.get_title(loc=loc) for loc in ("left", "center", "right")]
    return [t for t in texts if t]


def _ydata(ax) -> np.ndarray:
    parts = [np.asarray(line.get_ydata(), dtype=float).ravel() for line in ax.get_lines()]
    y = np.concatenate(parts) if parts else np.zeros(0)
    return y[np.isfinite(y)]


def figure_problems(fig, names: tuple[str, ...] = ()) -> list[str]:
    """What is wrong with a figure (empty list: nothing)."""
    problems = []
    titles = _titles(fig)
    text = "\n".join(titles)
    if not text.strip():
        problems.append("no title")
    for name in names:
        if name.lower() not in text.lower():
            problems.append(f"title {text!r} does not name {name!r}")
    for i, ax in enumerate(fig.axes):
        if not ax.get_visible() or not (ax.get_lines() or ax.collections or ax.images):
            continue
        for which, label in (("x", ax.get_xlabel()), ("y", ax.get_ylabel())):
            if not BRACKET_RE.search(label):
                problems.append(f"axes {i}: {which} label {label!r} has no unit in brackets")
        y = _ydata(ax)
        if y.size == 0:
            continue
        own = " ".join(ax.get_title(loc=loc) for loc in ("left", "center", "right"))
        marked = any(m in own for m in MARKS) or (len(fig.axes) == 1 and any(m in text for m in MARKS))
        lo, hi = ax.get_ylim()
        if ax.get_yscale() == "log":
            pos = y[y > 0]
            noise = pos.size == 0 or pos.max() < NOISE_ABS
            if noise and not marked:
                problems.append(f"axes {i}: only round-off values (max {pos.max() if pos.size else 0:.1e}) "
                                "but the panel does not say so")
            if marked and pos.size and lo < 1e-3 * pos.max():
                problems.append(f"axes {i}: round-off panel not floored (y from {lo:.1e})")
        else:
            amp, spread = float(np.max(np.abs(y))), float(np.ptp(y))
            noise = amp < NOISE_ABS or spread <= 1e-12 * amp
            if noise and not marked:
                problems.append(f"axes {i}: values vary by {spread:.1e} only (round-off) but the panel does not "
                                "say so")
            if marked and (hi - lo) < 5.0 * spread:
                problems.append(f"axes {i}: round-off panel not floored (range {hi - lo:.1e} for spread {spread:.1e})")
    return problems


def _unit_columns(df: pd.DataFrame) -> list[str]:
    return [c for c in df.columns if c == "unit" or c.endswith(" unit")]


def _is_text(series: pd.Series) -> bool:
    return (pd.api.types.is_bool_dtype(series) or pd.api.types.is_object_dtype(series)
            or pd.api.types.is_string_dtype(series))


def _markdown_header(path: Path) -> list[str]:
    line = path.read_text(encoding="utf-8").splitlines()[0].strip().strip("|")
    return [c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", line)]


def table_units(df: pd.DataFrame, where: str, problems: list[str]) -> list[tuple[str, str, str]]:
    """(quantity, unit, where) of every column (and of every row of a quantity/unit table)."""
    found = []
    unit_cols = _unit_columns(df)
    for col in df.columns:
        if col in unit_cols:
            continue
        m = UNIT_RE.match(str(col))
        if m:
            found.append((m["name"].strip().lower(), m["unit"].strip(), where))
            continue
        if _is_text(df[col]):
            continue
        covered = "unit" in unit_cols or any(u[: -len(" unit")] in str(col) for u in unit_cols if u != "unit")
        if not covered:
            problems.append(f"{where}: numeric column {col!r} has no unit in brackets")
    if {"quantity", "unit"} <= set(df.columns):
        for q, u in zip(df["quantity"], df["unit"]):
            found.append((str(q).strip().lower(), str(u).strip(), f"{where} (row {q!r})"))
    return found


def folder_problems(folder: Path) -> list[str]:
    """What is wrong with the tables of one scene folder."""
    problems: list[str] = []
    found = []
    csvs = sorted(folder.glob("*.csv"))
    for csv in csvs:
        df = pd.read_csv(csv)
        md = csv.with_suffix(".md")
        if not md.is_file():
            problems.append(f"{csv.name}: no Markdown twin")
        elif _markdown_header(md) != [str(c) for c in df.columns]:
            problems.append(f"{md.name}: header differs from the CSV's {list(df.columns)}")
        if any(str(c).startswith("Unnamed") for c in df.columns):
            problems.append(f"{csv.name}: an unnamed (index) column")
        found += table_units(df, csv.name, problems)
    by_quantity: dict[str, dict[str, str]] = {}
    for q, u, where in found:
        by_quantity.setdefault(q, {}).setdefault(u, where)
    for q, units in by_quantity.items():
        if len(units) > 1:
            problems.append(f"quantity {q!r} in several units: {units}")
    for dim, members in DIMENSIONS.items():
        used = {u: where for _, u, where in found if u in members}
        if len(used) > 1:
            problems.append(f"{dim} in several units: {used}")
    return problems


# ---------------------------------------------------------------------------------------------
# small results
# ---------------------------------------------------------------------------------------------
def circle_run(status: str = "finished", pos=None, vel=None, energy_noise: float | None = None,
               method: str = "rk45-projection", **meta) -> SimulationResult:
    """A point on a circle of radius 1 m at 2 rad/s, with chosen violations and energy noise."""
    t = np.linspace(0.0, 2.0, 41)
    q = np.column_stack([np.cos(2 * t), np.sin(2 * t)])
    v = 2.0 * np.column_stack([-np.sin(2 * t), np.cos(2 * t)])
    rng = np.random.default_rng(0)
    energy = np.full(t.size, 2.0)
    if energy_noise is not None:
        energy = energy * (1 + energy_noise * rng.uniform(-1, 1, t.size))
        energy[0] = 2.0
    settings = {"rtol": 1e-8, "atol": 1e-10} | meta
    return SimulationResult(
        t=t, q=q, v=v, status=status, message="" if status != "failed" else "Newton failed at t = 1.0 s",
        warnings=("energy drift above tolerance",) if status == "finished with warnings" else (),
        meta=run_metadata(method=method, system="circle_point", **settings),
        coordinate_names=["x [m]", "y [m]"], velocity_names=["vx [m/s]", "vy [m/s]"],
        constraint_names=["circle"],
        position_violation=np.abs(rng.normal(0, 1e-16, t.size)) if pos is None else pos,
        velocity_violation=np.abs(rng.normal(0, 3e-16, t.size)) if vel is None else vel,
        energy=energy,
    )


# ---------------------------------------------------------------------------------------------
# figure helpers on small results
# ---------------------------------------------------------------------------------------------
def test_run_title_names_system_integrator_settings_and_status():
    meta = run_metadata(method="rk45-projection", system="double_pendulum", rtol=1e-8, atol=1e-10)
    assert plot.run_title(meta) == "double pendulum — rk45-projection, rtol 1e-8, atol 1e-10"
    assert plot.run_title(meta, subject="double pendulum (scene)").startswith("double pendulum (scene) — ")
    fixed = run_metadata(method="generalized-alpha", system="chain", h=1e-3, rtol=1e-6, atol=1e-8)
    assert "generalized-alpha, h 0.001 s, rtol 1e-6, atol 1e-8" in plot.run_title(fixed)
    assert plot.run_title(meta, "finished with warnings").endswith("[finished with warnings]")
    assert "[FAILED: Newton failed" in plot.run_title(meta, "failed", message="Newton failed at t = 1 s")


@pytest.mark.parametrize("status", ["finished", "finished with warnings", "failed"])
def test_run_figures_have_titles_units_and_status(status):
    res = circle_run(status, pos=1e-9 * np.linspace(0, 1, 41), vel=1e-8 * np.linspace(1, 2, 41),
                     energy_noise=1e-7)
    figs = [plot.plot_violations(res, title="circle scene"), plot.plot_energy(res, title="circle scene"),
            plot.plot_time_history(res.coordinates(), ["x [m]", "y [m]"], title="circle scene"),
            plot.plot_xy_path(res.coordinates(), "x [m]", "y [m]", title="circle scene")]
    for fig in figs:
        assert figure_problems(fig, names=("circle scene", "rk45-projection", "rtol 1e-8")) == []
        text = "\n".join(_titles(fig))
        if status == "finished":
            assert "warnings" not in text and "FAILED" not in text
        else:
            assert ("finished with warnings" if status != "failed" else "FAILED") in text
        # no panel is marked: these are signals
        assert not any(m in text for m in MARKS)


def test_roundoff_panels_are_floored_and_marked_with_the_data_unchanged():
    res = circle_run()  # violations ~1e-16, energy exactly constant
    fig = plot.plot_violations(res, title="circle scene")
    assert figure_problems(fig, names=("circle scene",)) == []
    for ax, y, scale in zip(fig.axes, (res.position_violation, res.velocity_violation), (1.0, 1.0)):
        title = ax.get_title()
        assert "at round-off level (max" in title, title
        assert f"{np.max(y):.1e}" in title
        assert ax.get_yscale() == "log"
        assert ax.get_ylim()[0] == pytest.approx(EPS * scale)  # floored at eps * scale
        np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(), np.where(y > 0, y, np.nan))
    scaled = plot.plot_violations(res, scale=(0.01, 3.0))  # a system of 1 cm and 3 m/s
    assert [a.get_ylim()[0] for a in scaled.axes] == pytest.approx([0.01 * EPS, 3.0 * EPS])
    energy = plot.plot_energy(dataclasses.replace(res, energy=2.0 * (1 + 1e-15 * np.sign(np.sin(res.t)))))
    ax = energy.axes[0]
    assert "energy drift at round-off level" in ax.get_title()
    lo, hi = ax.get_ylim()
    assert lo <= -10 * plot.roundoff_level(1.0) and hi >= 10 * plot.roundoff_level(1.0)
    exact = plot.plot_energy(res)
    assert "energy drift exactly zero" in exact.axes[0].get_title()
    assert figure_problems(energy) == [] and figure_problems(exact) == []


def test_signal_panels_are_not_marked_but_floored_below():
    t = np.linspace(0.0, 2.0, 41)
    pos = 1e-10 * (1 + np.sin(5 * t) ** 2)
    pos[3] = 1e-19  # a dip into rounding: below the floor, not stretched down to it
    res = circle_run(pos=pos, vel=np.zeros(41))
    fig = plot.plot_violations(res)
    top, bottom = fig.axes
    assert "round-off" not in top.get_title() and top.get_ylim()[0] == pytest.approx(EPS)
    assert bottom.get_yscale() == "linear" and "velocity violation exactly zero" in bottom.get_title()
    assert figure_problems(fig, names=("circle point", "rk45-projection")) == []


def test_time_history_constant_to_roundoff_is_marked():
    res = circle_run()
    df = res.coordinates()
    df["z [m]"] = 0.45 + 1e-15 * np.sin(df["t [s]"])
    fig = plot.plot_time_history(df, ["z [m]"], title="circle scene")
    assert "constant to round-off level" in fig.axes[0].get_title()
    assert figure_problems(fig) == []
    # the checker itself: the same panel without the rule is caught
    from matplotlib.figure import Figure

    raw = Figure()
    ax = raw.add_subplot()
    ax.plot(df["t [s]"], df["z [m]"])
    ax.set(xlabel="t [s]", ylabel="z [m]", title="circle scene")
    assert any("round-off" in p for p in figure_problems(raw))


def _wp_table() -> pd.DataFrame:
    rows = []
    for method, kind, values, errors, status in (
            ("dop853-projection", "rtol", (1e-4, 1e-6, 1e-8), (1e-4, 1e-6, 1e-8), "finished"),
            ("generalized-alpha", "h [s]", (1e-2, 1e-3), (1e-3, 1e-5), "finished with warnings"),
            ("hht", "h [s]", (1e-2,), (np.nan,), "failed")):
        for val, err in zip(values, errors):
            rows.append({"problem": "chain2-planar", "method": method, "setting kind": kind, "setting value": val,
                         "rtol": val if kind == "rtol" else 1e-10, "atol": val if kind == "rtol" else 1e-10,
                         "error": err, "error measure": "|tip - tip_ref| [m]", "wall time [s]": 0.01 / val ** 0.2,
                         "n repeats": 1, "max position violation [m]": 1e-9, "max velocity violation [m/s]": 1e-8,
                         "final position violation [m]": 1e-10, "final velocity violation [m/s]": 1e-9,
                         "energy drift [-]": 1e-7, "n_steps": 10, "n_rejected": 0, "n_rhs": 60, "n_jac": 0,
                         "n_factor": 0, "n_newton": 0, "status": status, "message": "", "t reached [s]": 1.0})
    return pd.DataFrame(rows)


def test_work_precision_figure_and_tables():
    df = _wp_table()
    fig = work_precision_figure(df)
    assert figure_problems(fig, names=("chain2-planar", "t_end 1 s", "rtol 1e-4 … 1e-8", "h 0.01 … 0.001 s")) == []
    title = fig.axes[0].get_title()
    assert "2 finished with warnings (circled)" in title and "1 failed" in title
    labels = [line.get_label() for line in fig.axes[0].get_lines()]
    assert "finished with warnings" in labels and "hht (failed)" in labels
    table = report_table(df)
    assert list(table.columns) == REPORT_COLUMNS
    assert set(table["error unit"]) == {"m"} and list(table["setting unit"]) == ["-"] * 3 + ["s"] * 3
    problems: list[str] = []
    table_units(table, "wp", problems)
    summary = report_table(fastest_to_tolerance(df))
    table_units(summary, "wp_summary", problems)
    assert problems == []
    assert set(summary["error unit"]) == {"m"}


def test_checker_catches_missing_units_and_two_units_of_one_quantity(tmp_path):
    from core.results import write_table

    write_table(pd.DataFrame({"y [m]": [0.001], "steps": [3]}), tmp_path, "a")
    write_table(pd.DataFrame({"y [mm]": [1.0], "z [mm]": [2.0]}), tmp_path, "b")
    problems = folder_problems(tmp_path)
    assert any("'steps' has no unit" in p for p in problems)
    assert any("quantity 'y' in several units" in p for p in problems)
    assert any(p.startswith("length in several units") for p in problems)


# ---------------------------------------------------------------------------------------------
# scenes
# ---------------------------------------------------------------------------------------------
#: Words every figure title of a scene must contain (the scene's subject).
SUBJECTS = {
    "pendulum": "pendulum", "slider-crank": "slider crank", "n-link-chain": "chain",
    "four-bar-modes": "four-bar", "bouncing-ball": "bouncing ball", "andrews": "andrews",
    "work-precision": "t_end", "railway-contact-geometry": "contact geometry",
    "railway-creep-curves": "creep curves", "railway-two-point-contact": "two-point contact",
}


def _check_scene(name: str, tmp_path: Path) -> None:
    scenes = all_scenes(on_error=lambda plugin, exc: pytest.fail(f"plug-in {plugin}: {exc!r}"))
    if name not in scenes:
        pytest.skip(f"scene {name!r} is not installed")
    result = run_scene(scenes[name], tmp_path, fast=True, progress=_no_progress)
    assert result.figures, f"{name} draws no figure"
    problems = []
    for stem, fig in result.figures.items():
        problems += [f"{stem}.png: {p}" for p in figure_problems(fig, names=(SUBJECTS[name],))]
    problems += folder_problems(tmp_path / name)
    assert problems == []


@pytest.mark.parametrize("name", FAST_SCENES)
def test_fast_scene_report_files(name, tmp_path):
    _check_scene(name, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("name", SLOW_SCENES)
def test_slow_scene_report_files(name, tmp_path):
    _check_scene(name, tmp_path)
