"""Scenes: named, reproducible runs that write tables and figures.

A :class:`Scene` is a name, a title, a description and a function
``run(ctx: SceneContext) -> SceneResult``. :func:`run_scene` calls it and writes every
table (CSV + Markdown, :func:`core.results.write_table`) and figure (PNG,
:func:`core.plot.save_figure`) into ``<out_dir>/<scene name>/`` together with a
``README.md`` listing the files. The ``mbsuite run`` command drives it.

Where scenes come from (:func:`all_scenes`):

1. scenes registered with :func:`register_scene`; core's own demo scenes do so when
   :mod:`core.demo_scenes` is imported (lazily, and only if that module exists);
2. entry points in group ``"mbsuite.scenes"``: each loads to a callable returning a
   ``list[Scene]``. Domain packages (railway, biomech, coaster) register theirs in
   ``pyproject.toml``, so core never imports them.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import importlib.util
import re
import traceback
import warnings
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .errors import NameTakenError
from .paths import output_folder, write_atomically
from .registry import Registry

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    from matplotlib.figure import Figure

__all__ = [
    "SCENE_ENTRY_POINT_GROUP",
    "PluginLoadWarning",
    "Scene",
    "SceneContext",
    "SceneError",
    "SceneResult",
    "all_scenes",
    "register_scene",
    "run_scene",
    "tqdm_progress",
]

SCENE_ENTRY_POINT_GROUP = "mbsuite.scenes"
_DEMO_MODULE = "core.demo_scenes"
_NAME_RE = re.compile(r"^[a-z0-9][a-z0-9_\-]*$")

def _check_scene(obj) -> None:
    if not isinstance(obj, Scene):
        raise TypeError(f"register_scene expects a Scene, got {type(obj).__name__}")


#: Scenes registered in this process, by name (insertion order is listing order).
_REGISTRY: Registry[Scene] = Registry("scene", _check_scene)


class PluginLoadWarning(UserWarning):
    """A scene plug-in (entry point) could not be loaded; its scenes are missing."""


class SceneError(RuntimeError):
    """A scene failed; ``error.txt`` with the traceback was written to ``folder``."""

    def __init__(self, scene: str, folder: Path, cause: BaseException) -> None:
        super().__init__(f"scene {scene!r} failed: {type(cause).__name__}: {cause} (see {folder / 'error.txt'})")
        self.scene = scene
        self.folder = folder


def tqdm_progress(iterable: Iterable[Any], **kwargs: Any) -> Iterable[Any]:
    """Wrap ``iterable`` in a tqdm bar that is silent when stderr is not a terminal.

    Keyword arguments go to :class:`tqdm.tqdm` (``desc``, ``total``, ``unit``, ...);
    ``disable`` defaults to None, tqdm's "off on non-TTY" setting.
    """
    from tqdm import tqdm

    kwargs.setdefault("disable", None)
    return tqdm(iterable, **kwargs)


@dataclass(frozen=True)
class SceneContext:
    """What a running scene may use.

    Parameters
    ----------
    out_dir : Path
        The scene's own output folder (``<out>/<scene name>``), already created. Scenes
        normally return tables/figures instead of writing here; use it for extra files.
    progress : callable, optional
        ``progress(iterable, **tqdm_kwargs)`` wraps loops in a progress bar.
    fast : bool, optional
        Reduced resolution (shorter spans, fewer cases) for tests and smoke runs.
    executor : concurrent.futures.Executor, optional
        Where a scene's parameter sweep runs (:func:`core.sweep.run_sweep`); None (default) runs
        it serially in this process, the reference result.
    """

    out_dir: Path
    progress: Callable[..., Iterable[Any]] = tqdm_progress
    fast: bool = False
    executor: Any = None


@dataclass
class SceneResult:
    """Tables, figures and notes produced by a scene.

    Parameters
    ----------
    tables : dict of str to pandas.DataFrame
        File stem -> table; written as ``<stem>.csv`` and ``<stem>.md``.
    figures : dict of str to matplotlib.figure.Figure
        File stem -> figure; written as ``<stem>.png``.
    notes : str, optional
        Markdown text put into the scene's README (what was run, references).
    """

    tables: dict[str, pd.DataFrame] = field(default_factory=dict)
    figures: dict[str, Figure] = field(default_factory=dict)
    notes: str = ""


@dataclass(frozen=True)
class Scene:
    """A named, reproducible run.

    Parameters
    ----------
    name : str
        Identifier used on the command line and as folder name: lower-case letters,
        digits, ``_`` and ``-``.
    title : str
        One-line title shown by ``mbsuite list``.
    description : str
        What the scene reproduces, with its reference (paper, table/figure).
    run : callable
        ``run(ctx: SceneContext) -> SceneResult``.
    """

    name: str
    title: str
    description: str
    run: Callable[[SceneContext], SceneResult]

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not _NAME_RE.match(self.name):
            raise ValueError(
                f"scene name {self.name!r} must be lower-case letters, digits, '_' or '-' (it names a folder)"
            )
        if not callable(self.run):
            raise ValueError(f"scene {self.name!r}: run must be callable, got {type(self.run).__name__}")


def register_scene(scene: Scene) -> Scene:
    """Add a scene to the in-process registry (:class:`core.registry.Registry`: re-registering the
    same object is a no-op, a different scene under a taken name raises
    :class:`core.errors.NameTakenError`) and return it."""
    _check_scene(scene)
    return _REGISTRY.register(scene.name, scene)


def _scene_entry_points() -> list[importlib.metadata.EntryPoint]:
    return list(importlib.metadata.entry_points(group=SCENE_ENTRY_POINT_GROUP))


def _default_on_error(plugin: str, exc: BaseException) -> None:
    warnings.warn(
        f"scene plug-in {plugin!r} could not be loaded ({type(exc).__name__}: {exc}); its scenes are skipped",
        PluginLoadWarning,
        stacklevel=3,
    )


def all_scenes(on_error: Callable[[str, BaseException], None] | None = None) -> dict[str, Scene]:
    """Return every available scene by name: core's first, then plug-ins' in entry-point order.

    Parameters
    ----------
    on_error : callable, optional
        ``on_error(plugin_name, exception)`` is called for an entry point that fails to
        load or returns something other than a list of scenes. Default: emit a
        :class:`PluginLoadWarning`. Pass a function that re-raises to make it fatal.

    Returns
    -------
    dict of str to Scene

    Raises
    ------
    core.errors.NameTakenError
        If two sources provide scenes with the same name (a ``ValueError``).
    """
    on_error = _default_on_error if on_error is None else on_error
    if importlib.util.find_spec(_DEMO_MODULE) is not None:
        importlib.import_module(_DEMO_MODULE)  # registers core's scenes on import
    scenes: dict[str, Scene] = dict(_REGISTRY)
    source = {name: "core" for name in scenes}
    for ep in _scene_entry_points():
        label = f"{ep.name} ({ep.value})"
        try:
            provided = list(ep.load()())
            bad = [type(s).__name__ for s in provided if not isinstance(s, Scene)]
            if bad:
                raise TypeError(f"expected a list of Scene, got items of type {sorted(set(bad))}")
        except Exception as exc:  # a broken plug-in must not hide the other scenes
            on_error(label, exc)
            continue
        for scene in provided:
            if scene.name in scenes and scenes[scene.name] is not scene:
                raise NameTakenError(
                    f"scene name {scene.name!r} is provided by both {source[scene.name]} and plug-in {label}"
                )
            scenes[scene.name] = scene
            source[scene.name] = f"plug-in {label}"
    return scenes


def _scene_readme(scene: Scene, result: SceneResult, written: dict[str, list[Path]]) -> str:
    lines = [f"# {scene.title}", "", f"Scene `{scene.name}`.", ""]
    if scene.description.strip():
        lines += [scene.description.strip(), ""]
    if result.notes.strip():
        lines += [result.notes.strip(), ""]
    if written["tables"]:
        lines += ["## Tables", ""]
        for stem in result.tables:
            lines.append(f"- `{stem}`: [{stem}.csv]({stem}.csv), [{stem}.md]({stem}.md)")
        lines.append("")
    if written["figures"]:
        lines += ["## Figures", ""]
        for stem in result.figures:
            lines += [f"![{stem}]({stem}.png)", ""]
    return "\n".join(lines).rstrip() + "\n"


def _identity(path: Path) -> tuple[int, int, int]:
    st = path.stat()
    return st.st_ino, st.st_mtime_ns, st.st_size


def run_scene(
    scene: Scene,
    out_dir: str | Path,
    fast: bool = False,
    progress: Callable[..., Iterable[Any]] = tqdm_progress,
    executor: Any = None,
) -> SceneResult:
    """Run one scene and write its tables, figures and README into ``out_dir/<name>/``.

    Parameters
    ----------
    scene : Scene
        The scene to run.
    out_dir : str or Path
        Parent output folder; the scene writes into its own sub-folder.
    fast : bool, optional
        Passed on as ``ctx.fast``.
    progress : callable, optional
        Passed on as ``ctx.progress``.
    executor : concurrent.futures.Executor, optional
        Passed on as ``ctx.executor`` (sweeps inside the scene).

    Returns
    -------
    SceneResult

    Raises
    ------
    SceneError
        If the scene (or writing its output) raised. The traceback is written to
        ``<out_dir>/<name>/error.txt`` first; the original exception is the cause.
    """
    from .plot import save_figure
    from .results import write_table

    folder = output_folder(Path(out_dir) / scene.name, f"output folder of scene {scene.name!r}")
    error_file = folder / "error.txt"
    if error_file.exists():
        error_file.unlink()  # stale from an earlier failed run
    # files of an earlier run, by identity (every writer replaces a file by a new one, so a rewritten
    # file has a new inode and time stamp)
    earlier = {p: _identity(p) for p in folder.iterdir() if p.is_file() and p.name != "error.txt"}
    try:
        result = scene.run(SceneContext(out_dir=folder, progress=progress, fast=fast, executor=executor))
        if not isinstance(result, SceneResult):
            raise TypeError(f"scene {scene.name!r} returned {type(result).__name__}, expected SceneResult")
        written: dict[str, list[Path]] = {"tables": [], "figures": []}
        for stem, df in result.tables.items():
            written["tables"] += list(write_table(df, folder, stem).values())
        for stem, fig in result.figures.items():
            written["figures"].append(save_figure(fig, folder, stem))
        readme = _scene_readme(scene, result, written)
        write_atomically(folder / "README.md", lambda p: p.write_text(readme, encoding="utf-8"))
    except Exception as exc:
        # files of an earlier run that this run did not rewrite would pass for its results: removed
        stale = sorted(p.name for p, ident in earlier.items() if p.exists() and _identity(p) == ident)
        for name in stale:
            (folder / name).unlink()
        note = (f"\nremoved {len(stale)} file(s) of an earlier run that this run did not rewrite: "
                f"{', '.join(stale)}\n" if stale else "")
        error_file.write_text(
            f"scene {scene.name!r} failed\n{note}\n" + "".join(traceback.format_exception(exc)), encoding="utf-8"
        )
        raise SceneError(scene.name, folder, exc) from exc
    return result
