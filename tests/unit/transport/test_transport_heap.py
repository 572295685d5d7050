"""The agent's heap gives back what a large message's copies took, whichever thread freed them."""

from __future__ import annotations

import os
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


# Short-lived threads leave their arenas full of free chunks between a few blocks still in use (as an
# objective run's behaviors, result waiters and queries do in the agent): nothing of it is at a heap's
# top, so only a trim gives those pages back. ``trim_soon`` (the agent calls it after each run) must.
FRAGMENTS = """
import sys, threading, time
from kinema.transport import heap

def rss_mb():
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024

heap.bound_heap_growth()
kept = []
# All four hold their blocks at once before letting go: run one after another (a loaded machine), a
# thread would reuse the chunks the one before it freed, and the peak stayed under 100 MB.
together = threading.Barrier(4)

def run():
    blocks = [bytearray(1000) for _ in range(40_000)]  # 40 MB of small blocks in this thread's arena
    together.wait()
    kept.extend(blocks[::16])  # one in 16 outlives the run

baseline = rss_mb()
threads = [threading.Thread(target=run) for _ in range(4)]
for thread in threads:
    thread.start()
for thread in threads:
    thread.join()
fragmented = rss_mb()
if sys.argv[1] == "trim":
    heap.trim_soon()
deadline = time.monotonic() + 10 * heap.TRIM_AFTER_WORK_S + 5
while rss_mb() > fragmented - 50 and time.monotonic() < deadline:
    time.sleep(0.05)
print(round(fragmented - baseline), round(rss_mb() - baseline))
"""


def fragments_kept_mb(mode: str) -> tuple[int, int]:
    done = subprocess.run(
        [sys.executable, "-c", FRAGMENTS, mode], capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr
    fragmented, after = done.stdout.split()
    return int(fragmented), int(after)


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs Linux /proc to read the RSS")
@pytest.mark.skipif(_libc() is None, reason="malloc_trim is glibc's")
def test_trim_soon_gives_back_the_free_chunks_that_finished_threads_left_in_their_arenas() -> None:
    fragmented, after = fragments_kept_mb("trim")
    assert fragmented > 100, f"the threads' blocks took only {fragmented} MB: nothing to give back"
    assert after < fragmented - 50, (
        f"{fragmented} MB resident after the threads, still {after} MB after trim_soon "
        f"(without it: {fragments_kept_mb('none')[1]} MB)"
    )


def test_a_burst_of_trim_soon_schedules_one_trim(monkeypatch: pytest.MonkeyPatch) -> None:
    from kinema.transport import heap

    if heap._malloc_trim() is None:
        pytest.skip("malloc_trim is glibc's")
    monkeypatch.setattr(heap, "_due", [])
    for _ in range(50):
        heap.trim_soon()
    assert len(heap._due) <= 1  # one trim (or none left: it ran already on a very slow machine)


ARENAS = """
import os, sys, threading
from kinema.transport.heap import bound_heap_growth
from kinema.process.memory_probe import _arena_count, _glibc

if sys.argv[1] == "bounded":
    assert bound_heap_growth()

all_allocated = threading.Barrier(12)

def work():
    blocks = [bytearray(200) for _ in range(20_000)]  # small blocks, from this thread's arena
    del blocks[::2]
    # all alive at once, as the agent's threads are: an exited thread's arena is handed to the next one
    all_allocated.wait(60)

threads = [threading.Thread(target=work) for _ in range(12)]
for thread in threads:
    thread.start()
for thread in threads:
    thread.join()
print(_arena_count(_glibc()))
"""


@pytest.mark.skipif(_libc() is None, reason="the arena cap is glibc's (mallopt)")
def test_many_threads_share_a_few_heaps_once_the_heap_is_bounded() -> None:
    # Each arena keeps its own free chunks; the agent's threads mostly wait on Python's lock, so an arena
    # per thread only spread 35 MB of free chunks over 16 heaps.
    env = {key: value for key, value in os.environ.items() if key != "MALLOC_ARENA_MAX"}

    def arenas(mode: str) -> int:
        done = subprocess.run(
            [sys.executable, "-c", ARENAS, mode], capture_output=True, text=True, timeout=120, env=env
        )
        assert done.returncode == 0, done.stderr
        return int(done.stdout.strip())

    assert arenas("bounded") <= 2
    assert arenas("default") > 2  # glibc gives threads arenas of their own (up to 8 per core)
