"""Behaviors MoveIt Pro's example workspace uses, batch A: what an objective sees, and how bad input fails.

ReversePoseStampedVector, IsPoseNearIdentity, StopwatchBegin/End, UnpackJointStateMessage,
SaveCurrentState, BiasedCoinFlip, RepeatUnlessFailureEachTick and RepeatUnlessFailureWithinTick.
"""

from __future__ import annotations

import math
import random
from typing import Any

import pytest

from kinema.behaviors import (
    BehaviorContext,
    NodeStatus,
    PortInfo,
    StatefulBehavior,
    SyncBehavior,
    message_type,
    output_port,
)
from kinema.bt import ManualClock
from kinema.testing import build_tree, publish_repeatedly, run_objective, tick_behavior

PoseStamped = message_type("geometry_msgs/msg/PoseStamped")
JointState = message_type("sensor_msgs/msg/JointState")
ARM = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint"]


def _xml(body: str) -> str:
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main"><Sequence>'
        f"{body}</Sequence></BehaviorTree></root>"
    )


def _pose(x: float = 0.0, y: float = 0.0, z: float = 0.0, q: tuple[float, ...] = (0, 0, 0, 1)) -> Any:
    qx, qy, qz, qw = (float(v) for v in q)
    return PoseStamped(
        header={"frame_id": "world"},
        pose={"position": {"x": x, "y": y, "z": z}, "orientation": {"x": qx, "y": qy, "z": qz, "w": qw}},
    )


def _about_z(angle: float) -> tuple[float, ...]:
    return (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2))


# -- every new ID with exactly the ports MoveIt Pro's example objectives set ------------------------------

EXAMPLE_PORTS = """
<Action ID="CreatePoseStamped" position_xyz="1;0;0" pose_stamped="{a}"/>
<Action ID="CreatePoseStamped" position_xyz="2;0;0" pose_stamped="{b}"/>
<Action ID="ResetPoseStampedVector" vector="{contour_1}"/>
<Action ID="AddPoseStampedToVector" input="{a}" vector="{contour_1}"/>
<Action ID="AddPoseStampedToVector" input="{b}" vector="{contour_1}"/>
<Action ID="ReversePoseStampedVector" input_vector="{contour_1}" output_vector="{contour_1}"/>
<Action ID="CreatePoseStamped" position_xyz="0.01;0;0" pose_stamped="{error_pose}"/>
<Action ID="IsPoseNearIdentity" pose="{error_pose}" position_tolerance="0.03" rotation_tolerance="0.2"/>
<Fallback>
  <Action ID="BiasedCoinFlip" success_probability="0.500000"/>
  <AlwaysSuccess/>
</Fallback>
<Action ID="StopwatchBegin" timepoint="{timepoint_right}"/>
<Action ID="SaveCurrentState" saved_robot_state="{initial_robot_state}"/>
<Action ID="GetJointState" joint_state="{start_joint_state}"/>
<Action ID="UnpackJointStateMessage" joint_state="{start_joint_state}" effort="{start_effort}"
        header="{start_header}" name_="{joint_names}" position="{start_position}"
        velocity="{start_velocity}"/>
<Script code="tries := 0; picks := 0"/>
<Decorator ID="Inverter">
  <Decorator ID="RepeatUnlessFailureEachTick" num_cycles="5">
    <Decorator ID="Inverter"><Script code="tries += 1"/></Decorator>
  </Decorator>
</Decorator>
<Decorator ID="RepeatUnlessFailureWithinTick" num_cycles="7"><Script code="picks += 1"/></Decorator>
<Action ID="StopwatchEnd" timepoint="{timepoint_right}"/>
"""


