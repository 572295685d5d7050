"""A scaffolded behavior in a workspace config runs through the runtime, and a saved edit is used by the
next run without a restart (the kinema_runtime fixture of Kinema's pytest plugin)."""

from __future__ import annotations

import time
from pathlib import Path

from kinema.config import Workspace
from kinema.scaffold.behavior_package import new_behavior

CONFIG_YAML = 'based_on_package: "example_config"\n'
SUM_CHECK = """
<root BTCPP_format="4" main_tree_to_execute="Check Sum">
  <BehaviorTree ID="Check Sum" _description="Adds 2 and 3 with MyAdder and checks the sum.">
    <Sequence>
      <Action ID="MyAdder" int_1="2" int_2="3" int_out="{sum}"/>
      <ScriptCondition code="sum == {expected}"/>
    </Sequence>
  </BehaviorTree>
</root>
"""


def _workspace(workspace: Path) -> Path:
    config = workspace / "src" / "my_config"
    (config / "config").mkdir(parents=True)
    (config / "objectives").mkdir()
    (config / "config" / "config.yaml").write_text(CONFIG_YAML)
    (config / "package.xml").write_text("<package><name>my_config</name></package>\n")
    new_behavior("my_adder", "async", workspace=Workspace.discover(workspace), config="my_config")
    return workspace


def test_a_new_behavior_runs_in_the_runtime_and_an_edit_is_used_by_the_next_run(
    workspace: Path, kinema_runtime
) -> None:
    _workspace(workspace)
    checks = workspace / "checks"
    checks.mkdir()
    (checks / "check_sum.xml").write_text(SUM_CHECK.replace("{expected}", "5"))
    runtime = kinema_runtime("my_config", workspace=workspace, objective_dirs=[checks], hot_reload=True)
    client = runtime.client
    assert client.execute("MyAdder Example").succeeded
    assert client.execute("Check Sum").succeeded

    # Expect 2 * 3 now: the objective's edit is used by the next run, which fails against the old behavior.
    (checks / "check_sum.xml").write_text(SUM_CHECK.replace("{expected}", "6"))
    time.sleep(0.03)
    assert not client.execute("Check Sum").succeeded
    # Then edit the behavior while the runtime keeps running: the very next run uses it (a user's
    # `sed -i ... && kinema objective run` got the old code), waiting for the reload of what was saved.
    # A moment passes first, as between a save and a command's request (the file system's notice of the
    # save reaches the watcher).
    module = workspace / "src" / "my_adder" / "my_adder" / "my_adder.py"
    module.write_text(module.read_text().replace("int_1 + int_2", "int_1 * int_2"))
    time.sleep(0.03)
    result = client.execute("Check Sum")
    assert result.succeeded, result.error_message


FAULTY = """
from kinema.behaviors import AsyncBehavior, NodeStatus, SyncBehavior


class Crash(SyncBehavior):
    def tick(self):
        return 1 / 0


class CrashLater(AsyncBehavior):
    async def do_work(self):
        raise RuntimeError("lost the robot")
"""
FAULT_OBJECTIVES = """
<root BTCPP_format="4">
  <BehaviorTree ID="Crash Now"><Sequence name="steps"><Crash name="culprit"/></Sequence></BehaviorTree>
  <BehaviorTree ID="Crash Later"><Sequence name="steps"><CrashLater name="culprit"/></Sequence></BehaviorTree>
</root>
"""


def test_a_faulty_behavior_fails_its_objective_with_a_named_cause_and_the_runtime_keeps_serving(
    workspace: Path, write_package, kinema_runtime
) -> None:
    from kinema.scaffold.behavior_package import add_to_config

    _workspace(workspace)
    write_package("faulty", FAULTY, ["Crash", "CrashLater"])
    config_file = workspace / "src" / "my_config" / "config" / "config.yaml"
    add_to_config(config_file, "faulty", "faulty::TestLoader", objectives=False)
    checks = workspace / "checks"
    checks.mkdir()
    (checks / "faults.xml").write_text(FAULT_OBJECTIVES)
    client = kinema_runtime("my_config", workspace=workspace, objective_dirs=[checks]).client
    for objective, behavior, cause in (
        ("Crash Now", "Crash", "ZeroDivisionError"),
        ("Crash Later", "CrashLater", "lost the robot"),
    ):
        result = client.execute(objective)
        assert result.failed
        message = result.error_message
        assert f"behavior '{behavior}' of plugin 'faulty::TestLoader'" in message, message
        assert "culprit" in message and cause in message and "behaviors.py:" in message
        assert client.execute("MyAdder Example").succeeded


def test_a_broken_save_is_a_toast_with_file_and_line_and_the_last_good_version_keeps_running(
    workspace: Path, kinema_runtime
) -> None:
    _workspace(workspace)
    client = kinema_runtime("my_config", workspace=workspace, hot_reload=True).client
    logs = client.logs(timeout=10)
    module = workspace / "src" / "my_adder" / "my_adder" / "my_adder.py"
    text = module.read_text()
    module.write_text(text.replace("async def do_work(self) -> bool:", "async def do_work(self) -> bool"))
    line = text.splitlines().index("    async def do_work(self) -> bool:") + 1
    toast = next(entry for entry in logs if "not reloaded" in entry.text)
    logs.close()
    assert toast.level == "error"
    assert f"{module}:{line}" in toast.text and "SyntaxError" in toast.text
    assert client.execute("MyAdder Example").succeeded
