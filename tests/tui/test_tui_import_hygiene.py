"""The core stays headless: importing it never pulls in textual, rich or meshcat (checked in a subprocess)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

CORE = ["kinema.runtime", "kinema.sdk", "kinema.config", "kinema.bt", "kinema.transport", "kinema.plugins"]
UI_ONLY = ("textual", "rich", "meshcat")


@pytest.mark.parametrize("module", CORE)
def test_importing_the_core_imports_no_ui_library(module: str) -> None:
    code = (
        "import importlib, json, sys\n"
        f"importlib.import_module({module!r})\n"
        "print(json.dumps(sorted(m for m in sys.modules if m.split('.')[0] in "
        f"{UI_ONLY!r})))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True
    )
    assert json.loads(done.stdout) == [], f"importing {module} imported UI libraries"


def test_the_tui_models_import_without_textual() -> None:
    """The adapter interface and the UI-free models are usable (and testable) without textual."""
    code = (
        "import sys\n"
        "for name in ('kinema.tui.connection', 'kinema.tui.blackboard_model', 'kinema.tui.tree_outline',"
        " 'kinema.tui.config_view', 'kinema.tui.runtime_status', 'kinema.tui.fake_connection'):\n"
        "    __import__(name)\n"
        "print('textual' in sys.modules)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True
    )
    assert done.stdout.strip() == "False"