def test_an_objective_using_every_new_id_with_the_example_ports_runs(
    registry: Any, context: BehaviorContext
) -> None:
    state = {"name": ARM, "position": [0.1, 0.2, 0.3], "velocity": [0.0, 0.5, 0.0]}
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        run = run_objective(_xml(EXAMPLE_PORTS), registry=registry, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    board = run.blackboard
    assert [p.pose.position.x for p in board["contour_1"]] == [2.0, 1.0]
    assert list(board["initial_robot_state"].joint_state.name) == ARM
    assert list(board["initial_robot_state"].joint_state.velocity) == [0.0, 0.5, 0.0]
    assert board["joint_names"] == ARM and board["start_position"] == [0.1, 0.2, 0.3]
    # GetJointState keeps positions only, so the other lists come out empty
    assert board["start_velocity"] == [] and board["start_effort"] == []
    assert board["tries"] == 1  # the inverted loop retries only until the first success
    assert board["picks"] == 7
    assert any("s elapsed since StopwatchBegin" in toast for toast in run.toasts)


# -- ReversePoseStampedVector -------------------------------------------------------------------------


def test_reverse_pose_stamped_vector_reverses_in_place_and_into_another_entry(
    registry: Any, context: BehaviorContext
) -> None:
    body = """
    <Action ID="ResetPoseStampedVector" vector="{poses}"/>
    <Action ID="ResetPoseStampedVector" vector="{empty}"/>
    <Action ID="CreatePoseStamped" position_xyz="1;0;0" pose_stamped="{a}"/>
    <Action ID="CreatePoseStamped" position_xyz="2;0;0" pose_stamped="{b}"/>
    <Action ID="CreatePoseStamped" position_xyz="3;0;0" pose_stamped="{c}"/>
    <Action ID="AddPoseStampedToVector" input="{a}" vector="{poses}"/>
    <Action ID="AddPoseStampedToVector" input="{b}" vector="{poses}"/>
    <Action ID="AddPoseStampedToVector" input="{c}" vector="{poses}"/>
    <Action ID="ReversePoseStampedVector" input_vector="{poses}" output_vector="{reversed}"/>
    <Action ID="ReversePoseStampedVector" input_vector="{reversed}" output_vector="{reversed}"/>
    <Action ID="ReversePoseStampedVector" input_vector="{poses}" output_vector="{once}"/>
    <Action ID="ReversePoseStampedVector" input_vector="{empty}" output_vector="{empty}"/>
    """
    run = run_objective(_xml(body), registry=registry, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    xs = {key: [p.pose.position.x for p in run.blackboard[key]] for key in ("poses", "reversed", "once")}
    assert xs == {"poses": [1.0, 2.0, 3.0], "reversed": [1.0, 2.0, 3.0], "once": [3.0, 2.0, 1.0]}
    assert run.blackboard["empty"] == []


class _MixedVector(SyncBehavior):
    """A plugin of the user's writing an untyped vector holding a pose and a string."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [output_port("vector", None, "{mixed}", "A vector of anything.")]

    def tick(self) -> NodeStatus:
        self.set_output("vector", [_pose(1.0), "oops"])
        return NodeStatus.SUCCESS


def test_reverse_pose_stamped_vector_names_an_element_that_is_no_pose(
    registry: Any, context: BehaviorContext
) -> None:
    body = """
    <Action ID="_MixedVector" vector="{mixed}"/>
    <Action ID="ReversePoseStampedVector" input_vector="{mixed}" output_vector="{reversed}"/>
    """
    run = run_objective(_xml(body), registry=registry, behaviors=[_MixedVector], context=context)
    assert run.status == NodeStatus.FAILURE
    assert "ReversePoseStampedVector" in run.toasts[-1] and "port [input_vector]" in run.toasts[-1]
    assert "geometry_msgs::msg::PoseStamped" in run.toasts[-1]
    assert run.blackboard.get("reversed") is None


# -- IsPoseNearIdentity ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("pose", "status", "said"),
    [
        (_pose(), NodeStatus.SUCCESS, ()),
        (_pose(0.02, 0.01, 0.0, _about_z(0.15)), NodeStatus.SUCCESS, ()),
        (_pose(q=(0, 0, 0, -1)), NodeStatus.SUCCESS, ()),  # -q is the same rotation
        (_pose(q=(0, 0, 0, 0)), NodeStatus.SUCCESS, ()),  # an unset orientation is the identity
        (_pose(0.0, 0.04, 0.0), NodeStatus.FAILURE, ("translation 0.04 m exceeds position_tolerance",)),
        (_pose(q=_about_z(0.3)), NodeStatus.FAILURE, ("rotation 0.3 rad exceeds rotation_tolerance 0.2",)),
        (
            _pose(0.0, 0.0, -0.5, _about_z(-1.0)),
            NodeStatus.FAILURE,
            ("translation 0.5 m exceeds", "rotation 1 rad exceeds"),
        ),
    ],
)
def test_is_pose_near_identity_compares_translation_and_rotation_with_the_tolerances(
    behavior: Any, pose: Any, status: NodeStatus, said: tuple[str, ...]
) -> None:
    run = tick_behavior(
        behavior("IsPoseNearIdentity"),
        {"pose": pose, "position_tolerance": 0.03, "rotation_tolerance": 0.2},
    )
    assert run.status == status, run.toasts
    if said:
        assert all(text in run.toasts[-1] for text in said), run.toasts
    else:
        assert run.toasts == []


def test_is_pose_near_identity_refuses_a_negative_tolerance_and_a_nan_pose(behavior: Any) -> None:
    negative = tick_behavior(
        behavior("IsPoseNearIdentity"),
        {"pose": _pose(), "position_tolerance": -0.1, "rotation_tolerance": 0.2},
    )
    assert negative.status == NodeStatus.FAILURE
    assert "port [position_tolerance] = -0.1; a tolerance must be >= 0" in negative.toasts[-1]
    nan = tick_behavior(behavior("IsPoseNearIdentity"), {"pose": _pose(float("nan"))})
    assert nan.status == NodeStatus.FAILURE and "port [pose]" in nan.toasts[-1]


# -- StopwatchBegin / StopwatchEnd --------------------------------------------------------------------


class _Advance(SyncBehavior):
    """Moves the test's manual clock 2.5 s on (a stand-in for sim time passing)."""

    def tick(self) -> NodeStatus:
        self.context.clock.advance(2.5)
        return NodeStatus.SUCCESS


def test_the_stopwatch_measures_runtime_clock_time(registry: Any) -> None:
    context = BehaviorContext(clock=ManualClock(100.0))
    body = """
    <Action ID="StopwatchBegin" timepoint="{t}"/>
    <Action ID="_Advance"/>
    <Action ID="StopwatchEnd" timepoint="{t}"/>
    <Action ID="StopwatchEnd" timepoint="{t}" elapsed_duration="{elapsed}"/>
    """
    run = run_objective(_xml(body), registry=registry, behaviors=[_Advance], context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert run.blackboard["t"] == 100.0 and run.blackboard["elapsed"] == 2.5
    assert run.toasts == ["StopwatchEnd: 2.500 s elapsed since StopwatchBegin"] * 2
    assert run.messages[0].level == "info"


def test_stopwatch_end_without_a_begin_fails_saying_so(registry: Any) -> None:
    context = BehaviorContext(clock=ManualClock())
    run = run_objective(
        _xml('<Action ID="StopwatchEnd" timepoint="{never_started}"/>'), registry=registry, context=context
    )
    assert run.status == NodeStatus.FAILURE
    assert "nothing has written blackboard entry 'never_started'" in run.toasts[-1]


# -- UnpackJointStateMessage --------------------------------------------------------------------------


def test_unpack_joint_state_message_writes_each_field(behavior: Any) -> None:
    state = JointState(
        header={"frame_id": "base"}, name=ARM, position=[0.1, 0.2, 0.3], effort=[1.0, 2.0, 3.0]
    )
    run = tick_behavior(behavior("UnpackJointStateMessage"), {"joint_state": state})
    assert run.status == NodeStatus.SUCCESS
    out = run.outputs
    assert out["name_"] == ARM and out["position"] == [0.1, 0.2, 0.3]
    assert out["velocity"] == [] and out["effort"] == [1.0, 2.0, 3.0]
    assert out["header"].frame_id == "base"
    assert "name" not in out


def test_unpack_joint_state_message_refuses_another_message_when_the_tree_is_built(
    registry: Any, context: BehaviorContext
) -> None:
    from kinema.errors import KinemaError

    body = """
    <Action ID="CreatePoseStamped" pose_stamped="{p}"/>
    <Action ID="UnpackJointStateMessage" joint_state="{p}" name_="{names}"/>
    """
    with pytest.raises(KinemaError) as error:
        run_objective(_xml(body), registry=registry, context=context)
    assert "sensor_msgs::msg::JointState" in str(error.value)
    assert "geometry_msgs::msg::PoseStamped" in str(error.value)


def test_unpacked_names_and_positions_feed_create_robot_state(
    registry: Any, context: BehaviorContext
) -> None:
    # demo_trajectory_stitching.xml's chain: GetJointState -> UnpackJointStateMessage -> CreateRobotState.
    state = {"name": ARM, "position": [0.4, 0.5, 0.6]}
    body = """
    <Action ID="GetJointState" joint_state="{js}"/>
    <Action ID="UnpackJointStateMessage" joint_state="{js}" name_="{names}" position="{positions}"/>
    <Action ID="CreateRobotState" joint_names="{names}" positions="{positions}" robot_state="{rs}"/>
    """
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        run = run_objective(_xml(body), registry=registry, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert list(run.blackboard["rs"].joint_state.name) == ARM
    assert list(run.blackboard["rs"].joint_state.position) == [0.4, 0.5, 0.6]


# -- SaveCurrentState ---------------------------------------------------------------------------------


def test_save_current_state_keeps_every_joint_as_a_moveit_robot_state(
    behavior: Any, context: BehaviorContext
) -> None:
    state = {"name": [*ARM, "finger"], "position": [0.1, 0.2, 0.3, 0.04], "velocity": [0.0, 0.0, 0.1, 0.0]}
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        run = tick_behavior(behavior("SaveCurrentState"), context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    saved = run.outputs["saved_robot_state"]
    assert saved.__msgtype__ == "moveit_msgs/msg/RobotState"
    assert list(saved.joint_state.name) == [*ARM, "finger"]
    assert list(saved.joint_state.position) == [0.1, 0.2, 0.3, 0.04]
    assert list(saved.joint_state.velocity) == [0.0, 0.0, 0.1, 0.0]


def test_save_current_state_without_a_driver_fails_with_advice(
    behavior: Any, context: BehaviorContext, monkeypatch: pytest.MonkeyPatch
) -> None:
    import sys

    module = sys.modules[behavior("SaveCurrentState").__module__]
    monkeypatch.setattr(module, "TIMEOUT", 0.2)
    run = tick_behavior(behavior("SaveCurrentState"), context=context)
    assert run.status == NodeStatus.FAILURE
    assert "SaveCurrentState: no joint state received on /joint_states" in run.toasts[-1]
    assert "saved_robot_state" not in run.outputs


# -- BiasedCoinFlip -----------------------------------------------------------------------------------


def test_biased_coin_flip_follows_its_probability(behavior: Any) -> None:
    flip = behavior("BiasedCoinFlip")
    assert {tick_behavior(flip, {"success_probability": 1.0}).status for _ in range(20)} == {
        NodeStatus.SUCCESS
    }
    assert {tick_behavior(flip, {"success_probability": 0.0}).status for _ in range(20)} == {
        NodeStatus.FAILURE
    }
    random.seed(7)
    wins = [tick_behavior(flip, {"success_probability": 0.25}).status for _ in range(400)]
    assert 60 <= wins.count(NodeStatus.SUCCESS) <= 140  # 100 expected; outside is ~1e-8 likely


@pytest.mark.parametrize("value", [1.5, -0.1, float("nan")])
def test_biased_coin_flip_refuses_a_value_that_is_no_probability(behavior: Any, value: float) -> None:
    run = tick_behavior(behavior("BiasedCoinFlip"), {"success_probability": value})
    assert run.status == NodeStatus.FAILURE
    assert "port [success_probability]" in run.toasts[-1] and "give a value in [0, 1]" in run.toasts[-1]


# -- RepeatUnlessFailureEachTick / RepeatUnlessFailureWithinTick --------------------------------------


def _loop(decorator: str, cycles: int, child: str = '<Script code="n += 1"/>') -> str:
    return _xml(
        f'<Script code="n := 0"/><Decorator ID="{decorator}" num_cycles="{cycles}">{child}</Decorator>'
    )


@pytest.mark.parametrize("decorator", ["RepeatUnlessFailureEachTick", "RepeatUnlessFailureWithinTick"])
def test_the_loops_succeed_after_num_cycles_and_fail_at_the_first_failure(
    registry: Any, context: BehaviorContext, decorator: str
) -> None:
    done = run_objective(_loop(decorator, 4), registry=registry, context=context)
    assert done.status == NodeStatus.SUCCESS and done.blackboard["n"] == 4
    failing = '<Sequence><Script code="n += 1"/><ScriptCondition code="n &lt; 3"/></Sequence>'
    for cycles in (10, -1):
        failed = run_objective(_loop(decorator, cycles, failing), registry=registry, context=context)
        assert failed.status == NodeStatus.FAILURE and failed.blackboard["n"] == 3
    none = run_objective(_loop(decorator, 0), registry=registry, context=context)
    assert none.status == NodeStatus.SUCCESS and none.blackboard["n"] == 0
    bad = run_objective(_loop(decorator, -2), registry=registry, context=context)
    assert bad.status == NodeStatus.FAILURE and "port [num_cycles] = -2" in bad.toasts[-1]


def test_each_tick_runs_one_instant_iteration_per_tick_where_repeat_and_within_tick_run_all(
    registry: Any, context: BehaviorContext
) -> None:
    def first_tick(decorator: str) -> tuple[NodeStatus, int]:
        tree = build_tree(_loop(decorator, 3), registry=registry, context=context)
        status = tree.tick_once()  # re-ticks at once while a node asks for it, as the runtime does
        return status, tree.root_blackboard.get("n")

    assert first_tick("RepeatUnlessFailureEachTick") == (NodeStatus.RUNNING, 1)
    assert first_tick("RepeatUnlessFailureWithinTick") == (NodeStatus.SUCCESS, 3)
    assert first_tick("Repeat") == (NodeStatus.SUCCESS, 3)  # BT.CPP's Repeat: yield + immediate re-tick


def test_an_endless_within_tick_loop_of_instant_children_is_cancelled_on_the_objective_server(
    registry: Any, tmp_path: Any
) -> None:
    """MoveIt Pro's WithinTick loop over a child that always succeeds at once never leaves the tick; Kinema's
    lets the tick end every WITHIN_TICK_BUDGET_S and is ticked again at once, so a cancel still ends it."""
    import time
    from types import SimpleNamespace

    from kinema.bt import WallClock
    from kinema.runtime.objective_server import ObjectiveRequest, ObjectiveServer
    from kinema.runtime.objective_source import LibraryTreeSource, library_from_folders

    (tmp_path / "spin.xml").write_text(
        '<root BTCPP_format="4" main_tree_to_execute="Spin"><BehaviorTree ID="Spin">'
        + '<Sequence><Script code="n := 0"/><Decorator ID="RepeatUnlessFailureWithinTick" num_cycles="-1">'
        + '<Script code="n += 1"/></Decorator></Sequence></BehaviorTree></root>'
    )
    source = LibraryTreeSource(
        lambda: library_from_folders([tmp_path]),
        host=SimpleNamespace(registry=registry),
        context=None,
        clock=WallClock(),
    )
    with ObjectiveServer(source) as server:
        run = server.submit(ObjectiveRequest("Spin"))
        time.sleep(0.3)
        assert not run.done  # still looping
        assert server.cancel(run, reason="enough", timeout=5)
        result = run.wait(5)
    assert result is not None and result.cancelled, result
    # Served between two iterations: not by abandoning a tick thread stuck in the loop (which keeps
    # spinning, a core lost for good).
    assert "abandoned" not in result.error_message, result.error_message


class _TwoTicks(StatefulBehavior):
    """RUNNING on the tick that starts it, SUCCESS on the next."""

    def on_start(self) -> NodeStatus:
        return NodeStatus.RUNNING

    def on_running(self) -> NodeStatus:
        return NodeStatus.SUCCESS

    def on_halted(self) -> None:
        pass


@pytest.mark.parametrize(
    ("decorator", "statuses"),
    [
        # the next iteration starts on the tick after a success...
        ("RepeatUnlessFailureEachTick", ["RUNNING", "RUNNING", "RUNNING", "SUCCESS"]),
        # ...or in the tick that completed the previous one
        ("RepeatUnlessFailureWithinTick", ["RUNNING", "RUNNING", "SUCCESS"]),
    ],
)
def test_a_running_child_keeps_the_loop_running(
    registry: Any, context: BehaviorContext, decorator: str, statuses: list[str]
) -> None:
    xml = (
        '<root BTCPP_format="4"><BehaviorTree ID="T">'
        f'<Decorator ID="{decorator}" num_cycles="2"><Action ID="_TwoTicks"/></Decorator>'
        "</BehaviorTree></root>"
    )
    tree = build_tree(xml, registry=registry, behaviors=[_TwoTicks], context=context)
    seen = []
    for _ in range(len(statuses)):
        seen.append(tree.tick_exactly_once().name)
    assert seen == statuses
