"""Figures of gait results over the gait cycle: muscle forces per group, group totals, the
activation heat map.

Each function returns a pyplot-free :class:`matplotlib.figure.Figure` (save it with
:func:`core.plot.save_figure`). ``solutions`` map a criterion's name to its per-frame table of
:func:`biomech.muscle_forces.muscle_redundancy` (columns ``F_<muscle> [N]``, ``a_<muscle> [-]``),
``labels`` the same names to their legend text; an OpenSim result (``peer``: a table with a
``time`` column and one column per muscle, as :func:`biomech.opensim_peer.run_static_optimization`
returns) is overlaid dashed at its own times, ``peer_pct`` being those times in % of the cycle.
"""

from __future__ import annotations

import numpy as np

from .muscle_forces import group_force

__all__ = ["plot_muscle_group", "plot_group_totals", "plot_activation_heat_map"]

_STYLES = ("-", "-.", ":", "--")


def _figure(nrows=1, ncols=1, size=(7, 4)):
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, layout="constrained")
    return fig, fig.subplots(nrows, ncols, squeeze=False)


def _force_lines(a, pct, solutions, labels, members, peer, peer_pct, peer_label):
    """The summed force of ``members`` per criterion (and OpenSim's, dashed) on the axes ``a``."""
    for (crit, d), ls in zip(solutions.items(), _STYLES):
        a.plot(pct, group_force(d, members), ls, lw=1.6, label=f"mbsuite, {labels[crit]}")
    if peer is not None:
        a.plot(peer_pct, sum(peer[m] for m in members).to_numpy(), "--", lw=1.1, c="k", label=peer_label)
    a.grid(True, alpha=0.3)


def plot_muscle_group(pct, solutions: dict, labels: dict, members, title: str, peer=None, peer_pct=None,
                      peer_label: str = "OpenSim 4.6 static optimization"):
    """One panel per muscle of a group and one for the group's total force, over the gait cycle."""
    members = list(members)
    fig, ax = _figure(len(members) + 1, 1, size=(7, 2.6 * (len(members) + 1)))
    for k, name in enumerate(members + ["group"]):
        a = ax[k, 0]
        _force_lines(a, pct, solutions, labels, members if name == "group" else [name], peer, peer_pct, peer_label)
        a.set(ylabel=f"{'+'.join(members) if name == 'group' else name}\nforce [N]")
    ax[0, 0].legend(fontsize=7)
    ax[-1, 0].set(xlabel="right gait cycle [%]")
    ax[0, 0].set_title(title, fontsize=9)
    return fig


def plot_group_totals(pct, solutions: dict, labels: dict, groups: dict, title: str, model: str = "", peer=None,
                      peer_pct=None, peer_label: str = "OpenSim 4.6 static optimization"):
    """One panel per muscle group with its total force over the gait cycle (``model`` names the
    model in the axis labels)."""
    fig, ax = _figure(len(groups), 1, size=(7, 3 * len(groups)))
    for k, (gname, members) in enumerate(groups.items()):
        a = ax[k, 0]
        _force_lines(a, pct, solutions, labels, members, peer, peer_pct, peer_label)
        a.set(ylabel=f"{gname}{f' ({model})' if model else ''}\nforce [N]")
    ax[0, 0].legend(fontsize=7)
    ax[-1, 0].set(xlabel="right gait cycle [%]")
    ax[0, 0].set_title(title, fontsize=9)
    return fig


def plot_activation_heat_map(pct, solution, muscles, title: str):
    """The activation a_j of every muscle (rows) over the gait cycle (columns), colour from 0 to
    the largest activation."""
    A = np.array([solution[f"a_{m} [-]"].to_numpy() for m in muscles])
    fig, ax = _figure(size=(8, 5))
    im = ax[0, 0].imshow(A, aspect="auto", origin="upper", cmap="viridis", vmin=0.0, vmax=max(1e-3, float(A.max())),
                         extent=(pct[0], pct[-1], len(muscles) - 0.5, -0.5))
    ax[0, 0].set_yticks(range(len(muscles)), muscles, fontsize=7)
    ax[0, 0].set(xlabel="right gait cycle [%]", title=title)
    ax[0, 0].title.set_fontsize(9)
    fig.colorbar(im, ax=ax[0, 0], label="activation [-]")
    return fig
