"""docs/behavior-reference.md is the registry's behavior reference for lab_sim's loaders, kept current."""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

REPO = Path(__file__).resolve().parents[2]
PAGE = REPO / "docs" / "behavior-reference.md"
REGENERATE = "kinema behaviors --markdown -c lab_sim > docs/behavior-reference.md"


def test_the_behavior_reference_page_matches_the_registry() -> None:
    from kinema.cli.main import cli

    result = CliRunner().invoke(cli, ["behaviors", "--markdown", "-c", "lab_sim"])
    assert result.exit_code == 0, result.output
    if PAGE.read_text(encoding="utf-8") != result.output:
        page = set(PAGE.read_text(encoding="utf-8").splitlines())
        now = set(result.output.splitlines())
        changed = sorted(line for line in now ^ page if line.startswith(("### ", "| `")))[:10]
        raise AssertionError(
            f"{PAGE.name} is out of date; regenerate it with `{REGENERATE}`. Lines that differ:\n"
            + "\n".join(changed)
        )


def test_the_reference_gives_each_behavior_its_ports_with_direction_type_and_default() -> None:
    from kinema.cli.main import cli

    result = CliRunner().invoke(
        cli, ["behaviors", "--markdown", "-c", "lab_sim", "PushBackVector", "ForEach"]
    )
    assert result.exit_code == 0, result.output
    text = result.output
    assert "## Vector Handling" in text and "### PushBackVector" in text and "### ForEach" in text
    assert "| `element` | input | `BT::AnyTypeAllowed` | `{element}` |" in text
    assert "| `index` | output | `int` | `{index}` |" in text
    assert "Appends `element` to the end of `input_vector`" in text


def test_the_reference_names_the_former_spellings_objectives_may_still_use() -> None:
    from kinema.cli.main import cli

    result = CliRunner().invoke(
        cli, ["behaviors", "--markdown", "-c", "lab_sim", "CreatePoseStamped", "GetImage", "PushBackVector"]
    )
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert (
        "Former spellings (MoveIt Pro), read with a warning: `CreateStampedPose` "
        "(port `stamped_pose` is `pose_stamped`)."
    ) in lines
    assert (
        "Former spellings (MoveIt Pro), read with a warning: port `timeout_sec` is `message_timeout_sec`."
    ) in lines
    assert sum(line.startswith("Former spellings") for line in lines) == 2  # none for PushBackVector
