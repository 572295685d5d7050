"""Service and action responses inside behaviors are typed messages: mypy --strict knows their fields."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

from kinema.behaviors import ActionClientBehavior, ServiceClientBehavior
from kinema.errors import PluginError
from kinema.interfaces import load_interfaces
from kinema.interfaces.typed_codegen import TARGET, generate

ROOT = Path(__file__).resolve().parents[3]
EXAMPLE = ROOT / "plugins" / "examples" / "kinema_example_behaviors" / "my_add_two_ints_service_client.py"
TEMPLATE = ROOT / "cookiecutters" / "behavior_package" / "templates" / "service_client" / "behavior.py.jinja"

# A behavior that calls a service through the context and a transport node, and reads the response.
CALLER = """
from __future__ import annotations

from kinema.behaviors import SyncBehavior
from kinema.bt import NodeStatus
from kinema.interfaces.typed import AddTwoInts, Fibonacci, GetSimBodies


class Adds(SyncBehavior):
    def tick(self) -> NodeStatus:
        node = self.context.require_node("Adds")
        client = self.context.service_client(node, AddTwoInts, "/add_two_ints")
        response = client.call(AddTwoInts.Request(a=1, b=2), timeout=1.0)
        total: int = response.sum
        bodies = node.create_client(GetSimBodies, "/bodies").call({}).bodies
        names: list[str] = [body.name for body in bodies]
        goal = self.context.action_client(node, Fibonacci, "/fib").send_goal(Fibonacci.Goal(order=3))
        sequence = goal.result(timeout=1.0).result.sequence
        return NodeStatus.SUCCESS if total == 3 and names and len(sequence) else NodeStatus.FAILURE
"""


def mypy_strict(tmp_path: Path, sources: dict[str, str]) -> dict[str, list[str]]:
    """``mypy --strict`` over the modules ``sources`` (file name -> text), in one run: each file's errors.

    One run, not one per file: each run checks kinema and numpy again (``--no-incremental``), and six of
    them took over 300 s on a loaded 2-core machine.
    """
    if importlib.util.find_spec("mypy") is None:
        pytest.skip("mypy is not installed (pip install -e '.[test]' installs it)")
    for name, source in sources.items():
        (tmp_path / name).write_text(source)
    checked = subprocess.run(
        [
            sys.executable,
            "-m",
            "mypy",
            "--strict",
            "--no-incremental",
            "--cache-dir",
            str(tmp_path / "cache"),
            *sources,
        ],
        capture_output=True,
        text=True,
        timeout=900,
        cwd=tmp_path,
    )
    errors: dict[str, list[str]] = {name: [] for name in sources}
    for line in checked.stdout.splitlines():
        name = line.split(":", 1)[0]
        if name in errors:
            errors[name].append(line)
    reported = sum(map(len, errors.values()))
    assert checked.returncode == (1 if reported else 0), checked.stdout + checked.stderr
    return errors


def test_the_typed_module_is_generated_from_the_current_interface_files() -> None:
    assert TARGET.read_text(encoding="utf-8") == generate(), (
        "kinema/interfaces/typed.py is stale: run python -m kinema.interfaces.typed_codegen"
    )


def test_the_typed_classes_are_the_classes_the_transport_builds_messages_with() -> None:
    from kinema.interfaces.typed import AddTwoInts, Fibonacci, kinema_msgs__srv__GetSimBodies_Response

    registry = load_interfaces()
    assert AddTwoInts.type_name == "example_interfaces/srv/AddTwoInts"
    assert AddTwoInts.Response is registry.message_class("example_interfaces/srv/AddTwoInts_Response")
    assert Fibonacci.Feedback is registry.message_class("example_interfaces/action/Fibonacci_Feedback")
    reply = registry.deserialize(
        registry.serialize(AddTwoInts.Response(sum=42), AddTwoInts.Response.__msgtype__),
        "example_interfaces/srv/AddTwoInts_Response",
    )
    assert isinstance(reply, AddTwoInts.Response) and reply.sum == 42
    assert kinema_msgs__srv__GetSimBodies_Response is registry.message_class(
        "kinema_msgs/srv/GetSimBodies_Response"
    )


def test_client_behaviors_take_the_interface_classes_as_their_type_arguments() -> None:
    from kinema.interfaces.typed import AddTwoInts, Fibonacci, Trigger

    service = ServiceClientBehavior[AddTwoInts.Request, AddTwoInts.Response]
    assert service.service_type == "example_interfaces/srv/AddTwoInts"  # type: ignore[attr-defined]
    action = ActionClientBehavior[Fibonacci.Goal, Fibonacci.Result, Fibonacci.Feedback]
    assert action.action_type == "example_interfaces/action/Fibonacci"  # type: ignore[attr-defined]
    with pytest.raises(PluginError, match="must be example_interfaces/srv/AddTwoInts_Request"):
        ServiceClientBehavior[AddTwoInts.Request, Trigger.Response]
    with pytest.raises(PluginError, match=r"takes the message classes Name\.Request, Name\.Response"):
        ServiceClientBehavior[AddTwoInts.Response, AddTwoInts.Request]


@pytest.mark.slow
def test_mypy_strict_knows_the_fields_of_responses_in_behaviors(tmp_path: Path) -> None:
    example = EXAMPLE.read_text(encoding="utf-8")
    baked = TEMPLATE.read_text(encoding="utf-8").replace("{{ cookiecutter.behavior_id }}", "AddClient")
    wrong_field = example.replace("response.sum)", "response.total)")
    wrong_type = example.replace("response: AddTwoInts.Response", "response: AddTwoInts.Request")
    assert wrong_field != example and wrong_type != example
    errors = mypy_strict(
        tmp_path,
        {
            "caller.py": CALLER,
            "example.py": example,
            "add_client.py": baked,  # what `kinema new behavior` writes
            "misspelt.py": CALLER.replace("response.sum", "response.summ"),
            "wrong_field.py": wrong_field,
            "wrong_type.py": wrong_type,
        },
    )
    assert errors["caller.py"] == errors["example.py"] == errors["add_client.py"] == [], errors

    def said(name: str, text: str) -> bool:
        return any(text in line for line in errors[name])

    assert said("misspelt.py", 'has no attribute "summ"; maybe "sum"?'), errors["misspelt.py"]
    assert said("wrong_field.py", 'has no attribute "total"'), errors["wrong_field.py"]
    assert said("wrong_type.py", "process_response"), errors["wrong_type.py"]
