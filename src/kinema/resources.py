"""Where Kinema's bundled data lives: ``plugins/``, ``cookiecutters/``, ``configs/``, ``objectives/``.

In a wheel they are package data under ``kinema/_data/``; in an editable checkout they are the
top-level folders of the repository. Both layouts resolve through :func:`bundled_dir`.
"""

from __future__ import annotations

from pathlib import Path

_PACKAGE_DIR = Path(__file__).resolve().parent
_BUNDLED_NAMES = ("plugins", "cookiecutters", "configs", "objectives")


def bundled_dir(name: str) -> Path:
    """Return the folder of bundled data ``name`` (one of plugins, cookiecutters, configs, objectives)."""
    if name not in _BUNDLED_NAMES:
        raise ValueError(f"unknown bundled folder {name!r}; valid: {', '.join(_BUNDLED_NAMES)}")
    installed = _PACKAGE_DIR / "_data" / name
    if installed.is_dir():
        return installed
    return _PACKAGE_DIR.parent.parent / name
