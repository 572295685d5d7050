"""The network is closed by default: which listeners need mutual TLS and access rules, and the plan of
`kinema run --connect` (loopback for local processes, TLS for the others)."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import pytest
import zenoh

from kinema.errors import KinemaError
from kinema.runtime.router_plan import plan_router
from kinema.transport.exposure import ExposureError, check_listeners, is_loopback


@pytest.mark.parametrize(
    ("endpoint", "loopback"),
    [
        ("tcp/127.0.0.1:7447", True),
        ("tcp/127.3.2.1:7447", True),
        ("tcp/[::1]:7447", True),
        ("tcp/localhost:7447", True),
        ("tls/127.0.0.1:7448#iface=lo", True),
        ("unixsock-stream//tmp/kinema.sock", True),
        ("tcp/0.0.0.0:7447", False),
        ("tcp/[::]:7447", False),
        ("tcp/192.168.1.10:7447", False),
        ("tls/robot.local:7448", False),
        ("udp/10.0.0.2:7447", False),
    ],
)
def test_what_counts_as_loopback(endpoint: str, loopback: bool) -> None:
    assert is_loopback(endpoint) is loopback


def _config(**settings: object) -> zenoh.Config:
    config = zenoh.Config()
    for key, value in settings.items():
        config.insert_json5(key.replace("__", "/"), json.dumps(value))
    return config


SECURE = {
    "transport__link__tls__root_ca_certificate": "/etc/kinema/ca.pem",
    "transport__link__tls__listen_certificate": "/etc/kinema/router.pem",
    "transport__link__tls__listen_private_key": "/etc/kinema/router.key",
    "transport__link__tls__enable_mtls": True,
    "access_control__enabled": True,
}


def test_loopback_listeners_need_nothing() -> None:
    assert check_listeners(_config(), ["tcp/127.0.0.1:7447", "tcp/[::1]:7447"]) == []


def test_a_plain_listener_beyond_loopback_is_refused_unless_insecure() -> None:
    with pytest.raises(ExposureError) as refused:
        check_listeners(_config(), ["tcp/127.0.0.1:7447", "tcp/0.0.0.0:7447"])
    message = str(refused.value)
    assert "refusing to listen on tcp/0.0.0.0:7447" in message and "plain TCP" in message
    assert "kinema security init" in message and "--insecure" in message
    assert check_listeners(_config(), ["tcp/0.0.0.0:7447"], insecure=True) == ["tcp/0.0.0.0:7447"]


def test_tls_beyond_loopback_needs_client_certificates_and_deny_by_default_rules() -> None:
    assert check_listeners(_config(**SECURE), ["tls/192.168.1.10:7448"]) == []
    without_mtls = {**SECURE, "transport__link__tls__enable_mtls": False}
    with pytest.raises(ExposureError, match="enable_mtls"):
        check_listeners(_config(**without_mtls), ["tls/192.168.1.10:7448"])
    allowing = {**SECURE, "access_control__default_permission": "allow"}
    with pytest.raises(ExposureError, match="deny by default"):
        check_listeners(_config(**allowing), ["tls/192.168.1.10:7448"])
    without_rules = {key: value for key, value in SECURE.items() if not key.startswith("access")}
    with pytest.raises(ExposureError, match="access rules"):
        check_listeners(_config(**without_rules), ["tls/192.168.1.10:7448"])


def test_run_plans_a_loopback_listener_for_its_own_processes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("KINEMA_ZENOH_CONNECT", raising=False)
    monkeypatch.delenv("KINEMA_ZENOH_CONFIG", raising=False)
    monkeypatch.setenv("KINEMA_SECURITY_DIR", str(tmp_path / "nowhere"))
    with pytest.raises(KinemaError, match=r"kinema security init --address 192\.168\.1\.10"):
        plan_router("tls/192.168.1.10:7448")
    # Every interface: the certificate covers this machine's addresses, never "--address 0.0.0.0".
    with pytest.raises(KinemaError, match=r"run `kinema security init` first") as error:
        plan_router("tls/0.0.0.0:7448")
    assert "--address" not in str(error.value)
    (tmp_path / "router.json5").write_text("{}")
    plan = plan_router("tls/192.168.1.10:7448", tmp_path)
    assert plan.listen == ("tcp/127.0.0.1:7447", "tls/192.168.1.10:7448")
    assert plan.local == "tcp/127.0.0.1:7447" and plan.config_file == tmp_path / "router.json5"
    every_interface = plan_router("tcp/0.0.0.0:7450")
    assert every_interface.listen == ("tcp/0.0.0.0:7450",) and every_interface.local == "tcp/127.0.0.1:7450"
    assert plan_router(None).listen == ("tcp/127.0.0.1:7447",)


def test_a_router_config_file_in_the_environment_decides_where_run_listens(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("KINEMA_ZENOH_CONNECT", raising=False)
    router = tmp_path / "kinema-router.json5"
    router.write_text(
        '{mode: "router", listen: {endpoints: ["tcp/127.0.0.1:7500", "tls/192.168.1.10:7501"]}}'
    )
    monkeypatch.setenv("KINEMA_ZENOH_CONFIG", str(router))
    plan = plan_router(None)
    assert plan.listen == ("tcp/127.0.0.1:7500", "tls/192.168.1.10:7501")
    assert plan.local == "tcp/127.0.0.1:7500" and plan.config_file == router
    assert plan_router("tcp/127.0.0.1:7600").listen == ("tcp/127.0.0.1:7600",)  # --connect wins


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--client", "bad name"], "bad client name 'bad name'"),
        (["--address", "not*an/address"], "bad address 'not*an/address'"),
        (["--local", "tcp/0.0.0.0:7447"], "is not a loopback endpoint"),
    ],
)
def test_security_init_refuses_bad_input_in_one_line(tmp_path: Path, args: list[str], message: str) -> None:
    from kinema.cli.main import main

    argv = ["security", "init", "-d", str(tmp_path / "security"), "-a", "127.0.0.1", *args]
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(argv)
    assert code in (1, 2) and message in err.getvalue() and "Traceback" not in err.getvalue(), err.getvalue()
    assert not (tmp_path / "security" / "ca.key").exists()
