"""Time to resolve a config package and its objective library, against the bare parsing it needs.

A workspace is generated in a temporary folder: a 5-level ``based_on_package`` chain (each level with
a MoveIt Pro-sized config.yaml, its own objective library and a few overrides) and 500 objectives,
100 per level, shaped like lab_sim's (multi-line attributes, subtrees, a TreeNodesModel with ports and
metadata; some IDs repeat across levels so shadowing is exercised).

Measured, each as the median of several cold runs in this one process:

* Kinema: ``Workspace.discover`` + ``resolve_config`` (schema, merge with provenance, file checks) +
  ``ObjectiveLibrary.load`` (every objective with its metadata and ports);
* peer: the least any loader has to do, ``yaml.safe_load`` (libyaml) of the five config files plus
  ``lxml.etree.parse`` of the 500 objective files, nothing else.

It prints both times and the ratio. Target (issue 3): Kinema under 300 ms.
Run: ``python benchmarks/config_resolve.py [--repeat N]``.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import yaml
from lxml import etree

from kinema.config import ObjectiveLibrary, Workspace, resolve_config

LEVELS = 5
OBJECTIVES_PER_LEVEL = 100

OBJECTIVE = """<?xml version="1.0" encoding="UTF-8" ?>
<root BTCPP_format="4" main_tree_to_execute="{id}">
  <!--//////////-->
  <BehaviorTree
    ID="{id}"
    _description="Objective {n} of {package}: move to a waypoint, operate the gripper and come back.
Generated for the config resolution benchmark."
    _favorite="{favorite}"
  >
    <Control ID="Sequence" name="TopLevelSequence">
      <SubTree ID="Move to Waypoint" waypoint_name="Pick {n}" joint_group_name="manipulator" />
      <Action
        ID="MoveGripperAction"
        gripper_command_action_name="/robotiq_gripper_controller/gripper_cmd"
        position="0.7929"
        timeout="10.000000"
      />
      <Decorator ID="RetryUntilSuccessful" num_attempts="3">
        <Control ID="Fallback">
          <Action ID="Script" code="attempts += 1; done := attempts &gt;= 2" />
          <SubTree ID="Move to Waypoint" waypoint_name="Place {n}" joint_group_name="manipulator" />
        </Control>
      </Decorator>
      <Action ID="LogMessage" message="finished {id}" log_level="info" />
    </Control>
  </BehaviorTree>
  <TreeNodesModel>
    <SubTree ID="{id}">
      <input_port name="speed" default="1.0">velocity scale</input_port>
      <inout_port name="target" default="{{target}}" />
      <output_port name="result" />
      <MetadataFields>
        <Metadata subcategory="Application - Basic Examples" />
        <Metadata runnable="{runnable}" />
      </MetadataFields>
    </SubTree>
  </TreeNodesModel>
</root>
"""


def _config(level: int) -> str:
    name = f"level{level}"
    lines = [f"# level {level} of the benchmark chain"]
    if level > 0:
        lines.append(f'based_on_package: "level{level - 1}"')
    lines += [
        "hardware:",
        "  launch_control_node: True",
        "  robot_description:",
        f'    urdf: {{package: "{name}", path: "description/robot.urdf"}}',
        f'    srdf: {{package: "{name}", path: "description/robot.srdf"}}',
        "    urdf_params:",
        f'      - name: "robot{level}"',
        '      - use_fake_hardware: "true"',
        "moveit_params:",
        f'  joint_group_name: "group{level}"',
        f'  joint_limits: {{package: "{name}", path: "description/joint_limits.yaml"}}',
        "  publish: {planning_scene: True, state_updates: True}",
        "  trajectory_execution: {manage_controllers: True, allowed_start_tolerance: 0.01}",
        "ros2_control:",
        "  controllers_active_at_startup:",
        *(f'    - "controller_{level}_{k}"' for k in range(5)),
        "objectives:",
        "  behavior_loader_plugins:",
        f'    level{level}: ["kinema::Level{level}BehaviorsLoader"]',
        '    core: ["kinema::CoreBehaviorsLoader"]',
        "  objective_library_paths:",
        f'    {name}_objectives: {{package_name: "{name}", relative_path: "objectives"}}',
        f'  waypoints_file: {{package_name: "{name}", relative_path: "waypoints/waypoints.yaml"}}',
    ]
    return "\n".join(lines) + "\n"


def build_workspace(root: Path) -> list[Path]:
    """Write the chain under ``root/src``; return the files the peer parses."""
    files: list[Path] = []
    for level in range(LEVELS):
        package = root / "src" / f"level{level}"
        for sub in ("config", "description", "objectives", "waypoints"):
            (package / sub).mkdir(parents=True)
        for file in ("robot.urdf", "robot.srdf", "joint_limits.yaml"):
            (package / "description" / file).write_text("x\n")
        (package / "waypoints" / "waypoints.yaml").write_text("[]\n")
        config = package / "config" / "config.yaml"
        config.write_text(_config(level))
        files.append(config)
        for n in range(OBJECTIVES_PER_LEVEL):
            # every tenth ID repeats on each level, so deeper levels shadow shallower ones
            objective_id = f"Shared {n}" if n % 10 == 0 else f"Objective {level}-{n}"
            path = package / "objectives" / f"objective_{n:03d}.xml"
            path.write_text(
                OBJECTIVE.format(
                    id=objective_id,
                    n=n,
                    package=package.name,
                    favorite="true" if n % 25 == 0 else "false",
                    runnable="false" if n % 7 == 0 else "true",
                )
            )
            files.append(path)
    return files


def kinema_resolve(root: Path) -> int:
    resolved = resolve_config(f"level{LEVELS - 1}", Workspace.discover(root))
    library = ObjectiveLibrary.load(resolved)
    assert not library.errors, library.errors[:3]
    return len(library.objectives)


def peer_parse(files: list[Path]) -> int:
    count = 0
    for path in files:
        if path.suffix == ".yaml":
            yaml.load(path.read_text(), Loader=yaml.CSafeLoader)
        else:
            etree.parse(str(path))
            count += 1
    return count


def _median_ms(function, repeat: int) -> float:  # type: ignore[no-untyped-def]
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append((time.perf_counter() - start) * 1000)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7, help="runs per measurement (median is printed)")
    parser.add_argument("--smoke", action="store_true", help="one run of each measurement (the test suite)")
    args = parser.parse_args()
    if args.smoke:
        args.repeat = 1
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        files = build_workspace(root)
        objectives = kinema_resolve(root)
        expected = LEVELS * OBJECTIVES_PER_LEVEL - (LEVELS - 1) * (OBJECTIVES_PER_LEVEL // 10)
        assert objectives == expected, (objectives, expected)
        kinema_ms = _median_ms(lambda: kinema_resolve(root), args.repeat)
        peer_ms = _median_ms(lambda: peer_parse(files), args.repeat)
    files_count = LEVELS * OBJECTIVES_PER_LEVEL
    print(f"chain of {LEVELS} config packages, {files_count} objective files ({objectives} IDs)")
    print(f"kinema resolve_config + ObjectiveLibrary.load: {kinema_ms:7.1f} ms  (target < 300 ms)")
    print(f"peer yaml.safe_load + lxml.etree.parse only:   {peer_ms:7.1f} ms")
    print(f"ratio kinema / peer: {kinema_ms / peer_ms:.2f}x")


if __name__ == "__main__":
    main()
