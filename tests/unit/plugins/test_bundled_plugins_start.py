"""What loading the bundled plugins costs a one-shot command: no compiling at every start, no heavy imports.

``kinema objective list`` loads every behavior of the config to say which objectives cannot load; it should
start in a small multiple of the interpreter's own start (issue 31).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from kinema.bytecode import UserCacheSourceLoader, bytecode_cache_path
from kinema.plugins.importer import import_fresh, purge_modules


def _package(root: Path) -> Path:
    (root / "pkg").mkdir(parents=True)
    (root / "pkg" / "__init__.py").write_text("from .values import VALUE\n")
    (root / "pkg" / "values.py").write_text("VALUE = 1\n")
    return root


def test_a_never_reloaded_package_is_compiled_once_into_the_user_cache(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # PYTHONDONTWRITEBYTECODE (or a read-only checkout) must not make the bundled plugins compile each start.
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    root = _package(tmp_path / "src")
    first = import_fresh(root, "pkg", "pkg", cache_bytecode=True)
    values = str(root / "pkg" / "values.py")
    assert bytecode_cache_path(values).is_file()
    assert not (root / "pkg" / "__pycache__").exists()

    def no_compiling(*args: object, **kwargs: object) -> None:
        raise AssertionError("compiled although the user cache holds the code")

    monkeypatch.setattr(UserCacheSourceLoader, "source_to_code", no_compiling)
    second = import_fresh(root, "pkg", "pkg", cache_bytecode=True)
    assert (first.VALUE, second.VALUE) == (1, 1)
    purge_modules(first.__name__)
    purge_modules(second.__name__)


def test_a_changed_source_is_compiled_again_not_served_stale(tmp_path: Path) -> None:
    root = _package(tmp_path / "src")
    first = import_fresh(root, "pkg", "pkg", cache_bytecode=True)
    (root / "pkg" / "values.py").write_text("VALUE = 22\n")
    second = import_fresh(root, "pkg", "pkg", cache_bytecode=True)
    assert (first.VALUE, second.VALUE) == (1, 22)
    purge_modules(first.__name__)
    purge_modules(second.__name__)


def test_a_damaged_cache_file_is_replaced(tmp_path: Path) -> None:
    root = _package(tmp_path / "src")
    purge_modules(import_fresh(root, "pkg", "pkg", cache_bytecode=True).__name__)
    cached = bytecode_cache_path(str(root / "pkg" / "values.py"))
    cached.write_bytes(cached.read_bytes()[:-8])
    module = import_fresh(root, "pkg", "pkg", cache_bytecode=True)
    assert module.VALUE == 1
    purge_modules(module.__name__)


def test_loading_the_bundled_behaviors_imports_no_numpy_zenoh_watchdog_or_asyncio() -> None:
    code = (
        "import sys\n"
        "from kinema.plugins import BehaviorHost\n"
        "host = BehaviorHost(['kinema::CoreBehaviorsLoader', 'kinema::MujocoBehaviorsLoader'], None)\n"
        "report = host.load()\n"
        "assert not report.errors, report.errors\n"
        "assert len(host.registry.create_factory().manifests()) > 100\n"
        "from kinema.transport.session import resolve_endpoints\n"
        "heavy = ('numpy', 'rosbags', 'zenoh', 'watchdog', 'mujoco', 'pinocchio', 'asyncio')\n"
        "print(sorted(name for name in heavy if name in sys.modules))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


def test_kinema_own_modules_are_not_compiled_again_at_each_start(tmp_path: Path) -> None:
    # With PYTHONDONTWRITEBYTECODE, an editable install had no __pycache__ for kinema itself and every command
    # compiled each kinema module it imported: ~80 ms of a 230 ms `kinema objective list`.
    count_compiles = (
        "import importlib.machinery as machinery\n"
        "compiled = []\n"
        "original = machinery.SourceFileLoader.source_to_code\n"
        "def counting(self, data, path, *args, **kwargs):\n"
        "    compiled.append(path)\n"
        "    return original(self, data, path, *args, **kwargs)\n"
        "machinery.SourceFileLoader.source_to_code = counting\n"
        "import kinema.config, kinema.cli.main\n"
        "print(len([path for path in compiled if '/kinema/' in path]))\n"
        "print(sorted(path.rpartition('/kinema/')[2] for path in compiled if '/kinema/' in path))\n"
    )
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1", "XDG_CACHE_HOME": str(tmp_path / "cache")}
    command = [sys.executable, "-c", count_compiles]
    runs = [subprocess.run(command, capture_output=True, text=True, env=env, timeout=60) for _ in range(2)]
    assert all(run.returncode == 0 for run in runs), [run.stderr for run in runs]
    first, second = (run.stdout.splitlines() for run in runs)
    assert int(first[0]) > 20  # the first start compiles them (into the user cache) ...
    # ... the next one only loads them, but for the two that set this up
    assert second[1] == "['__init__.py', 'bytecode.py']"
    assert list((tmp_path / "cache" / "kinema" / "bytecode").rglob("schema.*.pyc"))
