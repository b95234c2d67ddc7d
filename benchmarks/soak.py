"""Soak: many steps of each FMU in one process, with the resident-set growth.

``python -m benchmarks.soak [STEPS] [MODELS_DIR]`` (default 10^6 steps): every FMU found in
``MODELS_DIR`` and ``MODELS_DIR/fmi3``, its default inputs, stepped through fmpy's low-level
API. The resident set is read after a warm-up of 10^4 steps and at the end.
"""

from __future__ import annotations

import time
from pathlib import Path

from benchmarks import report
from benchmarks.timing import resident_set_bytes
from fmu_harness.runs.runner import FmuInstance
from fmu_harness.console import summary

WARM_UP = 10_000


def soak(path: Path, steps: int) -> tuple[float, int, int]:
    """(seconds, resident set after warm-up, resident set at the end) for ``steps`` steps."""
    with FmuInstance(path) as fmu:
        fmu.initialize()
        outputs = fmu.outputs()
        step_size = fmu.description.defaultExperiment.stepSize or 1e-3
        step_size = float(step_size)
        for _ in range(WARM_UP):
            fmu.step(step_size)
            fmu.get(outputs)
        warm = resident_set_bytes()
        start = time.perf_counter()
        for _ in range(steps):
            fmu.step(step_size)
            fmu.get(outputs)
        return time.perf_counter() - start, warm, resident_set_bytes()


def main() -> None:
    arguments = report.parser(summary(__doc__))
    arguments.add_argument("steps", nargs="?", type=int, default=1_000_000, help="steps per FMU")
    arguments.add_argument("models", nargs="?", type=Path, default=Path("models"), help="folder of the FMUs")
    args = arguments.parse_args()
    measurement = report.Measurement()
    lines = ["| FMU | FMI | wall time [s] | µs/step | RSS after warm-up [MiB] | RSS growth [KiB] |", "|---|---|---|---|---|---|"]
    for folder, version in ((args.models, "2.0"), (args.models / "fmi3", "3.0")):
        for path in sorted(folder.glob("*.fmu")):
            seconds, warm, end = soak(path, args.steps)
            lines.append(f"| {path.stem} | {version} | {seconds:.1f} | {seconds / args.steps * 1e6:.1f} | "
                         f"{warm / 2**20:.1f} | {(end - warm) / 2**10:.0f} |")
    report.publish("benchmark-soak", measurement.stamp(f"{args.steps} steps per FMU after {WARM_UP} warm-up steps, "
                                                       "one process"), "\n".join(lines), args.update_docs)


if __name__ == "__main__":
    main()
