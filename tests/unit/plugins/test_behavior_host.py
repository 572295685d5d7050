"""Loading plugins into a registry, faults that stay contained, and reloads that swap atomically."""

from __future__ import annotations

from pathlib import Path

from kinema.bt import NodeStatus
from kinema.plugins import BehaviorHost, PluginSource, ReloadKind

TREE = '<root BTCPP_format="4"><BehaviorTree ID="T"><{id} out="{{out}}"/></BehaviorTree></root>'


def _run(registry, behavior_id: str) -> int:
    tree = registry.create_factory().create_tree_from_text(TREE.format(id=behavior_id))
    assert tree.tick_while_running() == NodeStatus.SUCCESS
    return tree.root_blackboard.get("out")


def test_a_workspace_package_loads_by_path_and_records_where_it_came_from(
    workspace: Path, make_package
) -> None:
    make_package("answers", classes={"Answer": 42, "Other": 7})
    host = BehaviorHost(["answers::TestLoader"], workspace)
    report = host.load()
    assert report.ok, report.errors
    assert sorted(host.registry) == ["Answer", "Other"]
    record = host.registry.plugins["answers::TestLoader"]
    assert record.spec.source is PluginSource.WORKSPACE and record.behaviors == ("Answer", "Other")
    assert host.registry["Answer"].plugin == "answers::TestLoader"
    assert host.registry["Answer"].location.file.endswith("behaviors.py")
    assert _run(host.registry, "Answer") == 42


def test_two_plugins_registering_one_id_is_an_error_naming_both(workspace: Path, make_package) -> None:
    make_package("first", classes={"Answer": 1})
    make_package("second", classes={"Answer": 2, "Unique": 3})
    host = BehaviorHost(["first::TestLoader", "second::TestLoader"], workspace)
    report = host.load()
    assert len(report.errors) == 1
    message = str(report.errors[0])
    assert "'Answer'" in message and "'first::TestLoader'" in message and "'second::TestLoader'" in message
    # The first plugin stays usable; the second is rejected as a whole, never half-loaded.
    assert sorted(host.registry) == ["Answer"]
    assert _run(host.registry, "Answer") == 1
    assert host.registry.plugins["second::TestLoader"].error is not None


OLD_NAME_MODULE = """
from kinema.behaviors import FormerSpelling, NodeStatus, SyncBehavior


class Modern(SyncBehavior):
    former_spellings = {spellings}

    @classmethod
    def provided_ports(cls):
        return []

    def tick(self):
        return NodeStatus.SUCCESS
"""


def test_a_former_name_claimed_by_two_plugins_fails_the_second_naming_both(
    workspace: Path, make_package
) -> None:
    make_package(
        "second",
        classes={"Modern": 0},
        behaviors=OLD_NAME_MODULE.format(spellings='(FormerSpelling("Legacy"),)'),
    )
    make_package(
        "third",
        classes={"Modern": 0},
        behaviors=OLD_NAME_MODULE.format(spellings='(FormerSpelling("Legacy"),)').replace("Modern", "Newer"),
        init=INIT_OF_NEWER,
    )
    host = BehaviorHost(["second::TestLoader", "third::TestLoader"], workspace)
    report = host.load()
    (error,) = report.errors
    assert "'Legacy' is declared the former name of both 'Modern'" in str(error) and "'Newer'" in str(error)
    assert sorted(host.registry) == ["Modern"]


def test_former_spellings_that_are_not_former_spellings_fail_the_plugin_at_load(
    workspace: Path, make_package
) -> None:
    make_package("bad", classes={"Modern": 0}, behaviors=OLD_NAME_MODULE.format(spellings='("Legacy",)'))
    host = BehaviorHost(["bad::TestLoader"], workspace)
    (error,) = host.load().errors
    assert "former_spellings of behavior 'Modern' must be a tuple of kinema.behaviors.FormerSpelling" in str(
        error
    )


INIT_OF_NEWER = """
from kinema.plugins import hookimpl

from .behaviors import Newer


@hookimpl
def register_behaviors(register):
    register(Newer)
"""


def test_a_plugin_that_raises_at_import_fails_alone_with_its_line(workspace: Path, make_package) -> None:
    make_package("good", classes={"Good": 1})
    make_package("bad", classes={"Bad": 2}, behaviors="import math\nRATIO = 1 / 0\n")
    host = BehaviorHost(["bad::TestLoader", "good::TestLoader"], workspace)
    report = host.load()
    assert list(host.registry) == ["Good"]
    (error,) = report.errors
    assert "'bad'" in error.message and "ZeroDivisionError" in error.message
    assert error.location is not None
    assert (Path(error.location.file).name, error.location.line) == ("behaviors.py", 2)


