"""The behavior package template: every type bakes into a package whose own tests pass as generated."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from kinema.config import Workspace, resolve_config
from kinema.errors import ScaffoldError
from kinema.plugins import BehaviorHost
from kinema.resources import bundled_dir
from kinema.scaffold.behavior_package import BEHAVIOR_TYPES, behavior_id_for, new_behavior
from kinema.testing import load_behavior_package

# Plugins of this environment the generated tests do not use; leaving them out halves each run's start-up.
LEAN_PYTEST = [
    "-p",
    "no:cacheprovider",
    "-p",
    "no:hypothesispytest",
    "-p",
    "no:textual-snapshot",
    "-p",
    "no:benchmark",
]


def _start_package_tests(package_dir: Path) -> subprocess.Popen[str]:
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    from importlib import metadata

    # As `kinema test` does: name the plugin when this environment's metadata predates its entry point.
    installed = any(entry.name == "kinema" for entry in metadata.entry_points(group="pytest11"))
    plugin = [] if installed else ["-p", "kinema.testing.plugin"]
    return subprocess.Popen(
        [sys.executable, "-m", "pytest", "-q", *LEAN_PYTEST, *plugin],
        cwd=package_dir,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=env,
    )


def _run_package_tests(package_dir: Path) -> tuple[int, str]:
    process = _start_package_tests(package_dir)
    output, _ = process.communicate(timeout=180)
    return process.returncode, output


@pytest.fixture(scope="module")
def baked(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, str, int, str]]:
    """Every type baked into one workspace; their test runs started together (they mostly wait on I/O)."""
    workspace = tmp_path_factory.mktemp("templates") / "ws"
    (workspace / "src").mkdir(parents=True)
    packages = {}
    for behavior_type in BEHAVIOR_TYPES:
        name = f"my_{behavior_type}"
        result = new_behavior(name, behavior_type, workspace=Workspace.discover(workspace))
        packages[behavior_type] = (result.package_dir, result.behavior_id)
    processes = {kind: _start_package_tests(folder) for kind, (folder, _) in packages.items()}
    outcomes = {}
    try:
        for kind, process in processes.items():
            output, _ = process.communicate(timeout=300)
            outcomes[kind] = (*packages[kind], process.returncode, output)
    finally:
        for process in processes.values():
            if process.poll() is None:
                process.kill()
    return outcomes


@pytest.mark.parametrize("behavior_type", BEHAVIOR_TYPES)
def test_each_type_bakes_into_a_package_whose_tests_pass(baked, behavior_type: str) -> None:
    package_dir, behavior_id, returncode, output = baked[behavior_type]
    name = f"my_{behavior_type}"
    assert package_dir.name == name and behavior_id == behavior_id_for(name)
    for relative in ("pyproject.toml", f"{name}/__init__.py", f"{name}/{name}.py", f"objectives/{name}.xml"):
        assert (package_dir / relative).is_file(), relative
    assert list(load_behavior_package(package_dir)) == [behavior_id]

    assert returncode == 0, output
    assert " passed" in output and "failed" not in output

    if shutil.which("ruff"):
        lint = subprocess.run(
            ["ruff", "check", "--isolated", "--line-length", "110", "--select", "E,F,W,I,B,UP", "."],
            cwd=package_dir,
            capture_output=True,
            text=True,
        )
        assert lint.returncode == 0, lint.stdout


def test_a_behavior_added_to_a_package_is_registered_and_tested(workspace: Path) -> None:
    new_behavior("adders", "async", workspace=Workspace.discover(workspace))
    added = new_behavior(
        "add_client", "service_client", workspace=Workspace.discover(workspace), package="adders"
    )
    package_dir = workspace / "src" / "adders"
    assert not added.created_package
    assert added.loader_name == "adders::AddersBehaviorsLoader"
    assert (package_dir / "adders" / "add_client.py").is_file()
    assert sorted(load_behavior_package(package_dir)) == ["AddClient", "Adders"]
    # The package README's table lists it too (it listed only the first behavior).
    readme = (package_dir / "README.md").read_text()
    first, second = "| `Adders` | async | `adders/adders.py` |", "| `AddClient` | service_client |"
    assert f"{first}\n{second} `adders/add_client.py` |\n" in readme
    assert package_dir / "README.md" in added.files
    returncode, output = _run_package_tests(package_dir)
    assert returncode == 0, output
    assert "6 passed" in output


@pytest.mark.parametrize(
    ("name", "behavior_type", "package", "message"),
    [
        ("Bad-Name", "async", None, "not a valid behavior name"),
        ("1st_behavior", "async", None, "not a valid behavior name"),
        ("class", "async", None, "keyword"),
        ("double__underscore", "async", None, "not a valid behavior name"),
        ("good_name", "asynchronous", None, "unknown behavior type 'asynchronous'.*async"),
        ("good_name", "async", "no_such_package", "no behavior package named 'no_such_package'"),
    ],
)
def test_bad_input_is_refused_before_anything_is_written(
    workspace: Path, name: str, behavior_type: str, package: str | None, message: str
) -> None:
    with pytest.raises(ScaffoldError, match=message):
        new_behavior(name, behavior_type, workspace=Workspace.discover(workspace), package=package)
    assert list((workspace / "src").iterdir()) == []


def test_a_taken_package_name_or_module_is_refused(workspace: Path) -> None:
    new_behavior("adders", "async", workspace=Workspace.discover(workspace))
    before = sorted(p for p in (workspace / "src").rglob("*"))
    with pytest.raises(ScaffoldError, match=r"already exists.*--package adders"):
        new_behavior("adders", "sync", workspace=Workspace.discover(workspace))
    with pytest.raises(ScaffoldError, match=r"adders\.py already exists"):
        new_behavior("adders", "sync", workspace=Workspace.discover(workspace), package="adders")
    assert sorted(p for p in (workspace / "src").rglob("*")) == before


def test_the_workspace_config_gets_the_loader_and_keeps_its_comments(workspace_with_config: Path) -> None:
    result = new_behavior(
        "my_adder", "async", workspace=Workspace.discover(workspace_with_config), config="my_config"
    )
    config_file = workspace_with_config / "src" / "my_config" / "config" / "config.yaml"
    assert result.config_file == config_file
    text = config_file.read_text()
    for comment in ("# my_config: the robot config", "# Our own objectives.", "# More behaviors go here."):
        assert comment in text
    # Long lines stay as written (ruamel's default folds at 80 columns, leaving a trailing space).
    joints = "shoulder_pan_joint, shoulder_lift_joint, elbow_joint, wrist_1_joint, wrist_2_joint"
    assert f"\nrobot_notes: [{joints}]\n" in text
    assert not any(line != line.rstrip() for line in text.splitlines())
    resolved = resolve_config("my_config", Workspace.discover(workspace_with_config))
    assert resolved.behavior_loader_plugins["my_adder"] == ["my_adder::MyAdderBehaviorsLoader"]
    # Unioned with the parents' loaders: example_config's tutorial behaviors stay active.
    assert "kinema::ExampleBehaviorsLoader" in resolved.behavior_loader_plugins["examples"]
    host = BehaviorHost.for_config(resolved)
    report = host.load()
    assert report.ok, report.errors
    assert {"MyAdder", "MyBehavior", "MyServiceClient"} <= set(host.registry)
    assert "my_adder_objectives" in [library.key for library in resolved.objective_library_paths]


def test_a_bundled_config_is_never_edited(workspace: Path) -> None:
    example = bundled_dir("configs") / "example_config" / "config" / "config.yaml"
    before = example.read_text()
    found = Workspace.discover(workspace)
    result = new_behavior("my_adder", "async", workspace=found, config="example_config")
    assert result.config_file is None
    assert example.read_text() == before


def test_the_template_refuses_bad_input_when_cookiecutter_runs_it_directly(tmp_path: Path) -> None:
    from cookiecutter.exceptions import FailedHookException
    from cookiecutter.main import cookiecutter

    template = bundled_dir("cookiecutters") / "behavior_package"
    with pytest.raises(FailedHookException):
        cookiecutter(
            str(template),
            no_input=True,
            output_dir=str(tmp_path),
            extra_context={"behavior_name": "Not-Valid"},
            default_config=True,
        )
    assert list(tmp_path.iterdir()) == []


def test_an_id_the_config_already_loads_is_refused(workspace: Path) -> None:
    found = Workspace.discover(workspace)
    # example_config loads the tutorial's bundled MyBehavior.
    with pytest.raises(ScaffoldError, match=r"'MyBehavior' is already registered by plugin 'kinema::Example"):
        new_behavior("my_behavior", "async", workspace=found, config="example_config")
    assert list((workspace / "src").iterdir()) == []


@pytest.mark.parametrize(
    "text",
    [
        "based_on_package: lab_sim\n",
        "based_on_package: lab_sim\nobjectives:\n",
        "based_on_package: lab_sim\nobjectives:\n  behavior_loader_plugins:\n"
        '    core: ["kinema::CoreBehaviorsLoader"]\n',
    ],
    ids=["no-objectives", "empty-objectives", "flow-list"],
)
def test_add_to_config_handles_sparse_and_flow_style_files(tmp_path: Path, text: str) -> None:
    import yaml

    from kinema.scaffold.behavior_package import add_to_config

    config = tmp_path / "config.yaml"
    config.write_text(text)
    changes = add_to_config(config, "my_pkg", "my_pkg::MyPkgBehaviorsLoader")
    assert len(changes) == 2
    data = yaml.safe_load(config.read_text())
    assert data["objectives"]["behavior_loader_plugins"]["my_pkg"] == ["my_pkg::MyPkgBehaviorsLoader"]
    assert data["objectives"]["objective_library_paths"]["my_pkg_objectives"] == {
        "package_name": "my_pkg",
        "relative_path": "objectives",
    }
    assert add_to_config(config, "my_pkg", "my_pkg::MyPkgBehaviorsLoader") == []


def test_every_place_that_lists_the_behavior_types_lists_the_same_ones() -> None:
    # The CLI's choices, the template's cookiecutter.json and its hook must offer what the scaffold bakes.
    import json
    import re

    from kinema.cli.new import new

    command = new.commands["behavior"]
    option = next(p for p in command.params if p.name == "behavior_type")
    template = Path(__file__).resolve().parents[2] / "cookiecutters" / "behavior_package"
    offered = json.loads((template / "cookiecutter.json").read_text())["behavior_type"]
    hook = (template / "hooks" / "pre_gen_project.py").read_text()
    hooked = re.findall(r'"(\w+)"', hook.split("TYPES = (", 1)[1].split(")", 1)[0])
    for listed in (list(option.type.choices), offered, hooked):  # type: ignore[attr-defined]
        assert sorted(listed) == sorted(BEHAVIOR_TYPES)
    for behavior_type in BEHAVIOR_TYPES:
        assert (template / "templates" / behavior_type / "behavior.py.jinja").is_file(), behavior_type
