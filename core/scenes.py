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

import contextvars
import importlib
import importlib.metadata
import importlib.util
import re
import time
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
    "SceneRun",
    "all_scenes",
    "example_path",
    "example_scene",
    "figures_to_show",
    "scene_run",
    "register_scene",
    "run_scene",
    "tqdm_progress",
    "write_index",
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
    mode : str, optional
        ``"fast"`` (reduced resolution for tests and smoke runs), ``"default"`` (the resolution
        the documentation quotes) or ``"full"`` (the exhaustive computations,
        ``mbsuite run --full``); :data:`core.provenance.MODES`.
    executor : concurrent.futures.Executor, optional
        Where a scene's parameter sweep runs (:func:`core.sweep.run_sweep`); None runs it
        serially in this process, the reference result.
    """

    out_dir: Path
    progress: Callable[..., Iterable[Any]] = tqdm_progress
    mode: str = "default"
    executor: Any = None

    def __post_init__(self) -> None:
        from .provenance import MODES

        if self.mode not in MODES:
            raise ValueError(f"scene mode {self.mode!r}: give one of {', '.join(MODES)}")

    @property
    def fast(self) -> bool:
        """Reduced resolution (``mode == "fast"``)."""
        return self.mode == "fast"

    @property
    def full(self) -> bool:
        """The exhaustive computations (``mode == "full"``)."""
        return self.mode == "full"


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
    full_adds : str, optional
        What ``mbsuite run --full`` computes beyond the default run (said in the README of a
        default run); empty when the default run is already complete.
    sweeps : bool, optional
        The scene runs cases on ``ctx.executor`` (:func:`core.sweep.run_sweep`).  ``mbsuite run``
        runs such scenes in its own process, their cases on the pool, and every other scene whole
        in a pool process beside them (:mod:`core.scene_scheduler`).
    """

    name: str
    title: str
    description: str
    run: Callable[[SceneContext], SceneResult]
    full_adds: str = ""
    sweeps: bool = False

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


def _scene_readme(scene: Scene, result: SceneResult | None, record) -> str:
    lines = [f"# {scene.title}", "", f"Scene `{scene.name}`.", ""]
    if scene.description.strip():
        lines += [scene.description.strip(), ""]
    if record.mode != "full" and scene.full_adds.strip():
        lines += [f"**Run in mode {record.mode}.** `mbsuite run {scene.name} --full` adds: "
                  f"{scene.full_adds.strip()}", ""]
    if result is not None and result.notes.strip():
        lines += [result.notes.strip(), ""]
    if result is not None and result.tables:
        lines += ["## Tables", ""]
        for stem in result.tables:
            lines.append(f"- `{stem}`: [{stem}.csv]({stem}.csv), [{stem}.md]({stem}.md) "
                         f"(metadata: [{stem}.csv-metadata.json]({stem}.csv-metadata.json))")
        lines.append("")
    if result is not None and result.figures:
        lines += ["## Figures", ""]
        for stem in result.figures:
            lines += [f"![{stem}]({stem}.png)", ""]
    lines.append(record.markdown_section())
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
    mode: str | None = None,
    workers: int = 1,
) -> SceneResult:
    """Run one scene and write its tables, figures and README into ``out_dir/<name>/``.

    Parameters
    ----------
    scene : Scene
        The scene to run.
    out_dir : str or Path
        Parent output folder; the scene writes into its own sub-folder.
    fast : bool, optional
        Shorthand for ``mode="fast"``.
    progress : callable, optional
        Passed on as ``ctx.progress``.
    executor : concurrent.futures.Executor, optional
        Passed on as ``ctx.executor`` (sweeps inside the scene).
    mode : str, optional
        ``"fast"``, ``"default"`` or ``"full"`` (:class:`SceneContext`); default ``"default"``, or
        ``"fast"`` with ``fast=True``.
    workers : int, optional
        Local processes behind ``executor``, for the run record.

    The folder also receives ``run.json`` (:class:`core.provenance.RunRecord`: mode, status, wall
    time, processor, versions, date, git revision), which the README's last section and every
    table's metadata repeat; a failed run writes it too, with the error.

    Returns
    -------
    SceneResult

    Raises
    ------
    SceneError
        If the scene (or writing its output) raised. The traceback is written to
        ``<out_dir>/<name>/error.txt`` first; the original exception is the cause.
    """
    from .provenance import RunRecord

    if mode is None:
        mode = "fast" if fast else "default"
    elif fast and mode != "fast":
        raise ValueError(f"run_scene({scene.name!r}): fast=True contradicts mode={mode!r}")
    record = RunRecord(scene=scene.name, mode=mode, started=RunRecord.utc_now(), workers=workers)
    start = time.perf_counter()
    folder = output_folder(Path(out_dir) / scene.name, f"output folder of scene {scene.name!r}")
    error_file = folder / "error.txt"
    if error_file.exists():
        error_file.unlink()  # stale from an earlier failed run
    # files of an earlier run, by identity (every writer replaces a file by a new one, so a rewritten
    # file has a new inode and time stamp)
    earlier = {p: _identity(p) for p in folder.iterdir() if p.is_file() and p.name != "error.txt"}
    try:
        result = scene.run(SceneContext(out_dir=folder, progress=progress, mode=mode, executor=executor))
        _write_output(scene, result, folder, record, start)
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
        record.status, record.wall_time_s = "failed", time.perf_counter() - start
        record.message = f"{type(exc).__name__}: {exc}".splitlines()[0][:300]
        (folder / "run.json").unlink(missing_ok=True)
        record.write(folder)
        raise SceneError(scene.name, folder, exc) from exc
    return result