def test_a_plugin_that_raises_while_registering_fails_alone(workspace: Path, make_package) -> None:
    init = (
        "from kinema.plugins import hookimpl\n"
        "from .behaviors import Answer\n\n"
        "@hookimpl\n"
        "def register_behaviors(register):\n"
        "    register(Answer)\n"
        "    raise RuntimeError('registration went wrong')\n"
    )
    make_package("faulty", classes={"Answer": 1}, init=init)
    make_package("good", classes={"Good": 1})
    host = BehaviorHost(["faulty::TestLoader", "good::TestLoader"], workspace)
    report = host.load()
    assert list(host.registry) == ["Good"]
    (error,) = report.errors
    assert "plugin 'faulty::TestLoader' failed in register_behaviors" in error.message
    assert "registration went wrong" in error.message
    assert error.location is not None and error.location.line == 7


def test_registering_something_that_is_not_a_behavior_names_the_plugin(workspace: Path, make_package) -> None:
    init = (
        "from kinema.plugins import hookimpl\n\n"
        "class NotABehavior:\n"
        "    pass\n\n"
        "@hookimpl\n"
        "def register_behaviors(register):\n"
        "    register(NotABehavior)\n"
    )
    make_package("confused", classes={}, init=init)
    report = BehaviorHost(["confused::TestLoader"], workspace).load()
    (error,) = report.errors
    assert "plugin 'confused::TestLoader': NotABehavior is not a behavior" in error.message
    assert error.location is not None and error.location.line == 3


def test_a_reload_swaps_the_registry_and_a_running_objective_keeps_its_classes(
    workspace: Path, make_package
) -> None:
    package = make_package("answers", classes={"Answer": 42})
    host = BehaviorHost(["answers::TestLoader"], workspace)
    host.load()
    events = []
    host.subscribe(events.append)
    before = host.registry
    running = before.create_factory().create_tree_from_text(TREE.format(id="Answer"))

    (package / "answers" / "behaviors.py").write_text(
        (package / "answers" / "behaviors.py").read_text().replace("42", "43")
    )
    (event,) = host.reload_package(package)
    assert event.kind is ReloadKind.BEHAVIORS_RELOADED and event.behaviors == ("Answer",)
    assert events == [event]
    assert _run(host.registry, "Answer") == 43
    # The tree built before the reload still runs the code it was built with.
    assert running.tick_while_running() == NodeStatus.SUCCESS
    assert running.root_blackboard.get("out") == 42
    assert _run(before, "Answer") == 42


def test_a_broken_reload_keeps_the_last_good_version_and_reports_the_line(
    workspace: Path, make_package
) -> None:
    package = make_package("answers", classes={"Answer": 42})
    host = BehaviorHost(["answers::TestLoader"], workspace)
    host.load()
    good = host.registry
    module = package / "answers" / "behaviors.py"
    module.write_text(module.read_text().replace("def tick(self):", "def tick(self:"))
    (event,) = host.reload_package(package)
    assert event.kind is ReloadKind.RELOAD_FAILED and not event.ok
    assert event.location is not None and Path(event.location.file) == module
    assert event.location.line == module.read_text().splitlines().index("    def tick(self:") + 1
    assert "keeping the last good version" in event.message
    assert host.registry["Answer"] is good["Answer"]
    assert _run(host.registry, "Answer") == 42
    assert host.registry.plugins["answers::TestLoader"].error is not None


def test_an_installed_entry_point_loads_like_any_plugin_and_a_workspace_package_overlays_it(
    workspace: Path, make_package, tmp_path: Path, monkeypatch
) -> None:
    from importlib import metadata

    from kinema.plugins import discovery

    site = tmp_path / "site"
    installed = make_package("installed_pkg", classes={"Installed": 5}).rename(site)
    monkeypatch.syspath_prepend(str(installed))
    entry = metadata.EntryPoint("installed::Loader", "installed_pkg", discovery.ENTRY_POINT_GROUP)
    monkeypatch.setattr(discovery.metadata, "entry_points", lambda group: [entry])

    host = BehaviorHost(["installed::Loader"], workspace)
    assert host.load().ok
    record = host.registry.plugins["installed::Loader"]
    assert record.spec.source is PluginSource.ENTRY_POINT and record.spec.root is None
    assert _run(host.registry, "Installed") == 5

    make_package("local_pkg", classes={"Local": 6}, loader="installed::Loader")
    host = BehaviorHost(["installed::Loader"], workspace)
    assert host.load().ok
    assert host.registry.plugins["installed::Loader"].spec.source is PluginSource.WORKSPACE
    assert list(host.registry) == ["Local"]
