"""Compiled code of Kinema's own modules and bundled plugins, kept in the user's cache folder.

CPython keeps compiled code in ``__pycache__`` folders beside the sources, unless ``PYTHONDONTWRITEBYTECODE``
is set (or the folder cannot be written, as in a read-only editable checkout). Then every ``kinema`` command
compiled each module it imported, again at every start: about 80 ms of a 230 ms ``kinema objective list``.
The same held for the bundled behavior plugins, which load under fresh module names every time.

Here the compiled code goes to ``<user cache>/kinema/bytecode/<absolute source path>.<tag>.pyc`` instead
(the source's path mirrored, as ``sys.pycache_prefix`` does), which keeps source trees free of
``__pycache__`` folders, as the variable asks. A cached file is used only when its header carries this
interpreter's magic number and the source's nanosecond mtime and size; anything else is compiled again and
the file replaced atomically, so two processes starting at once never read half a file.

:func:`cache_own_modules` applies this to ``kinema.*`` (called by ``kinema/__init__.py`` when the variable
is set); the plugin importer uses :class:`UserCacheSourceLoader` for the bundled plugins.
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import importlib.util
import marshal
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from types import ModuleType
from typing import Any


def _cache_root() -> Path:
    if sys.platform.startswith("linux"):  # platformdirs' answer, without importing it into every command
        base = os.environ.get("XDG_CACHE_HOME", "").strip() or os.path.expanduser("~/.cache")
        return Path(base) / "kinema" / "bytecode"
    import platformdirs

    return platformdirs.user_cache_path("kinema") / "bytecode"


def bytecode_cache_path(source_path: str) -> Path:
    """Where the compiled code of the source file ``source_path`` is kept (see the module docstring)."""
    source = Path(os.path.abspath(source_path))
    tag = sys.implementation.cache_tag or "python"
    mirrored = source.relative_to(source.anchor).with_name(f"{source.stem}.{tag}.pyc")
    return _cache_root() / mirrored


class UserCacheSourceLoader(importlib.machinery.SourceFileLoader):
    """Loads Python source through the user-cache copy of its compiled code (see the module docstring)."""

    def get_code(self, fullname: str) -> Any:
        source_path = self.get_filename(fullname)
        stat = os.stat(source_path)
        # the interpreter's magic number, then the source's identity: any change makes a miss
        header = importlib.util.MAGIC_NUMBER + f"{stat.st_mtime_ns}:{stat.st_size}\n".encode()
        cached = bytecode_cache_path(source_path)
        try:
            data = cached.read_bytes()
        except OSError:
            data = b""
        if data.startswith(header):
            try:
                return marshal.loads(data[len(header) :])
            except (EOFError, ValueError, TypeError):
                pass  # a damaged file: compile again and replace it
        code = self.source_to_code(self.get_data(source_path), source_path)
        try:
            cached.parent.mkdir(parents=True, exist_ok=True)
            partial = cached.with_name(f"{cached.name}.{os.getpid()}.tmp")
            partial.write_bytes(header + marshal.dumps(code))
            os.replace(partial, cached)
        except OSError:
            pass  # no writable cache folder: the module still loads, compiled as before
        return code


class _OwnModulesFinder(importlib.abc.MetaPathFinder):
    """Finds ``kinema.*`` as the path finder does, then loads their source through the user cache."""

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        if not fullname.startswith("kinema."):
            return None
        spec = importlib.machinery.PathFinder.find_spec(fullname, path, target)
        if spec is None or type(spec.loader) is not importlib.machinery.SourceFileLoader or not spec.origin:
            return spec
        spec.loader = UserCacheSourceLoader(fullname, spec.origin)
        return spec


_OWN_FINDER = _OwnModulesFinder()


def cache_own_modules() -> None:
    """Load Kinema's own modules through the user cache from now on (idempotent)."""
    if _OWN_FINDER not in sys.meta_path:
        sys.meta_path.insert(0, _OWN_FINDER)