def _write_output(scene: Scene, result: SceneResult, folder: Path, record, start: float) -> None:
    """Figures, then tables with the run record, the README and ``run.json`` into ``folder``."""
    from .plot import save_figure
    from .results import write_table

    if not isinstance(result, SceneResult):
        raise TypeError(f"scene {scene.name!r} returned {type(result).__name__}, expected SceneResult")
    for stem, fig in result.figures.items():
        save_figure(fig, folder, stem)
    record.wall_time_s = time.perf_counter() - start  # computation and figures; tables are quick
    for stem, df in result.tables.items():
        write_table(df, folder, stem, record=record)
    readme = _scene_readme(scene, result, record)
    write_atomically(folder / "README.md", lambda p: p.write_text(readme, encoding="utf-8"))
    record.write(folder)


def write_index(out_dir: str | Path) -> Path:
    """Write ``out_dir/README.md``: every scene folder present in ``out_dir`` with its title,
    status, mode, wall time and date, from the folders' ``run.json``
    (:class:`core.provenance.RunRecord`), not only the scenes of the last command.

    A folder with a ``README.md``, ``run.json`` or ``error.txt`` counts as a scene folder; one without
    a readable ``run.json`` (written by an older mbsuite or by hand) is listed with status
    "unknown".
    """
    from .provenance import read_run_record

    out = Path(out_dir)
    try:
        known = all_scenes(on_error=lambda plugin, exc: None)
    except Exception:  # the index must not fail because a plug-in does
        known = {}
    lines = ["# mbsuite output", "",
             "Every scene folder in this directory; each folder's README.md says how it was run.", "",
             "| scene | title | status | mode | wall time [s] | started (UTC) | git revision |",
             "|:--|:--|:--|:--|--:|:--|:--|"]
    marks = ("README.md", "run.json", "error.txt")
    for folder in sorted(p for p in out.iterdir() if p.is_dir() and any((p / m).exists() for m in marks)):
        rec = read_run_record(folder)
        title = known[folder.name].title if folder.name in known else ""
        if rec is None:
            lines.append(f"| [{folder.name}]({folder.name}/README.md) | {title} | unknown (no run.json) | | | | |")
            continue
        status = rec.status if rec.status == "ok" else f"{rec.status} (see {folder.name}/error.txt)"
        link = "README.md" if (folder / "README.md").exists() else "error.txt"
        lines.append(f"| [{folder.name}]({folder.name}/{link}) | {title} | {status} | {rec.mode} | "
                     f"{rec.wall_time_s:.1f} | {rec.started} | {rec.git_revision} |")
    text = "\n".join(lines) + "\n"
    return write_atomically(out / "README.md", lambda p: p.write_text(text, encoding="utf-8"))


