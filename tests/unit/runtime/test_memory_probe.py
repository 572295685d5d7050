"""KINEMA_DEBUG_MEMORY: the agent's hidden memory probe writes a report to its log on SIGUSR2, and is off
without the variable."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import pytest

SCRIPT = """
import logging, os, signal, sys, threading, time
logging.basicConfig(stream=sys.stdout, level=logging.INFO, format="%(name)s %(message)s")
from kinema.process import memory_probe
print("installed", memory_probe.install_from_environment(), flush=True)
if signal.getsignal(signal.SIGUSR2) is signal.SIG_DFL:
    sys.exit(0)
grown = []
for round in range(2):
    grown.append([bytearray(1000) for _ in range(2000)])  # what the second report sees grow
    os.kill(os.getpid(), signal.SIGUSR2)
    time.sleep(0.1)  # the handler runs in the main thread between bytecodes
    for thread in threading.enumerate():
        if thread.name == "kinema-memory-probe":
            thread.join()
"""


def run_probe(value: str | None) -> str:
    env = {k: v for k, v in os.environ.items() if k != "KINEMA_DEBUG_MEMORY"}
    if value is not None:
        env["KINEMA_DEBUG_MEMORY"] = value
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.mark.skipif(not hasattr(signal, "SIGUSR2") or not os.path.exists("/proc/self/smaps"), reason="Linux")
def test_sigusr2_writes_a_memory_report_with_what_grew_since_the_previous_one() -> None:
    out = run_probe("4")
    assert "installed True" in out
    first, second = out.split("kinema.memory memory report\n")[1:3]
    for report in (first, second):
        assert "VmRSS" in report and "resident by mapping" in report
        assert "python objects" in report and "malloc_trim(0) gave back" in report
        assert "modules: " in report and "kinema " in report
    # The second report diffs against the first: the 2 MB of bytearrays made between them show, with the
    # line that made them.
    growth = second.split("net since the previous report: ")[1]
    assert float(growth.split()[0]) > 1500, second  # kB
    assert "<string>:10" in growth.split("kB")[2], second


def test_without_the_variable_the_probe_stays_off() -> None:
    assert run_probe(None).strip() == "installed False"
