"""SwitchController, ListControllers, MoveGripperAction and SetMujocoState against fake servers."""

from __future__ import annotations

import threading
from typing import Any

import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import build_tree, tick_behavior

CONTROLLERS = [
    {"name": "joint_state_broadcaster", "state": "active", "required_command_interfaces": []},
    {
        "name": "joint_trajectory_controller",
        "state": "active",
        "required_command_interfaces": ["elbow_joint/position", "wrist_1_joint/position"],
    },
    {
        "name": "robotiq_gripper_controller",
        "state": "inactive",
        "required_command_interfaces": ["robotiq_85_left_knuckle_joint/position"],
    },
    {
        "name": "joint_trajectory_admittance_controller",
        "state": "inactive",
        "required_command_interfaces": ["elbow_joint/position", "wrist_1_joint/position"],
    },
]


class ControllerManager:
    """A fake controller manager recording switch requests."""

    def __init__(self, node: Any, ok: bool = True) -> None:
        self.requests: list[Any] = []
        self.listings = 0
        self.ok = ok
        node.create_service(
            "controller_manager_msgs/srv/ListControllers",
            "/controller_manager/list_controllers",
            self._list,
        )
        node.create_service(
            "controller_manager_msgs/srv/SwitchController",
            "/controller_manager/switch_controller",
            self._switch,
        )

    def _list(self, _request: Any) -> dict[str, Any]:
        self.listings += 1
        return {"controller": CONTROLLERS}

    def _switch(self, request: Any) -> dict[str, Any]:
        self.requests.append(request)
        return {"ok": self.ok, "message": "" if self.ok else "cannot activate robotiq_gripper_controller"}


