"""Figures of a train run: speed and height, wheel forces, rider load factors, the track in 3-D
coloured by a quantity, and the quality of a track frame.

Each function returns a pyplot-free :class:`matplotlib.figure.Figure` (save it with
:func:`core.plot.save_figure`); ``title`` is the figure's title, which should name the run
(scene, method, tolerance: :func:`core.plot.run_title`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["plot_speed_and_height", "plot_wheel_forces", "plot_load_factors", "plot_track_3d",
           "plot_frame_quality"]


def plot_speed_and_height(run, sections: pd.DataFrame, title: str):
    """Lead speed along the track and height of the lead wheelset over the lead arc length, the
    named sections shaded alternately and labelled.

    Parameters
    ----------
    run : coaster.train.TrainRun
    sections : pandas.DataFrame
        ``section``, ``L_start [m]``, ``L_end [m]`` (:func:`coaster.train.circuit_sections`).
    title : str
    """
    from matplotlib.figure import Figure

    L = run.L[:, 0]
    tab = run.table()
    fig = Figure(figsize=(10, 6.5))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    ax1.plot(L, tab["speed [m/s]"], color="C0")
    ax1.set_ylabel("speed along the track [m/s]")
    ax2.plot(L, tab["z [m]"], color="C2")
    ax2.set_ylabel("height of ws1 [m]")
    ax2.set_xlabel("arc length of the lead wheelset L1 [m]")
    for ax in (ax1, ax2):
        for _, r in sections.iterrows():
            ax.axvspan(r["L_start [m]"], r["L_end [m]"], alpha=0.06 if r.name % 2 else 0.0, color="k")
        ax.grid(alpha=0.3)
    for _, r in sections.iterrows():
        ax1.text(0.5 * (r["L_start [m]"] + r["L_end [m]"]), ax1.get_ylim()[1] * 0.95, r["section"], ha="center",
                 va="top", fontsize=7)
    ax1.set_title(title)
    return fig


def plot_wheel_forces(forces: pd.DataFrame, title: str, wheelsets=("ws1", "ws6")):
    """Wheel forces F_b (along the track's up axis) and F_n (lateral) over each wheelset's arc length.

    Parameters
    ----------
    forces : pandas.DataFrame
        :func:`coaster.train.wheel_forces` (columns ``{ws} L [m]``, ``{ws} F_b [N]``, ``{ws} F_n [N]``).
    title : str
    wheelsets : sequence of str
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 6.5))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    for ws in wheelsets:
        ax1.plot(forces[f"{ws} L [m]"], forces[f"{ws} F_b [N]"] / 1e3, label=ws)
        ax2.plot(forces[f"{ws} L [m]"], forces[f"{ws} F_n [N]"] / 1e3, label=ws)
    ax1.set_ylabel("F_b, along the track's up axis [kN]")
    ax2.set_ylabel("F_n, lateral [kN]")
    ax2.set_xlabel("arc length of the wheelset [m]")
    for ax in (ax1, ax2):
        ax.legend()
        ax.grid(alpha=0.3)
    ax1.set_title(title)
    return fig


def plot_load_factors(loads: pd.DataFrame, title: str, car: str = "car 1"):
    """Rider load factors n_x, n_y, n_z (car axes) over the lead arc length.

    Parameters
    ----------
    loads : pandas.DataFrame
        :meth:`coaster.train.TrainRun.rider_loads` (``L [m]``, ``n_x [g]``, ``n_y [g]``, ``n_z [g]``).
    title : str
    car : str
        The car in the axis label.
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 5))
    ax = fig.subplots()
    for c in ("n_x [g]", "n_y [g]", "n_z [g]"):
        ax.plot(loads["L [m]"], loads[c], label=c)
    ax.set_xlabel("arc length L1 [m]")
    ax.set_ylabel(f"load factor at the rider of {car} [g]")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()
    return fig


def plot_track_3d(frame, L, values, label: str, title: str, z_scale: float = 5.0):
    """The track centreline in 3-D, each piece between neighbouring samples coloured by the mean
    of ``values`` at its ends.

    Parameters
    ----------
    frame : core.curves.FramedCurve
        The framed track (its ``evaluate(L).position``).
    L : (n,) array_like
        Arc lengths of the samples (m), within the track.
    values : (n,) array_like
        The quantity at the samples (e.g. the rider's n_z).
    label : str
        Colour bar label with its unit.
    title : str
    z_scale : float
        Vertical exaggeration of the box.
    """
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    fig = Figure(figsize=(10, 8))
    ax = fig.add_subplot(projection="3d")
    P = frame.evaluate(np.asarray(L, float)).position
    seg = np.stack([P[:-1], P[1:]], axis=1)
    v = np.asarray(values, float)
    lc = Line3DCollection(seg, cmap="coolwarm", linewidths=3)
    lc.set_array(0.5 * (v[:-1] + v[1:]))
    ax.add_collection(lc)
    for a, lo, hi in ((ax.set_xlim, P[:, 0].min(), P[:, 0].max()), (ax.set_ylim, P[:, 1].min(), P[:, 1].max()),
                      (ax.set_zlim, P[:, 2].min(), P[:, 2].max())):
        a(lo, hi)
    ax.set_box_aspect((np.ptp(P[:, 0]), np.ptp(P[:, 1]), z_scale * np.ptp(P[:, 2])))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel(f"z [m] (×{z_scale:g})" if z_scale != 1 else "z [m]")
    fig.colorbar(lc, ax=ax, shrink=0.6, pad=0.12, label=label)
    ax.set_title(title)
    return fig


def plot_frame_quality(quality: pd.DataFrame, title: str):
    """Curvature, torsion, orthonormality error and rotation step along the track.

    Parameters
    ----------
    quality : pandas.DataFrame
        The samples of :func:`coaster.frames.frame_quality_summary`.
    title : str
    """
    from matplotlib.figure import Figure

    q = quality
    fig = Figure(figsize=(10, 8))
    ax = fig.subplots(4, 1, sharex=True)
    L = q["L [m]"]
    ax[0].plot(L, q["curvature [1/m]"], lw=0.8)
    ax[0].set_ylabel("curvature [1/m]")
    ax[1].plot(L, q["torsion [1/m]"], lw=0.8)
    lim = float(np.nanpercentile(np.abs(q["torsion [1/m]"]), 99)) * 1.5
    ax[1].set_ylim(-lim, lim)
    ax[1].set_ylabel("torsion [1/m]\n(99th pct. range)")
    ax[2].semilogy(L, np.maximum(q["max |R^T R - I| [-]"], 1e-17), lw=0.8)
    ax[2].set_ylabel("max |R^T R - I| [-]")
    ax[3].plot(L, q["rotation step [rad]"], lw=0.8, label="rotation between samples")
    ax[3].plot(L, q["|omega| dL [rad]"], lw=0.8, ls="--", label="|omega| dL")
    ax[3].set_ylabel("rotation step [rad]")
    ax[3].set_xlabel("arc length L [m]")
    ax[3].legend(fontsize=8)
    ax[0].set_title(title)
    fig.tight_layout()
    return fig
