"""``kinema tree validate`` reports a ``main_tree_to_execute`` that names no tree (BT.CPP cannot run it)."""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

from kinema.cli.main import cli


def test_a_main_tree_that_names_no_tree_is_reported_with_file_line_and_the_valid_ids(tmp_path: Path) -> None:
    path = tmp_path / "typo.xml"
    path.write_text(
        '<root BTCPP_format="4" main_tree_to_execute="Pick Objekt">\n'
        '  <BehaviorTree ID="Pick Object"><AlwaysSuccess/></BehaviorTree>\n'
        "</root>\n"
    )
    result = CliRunner().invoke(cli, ["tree", "validate", str(path)])
    assert result.exit_code == 1, result.output
    assert f"{path}:1: main_tree_to_execute='Pick Objekt' names no tree" in result.output, result.output
    assert "did you mean 'Pick Object'" in result.output
    assert "OK" not in result.output and "Traceback" not in result.output


def test_a_main_tree_defined_in_another_validated_file_is_fine(tmp_path: Path) -> None:
    main = tmp_path / "main.xml"
    main.write_text('<root BTCPP_format="4" main_tree_to_execute="Elsewhere"/>\n')
    other = tmp_path / "other.xml"
    other.write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Elsewhere"><AlwaysSuccess/></BehaviorTree></root>'
    )
    result = CliRunner().invoke(cli, ["tree", "validate", str(main), str(other)])
    assert result.exit_code == 0, result.output
