"""Motion and simulation speed on lab_sim: MuJoCo stepping, IK, planning and toppra, measured in one run.

Prints, for the bundled lab_sim cell:

* raw ``mj_step`` rate of the scene (the floor every driver builds on) and the real-time factor it
  implies, idle and while holding the cube;
* one collision check (coal via pinocchio, the planner's inner loop);
* IK p50/p90 for grasp poses around the work area (target < 2 ms);
* planning p50 for the pick-and-place moves mid -> pick, pick -> mid, mid -> place (target < 100 ms),
  with the default planner (straight joint-space move when free, else RRTConnect) and, as the peer,
  RRTConnect forced for the same queries;
* toppra p50 for the same paths (target < 20 ms).

No assertions: numbers only. Run: ``python benchmarks/motion.py [--repeats N]``. Further sections (the
driver's real-time factor, a full "3 Waypoints Pick and Place" cycle) are added to ``SECTIONS``.
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
    plan_joint_goal,
    time_parameterize,
)
from kinema.resources import bundled_dir

ARM = (
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
QUERIES = [
    ("3 Waypoint Mid Point", "3 Waypoint Pick Pose"),
    ("3 Waypoint Pick Pose", "3 Waypoint Mid Point"),
    ("3 Waypoint Mid Point", "3 Waypoint Place Pose"),
]


def _p(values: list[float], q: float) -> float:
    return float(np.percentile(values, q))


def _row(label: str, value: str, note: str = "") -> None:
    print(f"  {label:<44} {value:>18}  {note}")


def _waypoints() -> dict[str, dict[str, float]]:
    path = bundled_dir("configs") / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml"
    return {
        e["name"]: dict(zip(e["joint_state"]["name"], e["joint_state"]["position"], strict=True))
        for e in yaml.safe_load(path.read_text())
    }


def bench_mj_step(repeats: int) -> None:
    """Raw mj_step rate: idle at the default keyframe, and holding the cube at the mid point."""
    import mujoco

    desc = RobotDescription.lab_sim()
    m = mujoco.MjModel.from_xml_path(str(desc.mjcf))
    d = mujoco.MjData(m)
    print("MuJoCo scene (raw mj_step, Python loop)")
    for label, prepare in (("idle at keyframe 'default'", None), ("holding the cube", "grasp")):
        mujoco.mj_resetDataKeyframe(m, d, m.key("default").id)
        if prepare == "grasp":
            wp = _waypoints()["3 Waypoint Pick Pose"]
            for j in ARM:
                d.ctrl[m.actuator(j).id] = wp[j]
                d.joint(j).qpos[0] = wp[j]
            d.ctrl[m.actuator("robotiq_85_left_knuckle_joint").id] = 0.7929
            for _ in range(400):
                mujoco.mj_step(m, d)
        steps = 5000
        rates = []
        for _ in range(max(3, repeats // 10)):
            t0 = time.perf_counter()
            for _ in range(steps):
                mujoco.mj_step(m, d)
            rates.append(steps / (time.perf_counter() - t0))
        rate = statistics.median(rates)
        _row(
            label, f"{rate:,.0f} steps/s", f"= {rate * m.opt.timestep:.0f}x real time (dt {m.opt.timestep} s)"
        )


def _setup():  # -> (model, checker, configurations by waypoint name)
    desc = RobotDescription.lab_sim()
    model = desc.load_model()
    checker = CollisionChecker(model, desc.load_scene(model), padding=0.01)
    qs = {name: model.configuration(values) for name, values in _waypoints().items()}
    return model, checker, qs


def bench_collision(repeats: int) -> None:
    """Cost of one collision check at a valid configuration and at random ones."""
    model, checker, qs = _setup()
    rng = np.random.default_rng(0)
    random_qs = rng.uniform(model.lower, model.upper, (2000, len(model.joint_names)))
    q = qs["3 Waypoint Pick Pose"]
    n = 2000
    t0 = time.perf_counter()
    for _ in range(n):
        checker.in_collision(q)
    valid = (time.perf_counter() - t0) / n
    t0 = time.perf_counter()
    for x in random_qs:
        checker.in_collision(x)
    rand = (time.perf_counter() - t0) / len(random_qs)
    print(f"Collision checking ({checker.pair_count} geometry pairs, padding 0.01 m)")
    _row("valid configuration (all pairs tested)", f"{valid * 1e6:.1f} us")
    _row("random configurations (stops at first hit)", f"{rand * 1e6:.1f} us")


def bench_ik(repeats: int) -> None:
    """IK for grasp poses around the pick, place and mid points, seeded at the mid point."""
    model, _, qs = _setup()
    rng = np.random.default_rng(1)
    arm = list(model.group("manipulator").indices)
    seed = qs["3 Waypoint Mid Point"]
    targets = []
    for name in ("3 Waypoint Pick Pose", "3 Waypoint Place Pose", "3 Waypoint Mid Point"):
        for _ in range(max(10, repeats // 3)):
            q = qs[name].copy()
            q[arm] += rng.uniform(-0.3, 0.3, len(arm))
            targets.append(fk(model, np.clip(q, model.lower, model.upper), "grasp_link"))
    times, failures = [], 0
    opts = IkOptions()
    for T in targets:
        t0 = time.perf_counter()
        try:
            ik(model, T, seed, options=opts, group="manipulator")
        except Exception:
            failures += 1
        times.append(time.perf_counter() - t0)
    print(f"Inverse kinematics ({len(targets)} grasp-area targets, seeded at the mid point)")
    p50 = _p(times, 50) * 1e3
    _row("p50", f"{p50:.3f} ms", f"target < 2 ms ({2 / p50:.1f}x headroom)")
    _row("p90", f"{_p(times, 90) * 1e3:.3f} ms", f"{failures} failed")


def _time(fn: Callable[[], object], repeats: int) -> tuple[list[float], object]:
    out, result = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = fn()
        out.append(time.perf_counter() - t0)
    return out, result


def bench_planning_and_timing(repeats: int) -> None:
    """Planning and toppra for the pick-and-place moves; RRTConnect forced as the peer."""
    model, checker, qs = _setup()
    arm = model.group("manipulator").joint_names
    forced = PlanningOptions(try_direct=False)
    time_parameterize(  # warm-up: toppra and scipy import on first use
        plan_joint_goal(
            checker,
            qs["Home"],
            {j: qs["3 Waypoint Mid Point"][model.index(j)] for j in arm},
            group="manipulator",
        ),
        model,
    )
    print("Planning, manipulator group, padding 0.01 m (p50 over repeats)")
    paths = []
    for start, goal in QUERIES:
        goal_map = {j: float(qs[goal][model.index(j)]) for j in arm}
        default_t, path = _time(
            lambda s=start, g=goal_map: plan_joint_goal(checker, qs[s], g, group="manipulator"), repeats
        )
        ompl_t, _ = _time(
            lambda s=start, g=goal_map: plan_joint_goal(
                checker, qs[s], g, options=forced, group="manipulator"
            ),
            repeats,
        )
        paths.append((f"{start} -> {goal}", path))
        p50, peer = _p(default_t, 50) * 1e3, _p(ompl_t, 50) * 1e3
        _row(
            f"{start.replace('3 Waypoint ', '')} -> {goal.replace('3 Waypoint ', '')}",
            f"{p50:.2f} ms",
            f"RRTConnect forced: {peer:.1f} ms ({peer / p50:.1f}x); target < 100 ms",
        )
    print("Time parameterization (toppra, velocity and acceleration limits, p50)")
    for label, path in paths:
        tt, traj = _time(lambda p=path: time_parameterize(p, model), repeats)
        _row(
            label.replace("3 Waypoint ", ""),
            f"{_p(tt, 50) * 1e3:.2f} ms",
            f"{traj.duration:.2f} s motion, {len(traj.times)} points; target < 20 ms",
        )


SECTIONS: list[Callable[[int], None]] = [bench_mj_step, bench_collision, bench_ik, bench_planning_and_timing]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=30, help="repetitions per measurement (default 30)")
    parser.add_argument(
        "--smoke", action="store_true", help="two repetitions of each measurement (the test suite)"
    )
    args = parser.parse_args()
    if args.smoke:
        args.repeats = 2
    for section in SECTIONS:
        section(args.repeats)


if __name__ == "__main__":
    main()
