"""Path-loaded plugins are imported fresh each time, and import errors point at the user's line."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from kinema.errors import PluginError
from kinema.plugins.importer import import_fresh, purge_modules


def _package(root: Path, files: dict[str, str]) -> Path:
    for relative, text in files.items():
        path = root / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return root


def test_each_import_is_a_new_module_with_the_current_code(tmp_path: Path) -> None:
    root = _package(
        tmp_path,
        {"my_pkg/__init__.py": "from .values import VALUE\n", "my_pkg/values.py": "VALUE = 1\n"},
    )
    first = import_fresh(root, "my_pkg", "my_pkg")
    # Same size, same second: bytecode caches keyed on mtime would serve the old code here.
    (root / "my_pkg" / "values.py").write_text("VALUE = 2\n")
    second = import_fresh(root, "my_pkg", "my_pkg")
    assert (first.VALUE, second.VALUE) == (1, 2)
    assert first.__name__ != second.__name__
    assert not (root / "my_pkg" / "__pycache__").exists()
    purge_modules(first.__name__)
    assert first.__name__ not in sys.modules
    assert f"{first.__name__}.values" not in sys.modules
    assert second.__name__ in sys.modules
    purge_modules(second.__name__)


def test_a_submodule_can_be_the_plugin_module(tmp_path: Path) -> None:
    root = _package(tmp_path, {"pkg/__init__.py": "", "pkg/register.py": "NAME = 'register'\n"})
    module = import_fresh(root, "pkg.register", "pkg")
    assert module.NAME == "register"
    purge_modules(module.__name__.split(".")[0])


def test_a_syntax_error_names_the_file_and_line(tmp_path: Path) -> None:
    root = _package(
        tmp_path,
        {"pkg/__init__.py": "from .broken import X\n", "pkg/broken.py": "X = 1\n\ndef f(:\n    pass\n"},
    )
    before = set(sys.modules)
    with pytest.raises(PluginError) as caught:
        import_fresh(root, "pkg", "pkg")
    assert caught.value.location is not None
    assert Path(caught.value.location.file).name == "broken.py"
    assert caught.value.location.line == 3
    assert "SyntaxError" in caught.value.message and "'pkg'" in caught.value.message
    assert set(sys.modules) - before == set()


def test_an_exception_at_import_points_at_the_raising_line_in_the_users_file(tmp_path: Path) -> None:
    root = _package(
        tmp_path,
        {"pkg/__init__.py": "from . import helper\n", "pkg/helper.py": "A = 1\nB = A / 0\n"},
    )
    with pytest.raises(PluginError, match="ZeroDivisionError") as caught:
        import_fresh(root, "pkg", "pkg")
    assert caught.value.location is not None
    assert (Path(caught.value.location.file).name, caught.value.location.line) == ("helper.py", 2)


def test_an_absolute_import_of_the_package_itself_gets_a_hint(tmp_path: Path) -> None:
    root = _package(
        tmp_path,
        {"own_pkg/__init__.py": "from own_pkg.helper import X\n", "own_pkg/helper.py": "X = 1\n"},
    )
    with pytest.raises(PluginError, match=r"import the package's own modules relatively") as caught:
        import_fresh(root, "own_pkg", "own_pkg")
    assert caught.value.location is not None and caught.value.location.line == 1