# =============================================================================================
# Scenes written as example scripts
# =============================================================================================
#: the folder of the example scripts, beside the four packages in the checkout
EXAMPLES_FOLDER = "examples"

#: the context of the example script that ``mbsuite run`` is executing (None: run by hand)
_SCRIPT_CONTEXT: contextvars.ContextVar[tuple[SceneContext, dict] | None] = contextvars.ContextVar(
    "mbsuite_scene_script", default=None)


def example_path(relative: str | Path) -> Path:
    """The path of an example script, ``examples/<relative>`` in the checkout."""
    from .paths import repo_root

    path = repo_root() / EXAMPLES_FOLDER / relative
    if not path.is_file():
        raise FileNotFoundError(f"example script {path} does not exist (examples are read from the checkout)")
    return path


def example_scene(name: str, script: str | Path, title: str, description: str, full_adds: str = "") -> Scene:
    """A scene whose body is the example script ``examples/<script>``: ``mbsuite run NAME``
    executes the very file a user reads and copies.

    The script obtains its run with :func:`scene_run` (mode, output folder, sweep executor) and
    hands its tables, figures and notes over with :meth:`SceneRun.table`, :meth:`SceneRun.figure`,
    :meth:`SceneRun.note` and :meth:`SceneRun.done`.
    """

    def run(ctx: SceneContext) -> SceneResult:
        import runpy

        path = example_path(script)
        collected: dict = {}
        token = _SCRIPT_CONTEXT.set((ctx, collected))
        try:
            runpy.run_path(str(path), run_name="__main__")
        finally:
            _SCRIPT_CONTEXT.reset(token)
        if "result" not in collected:
            raise RuntimeError(f"example {path} ended without calling done() on its scene_run({name!r})")
        return collected["result"]

    run.__doc__ = f"Runs the example script examples/{script}."
    # a script that reads its run's executor sweeps (scene_run(...).executor, core.sweep.run_sweep)
    try:
        sweeps = re.search(r"\.executor\b", example_path(script).read_text(encoding="utf-8")) is not None
    except OSError:  # no such script: running the scene says so, naming the path
        sweeps = False
    return Scene(name, title, description, run, full_adds=full_adds, sweeps=sweeps)


def _env_workers() -> int:
    """Processes for the sweeps of a script run by hand: ``MBSUITE_WORKERS`` (default: every core)."""
    import os

    text = os.environ.get("MBSUITE_WORKERS", "").strip()
    if not text:
        return os.cpu_count() or 1
    try:
        workers = int(text)
    except ValueError:
        workers = 0
    if workers < 1:
        from .errors import InputError

        raise InputError(f"environment variable MBSUITE_WORKERS={text!r}: give a number of processes >= 1 "
                         "(1 runs the sweeps serially in this process)")
    return workers


