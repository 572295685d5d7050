"""A failed hot reload keeps the last good version; a run that uses it says so, with the file's error."""

from __future__ import annotations

import re
import time
from pathlib import Path

from kinema.bt import WallClock
from kinema.plugins import BehaviorHost
from kinema.runtime.objective_server import ObjectiveRequest, ObjectiveRun, ObjectiveServer
from kinema.runtime.objective_source import LibraryTreeSource, library_from_folders

RAISES = '''
from kinema.behaviors import NodeStatus, SyncBehavior


class Answer(SyncBehavior):
    """Fails loudly."""

    @classmethod
    def provided_ports(cls):
        return []

    def tick(self):
        raise ValueError("old code ran")
'''

OBJECTIVES = """<root BTCPP_format="4">
  <BehaviorTree ID="Uses Answer"><Answer/></BehaviorTree>
  <BehaviorTree ID="Plain"><AlwaysSuccess/></BehaviorTree>
</root>
"""


class _Notes:
    def __init__(self) -> None:
        self.notes: list[tuple[str, str]] = []

    def on_stale_code(self, run: ObjectiveRun, note: str) -> None:
        self.notes.append((run.objective_name, note))

    def on_status(self, *args: object) -> None: ...

    def on_node_status(self, *args: object) -> None: ...

    def on_blackboard(self, *args: object) -> None: ...

    def on_run_finished(self, *args: object) -> None: ...


def test_a_run_on_code_whose_reload_failed_names_the_file_the_error_and_the_version_that_runs(
    workspace: Path, make_package, tmp_path: Path
) -> None:
    package = make_package("answers", classes={"Answer": 0}, behaviors=RAISES)
    host = BehaviorHost(["answers::TestLoader"], workspace)
    assert host.load().ok
    loaded = time.strftime("%H:%M", time.localtime(host.registry.plugins["answers::TestLoader"].loaded_at))
    objectives = tmp_path / "objectives"
    objectives.mkdir()
    (objectives / "o.xml").write_text(OBJECTIVES)
    source = LibraryTreeSource(
        lambda: library_from_folders([objectives]), host=host, context=None, clock=WallClock()
    )
    module = package / "answers" / "behaviors.py"
    module.write_text(module.read_text().replace("def tick(self):", "def tick(self:"))
    (event,) = host.reload_package(package)
    assert not event.ok
    line = module.read_text().splitlines().index("    def tick(self:") + 1

    notes = _Notes()
    with ObjectiveServer(source, listeners=[notes]) as server:
        failed = server.submit(ObjectiveRequest("Uses Answer")).wait(5)
        plain = server.submit(ObjectiveRequest("Plain")).wait(5)
    assert failed is not None and failed.failed
    # The exception of the old code, then the note that the file on disk did not load.
    message = failed.error_message
    assert "ValueError: old code ran" in message
    assert f"{module}:{line}" in message and "SyntaxError" in message
    assert re.search(rf"Answer runs the version from {loaded} instead", message)
    assert message.index("ValueError") < message.index("note:")
    assert [name for name, _ in notes.notes] == ["Uses Answer"]  # said as the run starts, also on success
    assert plain is not None and plain.succeeded
