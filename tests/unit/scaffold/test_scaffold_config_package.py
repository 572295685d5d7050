from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from kinema.config import ObjectiveLibrary, Workspace, resolve_config
from kinema.errors import ScaffoldError
from kinema.resources import bundled_dir
from kinema.scaffold import (
    available_templates,
    check_package_name,
    generate,
    new_config_package,
    package_name_problem,
)


def _tree(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def test_new_config_resolves_at_once_and_saves_objectives_into_its_own_folder(workspace_root: Path):
    package = new_config_package("my_cell", "example_config", workspace=Workspace.discover(workspace_root))
    assert package == workspace_root.resolve() / "src" / "my_cell"
    assert _tree(package) == [
        "README.md",
        "config",
        "config/config.yaml",
        "objectives",
        "objectives/README.md",
        "package.xml",
    ]
    assert "<name>my_cell</name>" in (package / "package.xml").read_text()
    assert "<exec_depend>example_config</exec_depend>" in (package / "package.xml").read_text()
    resolved = resolve_config("my_cell", Workspace.discover(workspace_root))
    assert resolved.chain == ["lab_sim", "example_config", "my_cell"]
    assert resolved.get("objectives.objective_library_paths.my_cell_objectives") == {
        "package_name": "my_cell",
        "relative_path": "objectives",
    }
    library = ObjectiveLibrary.load(resolved)
    assert "Open and Close Gripper" in library  # inherited
    saved = library.save("Open Gripper", '<BehaviorTree ID="Open Gripper"><AlwaysSuccess/></BehaviorTree>')
    assert saved.file == package / "objectives" / "open_gripper.xml"
    assert saved.subcategory == "Grasping"  # metadata carried over from lab_sim's version


def test_template_variables_can_be_given_and_prompted(workspace_root: Path):
    asked: list[str] = []

    def prompt(name: str, default: str) -> str:
        asked.append(name)
        return "Jane Roe" if name == "maintainer" else default

    package = new_config_package(
        "cell_b",
        "lab_sim",
        workspace=Workspace.discover(workspace_root),
        no_input=False,
        extra_context={"description": "Cell B on site 3"},
        prompt=prompt,
    )
    xml = (package / "package.xml").read_text()
    assert "Jane Roe" in xml and "Cell B on site 3" in xml
    assert "description" not in asked and "package_name" not in asked and "maintainer" in asked


@pytest.mark.parametrize(
    ("name", "parent", "words"),
    [
        ("Bad-Name", "lab_sim", "not a valid package name"),
        ("double__underscore", "lab_sim", "not a valid package name"),
        ("trailing_", "lab_sim", "not a valid package name"),
        ("9lives", "lab_sim", "not a valid package name"),
        ("class", "lab_sim", "Python keyword"),
        ("lab_sim", "lab_sim", "based on itself"),
        ("fine_name", "lab_sm", "did you mean 'lab_sim'"),
        ("fine_name", "kinema_objectives", "no config package of that name"),
    ],
)
def test_bad_names_are_refused_before_anything_is_written(
    workspace_root: Path, name: str, parent: str, words: str
):
    before = _tree(workspace_root)
    with pytest.raises(ScaffoldError, match=words):
        new_config_package(name, parent, workspace=Workspace.discover(workspace_root))
    assert _tree(workspace_root) == before


def test_a_bundled_name_is_overlaid_by_the_new_workspace_package(workspace_root: Path):
    """The tutorial's `kinema new config example_config --based-on lab_sim` in a fresh workspace."""
    package = new_config_package("example_config", "lab_sim", workspace=Workspace.discover(workspace_root))
    assert package == workspace_root.resolve() / "src" / "example_config"
    found = Workspace.discover(workspace_root)
    assert found.package("example_config").path == package
    assert any("overlays the bundled one" in notice for notice in found.notices)
    assert resolve_config("example_config", found).chain == ["lab_sim", "example_config"]
    with pytest.raises(ScaffoldError, match="already exists"):
        new_config_package("example_config", "lab_sim", workspace=found)


def test_existing_folder_is_refused(workspace_root: Path, tmp_path: Path):
    (tmp_path / "out" / "taken").mkdir(parents=True)
    (tmp_path / "out" / "taken" / "keep.txt").write_text("mine")
    with pytest.raises(ScaffoldError, match="already exists"):
        new_config_package("taken", "lab_sim", tmp_path / "out", workspace=Workspace.discover(workspace_root))
    assert _tree(tmp_path / "out") == ["taken", "taken/keep.txt"]


def test_without_a_workspace_an_output_dir_is_needed(tmp_path: Path):
    with pytest.raises(ScaffoldError, match="no workspace is selected"):
        new_config_package("cell", "lab_sim", workspace=Workspace.bundled_only())
    package = new_config_package("cell", "lab_sim", tmp_path / "anywhere", workspace=Workspace.bundled_only())
    assert (package / "config" / "config.yaml").is_file()


def test_generate_checks_template_and_variables(tmp_path: Path):
    assert "config_package" in available_templates()
    with pytest.raises(
        ScaffoldError, match=r"no template named 'config_pakage'.*did you mean 'config_package'"
    ):
        generate("config_pakage", tmp_path, {})
    with pytest.raises(ScaffoldError, match="has no variable 'colour'"):
        generate("config_package", tmp_path, {"colour": "red"})
    assert list(tmp_path.iterdir()) == []


def test_a_validation_hook_refuses_input_before_writing(tmp_path: Path):
    def refuse(values: dict[str, str]) -> None:
        raise ScaffoldError(f"refused {values['package_name']}")

    with pytest.raises(ScaffoldError, match="refused cell"):
        generate("config_package", tmp_path / "out", {"package_name": "cell"}, validate=refuse)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("bad", ["Bad Name", "quote'\"\\name", "a__b"])
def test_the_template_hook_itself_refuses_bad_names(tmp_path: Path, bad: str):
    """Run by cookiecutter directly (no Kinema checks in front), the template still refuses."""
    script = (
        "import sys\n"
        "from cookiecutter.main import cookiecutter\n"
        "cookiecutter(sys.argv[1], no_input=True, extra_context={'package_name': sys.argv[2]},\n"
        "             output_dir=sys.argv[3])\n"
    )
    result = subprocess.run(
        [
            sys.executable,
            "-c",
            script,
            str(bundled_dir("cookiecutters") / "config_package"),
            bad,
            str(tmp_path / "out"),
        ],
        capture_output=True,
        text=True,
        env={"HOME": str(tmp_path), "PATH": "/usr/bin:/bin"},
        check=False,
    )
    assert result.returncode != 0
    assert "ERROR: " in result.stderr and "is not a valid package name" in result.stderr
    assert not (tmp_path / "out").exists() or list((tmp_path / "out").iterdir()) == []


def test_the_hook_error_reaches_the_user_as_a_scaffold_error(tmp_path: Path):
    # Bypassing Kinema's own name check shows the template's hook as the second line of defence.
    with pytest.raises(ScaffoldError, match="refused the input"):
        generate("config_package", tmp_path / "out", {"package_name": "Bad Name"})
    assert list((tmp_path / "out").iterdir()) == []


@pytest.mark.parametrize(
    ("name", "valid"),
    [
        ("my_robot_config", True),
        ("lab_sim2", True),
        ("a", True),
        ("My", False),
        ("a-b", False),
        ("", False),
        ("_a", False),
        ("a" * 101, False),
    ],
)
def test_package_name_rules(name: str, valid: bool):
    assert (package_name_problem(name) is None) is valid
    if not valid:
        with pytest.raises(ScaffoldError):
            check_package_name(name)
