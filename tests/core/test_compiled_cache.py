"""numba's disk cache keyed on every compiled source of mbsuite (core.compiled.cache).

The trap it closes: numba keys a cached function on its own file only, while its machine code
contains the compiled functions it calls in other files.  The tests check that every compiled
function of the packages is cached under the project-wide key, that the key changes with any
compiled source (a callee in another file included), and the first-run notice.
"""

from __future__ import annotations

import hashlib
import io
from pathlib import Path

import pytest

numba = pytest.importorskip("numba")

from core.compiled import cache as C  # noqa: E402
from core.compiled import dynamics as D  # noqa: E402
from core.compiled import elements as E  # noqa: E402
from core.compiled import vector as V  # noqa: E402
from core.integrators import compiled_radau, compiled_rk  # noqa: E402


def test_project_functions_use_the_project_locator():
    import railway.contact.search.kernels as K
    import railway.vehicles.wheel_rail_compiled as W

    dispatchers = [D.accelerations, D.project, compiled_rk.advance, compiled_radau.advance, V.put_row,
                   E.point_pair_jacobian]
    dispatchers += [v for v in vars(K).values() if isinstance(v, numba.core.registry.CPUDispatcher)][:2]
    dispatchers += [v for v in vars(W).values() if isinstance(v, numba.core.registry.CPUDispatcher)][:2]
    assert len(dispatchers) == 10
    for d in dispatchers:
        assert isinstance(d._cache._impl.locator, C.ProjectCacheLocator), d.py_func.__qualname__


def test_the_stamp_of_a_caller_is_its_file_and_every_compiled_source():
    """The index of a cached integrator stores (its own file's hash, the digest of all compiled
    sources); the callee files of other modules are among those sources."""
    stamp = compiled_radau.advance._cache._cache_file._source_stamp
    own = hashlib.sha256(Path(compiled_radau.__file__).read_bytes()).digest()
    assert stamp == (own, C.source_digest())
    sources = {p.name for p in C.compiled_sources()}
    for module in (D, E, V, compiled_rk, compiled_radau):
        assert Path(module.__file__).name in sources
    assert {"wheel_rail_compiled.py", "kernels.py", "_kernels.py", "compiled.py"} <= sources


def test_the_digest_changes_with_a_callee_in_another_file(tmp_path):
    """Editing vector.py (a callee of the element kernels) changes the key of every cached
    function, whose own file did not change."""
    paths = list(C.compiled_sources())
    i = next(k for k, p in enumerate(paths) if p.name == "vector.py" and p.parent.name == "compiled")
    edited = tmp_path / "vector.py"
    edited.write_bytes(paths[i].read_bytes().replace(b"def cross(", b"def cross(  ", 1))
    assert C.source_digest(paths) == C.source_digest()
    changed = paths[:i] + [edited] + paths[i + 1:]
    assert C.source_digest(changed) != C.source_digest(paths)


def test_user_functions_keep_numba_locators(tmp_path):
    assert C.ProjectCacheLocator.from_function(lambda: None, str(tmp_path / "mine.py")) is None


class _Terminal(io.StringIO):
    def __init__(self, tty):
        super().__init__()
        self._tty = tty

    def isatty(self):
        return self._tty


def test_first_run_notice_only_at_a_terminal_and_once(monkeypatch):
    monkeypatch.setattr(C, "is_cold", lambda d: True)
    monkeypatch.setattr(C, "_NOTIFIED", set())
    log = _Terminal(False)
    assert not C.notify_if_cold(compiled_rk.advance, "jit-x", "about 20 s", stream=log)
    assert log.getvalue() == ""
    monkeypatch.setattr(C, "_NOTIFIED", set())
    tty = _Terminal(True)
    assert C.notify_if_cold(compiled_rk.advance, "jit-x", "about 20 s", stream=tty)
    assert "compiling the jit-x integrator" in tty.getvalue() and "about 20 s" in tty.getvalue()
    assert not C.notify_if_cold(compiled_rk.advance, "jit-x", "about 20 s", stream=tty)  # once per process
    monkeypatch.setattr(C, "is_cold", lambda d: False)
    monkeypatch.setattr(C, "_NOTIFIED", set())
    assert not C.notify_if_cold(compiled_rk.advance, "jit-y", "about 20 s", stream=_Terminal(True))


def test_is_cold_reads_the_index():
    from core.models import n_link_chain
    from core.integrators import simulate

    simulate(n_link_chain(2), (0.0, 0.01), method="jit-dop853", rtol=1e-6, atol=1e-6)
    assert not C.is_cold(compiled_rk.advance)  # compiled now, so cached
