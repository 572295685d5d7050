"""A memory probe for finding what grows in a long-running process (a debugging aid, off by default).

With ``KINEMA_DEBUG_MEMORY`` set in its environment, the agent process installs the probe at start:
each ``SIGUSR2`` then writes one report to the process's log (the run folder's ``agent.log`` under
``kinema run``), at WARNING so it shows whatever the log level. A report holds

* the resident memory (``/proc/self/status``) and where it sits (``/proc/self/smaps``: the main heap,
  anonymous mappings such as glibc's thread arenas and native libraries' own pools, file mappings);
* glibc's allocator (``mallinfo2``): bytes in use, bytes free inside the heaps (fragmentation), bytes
  in blocks mapped on their own, and the number of arenas;
* the modules imported, counted by top-level package (what an import costs stays resident);
* the Python objects by type whose count changed since the previous report;
* what ``malloc_trim(0)``, run right then, gave back and how long it took (the part of the RSS that
  was free chunks scattered in the heaps);
* with ``KINEMA_DEBUG_MEMORY=N`` (N >= 1), started before anything else is imported: ``tracemalloc``
  with N frames per allocation, and the 15 places whose Python-allocated memory grew most since the
  previous report (numpy arrays included; memory allocated by C++ libraries is not traced).

Use: ``KINEMA_DEBUG_MEMORY=8 kinema run --headless``, run the workload a while, ``kill -USR2 <agent
pid>`` (the baseline), run it more, ``kill -USR2`` again and read the second report. Tracing costs
memory and time; never set it in production.
"""

from __future__ import annotations

import collections
import ctypes
import ctypes.util
import gc
import logging
import os
import re
import signal
import sys
import threading
import time
import tracemalloc
from typing import Any

ENV = "KINEMA_DEBUG_MEMORY"

log = logging.getLogger("kinema.memory")

_lock = threading.Lock()
_previous_counts: collections.Counter[str] = collections.Counter()
_previous_snapshot: tracemalloc.Snapshot | None = None


def install_from_environment() -> bool:
    """Install the probe when ``KINEMA_DEBUG_MEMORY`` is set (call first thing in ``main``): ``0`` or a word
    reports without tracing Python allocations, ``N`` >= 1 traces them with N frames.

    Returns True when installed. A value that is not a number installs the probe without tracemalloc.
    """
    value = os.environ.get(ENV, "").strip()
    if not value:
        return False
    frames = int(value) if value.isdigit() else 0
    if frames > 0 and not tracemalloc.is_tracing():
        tracemalloc.start(frames)
    signal.signal(
        signal.SIGUSR2, lambda *_: threading.Thread(target=_report, name="kinema-memory-probe").start()
    )
    log.warning("memory probe on (%s=%s): SIGUSR2 writes a memory report here", ENV, value)
    return True


def _report() -> None:
    with _lock:
        try:
            log.warning("memory report\n%s", report())
        except Exception:  # a debugging aid never takes the process down
            log.exception("memory report failed")


def report() -> str:
    """The text of one report (see the module's docstring); each call diffs against the previous one."""
    global _previous_snapshot
    lines = [_status(), _smaps(), _mallinfo()]
    counts = collections.Counter(type(o).__qualname__ for o in gc.get_objects())
    changed = sorted(
        (
            (n, counts[n] - _previous_counts[n])
            for n in counts | _previous_counts
            if counts[n] != _previous_counts[n]
        ),
        key=lambda item: -abs(item[1]),
    )
    packages = collections.Counter(name.partition(".")[0] for name in list(sys.modules))
    top = ", ".join(f"{name} {count}" for name, count in packages.most_common(12))
    lines.append(f"modules: {sum(packages.values())} imported; most from {top}")
    lines.append(f"python objects: {sum(counts.values())} tracked; changed since the previous report:")
    lines += [f"  {delta:+8d}  {name} ({counts[name]})" for name, delta in changed[:15]] or ["  none"]
    _previous_counts.clear()
    _previous_counts.update(counts)
    if tracemalloc.is_tracing():
        snapshot = tracemalloc.take_snapshot().filter_traces(
            [
                tracemalloc.Filter(False, tracemalloc.__file__),
                tracemalloc.Filter(False, __file__, all_frames=True),
            ]
        )
        traced, peak = tracemalloc.get_traced_memory()
        lines.append(f"tracemalloc: {traced / 1e6:.1f} MB traced (peak {peak / 1e6:.1f} MB)")
        if _previous_snapshot is not None:
            stats = snapshot.compare_to(_previous_snapshot, "traceback")
            grown = sorted(stats, key=lambda s: -s.size_diff)[:15]
            lines.append(f"  net since the previous report: {sum(s.size_diff for s in stats) / 1e3:+.1f} kB")
            for stat in grown:
                lines.append(f"  {stat.size_diff / 1e3:+9.1f} kB {stat.count_diff:+6d} blocks")
                lines += [f"      {frame.filename}:{frame.lineno}" for frame in stat.traceback]
        _previous_snapshot = snapshot
    lines.append(_trim())
    return "\n".join(lines)


