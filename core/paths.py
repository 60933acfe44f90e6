"""Locations of the repository checkout and its ``data/`` folder.

mbsuite is installed in editable mode (``make run`` / ``make test`` run
``pip install -e .``), and reference data are read from the ``data/`` folder of
the checkout, not from an installed copy: the wheel ships only the four import
packages. These helpers resolve paths relative to this file, so they work from any
working directory.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["repo_root", "data_path", "output_folder", "write_atomically"]


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


def output_folder(path: str | Path, what: str = "output folder") -> Path:
    """Create the folder ``path`` (and its parents) for writing and return it.

    Raises
    ------
    core.errors.InputError
        When ``path`` or one of its parents exists as a file (one line naming it), or the folder
        cannot be created (the operating system's reason).
    """
    from .errors import InputError

    out = Path(path)
    for p in (out, *out.parents):
        if p.exists() and not p.is_dir():
            where = "" if p == out else f" (its parent {str(p)!r} is a file)"
            raise InputError(f"{what} {str(out)!r} cannot be created: {'it is a file' if p == out else 'a parent is a file'}"
                             f"{where}; choose another path")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{what} {str(out)!r} cannot be created: {exc.strerror or exc}") from None
    return out


def write_atomically(path: str | Path, write) -> Path:
    """Write a file whole or not at all: ``write(tmp_path)`` writes a temporary file in the same
    folder, which then replaces ``path`` in one step (``os.replace``).  A failure while writing
    leaves an earlier ``path`` untouched and no partial file behind."""
    import os

    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path
