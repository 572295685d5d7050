"""Import a path-loaded plugin as a fresh module, every time.

Each load of a behavior package gets a new, unique top-level module name (``_kinema_plugin_<pkg>_<n>``),
so the new code never mixes with the old: classes a running objective still uses keep working, and the
next objective gets the new ones. Modules of the previous generation are purged from ``sys.modules``.

Sources of hot-reloadable packages are always compiled from the file, never from ``__pycache__``: CPython
validates cached bytecode by whole-second mtime and size, so two saves within one second that keep the size
(``1`` → ``2``) would otherwise load stale code.

Packages that never reload (Kinema's bundled plugins) keep their compiled code in the user's cache folder
(:mod:`kinema.bytecode`), checked against the source's nanosecond mtime and size, in every install mode.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import itertools
import re
import sys
import threading
import traceback
from collections.abc import Sequence
from importlib.machinery import ModuleSpec
from pathlib import Path
from types import ModuleType

from kinema.bytecode import UserCacheSourceLoader
from kinema.errors import PluginError, SourceLocation

_PREFIX = "_kinema_plugin_"
_IDENTIFIER_UNSAFE = re.compile(r"\W")
_counter = itertools.count(1)
_counter_lock = threading.Lock()


class _FreshSourceLoader(importlib.abc.SourceLoader):
    """Loads Python source without reading or writing bytecode caches."""

    def __init__(self, fullname: str, path: str) -> None:
        self.name = fullname
        self.path = path

    def get_filename(self, fullname: str) -> str:
        return self.path

    def get_data(self, path: str) -> bytes:
        return Path(path).read_bytes()


def _loader(fullname: str, path: str) -> importlib.abc.Loader:
    """The fresh loader, or the user-cache one for packages that never reload (bundled plugins)."""
    if fullname.split(".")[0] in _BYTECODE_OK:
        return UserCacheSourceLoader(fullname, path)
    return _FreshSourceLoader(fullname, path)


class _FreshPluginFinder(importlib.abc.MetaPathFinder):
    """Finds submodules of fresh plugin packages (``from .my_behavior import X``) with the fresh loader."""

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> ModuleSpec | None:
        if not fullname.startswith(_PREFIX) or "." not in fullname or not path:
            return None
        leaf = fullname.rpartition(".")[2]
        for folder in path:
            package_init = Path(folder) / leaf / "__init__.py"
            if package_init.is_file():
                return importlib.util.spec_from_file_location(
                    fullname,
                    package_init,
                    loader=_loader(fullname, str(package_init)),
                    submodule_search_locations=[str(package_init.parent)],
                )
            module_file = Path(folder) / f"{leaf}.py"
            if module_file.is_file():
                return importlib.util.spec_from_file_location(
                    fullname, module_file, loader=_loader(fullname, str(module_file))
                )
        return None


_FINDER = _FreshPluginFinder()
# Fresh top-level names whose modules may use bytecode caches (see import_fresh's cache_bytecode).
_BYTECODE_OK: set[str] = set()


def _install_finder() -> None:
    if _FINDER not in sys.meta_path:
        sys.meta_path.insert(0, _FINDER)


def import_fresh(root: Path, module: str, package: str, *, cache_bytecode: bool = False) -> ModuleType:
    """Import ``module`` (e.g. ``my_pkg`` or ``my_pkg.register``) from the behavior package at ``root``.

    Args:
        root: the behavior package folder (the one holding ``pyproject.toml``).
        module: the dotted module path relative to ``root``.
        package: the package name, used for the unique module name and in messages.
        cache_bytecode: keep the compiled code in the user's cache folder (see the module docstring); only
            for packages that are never reloaded (Kinema's bundled plugins), where it saves compiling at
            every start.

    Returns:
        The freshly executed module that implements the hooks.

    Raises:
        PluginError: the module raised or has a syntax error; the location is the line in the user's
            file where it happened.
    """
    _install_finder()
    top, _, rest = module.partition(".")
    init = Path(root) / top / "__init__.py"
    with _counter_lock:
        generation = next(_counter)
    fresh_top = f"{_PREFIX}{_IDENTIFIER_UNSAFE.sub('_', package)}_{generation}"
    if cache_bytecode:
        _BYTECODE_OK.add(fresh_top)
    spec = importlib.util.spec_from_file_location(
        fresh_top,
        init,
        loader=_loader(fresh_top, str(init)),
        submodule_search_locations=[str(init.parent)],
    )
    assert spec is not None and spec.loader is not None
    top_module = importlib.util.module_from_spec(spec)
    sys.modules[fresh_top] = top_module
    try:
        spec.loader.exec_module(top_module)
        result = importlib.import_module(f"{fresh_top}.{rest}") if rest else top_module
    except BaseException as error:
        purge_modules(fresh_top)
        if isinstance(error, KeyboardInterrupt):
            raise
        hint = ""
        if isinstance(error, ModuleNotFoundError) and (error.name or "").split(".")[0] == top:
            hint = (
                f"; import the package's own modules relatively (from .module import X): '{top}' is "
                "loaded from its folder, not installed"
            )
        raise PluginError(
            f"behavior package '{package}' failed to import: {describe_exception(error)}{hint}",
            location=user_location(error, Path(root)),
        ) from error
    return result


def purge_modules(top: str) -> int:
    """Remove the fresh package ``top`` and all its submodules from ``sys.modules``; return how many."""
    doomed = [name for name in list(sys.modules) if name == top or name.startswith(top + ".")]
    for name in doomed:
        sys.modules.pop(name, None)
    return len(doomed)


def describe_exception(error: BaseException) -> str:
    """``SyntaxError: invalid syntax`` style one-liner (no traceback)."""
    if isinstance(error, SyntaxError):
        return f"SyntaxError: {error.msg}"
    text = str(error)
    return f"{type(error).__name__}: {text}" if text else type(error).__name__


def user_location(error: BaseException, root: Path) -> SourceLocation | None:
    """The ``file:line`` in the user's code (under ``root``) closest to where ``error`` was raised.

    Syntax errors carry their own location; for other exceptions the innermost traceback frame in a
    file under ``root`` wins, so the message points at the user's line, not at Kinema's.
    """
    root = Path(root).resolve()
    if isinstance(error, SyntaxError) and error.filename:
        return SourceLocation(error.filename, error.lineno or 0)
    frames = traceback.extract_tb(error.__traceback__)
    for frame in reversed(frames):
        try:
            inside = Path(frame.filename).resolve().is_relative_to(root)
        except (OSError, ValueError):
            inside = False
        if inside:
            return SourceLocation(frame.filename, frame.lineno or 0)
    if frames:
        return SourceLocation(frames[-1].filename, frames[-1].lineno or 0)
    return None
