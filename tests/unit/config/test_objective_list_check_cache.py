"""`kinema objective list` reuses its last check of which objectives can load, and only while it holds.

Loading every behavior of the config is most of the command's time (issue 31: within 5x of `python -c
pass`); the answer is kept under a fingerprint of the objective files, the plugins' sources and Kinema's.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from kinema.cli.main import main
from kinema.config import ObjectiveLibrary, Workspace, resolve_config
from kinema.plugins import BehaviorHost
from kinema.plugins.discovery import PluginSource, PluginSpec
from kinema.runtime.library_check import check_fingerprint


def _list(capsys: pytest.CaptureFixture[str], ws: Any) -> str:
    assert main(["objective", "list", "-w", str(ws.root), "-c", "robot"]) == 0
    return capsys.readouterr().out


def test_an_unchanged_library_is_not_checked_again_and_a_changed_one_is(
    capsys: pytest.CaptureFixture[str], ws: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    ws.config("robot")
    path = ws.objective("robot", "Fine")
    first = _list(capsys, ws)
    assert "Fine" in first and "cannot load" not in first

    def no_loading(self: BehaviorHost, specs: object) -> None:
        raise AssertionError("the behaviors were loaded again for an unchanged library")

    with monkeypatch.context() as patch:
        patch.setattr(BehaviorHost, "load_specs", no_loading)
        assert _list(capsys, ws) == first

    # the same size, written right after: only the content tells the two apart
    path.write_text(path.read_text().replace("AlwaysSuccess", "AlwaysSuccesX"))
    changed = _list(capsys, ws)
    assert "1 of 1 objectives cannot load" in changed and "AlwaysSuccesX" in changed


def test_the_fingerprint_follows_a_plugin_source_and_the_objective_files(ws: Any, tmp_path: Path) -> None:
    ws.config("robot")
    ws.objective("robot", "Fine")
    library = ObjectiveLibrary.load(resolve_config("robot", Workspace.discover(ws.root)))
    package = tmp_path / "behaviors"
    (package / "my_behaviors").mkdir(parents=True)
    source = package / "my_behaviors" / "__init__.py"
    source.write_text("VALUE = 1\n")
    spec = PluginSpec("my::Loader", PluginSource.WORKSPACE, "my_behaviors", "my_behaviors", root=package)
    before = check_fingerprint(library, [spec])
    assert check_fingerprint(library, [spec]) == before
    source.write_text("VALUE = 22\n")
    assert check_fingerprint(library, [spec]) != before
    assert check_fingerprint(library, []) != check_fingerprint(library, [spec])
    ws.objective("robot", "Another")
    grown = ObjectiveLibrary.load(resolve_config("robot", Workspace.discover(ws.root)))
    assert check_fingerprint(grown, [spec]) != check_fingerprint(library, [spec])