class SceneRun:
    """The run of an example script: what the script may use, and where its results go.

    Under ``mbsuite run NAME`` (or :func:`run_scene`), :func:`scene_run` returns the runner's
    context and :meth:`done` hands the collected tables and figures to the runner, which writes
    them with the run record. Run by hand (``python examples/...``, in a notebook or by
    sphinx-gallery) it runs at the mode of the environment variable ``MBSUITE_MODE`` (fast,
    default or full; default "default"), and :meth:`done` writes the same output folder as
    ``mbsuite run`` would, into ``MBSUITE_OUT`` (default ``out``) below the working directory.

    Attributes
    ----------
    name : str
        The scene's name.
    mode : str
        "fast", "default" or "full".
    out_dir : Path
        The scene's output folder.
    """

    def __init__(self, name: str, ctx: SceneContext | None = None, collected: dict | None = None) -> None:
        import os

        from .provenance import MODES

        self.name = name
        self._collected = collected
        self._start = time.perf_counter()
        self._own_pool = None
        self.result = SceneResult()
        if ctx is None:
            mode = os.environ.get("MBSUITE_MODE", "default").strip().lower() or "default"
            if mode not in MODES:
                raise ValueError(f"environment variable MBSUITE_MODE={mode!r}: give one of {', '.join(MODES)}")
            folder = output_folder(Path(os.environ.get("MBSUITE_OUT", "out")) / name,
                                   f"output folder of scene {name!r}")
            ctx = SceneContext(out_dir=folder, mode=mode)
        self.ctx = ctx

    # what the script uses ------------------------------------------------------------------
    @property
    def mode(self) -> str:
        return self.ctx.mode

    @property
    def fast(self) -> bool:
        return self.ctx.fast

    @property
    def full(self) -> bool:
        return self.ctx.full

    @property
    def out_dir(self) -> Path:
        return self.ctx.out_dir

    def progress(self, iterable: Iterable[Any], **kwargs: Any) -> Iterable[Any]:
        """``iterable`` in a progress bar (silent when stderr is not a terminal)."""
        return self.ctx.progress(iterable, **kwargs)

    @property
    def executor(self):
        """Where the script's sweeps run (:func:`core.sweep.run_sweep`): the runner's executor, or,
        run by hand, a process pool on every local core (``MBSUITE_WORKERS=1``: serial), started
        when first used and shut down by :meth:`done`."""
        if self._collected is not None:
            return self.ctx.executor
        if self._own_pool is None:
            import concurrent.futures

            workers = _env_workers()
            if workers <= 1:
                return None
            self._own_pool = concurrent.futures.ProcessPoolExecutor(max_workers=workers)
        return self._own_pool

    # what the script produces --------------------------------------------------------------
    def table(self, stem: str, df: pd.DataFrame) -> pd.DataFrame:
        """Keep ``df`` as table ``<stem>.csv`` / ``<stem>.md``; returns it (to display it)."""
        self.result.tables[stem] = df
        return df

    def figure(self, stem: str, fig: Figure) -> Figure:
        """Keep ``fig`` as figure ``<stem>.png``; returns it.  Run by hand with the environment
        variable ``MBSUITE_SHOW_FIGURES`` set (the documentation's build sets it), the figure is
        also queued for display (:func:`figures_to_show`: sphinx-gallery's scraper in
        ``docs/_ext/scene_figures.py``)."""
        import os

        self.result.figures[stem] = fig
        if self._collected is None and os.environ.get("MBSUITE_SHOW_FIGURES"):
            _FIGURES_TO_SHOW.append(fig)
        return fig

    def note(self, text: str) -> None:
        """Add a paragraph of Markdown to the scene's README."""
        self.result.notes = (self.result.notes + "\n\n" + text.strip()).strip()

    def done(self) -> SceneResult:
        """Hand the results over: to the runner under ``mbsuite run``; written to
        :attr:`out_dir` with the run record when run by hand."""
        if self._own_pool is not None:
            self._own_pool.shutdown()
            self._own_pool = None
        if self._collected is not None:
            self._collected["result"] = self.result
            return self.result
        from .provenance import RunRecord

        scene = all_scenes(on_error=lambda plugin, exc: None).get(self.name)
        if scene is None:
            scene = Scene(self.name, self.name, "", lambda ctx: self.result)
        record = RunRecord(scene=self.name, mode=self.mode, workers=_env_workers(), started=RunRecord.utc_now())
        _write_output(scene, self.result, self.out_dir, record, self._start)
        print(f"{self.name}: {len(self.result.tables)} table(s), {len(self.result.figures)} figure(s) written to "
              f"{self.out_dir} (mode {self.mode}, {record.wall_time_s:.1f} s)")
        return self.result


#: figures of scripts run by hand, not yet displayed (pyplot-free figures are invisible to
#: sphinx-gallery's matplotlib scraper)
_FIGURES_TO_SHOW: list = []


def figures_to_show() -> list:
    """The figures that scripts run by hand handed over since the last call (emptied)."""
    figs = list(_FIGURES_TO_SHOW)
    _FIGURES_TO_SHOW.clear()
    return figs


def scene_run(name: str) -> SceneRun:
    """The run of the example script of scene ``name`` (:class:`SceneRun`): the runner's when
    ``mbsuite run`` executes the script, else a run by hand at ``MBSUITE_MODE``."""
    current = _SCRIPT_CONTEXT.get()
    if current is None:
        return SceneRun(name)
    ctx, collected = current
    if ctx.out_dir.name != name:
        raise ValueError(f"scene_run({name!r}) in the script of scene {ctx.out_dir.name!r}: the names differ")
    return SceneRun(name, ctx, collected)
