"""Architecture rules: the one-way dependency rule and packaging sanity.

``core`` <- ``railway`` | ``biomech`` | ``coaster``: core imports no domain package and
the domains never import each other. Checked by parsing every module with :mod:`ast`
(no imports are executed), covering ``import x``, ``from x import y``, relative imports
resolved against the module's package, and ``importlib.import_module("x")`` /
``__import__("x")`` with literal names.
"""

from __future__ import annotations

import ast
import importlib
import importlib.util
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PACKAGES = ("core", "railway", "biomech", "coaster")
DOMAINS = ("railway", "biomech", "coaster")


def imported_top_levels(source: str, package: list[str]) -> list[tuple[int, str]]:
    """Return ``(line, top-level package)`` for every import in ``source``.

    Parameters
    ----------
    source : str
        Module source text.
    package : list of str
        Package containing the module (``["core", "integrators"]``); relative imports
        are resolved against it. A relative import that climbs above the top-level
        package is reported as ``"<beyond top level>"``.
    """
    found: list[tuple[int, str]] = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name.split(".")[0]) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0:
                found.append((node.lineno, (node.module or "").split(".")[0]))
                continue
            up = node.level - 1
            if up >= len(package):
                found.append((node.lineno, "<beyond top level>"))
                continue
            base = package[: len(package) - up]
            found.append((node.lineno, base[0]))
        elif isinstance(node, ast.Call) and node.args:
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
            first = node.args[0]
            if name in ("import_module", "__import__") and isinstance(first, ast.Constant):
                if isinstance(first.value, str) and not first.value.startswith("."):
                    found.append((node.lineno, first.value.split(".")[0]))
    return found


def _violations(package: str, forbidden: set[str]) -> list[str]:
    root = REPO / package
    if not root.is_dir():
        return []
    bad = []
    for path in sorted(root.rglob("*.py")):
        rel_pkg = list(path.relative_to(REPO).parts[:-1])
        for line, top in imported_top_levels(path.read_text(encoding="utf-8"), rel_pkg):
            if top in forbidden or top == "<beyond top level>":
                bad.append(f"{path.relative_to(REPO)}:{line} imports {top}")
    return bad


def test_checker_detects_forbidden_imports():
    """The ast walk itself must catch every import form (guards against a vacuous rule)."""
    src = textwrap.dedent(
        """
        import numpy as np
        import railway.contact
        from biomech import muscles
        from ... import coaster
        from . import results
        import importlib
        importlib.import_module("coaster.track")
        """
    )
    tops = [top for _, top in imported_top_levels(src, ["core", "integrators"])]
    assert "railway" in tops and "biomech" in tops and "coaster" in tops
    assert "<beyond top level>" in tops  # `from ... import coaster` from core/integrators/x.py
    assert tops.count("core") == 1  # `from . import results`
    # Relative imports inside a domain resolve to that domain.
    assert imported_top_levels("from ..geometry import profile", ["railway", "contact"]) == [(1, "railway")]


def test_core_imports_no_domain_package():
    assert _violations("core", set(DOMAINS)) == []


@pytest.mark.parametrize("domain", DOMAINS)
def test_domains_do_not_import_each_other(domain):
    assert _violations(domain, set(DOMAINS) - {domain}) == []


@pytest.mark.parametrize("package", PACKAGES)
def test_packages_resolve_inside_the_checkout(package):
    """Catches shadowing by unrelated PyPI distributions (e.g. `coaster`, `railway`)."""
    spec = importlib.util.find_spec(package)
    if spec is None:
        assert not (REPO / package).exists(), f"{package}/ exists but is not importable"
        pytest.skip(f"{package} does not exist in this checkout yet")
    origin = Path(spec.origin or next(iter(spec.submodule_search_locations)))
    assert REPO in origin.resolve().parents, f"{package} resolves to {origin}, outside {REPO}"


def test_core_file_inside_repo():
    import core

    assert Path(core.__file__).resolve() == REPO / "core" / "__init__.py"


def test_no_init_in_tests():
    """tests/ is not a package (pytest --import-mode=importlib)."""
    assert sorted((REPO / "tests").rglob("__init__.py")) == []


def test_import_core_is_light_and_domain_free():
    """`import core` loads no submodule, no domain package and no heavy dependency."""
    code = (
        "import sys, core; "
        "mods = sorted(m for m in sys.modules if m.split('.')[0] in "
        "('railway', 'biomech', 'coaster', 'numpy', 'scipy', 'pandas', 'matplotlib', 'cvxpy')); "
        "subs = sorted(m for m in sys.modules if m.startswith('core.')); print(mods, subs)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, check=True)
    assert out.stdout.strip() == "[] []"


def test_lazy_exports():
    import core

    assert set(core.__all__) >= set(core._EXPORTS)
    for name, submodule in core._EXPORTS.items():
        full = f"core.{submodule}"
        if importlib.util.find_spec(full) is None:
            assert not hasattr(core, name), f"core.{name} resolved although {full} is missing"
        else:
            assert getattr(core, name) is getattr(importlib.import_module(full), name)
    with pytest.raises(AttributeError, match="no attribute"):
        core.this_name_does_not_exist  # noqa: B018


def test_data_paths_resolve_to_checkout():
    from core.paths import data_path, repo_root

    assert repo_root() == REPO
    assert data_path(must_exist=False) == REPO / "data"
    assert data_path("x", "y.csv", must_exist=False) == REPO / "data" / "x" / "y.csv"
    with pytest.raises(ValueError, match="outside"):
        data_path("..", "pyproject.toml", must_exist=False)
    with pytest.raises(FileNotFoundError, match="no_such_file"):
        data_path("no_such_file.csv")
