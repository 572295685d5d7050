"""PublishVelocityForceCommand and ForceExceedsThreshold on a private network (no driver)."""

from __future__ import annotations

import threading
import time
from typing import Any

import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.plugins import BehaviorRegistry
from kinema.testing import build_tree, tick_behavior
from kinema.transport import from_dict

COMMAND = "moveit_pro_controllers_msgs/msg/VelocityForceCommand"
WRENCH = "geometry_msgs/msg/WrenchStamped"

PUBLISH_FOR_300_MS = """
<root BTCPP_format="4" main_tree_to_execute="Push">
  <BehaviorTree ID="Push">
    <Sequence>
      <Action ID="CreateTwistStamped" reference_frame="grasp_link" twist_stamped="{stamped}"
              linear_velocity_xyz="0;0;0.05" angular_velocity_xyz="0;0;0"/>
      <Action ID="UnpackTwistStampedMessage" twist_stamped="{stamped}" twist="{twist}" header="{header}"/>
      <Action ID="CreateWrenchStamped" reference_frame="grasp_link" wrench_stamped="{zero}"
              force_xyz="0;0;0" torque_xyz="0;0;0"/>
      <Action ID="UnpackWrenchStampedMessage" wrench_stamped="{zero}" wrench="{wrench}" header="{header}"/>
      <Decorator ID="ForceSuccess">
        <Decorator ID="Timeout" msec="300">
          <Action ID="PublishVelocityForceCommand" twist="{twist}" wrench="{wrench}" publish_rate="50"
                  velocity_controlled_axes="0;0;1;0;0;0" force_controlled_axes="1;1;0;0;0;0"
                  wrench_gain="0.02"/>
        </Decorator>
      </Decorator>
    </Sequence>
  </BehaviorTree>
</root>
"""


def _collect(node: Any, type_name: str, topic: str) -> list[Any]:
    box: list[Any] = []
    node.create_subscription(type_name, topic, box.append)
    return box


def test_the_command_streams_at_its_rate_until_the_timeout_halts_it(
    registry: BehaviorRegistry, node: Any, lab_sim_model: Any
) -> None:
    # On a manual clock the count is exact whatever the machine's load: 50 Hz inside a 300 ms Timeout.
    from kinema.bt import ManualClock
    from kinema.config import resolve_config

    clock = ManualClock()
    context = BehaviorContext(node, clock=clock, robot_model=lab_sim_model, config=resolve_config("lab_sim"))
    received = _collect(node, COMMAND, "/velocity_force_controller/command")
    published: list[Any] = []
    make_publisher = context.publisher

    def counting_publisher(*args: Any, **kwargs: Any) -> Any:
        publisher = make_publisher(*args, **kwargs)
        send = publisher.publish
        publisher.publish = lambda message: (published.append(message), send(message))[1]
        return publisher

    context.publisher = counting_publisher  # type: ignore[method-assign]
    try:
        tree = build_tree(PUBLISH_FOR_300_MS, registry=registry, context=context)
        status = tree.tick_once()
        while status is NodeStatus.RUNNING:
            clock.advance(0.005)
            status = tree.tick_once()
        assert status is NodeStatus.SUCCESS
        # a command at 0, 20, ... 280 ms: the one due at 300 ms meets the Timeout's halt
        assert len(published) == 15, len(published)
        for _ in range(50):
            clock.advance(0.02)  # no timer of the halted behavior publishes again
        assert len(published) == 15
        deadline = time.monotonic() + 30.0
        while len(received) < 15 and time.monotonic() < deadline:
            time.sleep(0.01)
        assert len(received) == 15, len(received)
    finally:
        context.close()
    command = received[-1]
    assert command.twist.linear.z == pytest.approx(0.05)
    assert command.velocity_controlled_axes.z and not command.velocity_controlled_axes.x
    assert command.force_controlled_axes.x and command.force_controlled_axes.y
    assert not command.force_controlled_axes.z
    assert command.wrench_gain == pytest.approx(0.02)


