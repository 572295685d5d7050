from __future__ import annotations

import subprocess
import sys

from kinema import __version__
from kinema.cli.main import main


def test_version_prints_the_package_version(capsys):
    assert main(["--version"]) == 0
    assert __version__ in capsys.readouterr().out


def test_help_lists_verbs_and_does_not_import_heavy_modules():
    code = (
        "import sys; from kinema.cli.main import main; rc = main(['--help']);"
        # kinema.config: `kinema new` reached it through kinema.scaffold (40-100 ms of `kinema --help`).
        "heavy = [m for m in ('mujoco', 'pinocchio', 'zenoh', 'textual', 'meshcat', 'ompl', 'kinema.config')"
        " if m in sys.modules];"
        "print('HEAVY', heavy); raise SystemExit(rc)"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    assert "Commands" in result.stdout
    assert "HEAVY []" in result.stdout


def test_unknown_verb_exits_non_zero(capsys):
    assert main(["no-such-verb"]) != 0
    assert "No such command" in capsys.readouterr().err


def test_a_mistyped_verb_gets_a_suggestion(capsys):
    assert main(["objectives", "list"]) != 0
    assert "No such command 'objectives'; did you mean 'objective'?" in capsys.readouterr().err


def test_each_verb_summary_in_help_is_a_whole_sentence(capsys, monkeypatch):
    # A summary cut at a fixed length ended mid-sentence: "Generate a new package: from a template, or a
    # robot's config package from its..."
    monkeypatch.setenv("COLUMNS", "80")
    assert main(["--help"]) == 0
    listing = capsys.readouterr().out.split("Commands:", 1)[1]
    summaries: dict[str, str] = {}
    verb = ""
    for line in listing.splitlines():
        if line.startswith("  ") and not line.startswith("   "):
            verb, _, text = line.strip().partition(" ")
            summaries[verb] = text.strip()
        elif line.strip():
            summaries[verb] += " " + line.strip()
    assert "objective" in summaries and "run" in summaries
    for verb, summary in summaries.items():
        assert summary.endswith((".", ")")) and "..." not in summary, (verb, summary)


def test_a_mistyped_subcommand_gets_a_suggestion(capsys):
    assert main(["objective", "lsit"]) != 0
    assert "No such command 'lsit'; did you mean 'list'?" in capsys.readouterr().err
