"""A process that reads a cell's frequent mid-sized messages does not come to hold the sender's pool.

zenoh sends a message through the sender's shared-memory pool once it is larger than a threshold (3 kB by
default), at advancing offsets, so a reader of many such messages touched the whole 16 MiB pool: the agent
held 16 MB of the driver's pool resident, and more in zenoh's receive buffers, for transforms and node
tables a few kB each. Kinema's sessions keep shared memory for large payloads (camera images, clouds).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from kinema.transport import free_endpoint

KEY = "kinema_test/mid_sized"
COUNT = 1500
SIZE = 10_000  # a transform tree or a node table of a large objective

READER = f"""
import sys, threading, time
from kinema.transport import host_router
count = [0]
def on_sample(sample):
    count[0] += 1
with host_router(sys.argv[1]) as session:
    subscriber = session.zenoh.declare_subscriber("{KEY}", on_sample)
    print("ready", flush=True)
    sys.stdin.readline()  # the writer is done; what reaches us has arrived within a moment
    settled, last = time.monotonic() + 1.0, -1
    while count[0] != last or time.monotonic() < settled:
        last = count[0]
        time.sleep(0.2)
    if count[0] < {COUNT}:
        sys.exit(f"received {{count[0]}} of {COUNT} messages")
    resident_kb, mapping = 0, ""
    for line in open("/proc/self/smaps"):
        fields = line.split()
        if "-" in fields[0] and len(fields) >= 5 and ":" in fields[3]:
            mapping = fields[5] if len(fields) > 5 else ""
        elif fields[0] == "Rss:" and mapping.endswith(".zenoh"):
            resident_kb += int(fields[1])
    print(resident_kb, flush=True)
    subscriber.undeclare()
"""

WRITER = f"""
import sys, time
import zenoh
from kinema.transport import open_session
with open_session(sys.argv[1]) as session:
    # Every message arrives, on a loaded machine too: the pool's offsets advance with each one sent.
    publisher = session.zenoh.declare_publisher("{KEY}", congestion_control=zenoh.CongestionControl.BLOCK)
    time.sleep(0.5)  # the route to the reader is in place
    for number in range({COUNT}):
        publisher.put(bytes([number % 256]) * {SIZE})
        if number % 100 == 0:
            time.sleep(0.005)  # as a cell sends them: a stream, not one burst
    time.sleep(1.0)
"""


@pytest.mark.skipif(not Path("/proc/self/smaps").exists(), reason="needs Linux /proc to read the memory")
def test_a_reader_of_many_mid_sized_messages_holds_none_of_the_senders_shared_memory() -> None:
    endpoint = free_endpoint()
    reader = subprocess.Popen(
        [sys.executable, "-c", READER, endpoint],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert reader.stdout is not None and reader.stdout.readline().strip() == "ready"
        writer = subprocess.run(
            [sys.executable, "-c", WRITER, endpoint], capture_output=True, text=True, timeout=120
        )
        assert writer.returncode == 0, writer.stderr
        out, err = reader.communicate("done\n", timeout=60)
    finally:
        reader.kill()
    assert reader.returncode == 0, err
    resident_kb = int(out.split()[-1])
    assert resident_kb < 1024, f"the reader holds {resident_kb} kB of shared memory for {COUNT} x 10 kB"
