"""Wall time of full "3 Waypoints Pick and Place" cycles on lab_sim at max sim speed, and their sim time.

One run starts a router, lab_sim's MuJoCo driver (``sim_speed=max``) and the agent in this process, warms
the planner up, then measures:

* **objective**: the objective "3 Waypoints Pick and Place" started through the SDK; a cycle is one pass
  of its ``KeepRunningUntilFailure`` body (cube table -> tray -> table, 12 moves and 4 gripper actions),
  timed from the node status stream. The cube's position is checked after each cycle.
* **peer (plain script)**: the same 12 moves and 4 gripper actions, planned with ``kinema.motion`` and sent
  straight to the driver's FollowJointTrajectory / GripperCommand actions from a Python loop, with no
  objective server, behavior tree or blackboard in between.

It prints wall seconds per cycle, the sim seconds each represents (so the real-time factor), and the
ratio objective / peer: what the runtime adds on top of planning and simulating. Numbers only, no
assertions. The objective and the script alternate over ``--rounds`` rounds (each from the start keyframe)
so that the load of a shared machine weighs on both; the figures are medians over every cycle, and the
ratio is also given per round. Run:
``python benchmarks/pick_and_place.py [--cycles N] [--rounds R] [--library kinema|moveit_pro] [--smoke]``
(``moveit_pro`` runs a copy of ``../shared/compat/moveit_pro/objectives`` when that folder exists).

:func:`measure_objective_cycles` is reusable (``benchmarks/motion.py`` may call it).
"""

from __future__ import annotations

import argparse
import math
import shutil
import statistics
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from kinema.resources import bundled_dir

OBJECTIVE = "3 Waypoints Pick and Place"
PICK = "3 Waypoint Pick Pose"
PLACE = "3 Waypoint Place Pose"
MID = "3 Waypoint Mid Point"
CLOSED, OPEN = 0.7929, 0.0
CUBE_START = np.array([-0.30, 0.62, 0.499])
SHARED_OBJECTIVES = (
    Path(__file__).resolve().parents[1].parent / "shared" / "compat" / "moveit_pro" / "objectives"
)


@dataclass
class Cycle:
    """One measured cycle: wall and sim seconds, and where the cube ended up."""

    wall: float
    sim: float
    cube_error: float


def _workspace(root: Path, library: str) -> tuple[str, Path | None]:
    """The config to run: lab_sim itself, or a temporary child of it running MoveIt Pro's files."""
    if library == "kinema":
        return "lab_sim", None
    if not SHARED_OBJECTIVES.is_dir():
        raise SystemExit(f"--library moveit_pro needs {SHARED_OBJECTIVES}")
    package = root / "src" / "bench_lab_sim"
    (package / "config").mkdir(parents=True)
    shutil.copytree(SHARED_OBJECTIVES, package / "objectives")
    (package / "empty").mkdir()
    config = {
        "based_on_package": "lab_sim",
        "objectives": {
            "objective_library_paths": {
                "core_objectives": {"package_name": "bench_lab_sim", "relative_path": "objectives"},
                "lab_sim_objectives": {"package_name": "bench_lab_sim", "relative_path": "empty"},
            }
        },
    }
    (package / "config" / "config.yaml").write_text(yaml.safe_dump(config))
    return "bench_lab_sim", root


