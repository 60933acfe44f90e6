"""Locations of the repository checkout and its ``data/`` folder.

mbsuite is installed in editable mode (``make run`` / ``make test`` run
``pip install -e .``), and reference data are read from the ``data/`` folder of
the checkout, not from an installed copy: the wheel ships only the four import
packages. These helpers resolve paths relative to this file, so they work from any
working directory.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["repo_root", "data_path"]


def repo_root() -> Path:
    """Return the root of the mbsuite checkout (the folder holding ``core/``).

    Returns
    -------
    Path
        Absolute path of the repository root.
    """
    return Path(__file__).resolve().parents[1]


def data_path(*parts: str | Path, must_exist: bool = True) -> Path:
    """Return the path of a file or folder inside the checkout's ``data/`` folder.

    Parameters
    ----------
    *parts : str or Path
        Path components below ``data/``, e.g. ``data_path("railway", "s1002.txt")``.
        With no parts the ``data/`` folder itself is returned.
    must_exist : bool, optional
        If True (default) raise :class:`FileNotFoundError` when the path is missing.

    Returns
    -------
    Path
        Absolute path below ``<repo>/data``.

    Raises
    ------
    ValueError
        If the parts are absolute or climb out of ``data/`` (``..``).
    FileNotFoundError
        If ``must_exist`` and the path does not exist.
    """
    root = (repo_root() / "data").resolve()
    path = root.joinpath(*parts).resolve()
    if path != root and root not in path.parents:
        raise ValueError(f"data_path{tuple(str(p) for p in parts)!r} points outside {root}")
    if must_exist and not path.exists():
        raise FileNotFoundError(f"data file {path} does not exist (data is read from the checkout)")
    return path
