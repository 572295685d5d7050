"""docs/multi-machine.md, run on loopback: its zenoh configs are valid and do what the page says.

The router and client configs are taken from the page verbatim, with only the certificate folder and
the addresses replaced; certificates are generated as the page shows (X.509 v3, signed by a test CA).
"""

from __future__ import annotations

import queue
import re
import shutil
import subprocess
from collections.abc import Callable
from pathlib import Path

import pytest
import zenoh

from kinema.errors import TransportError
from kinema.transport import Node, host_router, open_session

DOC = Path(__file__).resolve().parents[3] / "docs" / "multi-machine.md"


def _json5_blocks() -> dict[str, str]:
    blocks = re.findall(r"```json5\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.DOTALL)
    named = {}
    for block in blocks:
        first = block.splitlines()[0]
        if first.startswith("// "):
            named[first[3:].strip()] = block
    return named


def test_documented_configs_use_real_zenoh_keys() -> None:
    blocks = _json5_blocks()
    assert set(blocks) == {"kinema-router.json5", "kinema-client.json5"}
    for text in blocks.values():
        zenoh.Config.from_json5(text)  # zenoh rejects unknown keys


def _certificates(folder: Path) -> None:
    def run(*argv: str) -> None:
        subprocess.run(argv, cwd=folder, check=True, capture_output=True, timeout=60)

    run(
        "openssl",
        "req",
        "-x509",
        "-newkey",
        "rsa:2048",
        "-nodes",
        "-days",
        "2",
        "-keyout",
        "ca.key",
        "-out",
        "ca.pem",
        "-subj",
        "/CN=kinema-test-ca",
        "-addext",
        "basicConstraints=critical,CA:TRUE",
        "-addext",
        "keyUsage=critical,keyCertSign,cRLSign",
    )
    for name in ("robot-router", "operator-laptop"):
        (folder / f"{name}.ext").write_text(
            "basicConstraints=CA:FALSE\nsubjectAltName=IP:127.0.0.1\nextendedKeyUsage=serverAuth,clientAuth\n"
        )
        run(
            "openssl",
            "req",
            "-newkey",
            "rsa:2048",
            "-nodes",
            "-keyout",
            f"{name}.key",
            "-out",
            f"{name}.csr",
            "-subj",
            f"/CN={name}",
        )
        run(
            "openssl",
            "x509",
            "-req",
            "-in",
            f"{name}.csr",
            "-CA",
            "ca.pem",
            "-CAkey",
            "ca.key",
            "-CAcreateserial",
            "-days",
            "2",
            "-extfile",
            f"{name}.ext",
            "-out",
            f"{name}.pem",
        )


@pytest.mark.skipif(shutil.which("openssl") is None, reason="needs the openssl command to make certificates")
def test_mutual_tls_and_access_rules(
    tmp_path: Path, endpoints: Callable[[], str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("KINEMA_ZENOH_CONNECT")  # the laptop's only setting is its client config file
    _certificates(tmp_path)
    local, lan = endpoints(), endpoints().replace("tcp/", "tls/")
    blocks = _json5_blocks()
    router_file = tmp_path / "kinema-router.json5"
    router_file.write_text(
        blocks["kinema-router.json5"]
        .replace("/etc/kinema/tls/", f"{tmp_path}/")
        .replace("tcp/127.0.0.1:7447", local)
        .replace("tls/192.168.1.10:7448", lan)
    )
    client_file = tmp_path / "kinema-client.json5"
    client_file.write_text(
        blocks["kinema-client.json5"]
        .replace("/home/operator/.config/kinema/tls/", f"{tmp_path}/")
        .replace("tls/192.168.1.10:7448", lan)
    )
    with host_router(domain_id=0, config_file=str(router_file)) as router:
        assert router.listen == [local, lan]
        with open_session(local, domain_id=0) as robot:
            agent = Node(robot, "agent")
            agent.create_service(
                "moveit_studio_sdk_msgs/srv/ExecuteObjective",
                "/execute_objective",
                lambda r: {"error_code": {"val": 1}},
            )
            agent.create_service(
                "controller_manager_msgs/srv/SwitchController",
                "/controller_manager/switch_controller",
                lambda r: {"ok": True},
            )
            snapshot = agent.create_publisher(
                "std_msgs/msg/String", "/objective_server/blackboard", latched=True
            )
            snapshot.publish({"data": "latest snapshot"})
            with open_session(domain_id=0, mode="client", config_file=str(client_file)) as laptop:
                assert laptop.endpoints == [lan]
                operator = Node(laptop, "operator")
                latched: queue.Queue[str] = queue.Queue()
                operator.create_subscription(
                    "std_msgs/msg/String",
                    "/objective_server/blackboard",
                    lambda m: latched.put(m.data),
                    latched=True,
                )
                assert latched.get(timeout=5) == "latest snapshot"  # the cached sample passes the rules
                execute = operator.create_client(
                    "moveit_studio_sdk_msgs/srv/ExecuteObjective", "/execute_objective"
                )
                assert execute.call({"objective_name": "Close Gripper"}, timeout=5).error_code.val == 1
                switch = operator.create_client(
                    "controller_manager_msgs/srv/SwitchController", "/controller_manager/switch_controller"
                )
                # Not in the operators' rules: the router drops the query. It comes back empty ("no server")
                # or, on a loaded machine, runs out the whole 0.5 s ("did not answer"): never an answer.
                with pytest.raises(TransportError, match=r"no server|did not answer"):
                    switch.call({}, timeout=0.5)
            # The local process may do everything.
            local_switch = Node(robot, "local").create_client(
                "controller_manager_msgs/srv/SwitchController", "/controller_manager/switch_controller"
            )
            assert local_switch.call({}, timeout=5).ok
        # Without a client certificate the TLS listener refuses the link.
        with pytest.raises(TransportError):
            open_session(
                lan,
                mode="client",
                config_overrides={"transport/link/tls/root_ca_certificate": str(tmp_path / "ca.pem")},
                connect_timeout=1,
            )