@pytest.mark.parametrize(
    ("ports", "problem"),
    [
        ({"velocity_controlled_axes": "0;0;1;0;0"}, "has 5 values"),
        ({"velocity_controlled_axes": "0;0;2;0;0;0"}, "each 0 or 1"),
        (
            {"velocity_controlled_axes": "0;0;1;0;0;0", "force_controlled_axes": "0;0;1;0;0;0"},
            "names z, which velocity_controlled_axes names too",
        ),
        ({"publish_rate": 0.0}, "give a rate above 0 Hz"),
    ],
)
def test_bad_command_ports_fail_with_the_port_and_the_fix(
    behavior: Any, context: BehaviorContext, ports: dict[str, Any], problem: str
) -> None:
    twist = from_dict("geometry_msgs/msg/Twist", {})
    wrench = from_dict("geometry_msgs/msg/Wrench", {})
    run = tick_behavior(
        behavior("PublishVelocityForceCommand"), {"twist": twist, "wrench": wrench, **ports}, context=context
    )
    assert run.status is NodeStatus.FAILURE
    assert problem in run.toasts[-1], run.toasts


def _publish_forces(node: Any, forces: list[float], topic: str = "/ft/wrench") -> threading.Thread:
    publisher = node.create_publisher(WRENCH, topic)

    def loop() -> None:
        # The behavior subscribes first: what is published before its subscription is on the graph is lost.
        deadline = time.monotonic() + 30.0
        while publisher.subscription_count() == 0 and time.monotonic() < deadline:
            time.sleep(0.01)
        for force in forces:
            publisher.publish(
                {"header": {"frame_id": "tool0"}, "wrench": {"force": {"x": 0.6 * force, "z": -0.8 * force}}}
            )
            time.sleep(0.02)

    thread = threading.Thread(target=loop, daemon=True)
    thread.start()
    return thread


FORCE_FOUR_TIMES = """
<root BTCPP_format="4" main_tree_to_execute="Wait">
  <BehaviorTree ID="Wait">
    <Action ID="ForceExceedsThreshold" wrench_topic_name="/ft/wrench" force_threshold="30.0"
            minimum_consecutive_wrench_values="4"/>
  </BehaviorTree>
</root>
"""


def _tick_while(tree: Any, condition: Any, timeout: float = 30.0) -> NodeStatus:
    """Tick ``tree`` while it runs and ``condition()`` is false; its last status."""
    deadline = time.monotonic() + timeout
    while True:
        status = tree.tick_once()
        if status is not NodeStatus.RUNNING or condition():
            return status
        assert time.monotonic() < deadline, "timed out"
        tree.sleep(0.005)


def test_force_exceeds_threshold_needs_the_force_above_it_that_many_times_in_a_row(
    registry: BehaviorRegistry, context: BehaviorContext
) -> None:
    # The magnitude counts (x and z together); a dip below the threshold starts the count again. The
    # wrenches go out in two parts, so the test does not race the behavior's subscription against its own:
    # after the first eight (three above the threshold since the dip) it must still run; the ninth ends it.
    # Counting every 31 N would have ended it at the sixth.
    seen = _collect(context.node, WRENCH, "/ft/wrench")
    tree = build_tree(FORCE_FOUR_TIMES, registry=registry, context=context)
    first = _publish_forces(context.node, [5.0, 31.0, 31.0, 31.0, 12.0, 31.0, 31.0, 31.0])
    status = _tick_while(tree, lambda: not first.is_alive() and len(seen) >= 8)
    # Give the behavior's own subscription the same time again to receive what the test's has received.
    until = time.monotonic() + 0.5
    while status is NodeStatus.RUNNING and time.monotonic() < until:
        status = tree.tick_once()
        tree.sleep(0.005)
    assert status is NodeStatus.RUNNING, "it ended before the fourth 31 N after the dip"
    second = _publish_forces(context.node, [31.0] * 50)
    status = _tick_while(tree, lambda: False)
    second.join()
    assert status is NodeStatus.SUCCESS


def test_force_exceeds_threshold_keeps_running_below_it(behavior: Any, context: BehaviorContext) -> None:
    thread = _publish_forces(context.node, [29.0] * 100)
    with pytest.raises(TimeoutError):
        tick_behavior(
            behavior("ForceExceedsThreshold"),
            {
                "wrench_topic_name": "/ft/wrench",
                "force_threshold": 30.0,
                "minimum_consecutive_wrench_values": 1,
            },
            context=context,
            timeout=1.0,
        )
    thread.join()


def test_force_exceeds_threshold_fails_when_no_wrench_comes(
    behavior: Any, context: BehaviorContext, monkeypatch: pytest.MonkeyPatch
) -> None:
    cls = behavior("ForceExceedsThreshold")
    monkeypatch.setattr(cls, "no_message_timeout", 0.5)
    run = tick_behavior(cls, {"wrench_topic_name": "/nobody/wrench"}, context=context, timeout=10.0)
    assert run.status is NodeStatus.FAILURE
    assert "no wrench on /nobody/wrench within 0.5 s" in run.toasts[-1], run.toasts
