"""Wall time of one parameter sweep on a local Dask cluster of 1 and of 2 worker processes.

Usage: ``python -m benchmarks.sweep_scaling [--fmu models/TripodCoupling.fmu] [--repeat 3]``
after ``python build_fmu.py``. Not part of the test suite. Each measurement starts a fresh
cluster first and times :func:`fmu_harness.runs.sweep.sweep` from shipping the FMU to the finished
table (so each worker's first extraction and imports count); the best of ``--repeat``
alternating measurements is printed, which damps the noise of other load on the machine.
"""

from __future__ import annotations

import time
from pathlib import Path

from benchmarks import report
from fmu_harness.runs.sweep import Timing, grid, open_client, sweep
from fmu_harness.console import summary

AXES = {
    "beta": [0.05 * k for k in range(1, 13)],
    "omega_in": [100.0, 150.0, 200.0, 250.0],
    "r": [0.02, 0.026],
    "kinematics": [1],
}
TIMING = Timing(turns=4)
"""96 points, each four input turns in 4 x 360 steps with the exact kinematics."""


def wall_time(fmu: Path, workers: int) -> float:
    """Seconds for the sweep of :data:`AXES` on a fresh local cluster of ``workers`` processes."""
    points = grid(AXES)
    with open_client(workers=workers) as client:
        start = time.perf_counter()
        table = sweep(client, fmu, points, TIMING)
        elapsed = time.perf_counter() - start
    failed = table.column("status").to_pylist().count("failed")
    if failed:
        raise RuntimeError(f"{failed} of {len(points)} runs failed")
    return elapsed


def main() -> None:
    parser = report.parser(summary(__doc__))
    parser.add_argument("--fmu", type=Path, default=Path("models") / "TripodCoupling.fmu")
    parser.add_argument("--repeat", type=int, default=3, help="measurements per cluster size")
    args = parser.parse_args()
    measurement = report.Measurement()
    times = [(wall_time(args.fmu, 1), wall_time(args.fmu, 2)) for _ in range(args.repeat)]
    one, two = (min(column) for column in zip(*times))
    lines = ["| workers | wall time [s] |", "|---|---|", f"| 1 | {one:.2f} |", f"| 2 | {two:.2f} |",
             f"\nSpeed-up with 2 workers: {one / two:.2f}x."]
    report.publish("benchmark-sweep-scaling", measurement.stamp(
        f"{len(grid(AXES))} runs of {args.fmu.stem}, best of {args.repeat} alternating measurements"),
        "\n".join(lines), args.update_docs)


if __name__ == "__main__":
    main()
