"""Timing of repeated calls for the latency benchmarks: samples in ns, and their p50/p99.

Used by ``sdk_latency.py`` and ``transport_rtt.py`` (run as scripts, so ``benchmarks/`` is on the path).
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable

MICROSECOND_NS = 1_000
MILLISECOND_NS = 1_000_000


def time_calls(call: Callable[[], object], calls: int, warmup: int) -> list[int]:
    """Run ``call`` ``warmup`` times untimed, then ``calls`` times; return each duration in ns."""
    for _ in range(warmup):
        call()
    samples = []
    for _ in range(calls):
        start = time.perf_counter_ns()
        call()
        samples.append(time.perf_counter_ns() - start)
    return samples


def percentiles(samples_ns: list[int], unit_ns: int) -> tuple[float, float]:
    """(p50, p99) of ``samples_ns`` in units of ``unit_ns`` (``MICROSECOND_NS``, ``MILLISECOND_NS``)."""
    ordered = sorted(samples_ns)
    p50 = statistics.median(ordered) / unit_ns
    p99 = ordered[min(len(ordered) - 1, int(len(ordered) * 0.99))] / unit_ns
    return p50, p99
