"""The network is closed by default, as a user sees it: `kinema run` refuses a plain listener beyond
loopback, `--insecure` warns, and `kinema security init` makes the mutual-TLS path one command."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from kinema.transport import free_endpoint

READY = "objectives can be started"
QUICK = '<root BTCPP_format="4"><BehaviorTree ID="Hello"><AlwaysSuccess/></BehaviorTree></root>'


def _port(endpoint: str) -> str:
    return endpoint.rsplit(":", 1)[1]


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    return {
        **{k: v for k, v in os.environ.items() if k not in ("KINEMA_ZENOH_CONFIG", "KINEMA_SECURITY_DIR")},
        "XDG_STATE_HOME": str(tmp_path / "state"),
        "XDG_CONFIG_HOME": str(tmp_path / "config"),
        "XDG_DATA_HOME": str(tmp_path / "data"),
        "KINEMA_ZENOH_CONNECT": free_endpoint(),
        "KINEMA_CONFIG": "lab_sim",
    }


def _kinema(env: dict[str, str], *args: str, stdin: str | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "kinema", *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
        input=stdin,
    )


class Running:
    """A `kinema run` in the background, stopped at the end."""

    def __init__(self, env: dict[str, str], *args: str, drivers: bool = False) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "kinema", "run", "--headless", *([] if drivers else ["-n"]), *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env=env,
        )
        self.lines: list[str] = []
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self.lines.append(line)
            if READY in line:
                break
        assert READY in "".join(self.lines), "".join(self.lines)

    def stop(self) -> None:
        self.process.terminate()
        try:
            self.process.wait(20)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait(5)


@pytest.fixture
def running(env: dict[str, str]) -> Iterator[list[Running]]:
    started: list[Running] = []
    yield started
    for run in started:
        run.stop()


def test_a_plain_listener_beyond_loopback_is_refused_and_insecure_warns(
    env: dict[str, str], running: list[Running]
) -> None:
    everywhere = f"tcp/0.0.0.0:{_port(free_endpoint())}"
    refused = _kinema(env, "run", "--headless", "-n", "--connect", everywhere)
    assert refused.returncode == 1, refused.stdout + refused.stderr
    assert f"refusing to listen on {everywhere}" in refused.stderr, refused.stderr
    assert "kinema security init" in refused.stderr and "--insecure" in refused.stderr
    assert "Traceback" not in refused.stderr + refused.stdout and READY not in refused.stdout
    # Nothing ran: no run folder is left to become `kinema logs`' newest run.
    runs = Path(env["XDG_STATE_HOME"]) / "kinema" / "runs"
    assert not runs.is_dir() or not any(runs.iterdir()), sorted(runs.iterdir())

    run = Running(env, "--insecure", "--connect", everywhere)
    running.append(run)
    output = "".join(run.lines)
    assert f"WARNING: listening on {everywhere} without TLS client certificates" in output, output
    assert "kinema security init" in output
    local = f"tcp/127.0.0.1:{_port(everywhere)}"
    assert f"hosting the router at {local}" in output  # its own processes join over loopback
    done = _kinema(env, "objective", "do", "-", "--connect", local, stdin=QUICK)
    assert done.returncode == 0, done.stdout + done.stderr


def test_security_init_then_mutual_tls_between_two_processes(
    env: dict[str, str], running: list[Running], tmp_path: Path
) -> None:
    folder = tmp_path / "security"
    tls = f"tls/127.0.0.1:{_port(free_endpoint())}"
    made = _kinema(
        env,
        "security",
        "init",
        "-d",
        str(folder),
        "-a",
        "127.0.0.1",
        "--client",
        "laptop",
        "--machine",
        "robot2",
        "--port",
        _port(tls),
        "--local",
        env["KINEMA_ZENOH_CONNECT"],
    )
    assert made.returncode == 0, made.stdout + made.stderr
    assert f"kinema run --connect {tls}" in made.stdout
    client_config = folder / "clients" / "laptop.json5"
    for private in (folder / "ca.key", folder / "router.key", client_config):
        assert stat.S_IMODE(private.stat().st_mode) == 0o600, private

    run = Running(env, "--connect", tls, "--security", str(folder))
    running.append(run)
    assert f"other machines join at {tls}" in "".join(run.lines)

    # The operator's machine: only the one client file, no KINEMA_ZENOH_CONNECT.
    laptop = {k: v for k, v in env.items() if k != "KINEMA_ZENOH_CONNECT"}
    laptop["KINEMA_ZENOH_CONFIG"] = str(client_config)
    # An operator runs library objectives by name; ad-hoc XML is a grant it does not hold.
    refused_xml = _kinema(laptop, "objective", "do", "-", stdin=QUICK)
    assert refused_xml.returncode == 1, refused_xml.stdout + refused_xml.stderr
    assert "lacks that grant" in refused_xml.stderr and "Traceback" not in refused_xml.stderr
    listed = _kinema(laptop, "topic", "list")
    assert listed.returncode == 0 and "/objective_server_heartbeat" in listed.stdout, listed.stderr
    # The access rules: an operator may not edit waypoints (the call is dropped at the router).
    erase = ["service", "call", "/edit_waypoints", "moveit_studio_agent_msgs/srv/EditWaypoints"]
    erase += ["{operation: 2, waypoint_name: 'No Such Waypoint'}", "--timeout", "3"]
    dropped = _kinema(laptop, *erase)
    assert dropped.returncode == 1 and "no server" in dropped.stderr, dropped.stdout + dropped.stderr
    assert "may be its access rules" in dropped.stderr  # dropped, not refused: the likely cause is named
    # Another machine of the cell may do everything (here: get the agent's answer).
    machine = {**laptop, "KINEMA_ZENOH_CONFIG": str(folder / "clients" / "robot2.json5")}
    answered = _kinema(machine, *erase)
    assert answered.returncode == 0 and "no waypoint named" in answered.stdout, (
        answered.stdout + answered.stderr
    )
    done = _kinema(machine, "objective", "do", "-", stdin=QUICK)
    assert done.returncode == 0, done.stdout + done.stderr

    # Without a client certificate (only the CA) the TLS listener refuses the link.
    stranger = tmp_path / "stranger.json5"
    only_the_ca = {"root_ca_certificate": str(folder / "ca.pem")}
    stranger.write_text(
        json.dumps(
            {"mode": "client", "connect": {"endpoints": [tls]}, "transport": {"link": {"tls": only_the_ca}}}
        )
    )
    refused = _kinema({**laptop, "KINEMA_ZENOH_CONFIG": str(stranger)}, "topic", "list")
    assert refused.returncode == 1, refused.stdout
    assert "Traceback" not in refused.stderr


def _read_file_xml(path: str) -> str:
    return (
        '<root BTCPP_format="4"><BehaviorTree ID="Peek"><Sequence>'
        f'<ReadTextFileAsString text_filename="{path}" string_file_contents="{{contents}}"/>'
        "</Sequence></BehaviorTree></root>"
    )


def _write_file_xml(path: str) -> str:
    return (
        '<root BTCPP_format="4"><BehaviorTree ID="Drop"><Sequence>'
        '<CreatePoseStamped pose_stamped="{pose}"/>'
        f'<SavePoseStampedToYaml message="{{pose}}" yaml_filename="{path}"/>'
        "</Sequence></BehaviorTree></root>"
    )


def test_an_operator_runs_library_objectives_and_no_objective_reaches_files_outside_the_cell(
    env: dict[str, str], running: list[Running], tmp_path: Path
) -> None:
    """The probe's HIGH finding: an operator's XML wrote YAML at an absolute path and read /etc/passwd
    and the CA's key back. The operator now runs "Close Gripper" by name and is refused XML; a client
    with the XML grant reaches no file outside the workspace, the packages and Kinema's data folder."""
    folder = tmp_path / "security"
    tls = f"tls/127.0.0.1:{_port(free_endpoint())}"
    made = _kinema(
        env,
        *("security", "init", "-d", str(folder), "-a", "127.0.0.1", "--client", "operator"),
        *("--client", "scripter", "--allow-xml", "scripter", "--port", _port(tls)),
        *("--local", env["KINEMA_ZENOH_CONNECT"]),
    )
    assert made.returncode == 0, made.stdout + made.stderr
    roles = _kinema(env, "security", "-d", str(folder))
    assert roles.returncode == 0, roles.stderr
    assert "operator: operator" in roles.stdout and "scripter: operator with XML" in roles.stdout
    assert "run ad-hoc objective XML" in roles.stdout and "file rule" not in roles.stderr

    running.append(Running(env, "--connect", tls, "--security", str(folder), drivers=True))
    remote = {k: v for k, v in env.items() if k != "KINEMA_ZENOH_CONNECT"}
    operator = {**remote, "KINEMA_ZENOH_CONFIG": str(folder / "clients" / "operator.json5")}
    scripter = {**remote, "KINEMA_ZENOH_CONFIG": str(folder / "clients" / "scripter.json5")}

    # The operator: library objectives by name, through the CLI's JSON door and the SDK's action.
    closed = _kinema(operator, "objective", "run", "Close Gripper")
    assert closed.returncode == 0, closed.stdout + closed.stderr
    sdk = "from kinema.sdk import ObjectiveClient as C\nprint(C().execute('Close Gripper').succeeded)\n"
    through_sdk = subprocess.run(
        [sys.executable, "-c", sdk], capture_output=True, text=True, env=operator, timeout=120
    )
    assert through_sdk.returncode == 0 and through_sdk.stdout.strip() == "True", (
        through_sdk.stdout + through_sdk.stderr
    )
    xml_through_sdk = subprocess.run(
        [
            sys.executable,
            "-c",
            f"from kinema.sdk import ObjectiveClient\nObjectiveClient().do_xml({QUICK!r})\n",
        ],
        capture_output=True,
        text=True,
        env=operator,
        timeout=120,
    )
    assert xml_through_sdk.returncode == 1 and "lacks that grant" in xml_through_sdk.stderr, (
        xml_through_sdk.stdout + xml_through_sdk.stderr
    )
    # ... cancels, and watches.
    cancelled = _kinema(operator, "objective", "cancel")
    assert "no Kinema runtime" not in cancelled.stderr and "Traceback" not in cancelled.stderr, cancelled
    status = _kinema(operator, "objective", "status")
    assert status.returncode == 0 and "Close Gripper" in status.stdout, status.stdout + status.stderr
    for xml in (_read_file_xml("/etc/passwd"), _read_file_xml(str(folder / "ca.key"))):
        refused = _kinema(operator, "objective", "do", "-", stdin=xml)
        assert refused.returncode == 1 and "lacks that grant" in refused.stderr, (
            refused.stdout + refused.stderr
        )

    # With the XML grant: the file rule and the security rule hold whoever asks.
    outside = tmp_path / "outside"
    outside.mkdir()
    for xml, rule in (
        (_read_file_xml("/etc/passwd"), "refused by the file rule"),
        (_read_file_xml(str(folder / "ca.key")), "refused by the security rule"),
        (_read_file_xml(str(folder / "clients" / ".." / "ca.key")), "refused by the security rule"),
        (_write_file_xml(str(outside / "dropped")), "refused by the file rule"),
        (_write_file_xml(str(folder / "dropped")), "refused by the security rule"),
    ):
        done = _kinema(scripter, "objective", "do", "-", stdin=xml)
        said = done.stdout + done.stderr
        assert done.returncode == 1 and rule in said, said
        assert "root:" not in said and "PRIVATE KEY" not in said
    assert list(outside.iterdir()) == [] and not list(folder.glob("dropped*"))
