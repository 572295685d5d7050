"""toppra, imported without the libraries it imports at its top for parts that Kinema's timing never uses.

toppra's modules import ``matplotlib.pyplot`` (for plots), ``scipy.interpolate`` (for its own path classes)
and ``scipy.sparse`` (for the ECOS solver). Timing a path (:mod:`kinema.motion.timing`) uses none of them:
it hands toppra a :class:`~kinema.motion.clamped_spline.ClampedCubicSpline` and solves with toppra's own
solver. Loaded, they held about 30 MB (matplotlib, PIL, kiwisolver, fonttools) and 35 MB (scipy's
interpolate, optimize, sparse, linalg, special, fft, spatial) in every agent.

While toppra is imported, those import statements *in toppra's own modules* get stand-ins: ``import
matplotlib.pyplot as plt`` a module that imports the real one when an attribute of it is first read, and
``from scipy.interpolate import CubicSpline`` a name that imports the real one when it is first called or
an attribute of it is read. So every part of toppra still works, and loads what it needs on first use
(``toppra.SplineInterpolator(...)`` loads scipy). A stand-in is no class: ``isinstance(x, CubicSpline)`` in
toppra's modules fails, and toppra has no such test.

Only toppra's statements are answered so: the stand-ins never enter ``sys.modules``, and an import from any
other module, in any thread, during toppra's import or after it, gets the real module. A library already
imported is handed over as it is.
"""

from __future__ import annotations

import builtins
import importlib
import sys
import threading
import types
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from typing import Any

__all__ = ["import_toppra"]

#: The top-level packages whose import in toppra's modules is deferred.
DEFERRED = ("matplotlib", "scipy")

_lock = threading.Lock()


def import_toppra() -> types.ModuleType:
    """``toppra`` with ``toppra.algorithm`` and ``toppra.constraint`` imported, the first time without
    loading :data:`DEFERRED` (see the module's docstring)."""
    with _lock:
        if "toppra" not in sys.modules:
            with _deferring_imports_of(DEFERRED, importer="toppra"):
                import toppra
                import toppra.algorithm
                import toppra.constraint
    import toppra

    return toppra


class _DeferredModule(types.ModuleType):
    """Stands in for a module that is imported only when one of its attributes is first read."""

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):  # __file__, __path__ ... asked by tools walking modules load nothing
            raise AttributeError(name)
        return getattr(importlib.import_module(self.__name__), name)


class _DeferredName:
    """Stands in for ``module.name``, imported when it is first called or an attribute of it is read."""

    def __init__(self, module: str, name: str) -> None:
        self._module = module
        self._name = name

    def _resolve(self) -> Any:
        return getattr(importlib.import_module(self._module), self._name)

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self._resolve()(*args, **kwargs)

    def __getattr__(self, attribute: str) -> Any:
        if attribute.startswith("__"):
            raise AttributeError(attribute)
        return getattr(self._resolve(), attribute)

    def __repr__(self) -> str:
        return f"<deferred {self._module}.{self._name}>"


def _stand_in(name: str, fromlist: Sequence[str] | None) -> Any:
    """What an import statement of module ``name`` gets instead of the module (the value of
    ``__import__``): for ``from name import a, b`` a namespace of deferred names, for ``import a.b.c`` the
    deferred top package ``a`` with ``a.b`` and ``a.b.c`` deferred modules under it."""
    if fromlist:
        return types.SimpleNamespace(**{attribute: _DeferredName(name, attribute) for attribute in fromlist})
    parts = name.split(".")
    top = module = _DeferredModule(parts[0])
    for depth in range(2, len(parts) + 1):
        child = _DeferredModule(".".join(parts[:depth]))
        setattr(module, parts[depth - 1], child)
        module = child
    return top


@contextmanager
def _deferring_imports_of(packages: Sequence[str], importer: str) -> Iterator[None]:
    """Within the block, absolute imports of ``packages`` (and their submodules) not yet loaded, in the
    modules of package ``importer``, get stand-ins (:func:`_stand_in`); every other import is untouched."""
    real_import = builtins.__import__

    def deferring_import(
        name: str,
        globals: Mapping[str, Any] | None = None,
        locals: Mapping[str, Any] | None = None,
        fromlist: Sequence[str] | None = (),
        level: int = 0,
    ) -> Any:
        caller = globals.get("__name__", "") if globals else ""
        if (
            level == 0
            and name.partition(".")[0] in packages
            and name not in sys.modules
            and (caller == importer or caller.startswith(importer + "."))
        ):
            return _stand_in(name, fromlist)
        return real_import(name, globals, locals, fromlist, level)

    builtins.__import__ = deferring_import
    try:
        yield
    finally:
        if builtins.__import__ is deferring_import:
            builtins.__import__ = real_import
