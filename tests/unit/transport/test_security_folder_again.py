"""``kinema security init`` run again adds clients: the ones an earlier run gave access keep it (a new user
ran it three times, each with one new client, and the first two lost their access)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from kinema.transport.security_folder import CLIENTS, holders, init_security_folder


def test_running_it_again_adds_clients_and_keeps_the_earlier_ones(tmp_path: Path) -> None:
    folder = tmp_path / "security"
    init_security_folder(folder, addresses=["127.0.0.1"], clients=["laptop"])
    laptop = (folder / CLIENTS / "laptop.json5").read_text()
    init_security_folder(folder, addresses=["127.0.0.1"], clients=[], machines=["second-pc"])
    init_security_folder(folder, addresses=["127.0.0.1"], clients=["tablet"], xml_clients=["tablet"])
    assert sorted(holders(folder) or []) == [
        ("laptop", "operator"),
        ("second-pc", "machine (everything)"),
        ("tablet", "operator with XML"),
    ]
    # The earlier client's file (its key and certificate, signed by the CA that was kept) is left as is.
    assert (folder / CLIENTS / "laptop.json5").read_text() == laptop
    # A client named again takes the role given now.
    init_security_folder(folder, addresses=["127.0.0.1"], clients=["tablet"])
    assert ("tablet", "operator") in (holders(folder) or [])
    # --force makes a new CA: the earlier certificates are worthless, so only the clients named remain.
    init_security_folder(folder, addresses=["127.0.0.1"], clients=["laptop"], force=True)
    assert holders(folder) == [("laptop", "operator")]


def test_adding_a_client_while_kinema_runs_says_to_restart_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user added a client while the runtime ran; the router still had the old rules, and the new
    client only read "no Kinema runtime answered"."""
    from kinema.cli.main import main
    from kinema.runtime.instance import InstanceRecord

    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        InstanceRecord(sleeper.pid, "tls/127.0.0.1:7448", str(tmp_path), "lab_sim").save()
        code = main(
            [
                "security",
                "init",
                "-d",
                str(tmp_path / "security"),
                "--address",
                "127.0.0.1",
                "--client",
                "tablet",
            ]
        )
        err = capsys.readouterr().err
    finally:
        sleeper.kill()
        sleeper.wait(5)
    assert code == 0
    assert f"note: the running kinema run (pid {sleeper.pid}, config lab_sim) read the access rules" in err
    assert "restart it (`kinema down`" in err
