"""How a result was obtained: the run record written beside every scene's tables.

A wall time belongs to a processor, a number to a code revision, a table to the resolution it
was computed at. Every scene folder therefore holds a ``run.json`` (:class:`RunRecord`), its
README ends with a "How this scene was run" section, and every table carries the same record:

* ``<stem>.csv-metadata.json`` beside ``<stem>.csv`` -- the table's metadata file as the W3C
  recommendation *Metadata Vocabulary for Tabular Data* (CSVW, 2015, section 5.2 and *Model for
  Tabular Data and Metadata on the Web*, section 5.1.3: a metadata file found at
  ``{+url}-metadata.json``) locates it, so CSVW-aware readers find it and ``pd.read_csv`` is
  undisturbed (no comment lines in the CSV);
* one italic line under the Markdown table (:meth:`RunRecord.markdown_line`).

Modes (:data:`MODES`): ``fast`` reduced resolution for smoke runs and tests, ``default`` the
resolution the documentation quotes, ``full`` the exhaustive computations (``mbsuite run
--full``).
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import platform
import subprocess
from dataclasses import asdict, dataclass, field
from functools import lru_cache
from pathlib import Path

from .paths import repo_root

__all__ = ["MODES", "RunRecord", "cpu_model", "git_revision", "host_line", "package_versions", "read_run_record"]

#: the resolutions a scene runs at, from the smoke test to the exhaustive computation
MODES = ("fast", "default", "full")

#: the packages whose versions a result depends on (those installed are recorded)
_PACKAGES = ("numpy", "scipy", "numba", "pandas", "matplotlib", "cvxpy", "clarabel", "pydantic", "pint")

RUN_RECORD_FILE = "run.json"


@lru_cache(maxsize=1)
def cpu_model() -> str:
    """Processor name with family/model/stepping from ``/proc/cpuinfo`` (Linux), else
    ``platform.processor()``; "unknown" when neither says."""
    info: dict[str, str] = {}
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            key = key.strip()
            if key in ("model name", "cpu family", "model", "stepping") and key not in info:
                info[key] = value.strip()
            if not line.strip() and info:
                break
    except OSError:
        pass
    if "model name" in info:
        extra = ", ".join(f"{k} {info[k]}" for k in ("cpu family", "model", "stepping") if k in info)
        return f"{info['model name']} ({extra})" if extra else info["model name"]
    return platform.processor() or "unknown"


@lru_cache(maxsize=1)
def package_versions() -> dict[str, str]:
    """mbsuite, Python and the numerical libraries' versions (installed ones only)."""
    import importlib.metadata

    from . import __version__

    versions = {"mbsuite": __version__, "python": platform.python_version()}
    for name in _PACKAGES:
        try:
            versions[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            continue
    return versions


@lru_cache(maxsize=1)
def git_revision() -> str:
    """The checkout's commit (short hash), with ``+modified`` when tracked files differ from it;
    "unknown" outside a git checkout or without git."""
    root = repo_root()
    try:
        rev = subprocess.run(["git", "-C", str(root), "rev-parse", "--short=12", "HEAD"], capture_output=True,
                             text=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return f"{rev}+modified" if dirty else rev


def host_line() -> str:
    """One line: processor, logical cores, Python and the numerical libraries' versions."""
    v = package_versions()
    libs = ", ".join(f"{k} {v[k]}" for k in ("numpy", "scipy", "numba") if k in v)
    return f"{cpu_model()}, {os.cpu_count()} logical cores; Python {v['python']}; {libs}"


@dataclass
class RunRecord:
    """How one scene run was made.

    Parameters
    ----------
    scene : str
        Scene name.
    mode : str
        One of :data:`MODES`.
    status : str
        ``"ok"``, or ``"failed"`` with :attr:`message` saying where it stopped.
    started : str
        Start, ISO 8601 in UTC.
    wall_time_s : float
        Wall time of the scene (computation and writing), seconds.
    workers : int
        Local processes available to the scene's sweeps (1 = serial in the scene's process).
    processor, cores, versions, git_revision
        The host and code, filled in by :meth:`now`.
    message : str
        Why a failed run stopped.
    """

    scene: str
    mode: str
    status: str = "ok"
    started: str = ""
    wall_time_s: float = 0.0
    workers: int = 1
    processor: str = field(default_factory=cpu_model)
    cores: int = field(default_factory=lambda: os.cpu_count() or 1)
    versions: dict[str, str] = field(default_factory=package_versions)
    git_revision: str = field(default_factory=git_revision)
    message: str = ""

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ValueError(f"run mode {self.mode!r}: give one of {', '.join(MODES)}")

    @staticmethod
    def utc_now() -> str:
        return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")

    def to_dict(self) -> dict:
        return asdict(self)

    def markdown_line(self) -> str:
        """One line for the foot of a Markdown table."""
        v = self.versions
        libs = ", ".join(f"{k} {v[k]}" for k in ("numpy", "scipy", "numba") if k in v)
        return (f"*Scene `{self.scene}`, mode {self.mode}, {self.wall_time_s:.1f} s wall time on {self.processor} "
                f"({self.cores} cores, {self.workers} worker(s)); mbsuite {v.get('mbsuite', '?')} "
                f"(git {self.git_revision}), Python {v.get('python', '?')}, {libs}; {self.started}.*")

    def markdown_section(self) -> str:
        """The README section "How this scene was run"."""
        rows = [("mode", self.mode), ("status", self.status + (f": {self.message}" if self.message else "")),
                ("wall time", f"{self.wall_time_s:.1f} s"), ("started (UTC)", self.started),
                ("processor", f"{self.processor}, {self.cores} logical cores"),
                ("sweep workers", str(self.workers)), ("git revision", self.git_revision),
                ("versions", ", ".join(f"{k} {val}" for k, val in self.versions.items()))]
        lines = ["## How this scene was run", "", "| | |", "|:--|:--|"]
        lines += [f"| {k} | {val.replace('|', '/')} |" for k, val in rows]
        return "\n".join(lines) + "\n"

    def csvw(self, csv_name: str, title: str = "") -> dict:
        """The CSVW metadata document of table ``csv_name`` (``{+url}-metadata.json``)."""
        doc = {"@context": "http://www.w3.org/ns/csvw", "url": csv_name}
        if title:
            doc["dc:title"] = title
        doc["dc:created"] = self.started
        doc["mbsuite:run"] = self.to_dict()
        return doc

    def write(self, folder: str | Path) -> Path:
        """Write ``run.json`` into ``folder``."""
        from .paths import write_atomically

        path = Path(folder) / RUN_RECORD_FILE
        text = json.dumps(self.to_dict(), indent=2, ensure_ascii=False) + "\n"
        return write_atomically(path, lambda p: p.write_text(text, encoding="utf-8"))


def read_run_record(folder: str | Path) -> RunRecord | None:
    """The :class:`RunRecord` in ``folder/run.json``; None when there is none or it is unreadable
    (a folder written by an older mbsuite, or by hand)."""
    path = Path(folder) / RUN_RECORD_FILE
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        return RunRecord(**data)
    except (OSError, ValueError, TypeError):
        return None
