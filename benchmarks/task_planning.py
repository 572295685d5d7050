"""Task planning speed on lab_sim: MoveIt Pro's pick and place tasks vs the same motions planned one by one.

The tasks are the planning halves of lab_sim's "Pick from Pose" and "Place at Pose" (current state,
connect, a 10 cm approach along the grasp axis, batch pose IK over the candidate poses), planned with
:func:`kinema.motion.task.plan_task`. The peer, in the same run, plans the same motions as separate calls
the way an objective without MTC would (PlanToJointGoal / PlanCartesianPath): IK for the grasp, IK for the
pre-grasp 10 cm back, ``plan_joint_goal`` to the pre-grasp, ``plan_cartesian_path`` down to the grasp,
toppra on both.

A second pair measures a search around an obstacle (a block where the straight move from "3 Waypoint Mid
Point" to "3 Waypoint Pick Pose" takes the gripper): the seeded RRT-Connect the task stages use against
OMPL's RRTConnect, which plans without a seed.

Prints p50/p95 planning time of each and their ratio. Target (issue 13): a pick task under 300 ms p50 on
2 cores. No assertions: numbers only. Run: ``python benchmarks/task_planning.py [--repeats N]``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np
import yaml

from kinema.motion import (
    CollisionChecker,
    IkOptions,
    PlanningOptions,
    RobotDescription,
    fk,
    ik,
    plan_cartesian_path,
    plan_joint_goal,
    time_parameterize,
)
from kinema.motion.planning_scene import PlanningScene
from kinema.motion.task import Task, plan_task
from kinema.motion.task_stages import BatchPoseIK, Connect, CurrentState, MotionSettings, MoveAlongFrameAxis
from kinema.motion.trajectory import JointPath
from kinema.resources import bundled_dir

CUBE = np.array([-0.3, 0.62, 0.499])
GRASP_ABOVE_CENTRE = 0.02
APPROACH = 0.1


def _percentiles(samples: list[float]) -> tuple[float, float]:
    ordered = sorted(samples)
    p95 = ordered[min(len(ordered) - 1, round(0.95 * (len(ordered) - 1)))]
    return statistics.median(ordered), p95


def _time(fn: Callable[[], object], repeats: int) -> list[float]:
    fn()  # warm up (imports, caches)
    out = []
    for _ in range(repeats):
        began = time.perf_counter()
        fn()
        out.append(time.perf_counter() - began)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--smoke", action="store_true", help="two repeats of each (the test suite)")
    args = parser.parse_args()
    if args.smoke:
        args.repeats = 2

    description = RobotDescription.lab_sim()
    model = description.load_model()
    checker = CollisionChecker(model, description.load_scene(model), padding=0.0)
    waypoints = {
        e["name"]: dict(zip(e["joint_state"]["name"], e["joint_state"]["position"], strict=True))
        for e in yaml.safe_load(
            (bundled_dir("configs") / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml").read_text()
        )
    }
    start = model.configuration(waypoints["Look at Table"])
    down = fk(model, model.configuration(waypoints["3 Waypoint Pick Pose"]), "grasp_link")[:3, :3]

    def pose(position: np.ndarray) -> np.ndarray:
        out = np.eye(4)
        out[:3, :3] = down
        out[:3, 3] = position
        return out

    grasp = pose(CUBE + np.array([0.0, 0.0, GRASP_ABOVE_CENTRE]))
    place = pose(CUBE + np.array([0.15, 0.05, GRASP_ABOVE_CENTRE]))
    # "Pick from Pose Vector" hands batch IK yaw-equivalent candidates; two unreachable ones make it work.
    far = pose(np.array([3.0, 3.0, 0.8]))

    def task(name: str, targets: list[np.ndarray]) -> Task:
        return Task(
            name,
            [
                CurrentState(start),
                Connect(MotionSettings(link_padding=0.0, group="manipulator")),
                MoveAlongFrameAxis(
                    (0, 0, 1),
                    "grasp_link",
                    "grasp_link",
                    APPROACH,
                    APPROACH,
                    motion=MotionSettings(group="manipulator", link_padding=0.0),
                ),
                BatchPoseIK([("world", t) for t in targets], "grasp_link", group="manipulator"),
            ],
        )

    def separately(target: np.ndarray) -> None:
        q_grasp = ik(model, target, start, "manipulator", "grasp_link", options=IkOptions(attempts=20))
        pre = target.copy()
        pre[:3, 3] -= APPROACH * target[:3, 2]
        q_pre = ik(model, pre, q_grasp, "manipulator", "grasp_link", options=IkOptions(attempts=20))
        to_pre = plan_joint_goal(checker, start, q_pre, "manipulator")
        down_path = plan_cartesian_path(checker, q_pre, [target], "manipulator", "grasp_link")
        time_parameterize(to_pre, model)
        time_parameterize(JointPath(down_path.path.joint_names, down_path.path.positions), model)

    rows = [
        ("pick task (plan_task)", lambda: plan_task(task("pick", [grasp]), checker)),
        ("pick, separate calls", lambda: separately(grasp)),
        ("place task (plan_task)", lambda: plan_task(task("place", [place]), checker)),
        ("place, separate calls", lambda: separately(place)),
        ("pick task, 3 candidates", lambda: plan_task(task("pick", [far, far, grasp]), checker)),
    ]
    blocked = CollisionChecker(model, PlanningScene(dict(checker.scene.objects)), padding=0.01)
    mid = model.configuration(waypoints["3 Waypoint Mid Point"])
    pick = model.configuration(waypoints["3 Waypoint Pick Pose"])
    block = np.eye(4)
    block[:3, 3] = (fk(model, mid, "grasp_link")[:3, 3] + fk(model, pick, "grasp_link")[:3, 3]) / 2
    blocked.scene.add_box("block", (0.03, 0.03, 0.03), block)
    seeds = iter(range(10**6))  # a new seed each time: the spread of searches, not one search repeated
    rows += [
        (
            "around a block, seeded",
            lambda: plan_joint_goal(
                blocked,
                mid,
                pick,
                options=PlanningOptions(timeout=5.0, seed=next(seeds)),
                group="manipulator",
            ),
        ),
        (
            "around a block, OMPL",
            lambda: plan_joint_goal(
                blocked, mid, pick, options=PlanningOptions(timeout=5.0), group="manipulator"
            ),
        ),
    ]
    results = {}
    print(f"task planning on lab_sim, {args.repeats} repeats each (seconds)")
    for label, fn in rows:
        p50, p95 = _percentiles(_time(fn, args.repeats))
        results[label] = p50
        print(f"  {label:26s} p50 {p50 * 1000:7.1f} ms   p95 {p95 * 1000:7.1f} ms")
    for kind in ("pick", "place"):
        task_p50 = results[f"{kind} task (plan_task)"]
        peer = results[f"{kind}, separate calls"]
        print(f"  {kind}: task / separate calls = {task_p50 / peer:.2f}")
    ratio = results["around a block, seeded"] / results["around a block, OMPL"]
    print(f"  around a block: seeded RRT-Connect / OMPL RRTConnect = {ratio:.2f}")
    met = "met" if results["pick task (plan_task)"] < 0.3 else "NOT met"
    print(f"  target: pick task p50 < 300 ms -> {met}")


if __name__ == "__main__":
    main()
