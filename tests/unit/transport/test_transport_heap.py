"""The agent's heap gives back what a large message's copies took, whichever thread freed them."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from kinema.transport.heap import _libc

# Run in a fresh interpreter: mallopt is process-wide, and glibc's thresholds depend on what the
# process freed before. A thread (not the main one: its own arena) makes and drops 10-30 MB blocks,
# as zenoh's threads do with a large message's fragments and copies.
SCRIPT = """
import sys, threading
from kinema.transport.heap import bound_heap_growth, release_free_memory

MB = 1 << 20

def rss_mb():
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024

if sys.argv[1] == "bounded":
    assert bound_heap_growth()

def receive():
    for size in (10, 20, 30, 20, 10):
        block = bytearray(size * MB)
        block[::4096] = b"x" * len(block[::4096])  # resident, as a received payload is
        del block

baseline = rss_mb()
thread = threading.Thread(target=receive)
thread.start()
thread.join()
release_free_memory()
print(round(rss_mb() - baseline, 1))
"""


def kept_mb(mode: str) -> float:
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT, mode], capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr
    return float(done.stdout.strip())


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs Linux /proc to read the RSS")
@pytest.mark.skipif(_libc() is None, reason="the heap thresholds are glibc's (mallopt)")
def test_blocks_freed_by_another_thread_leave_no_memory_behind_once_the_heap_is_bounded() -> None:
    bounded = kept_mb("bounded")
    default = kept_mb("default")  # glibc 2.36 keeps about 20 MB here
    assert bounded < 5.0, (
        f"the process kept {bounded} MB after freeing 10-30 MB blocks on a thread "
        f"(with glibc's default thresholds it kept {default} MB)"
    )