class Cell:
    """Router, driver and agent in this process, with an SDK client and a probe node."""

    def __init__(self, config: str, workspace: Path | None) -> None:
        from kinema.config import Workspace
        from kinema.drivers.mujoco import MujocoDriver, MujocoDriverSettings
        from kinema.runtime.agent_process import AgentOptions, build_agent
        from kinema.sdk import ObjectiveClient
        from kinema.transport import Node, free_endpoint, host_router, open_session

        endpoint = free_endpoint()
        self._closers: list[Any] = []
        router = host_router(endpoint)
        self._closers.append(router.close)
        driver_session = open_session(endpoint)
        self._closers.append(driver_session.close)
        ws = Workspace.discover(workspace) if workspace else None
        self.driver = MujocoDriver(
            driver_session, MujocoDriverSettings.from_config(config, ws, sim_speed=math.inf)
        )
        self.driver.start()
        self._closers.append(self.driver.stop)
        agent_session = open_session(endpoint)
        self._closers.append(agent_session.close)
        options = AgentOptions(config=config, workspace=workspace, clock="sim", hot_reload=False)
        self.agent = build_agent(options, agent_session)
        self.agent.start()
        self._closers.append(self.agent.close)
        client_session = open_session(endpoint)
        self._closers.append(client_session.close)
        self.client = ObjectiveClient(session=client_session)
        self._closers.append(self.client.close)
        self.client.wait_for_runtime()
        self.node = Node(client_session, "pick_and_place_bench")
        self._bodies = self.node.create_client("kinema_msgs/srv/GetSimBodies", "/mujoco/bodies")
        self._peer: dict[str, Any] = {}

    def cube(self) -> np.ndarray:
        for body in self._bodies.call({}, timeout=10.0).bodies:
            if body.name == "cube":
                p = body.pose.position
                return np.array([p.x, p.y, p.z])
        raise RuntimeError("no cube in the simulation")

    def peer(self) -> dict[str, Any]:
        """What the plain script plans and moves with, made once per cell (not a set of clients per round)."""
        if self._peer:
            return self._peer
        from kinema.config import WaypointStore
        from kinema.motion import CollisionChecker, RobotDescription

        description = RobotDescription.lab_sim()
        model = description.load_model()
        store = WaypointStore(bundled_dir("configs") / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml")
        arm = model.group("manipulator").joint_names
        goals = {}
        for name in (PICK, PLACE, MID):
            waypoint = store.get(name)
            positions = dict(zip(waypoint.joint_names, waypoint.positions, strict=True))
            goals[name] = {joint: positions[joint] for joint in arm}
        self._peer = {
            "checker": CollisionChecker(model, description.load_scene(model), padding=0.01),
            "model": model,
            "goals": goals,
            "follow": self.node.create_action_client(
                "control_msgs/action/FollowJointTrajectory",
                "/joint_trajectory_controller/follow_joint_trajectory",
            ),
            "gripper": self.node.create_action_client(
                "control_msgs/action/GripperCommand", "/robotiq_gripper_controller/gripper_cmd"
            ),
        }
        return self._peer

    def close(self) -> None:
        for close in reversed(self._closers):
            close()


def measure_objective_cycles(cell: Cell, cycles: int) -> list[Cycle]:
    """Run the objective until ``cycles`` passes of its loop body have finished; time each pass."""
    from kinema.sdk.client import NodeStatusSubscription

    ends: list[tuple[float, float]] = []
    loop_uid: list[int] = []
    ended = threading.Condition()

    def on_changes(message: Any) -> None:
        for change in message.changes:
            if change.node_id == "KeepRunningUntilFailure" and not loop_uid:
                loop_uid.append(int(change.uid))
            # uids number the tree depth first, so the loop's body is the node right after it.
            if loop_uid and int(change.uid) == loop_uid[0] + 1 and change.status == 2:  # SUCCESS
                with ended:
                    ends.append((time.monotonic(), cell.driver.sim_time))
                    ended.notify_all()

    # The SDK's decoder: the agent publishes status codes and a node table, not named changes.
    subscription = NodeStatusSubscription(cell.node, on_changes)
    handle = cell.client.start(OBJECTIVE)
    errors: list[float] = []
    try:
        # The first pass starts after the move to the mid point; whole passes are timed between two ends.
        for count in range(1, cycles + 2):
            with ended:
                if not ended.wait_for(lambda count=count: len(ends) >= count, 120.0):
                    raise RuntimeError(f"cycle {count} did not finish: {handle.status}")
            # The next pass first moves down to the cube, so it still rests where this pass left it.
            errors.append(float(np.linalg.norm(cell.cube() - CUBE_START)))
    finally:
        cell.client.cancel()
        handle.result(30.0)
        subscription.close()
    return [
        Cycle(b[0] - a[0], b[1] - a[1], error)
        for a, b, error in zip(ends, ends[1 : cycles + 1], errors[1:], strict=False)
    ]


def measure_script_cycles(cell: Cell, cycles: int) -> list[Cycle]:
    """The peer: the same motions, planned with kinema.motion and sent straight to the driver."""
    peer = cell.peer()
    checker, model, goals, follow, gripper = (
        peer["checker"],
        peer["model"],
        peer["goals"],
        peer["follow"],
        peer["gripper"],
    )
    # Subscribed while the script runs only: decoding every /joint_states would load the objective's rounds.
    latest: list[Any] = []
    subscription = cell.node.create_subscription("sensor_msgs/msg/JointState", "/joint_states", latest.append)
    try:
        return _script_cycles(cell, cycles, checker, model, goals, follow, gripper, latest)
    finally:
        subscription.close()


def _script_cycles(
    cell: Cell,
    cycles: int,
    checker: Any,
    model: Any,
    goals: dict[str, dict[str, float]],
    follow: Any,
    gripper: Any,
    latest: list[Any],
) -> list[Cycle]:
    from kinema.motion import plan_joint_goal, time_parameterize

    def current() -> np.ndarray:
        while not latest:
            time.sleep(0.001)
        message = latest[-1]
        index = {n: i for i, n in enumerate(message.name)}
        return np.array([message.position[index[j]] for j in model.joint_names])

    def move(name: str) -> None:
        trajectory = time_parameterize(plan_joint_goal(checker, current(), goals[name], "manipulator"), model)
        points = [
            {
                "positions": trajectory.positions[i].tolist(),
                "velocities": trajectory.velocities[i].tolist(),
                "time_from_start": {
                    "sec": int(trajectory.times[i]),
                    "nanosec": round((trajectory.times[i] % 1.0) * 1e9) % 1_000_000_000,
                },
            }
            for i in range(len(trajectory.times))
        ]
        goal = {"trajectory": {"joint_names": list(trajectory.joint_names), "points": points}}
        result = follow.send_goal(goal, timeout=10.0).result(60.0)
        if not result.succeeded:
            raise RuntimeError(f"move to {name} failed: {result.result.error_string}")
        latest.clear()

    def grip(position: float) -> None:
        result = gripper.send_goal({"command": {"position": position}}, timeout=10.0).result(30.0)
        if not result.succeeded:
            raise RuntimeError(f"gripper to {position} failed")

    move(MID)
    grip(OPEN)
    measured = []
    for _ in range(cycles):
        wall, sim = time.monotonic(), cell.driver.sim_time
        for source, target in ((PICK, PLACE), (PLACE, PICK)):
            move(source)
            grip(CLOSED)
            move(MID)
            move(target)
            grip(OPEN)
            move(MID)
        measured.append(Cycle(time.monotonic() - wall, cell.driver.sim_time - sim, 0.0))
    error = float(np.linalg.norm(cell.cube() - CUBE_START))
    return [Cycle(c.wall, c.sim, error) for c in measured]


def _report(label: str, cycles: list[Cycle]) -> float:
    wall = statistics.median(c.wall for c in cycles)
    sim = statistics.median(c.sim for c in cycles)
    print(
        f"  {label:<34} {wall:7.2f} s wall/cycle  {sim:6.1f} s sim/cycle  {sim / wall:5.1f}x real time  "
        f"cube back within {1000 * max(c.cube_error for c in cycles):.1f} mm  ({len(cycles)} cycles)"
    )
    return wall


def _reset(cell: Cell) -> None:
    """Back to the start keyframe (arm and cube)."""
    set_state = cell.node.create_client("kinema_msgs/srv/SetMujocoState", "/mujoco/set_state")
    if not set_state.call({"keyframe": "default"}, timeout=10.0).success:
        raise RuntimeError("cannot reset the simulation to keyframe 'default'")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cycles", type=int, default=3, help="cycles per variant and round (default 3)")
    parser.add_argument(
        "--rounds",
        type=int,
        default=3,
        help="rounds, each timing the objective then the script, so that a load that changes over the run "
        "weighs on both alike (default 3)",
    )
    parser.add_argument("--smoke", action="store_true", help="one cycle of each variant (the test suite)")
    parser.add_argument(
        "--library",
        choices=("kinema", "moveit_pro"),
        default="kinema",
        help="Kinema's own objectives (default) or MoveIt Pro's lab_sim files from ../shared",
    )
    args = parser.parse_args()
    if args.smoke:
        args.cycles, args.rounds = 1, 1
    with tempfile.TemporaryDirectory() as tmp:
        config, workspace = _workspace(Path(tmp), args.library)
        cell = Cell(config, workspace)
        try:
            started = time.monotonic()
            warm = cell.client.execute("Look at Table")  # loads the model, scene and planner once
            warmup = time.monotonic() - started
            print(f"lab_sim, sim speed max, {args.library} objectives; warm-up {warmup:.2f} s ({warm})")
            objective_cycles: list[Cycle] = []
            script_cycles: list[Cycle] = []
            ratios = []
            for round_ in range(args.rounds):
                if round_:
                    _reset(cell)
                objective = measure_objective_cycles(cell, args.cycles)
                _reset(cell)
                script = measure_script_cycles(cell, args.cycles)
                objective_cycles += objective
                script_cycles += script
                ratios.append(
                    statistics.median(c.wall for c in objective) / statistics.median(c.wall for c in script)
                )
            objective_wall = _report(f'objective "{OBJECTIVE}"', objective_cycles)
            script_wall = _report("peer: plain script, same motions", script_cycles)
            rounds = ", ".join(f"{r:.2f}" for r in ratios)
            print(
                f"  objective / plain script: {objective_wall / script_wall:.2f}x "
                f"(per round: {rounds}; median {statistics.median(ratios):.2f}x)"
            )
        finally:
            cell.close()


if __name__ == "__main__":
    main()
