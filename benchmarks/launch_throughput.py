"""CPU time of one vehicle launch (``VehicleLaunch.ssp``, native FMUs) per master and step, as a sweep runs it.

Usage: ``python -m benchmarks.launch_throughput [--package models/native/VehicleLaunch.ssp]
[--stop-time 4] [--repeat 3] [--update-docs]`` after ``python build_fmu.py``. Not part of the test
suite. Each master runs the package's launch in this process through
:func:`fmu_harness.runs.system_sweep.run_system`, recording the outputs of the sweep's metrics, and
the CPU time of the whole run (instantiation included; ``time.process_time``, every thread of the
process, so libcosim's worker threads count), the least of ``--repeat`` alternating measurements
(other load on the machine only adds), is printed beside its step and its ratio to the goal of 2 s of
CPU per 4 s launch.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from benchmarks import report
from fmu_harness.runs.system_sweep import SystemInterface, UnpackedSystem, run_system
from fmu_harness.console import summary

GOAL = 2.0 / 4.0
"""CPU seconds per simulated second of launch: at most 2 s of CPU per 4 s launch (issue 29)."""
OPTIONS = (("jacobi", 1e-4), ("libcosim", 1e-4), ("gauss-seidel", 2e-4), ("gauss-seidel", 4e-4),
           ("gauss-seidel", 8e-4))
"""(master, step): the package's step in the Jacobi masters (the accuracy of docs/vehicle_launch.md),
Gauss-Seidel at steps up to its stability limit."""


def cpu_seconds(interface: SystemInterface, unpacked: UnpackedSystem, master: str, step: float, stop_time: float,
                scratch: Path) -> float:
    """CPU seconds of one launch of ``stop_time`` by ``master`` at ``step``."""
    start = time.process_time()
    run_system(interface, unpacked, {}, stop_time, step, master, scratch)
    return time.process_time() - start


def launch_arguments(doc: str | None) -> argparse.Namespace:
    """The command line of a benchmark of whole launches: ``--package``, ``--stop-time``, ``--repeat``."""
    parser = report.parser(summary(doc))
    parser.add_argument("--package", type=Path, default=Path("models") / "native" / "VehicleLaunch.ssp")
    parser.add_argument("--stop-time", type=float, default=4.0, help="launch length [s] (default 4)")
    parser.add_argument("--repeat", type=int, default=3, help="measurements of each (default 3)")
    return parser.parse_args()


def main() -> None:
    args = launch_arguments(__doc__)
    measurement = report.Measurement()
    interface = SystemInterface.of(args.package)
    lines = ["| master | step [s] | steps | CPU per launch [s] | CPU per step [us] | of the goal |",
             "|---|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory(prefix="launch-throughput-") as scratch:
        unpacked = UnpackedSystem.write(args.package.read_bytes(), Path(scratch) / "package", interface)
        measured = [[cpu_seconds(interface, unpacked, master, step, args.stop_time, Path(scratch))
                     for master, step in OPTIONS] for _ in range(args.repeat)]
        for (master, step), seconds in zip(OPTIONS, map(min, zip(*measured))):
            steps = round(args.stop_time / step)
            lines.append(f"| {master} | {step:g} | {steps} | {seconds:.2f} | {1e6 * seconds / steps:.0f} | "
                         f"{seconds / (GOAL * args.stop_time):.2f} |")
    report.publish("benchmark-launch-throughput", measurement.stamp(
        f"{args.stop_time:g} s launches of {args.package.stem} (native FMUs), one process, CPU by time.process_time, "
        f"least of {args.repeat} alternating measurements"), "\n".join(lines), args.update_docs)


if __name__ == "__main__":
    main()
