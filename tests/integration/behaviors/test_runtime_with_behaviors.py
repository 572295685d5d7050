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

    # Edit the behavior and the objective while the runtime keeps running: 2 * 3 is expected now.
    module = workspace / "src" / "my_adder" / "my_adder" / "my_adder.py"
    module.write_text(module.read_text().replace("int_1 + int_2", "int_1 * int_2"))
    (checks / "check_sum.xml").write_text(SUM_CHECK.replace("{expected}", "6"))
    deadline = time.monotonic() + 10
    while not (result := client.execute("Check Sum")).succeeded and time.monotonic() < deadline:
        time.sleep(0.1)
    assert result.succeeded, result.error_message