def test_switch_controller_strips_the_slash_and_switches_strictly(
    behavior: Any, context: BehaviorContext
) -> None:
    manager = ControllerManager(context.node)
    run = tick_behavior(
        behavior("SwitchController"),
        {"activate_controllers": "/joint_trajectory_controller", "automatic_deactivation": False},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    (request,) = manager.requests
    assert list(request.activate_controllers) == ["joint_trajectory_controller"]
    assert list(request.deactivate_controllers) == []
    assert request.strictness == 2


def test_controllers_listed_with_spaces_as_moveit_studio_wrote_them_are_each_switched(
    behavior: Any, context: BehaviorContext
) -> None:
    manager = ControllerManager(context.node)
    run = tick_behavior(
        behavior("SwitchController"),
        {
            "activate_controllers": "/joint_trajectory_controller /robotiq_gripper_controller",
            "automatic_deactivation": False,
        },
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    (request,) = manager.requests
    assert list(request.activate_controllers) == ["joint_trajectory_controller", "robotiq_gripper_controller"]


def test_activating_deactivates_controllers_claiming_the_same_joints(
    behavior: Any, context: BehaviorContext
) -> None:
    manager = ControllerManager(context.node)
    run = tick_behavior(
        behavior("SwitchController"),
        {"activate_controllers": ["joint_trajectory_admittance_controller", "robotiq_gripper_controller"]},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    request = manager.requests[-1]
    assert list(request.deactivate_controllers) == ["joint_trajectory_controller"]


def test_a_refused_switch_fails_with_the_managers_reason(behavior: Any, context: BehaviorContext) -> None:
    ControllerManager(context.node, ok=False)
    run = tick_behavior(behavior("SwitchController"), {"deactivate_controllers": "a;b"}, context=context)
    assert run.status == NodeStatus.FAILURE
    assert "refused" in run.toasts[-1] and "cannot activate robotiq_gripper_controller" in run.toasts[-1]


def test_switch_controller_without_a_manager_fails(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(
        behavior("SwitchController"),
        {"activate_controllers": "x", "automatic_deactivation": False, "timeout": 0.3},
        context=context,
    )
    assert run.status == NodeStatus.FAILURE
    assert "cannot reach the controller manager" in run.toasts[-1]


def test_list_controllers_filters_by_kind_and_state(behavior: Any, context: BehaviorContext) -> None:
    ControllerManager(context.node)
    ListControllers = behavior("ListControllers")
    active_commands = tick_behavior(ListControllers, {"type": "command", "state": "active"}, context=context)
    assert active_commands.outputs["controller_list"] == ["joint_trajectory_controller"]
    everything = tick_behavior(ListControllers, context=context)
    assert len(everything.outputs["controller_list"]) == 4
    broadcasters = tick_behavior(ListControllers, {"type": "state"}, context=context)
    assert broadcasters.outputs["controller_list"] == ["joint_state_broadcaster"]
    wrong = tick_behavior(ListControllers, {"type": "commands"}, context=context)
    assert wrong.status == NodeStatus.FAILURE and "type must be one of" in wrong.toasts[-1]


def test_reset_style_listing_feeds_a_switch(behavior: Any, registry: Any, context: BehaviorContext) -> None:
    manager = ControllerManager(context.node)
    tree = build_tree(
        """<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence>
             <Action ID="ListControllers" type="command" controller_list="{c}" state="active" />
             <Action ID="SwitchController" deactivate_controllers="{c}" />
           </Sequence></BehaviorTree></root>""",
        registry=registry,
        context=context,
    )
    from kinema.testing import tick_until_done

    status, _ = tick_until_done(tree)
    assert status == NodeStatus.SUCCESS
    assert list(manager.requests[-1].deactivate_controllers) == ["joint_trajectory_controller"]


class Gripper:
    """A fake GripperCommand server ending each goal as told."""

    def __init__(self, node: Any, *, reached: bool = True, stalled: bool = False, hold: bool = False) -> None:
        self.goals: list[Any] = []
        self.cancelled = threading.Event()
        self.reached, self.stalled, self.hold = reached, stalled, hold
        node.create_action_server(
            "control_msgs/action/GripperCommand", "/robotiq_gripper_controller/gripper_cmd", self._execute
        )

    def _execute(self, handle: Any) -> Any:
        self.goals.append(handle.goal)
        if self.hold:
            handle.cancel_requested_event.wait(10.0)
            self.cancelled.set()
            handle.canceled({"position": 0.1})
            return None
        return {
            "position": handle.goal.command.position if self.reached else 0.33,
            "reached_goal": self.reached,
            "stalled": self.stalled,
        }


def test_move_gripper_sends_the_position(behavior: Any, context: BehaviorContext) -> None:
    gripper = Gripper(context.node)
    run = tick_behavior(behavior("MoveGripperAction"), {"position": 0.7929}, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert abs(gripper.goals[0].command.position - 0.7929) < 1e-9


def test_a_stalled_gripper_holds_an_object_and_succeeds(behavior: Any, context: BehaviorContext) -> None:
    Gripper(context.node, reached=False, stalled=True)
    run = tick_behavior(behavior("MoveGripperAction"), {"position": 0.7929}, context=context)
    assert run.status == NodeStatus.SUCCESS


def test_a_gripper_that_neither_reaches_nor_stalls_fails(behavior: Any, context: BehaviorContext) -> None:
    Gripper(context.node, reached=False, stalled=False)
    run = tick_behavior(behavior("MoveGripperAction"), {"position": 0.7929}, context=context)
    assert run.status == NodeStatus.FAILURE
    assert "without reaching 0.7929" in run.toasts[-1]


@pytest.mark.parametrize(
    ("require_grasp", "reached", "stalled", "expected"),
    [
        # Closing an empty gripper on purpose (MoveIt Pro's Close Gripper, Push Button) succeeds.
        (False, True, False, NodeStatus.SUCCESS),
        (False, False, True, NodeStatus.SUCCESS),
        # A pick that must hold something: the fingers reaching closed means they met nothing.
        (True, True, False, NodeStatus.FAILURE),
        (True, False, True, NodeStatus.SUCCESS),
    ],
)
def test_the_grasp_check_fails_a_close_on_nothing_only_when_asked(
    behavior: Any,
    context: BehaviorContext,
    require_grasp: bool,
    reached: bool,
    stalled: bool,
    expected: NodeStatus,
) -> None:
    Gripper(context.node, reached=reached, stalled=stalled)
    run = tick_behavior(
        behavior("MoveGripperAction"), {"position": 0.7929, "require_grasp": require_grasp}, context=context
    )
    assert run.status == expected, run.toasts
    if expected == NodeStatus.FAILURE:
        assert "the gripper closed on nothing" in run.toasts[-1]
        assert "ForceSuccess" in run.toasts[-1]
        # A pick cancelled half-way leaves the cube elsewhere: the next run's failure says how to reset.
        assert "`kinema sim reset` puts the objects back" in run.toasts[-1]


def test_forcesuccess_lets_a_pick_that_closed_on_nothing_go_on(
    registry: Any, context: BehaviorContext
) -> None:
    from kinema.testing import run_objective

    Gripper(context.node, reached=True, stalled=False)
    close = (
        '<Action ID="MoveGripperAction" position="0.7929" require_grasp="true" '
        'gripper_command_action_name="/robotiq_gripper_controller/gripper_cmd"/>'
    )
    tree = '<root BTCPP_format="4"><BehaviorTree ID="T">{}</BehaviorTree></root>'
    plain = run_objective(tree.format(close), registry=registry, context=context)
    assert plain.status == NodeStatus.FAILURE
    forced = run_objective(
        tree.format(f'<Decorator ID="ForceSuccess">{close}</Decorator>'), registry=registry, context=context
    )
    assert forced.status == NodeStatus.SUCCESS


def test_a_slow_gripper_times_out_and_halting_cancels(behavior: Any, context: BehaviorContext) -> None:
    gripper = Gripper(context.node, hold=True)
    run = tick_behavior(behavior("MoveGripperAction"), {"position": 0.5, "timeout": 0.3}, context=context)
    assert run.status == NodeStatus.FAILURE
    assert "No result" in run.toasts[-1]
    assert gripper.cancelled.wait(5.0)


def test_set_mujoco_state_sends_the_robot_state(behavior: Any, context: BehaviorContext) -> None:
    requests: list[Any] = []

    def answer(request: Any) -> dict[str, Any]:
        requests.append(request)
        return {"success": True}

    context.node.create_service("kinema_msgs/srv/SetMujocoState", "/mujoco/set_state", answer)
    state = tick_behavior(
        behavior("CreateRobotState"), {"joint_names": "elbow_joint", "positions": "0.5"}, context=context
    ).outputs["robot_state"]
    run = tick_behavior(behavior("SetMujocoState"), {"robot_state": state}, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert list(requests[0].joint_state.name) == ["elbow_joint"]
    assert list(requests[0].joint_state.position) == [0.5]
    assert requests[0].keyframe == ""


def test_set_mujoco_state_reports_a_refusal(behavior: Any, context: BehaviorContext) -> None:
    context.node.create_service(
        "kinema_msgs/srv/SetMujocoState",
        "/mujoco/set_state",
        lambda _r: {"success": False, "message": "unknown keyframe 'hom'"},
    )
    run = tick_behavior(behavior("SetMujocoState"), {"keyframe": "hom", "robot_state": None}, context=context)
    assert run.status == NodeStatus.FAILURE
    assert "unknown keyframe 'hom'" in run.toasts[-1]


def test_activating_an_active_controller_needs_no_switch(behavior: Any, context: BehaviorContext) -> None:
    manager = ControllerManager(context.node)
    run = tick_behavior(
        behavior("SwitchController"),
        {"activate_controllers": "/joint_trajectory_controller"},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert manager.requests == []


def test_a_controller_listed_active_a_moment_ago_is_not_listed_again_until_this_cell_switches(
    behavior: Any, context: BehaviorContext
) -> None:
    manager = ControllerManager(context.node)
    activate = {"activate_controllers": "/joint_trajectory_controller"}
    for _ in range(2):  # one motion after another: SwitchController before each
        run = tick_behavior(behavior("SwitchController"), activate, context=context)
        assert run.status == NodeStatus.SUCCESS, run.toasts
    assert (manager.listings, manager.requests) == (1, [])
    deactivate = {"deactivate_controllers": "joint_trajectory_controller"}
    run = tick_behavior(behavior("SwitchController"), deactivate, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert len(manager.requests) == 1
    # This cell switched: what it knew of the states is no longer trusted.
    run = tick_behavior(behavior("SwitchController"), activate, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert manager.listings == 2


def test_a_listing_older_than_a_second_is_not_trusted(
    behavior: Any, context: BehaviorContext, monkeypatch: Any
) -> None:
    import sys

    switching = sys.modules[behavior("SwitchController").__module__]
    monkeypatch.setattr(switching, "STATES_VALID_FOR", 0.0)
    manager = ControllerManager(context.node)
    activate = {"activate_controllers": "joint_trajectory_controller"}
    for _ in range(2):
        run = tick_behavior(behavior("SwitchController"), activate, context=context)
        assert run.status == NodeStatus.SUCCESS, run.toasts
    assert manager.listings == 2


class StatefulManager(ControllerManager):
    """A fake controller manager whose switches change what it lists."""

    def __init__(self, node: Any) -> None:
        import copy

        self.states = copy.deepcopy(CONTROLLERS)
        super().__init__(node)

    def state(self, name: str) -> dict[str, Any]:
        return next(c for c in self.states if c["name"] == name.strip("/"))

    def _list(self, _request: Any) -> dict[str, Any]:
        self.listings += 1
        return {"controller": self.states}

    def _switch(self, request: Any) -> dict[str, Any]:
        for name in request.deactivate_controllers:
            self.state(name)["state"] = "inactive"
        for name in request.activate_controllers:
            self.state(name)["state"] = "active"
        return super()._switch(request)


def test_a_controller_switched_elsewhere_since_its_listing_is_activated_and_the_trajectory_sent_again(
    behavior: Any, context: BehaviorContext
) -> None:
    """The trusted listing is stale (a reset of the simulation went back to the startup controllers): the
    controller turns the goal down as inactive, and ExecuteTrajectory asks the controller manager again,
    activates it and sends the trajectory once more, instead of failing the objective."""
    from kinema.transport import from_dict

    manager = StatefulManager(context.node)
    jtc = manager.state("joint_trajectory_controller")
    goals: list[str] = []

    def execute(handle: Any) -> Any:
        if jtc["state"] != "active":
            goals.append("turned down")
            handle.abort({"error_code": -1, "error_string": "joint_trajectory_controller is inactive"})
            return None
        goals.append("executed")
        return {"error_code": 0, "error_string": ""}

    context.node.create_action_server(
        "control_msgs/action/FollowJointTrajectory",
        "/joint_trajectory_controller/follow_joint_trajectory",
        execute,
    )
    run = tick_behavior(
        behavior("SwitchController"), {"activate_controllers": "joint_trajectory_controller"}, context=context
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    jtc["state"] = "inactive"  # switched by someone else within the second the listing is trusted
    trajectory = from_dict(
        "trajectory_msgs/msg/JointTrajectory",
        {
            "joint_names": ["elbow_joint"],
            "points": [{"positions": [0.1], "time_from_start": {"sec": 1, "nanosec": 0}}],
        },
    )
    run = tick_behavior(behavior("ExecuteTrajectory"), {"joint_trajectory_msg": trajectory}, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert goals == ["turned down", "executed"]
    assert [list(r.activate_controllers) for r in manager.requests] == [["joint_trajectory_controller"]]
