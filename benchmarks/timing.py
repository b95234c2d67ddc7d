"""Timing and machine helpers shared by the benchmarks (not part of the test suite)."""

from __future__ import annotations

import os
import platform
import time
from collections.abc import Callable


def best_of(function: Callable[[], object], repeats: int = 5, clock: Callable[[], float] = time.perf_counter) -> float:
    """Smallest time of ``repeats`` calls [s] on ``clock`` (wall time by default): the least disturbed by other load."""
    times = []
    for _ in range(repeats):
        start = clock()
        function()
        times.append(clock() - start)
    return min(times)


def resident_set_bytes() -> int:
    """Current resident set size of this process (Linux /proc; 0 where unavailable)."""
    try:
        with open("/proc/self/statm") as handle:
            return int(handle.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except OSError:
        return 0


def cpu_model() -> str:
    """The processor's name (Linux /proc/cpuinfo; else what :mod:`platform` knows)."""
    try:
        with open("/proc/cpuinfo") as handle:
            for line in handle:
                if line.startswith("model name"):
                    return f"{line.split(':', 1)[1].strip()} ({platform.machine()})"
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine() -> str:
    """CPU model, core count and Python version: ``Intel(R) Xeon(R) Processor (x86_64), 2 cores, Python 3.11.7``."""
    return f"{cpu_model()}, {os.cpu_count()} cores, Python {platform.python_version()}"
