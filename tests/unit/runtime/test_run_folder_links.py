"""``kinema logs`` and ``kinema export-logs`` never read through a symbolic link out of the run folder."""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest
from click.testing import CliRunner

from kinema.cli.main import cli
from kinema.runtime.run_folder import RunFolder, list_runs

SECRET = "the private key of this machine"


@pytest.fixture(autouse=True)
def state_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    return tmp_path / "state"


@pytest.fixture
def run_with_links(tmp_path: Path) -> RunFolder:
    outside = tmp_path / "home"
    (outside / ".ssh").mkdir(parents=True)
    (outside / ".ssh" / "id_ed25519").write_text(SECRET)
    (outside / "notes.log").write_text(f"2026-11-24 05:00:00.000 ERROR   [x] {SECRET}\n")
    run = RunFolder.create("lab_sim")
    run.log_file("agent").write_text("2026-11-24 05:00:00.000 INFO    [kinema.agent] agent serving\n")
    (run.path / "ssh").symlink_to(outside / ".ssh", target_is_directory=True)
    (run.path / "key.txt").symlink_to(outside / ".ssh" / "id_ed25519")
    (run.path / "driver.log").symlink_to(outside / "notes.log")
    return run


def test_export_logs_archives_the_run_files_and_skips_links(
    run_with_links: RunFolder, tmp_path: Path
) -> None:
    archive = tmp_path / "logs.zip"
    result = CliRunner().invoke(cli, ["export-logs", "-o", str(archive)])
    assert result.exit_code == 0, result.output
    with zipfile.ZipFile(archive) as zipped:
        names = sorted(Path(name).name for name in zipped.namelist())
        contents = b"".join(zipped.read(name) for name in zipped.namelist())
    assert names == ["agent.log"]
    assert SECRET.encode() not in contents
    for link in ("driver.log", "key.txt", "ssh"):
        assert f"skipped {link}: a symbolic link" in result.output, result.output
    assert "wrote" in result.output and "(1 files" in result.output


def test_logs_does_not_print_a_linked_file(run_with_links: RunFolder) -> None:
    result = CliRunner().invoke(cli, ["logs"])
    assert result.exit_code == 0, result.output
    assert "agent serving" in result.output and SECRET not in result.output


def test_a_linked_run_folder_is_not_a_run(tmp_path: Path, run_with_links: RunFolder) -> None:
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (run_with_links.path.parent / "99999999-999999-000000-evil").symlink_to(
        elsewhere, target_is_directory=True
    )
    assert [run.path for run in list_runs()] == [run_with_links.path]


def test_export_logs_into_a_missing_folder_is_one_line_not_a_traceback(
    run_with_links: RunFolder, tmp_path: Path
) -> None:
    from kinema.cli.main import main

    target = tmp_path / "no" / "such" / "folder" / "logs.zip"
    code = main(["export-logs", "-o", str(target)])
    assert code == 1 and not target.exists()