def _trim() -> str:
    """Trim the heap now and say what that gave back: the part of the RSS that was free chunks."""
    libc = _glibc()
    if libc is None or not hasattr(libc, "malloc_trim"):
        return "malloc_trim: not glibc"
    before = _rss_kb()
    started = time.perf_counter()
    libc.malloc_trim(0)
    took = time.perf_counter() - started
    return f"malloc_trim(0) gave back {(before - _rss_kb()) / 1024:.1f} MB in {took * 1e3:.1f} ms"


def _rss_kb() -> int:
    with open("/proc/self/status") as status:
        return next(int(line.split()[1]) for line in status if line.startswith("VmRSS:"))


def _status() -> str:
    fields = {}
    with open("/proc/self/status") as status:
        for line in status:
            name, _, value = line.partition(":")
            fields[name] = value.strip()
    return " ".join(f"{name} {fields.get(name, '?')}" for name in ("VmRSS", "RssAnon", "RssFile", "Threads"))


_MAPPING = re.compile(r"^[0-9a-f]+-[0-9a-f]+ \S+ \S+ \S+ \S+\s*(.*)$")


def _smaps() -> str:
    """Resident kB by kind of mapping."""
    kinds: collections.Counter[str] = collections.Counter()
    anon_count = 0
    kind = ""
    with open("/proc/self/smaps") as smaps:
        for line in smaps:
            match = _MAPPING.match(line)
            if match:
                name = match.group(1)
                kind = (
                    "anon"
                    if not name
                    else name
                    if name.startswith("[")
                    else "library"
                    if ".so" in name
                    else "file"
                )
                anon_count += kind == "anon"
            elif line.startswith("Rss:"):
                kinds[kind] += int(line.split()[1])
    parts = ", ".join(f"{name} {kb / 1024:.1f} MB" for name, kb in kinds.most_common(5))
    return f"resident by mapping: {parts} ({anon_count} anonymous mappings)"


class _MallInfo2(ctypes.Structure):
    _fields_ = [
        (name, ctypes.c_size_t)
        for name in (
            "arena",
            "ordblks",
            "smblks",
            "hblks",
            "hblkhd",
            "usmblks",
            "fsmblks",
            "uordblks",
            "fordblks",
            "keepcost",
        )
    ]


def _glibc() -> Any:
    name = ctypes.util.find_library("c")
    try:
        return ctypes.CDLL(name) if name else None
    except OSError:
        return None


def _mallinfo() -> str:
    libc = _glibc()
    if libc is None or not hasattr(libc, "mallinfo2"):
        return "glibc allocator: no mallinfo2 here"
    libc.mallinfo2.restype = _MallInfo2
    info = libc.mallinfo2()
    arenas = "?"
    if hasattr(libc, "malloc_info") and hasattr(libc, "open_memstream"):
        arenas = str(_arena_count(libc))
    return (
        f"glibc allocator: {info.uordblks / 1e6:.1f} MB in use, {info.fordblks / 1e6:.1f} MB free in "
        f"{info.ordblks} chunks inside {info.arena / 1e6:.1f} MB of heaps, {info.hblkhd / 1e6:.1f} MB in "
        f"{info.hblks} blocks mapped on their own, {arenas} arenas"
    )


def _arena_count(libc: Any) -> int:
    buffer, size = ctypes.c_char_p(), ctypes.c_size_t()
    libc.open_memstream.restype = ctypes.c_void_p
    stream = libc.open_memstream(ctypes.byref(buffer), ctypes.byref(size))
    libc.malloc_info(0, ctypes.c_void_p(stream))
    libc.fclose(ctypes.c_void_p(stream))
    text = ctypes.string_at(buffer, size.value).decode()
    libc.free(buffer)
    return text.count("<heap nr=")
