"""Soak: many steps of each FMU in one process, with the resident-set growth.

``python -m benchmarks.soak [STEPS] [MODELS_DIR]`` (default 10^6 steps): every FMU found in
``MODELS_DIR`` and ``MODELS_DIR/fmi3``, its default inputs, stepped through fmpy's low-level
API. The resident set is read after a warm-up of 10^4 steps and at the end.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from benchmarks.timing import machine, resident_set_bytes
from fmu_harness.runs.runner import FmuInstance

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


def main(steps: int = 1_000_000, models: Path = Path("models")) -> None:
    print(f"Soak: {steps} steps per FMU, one process; {machine()}")
    print("| FMU | FMI | wall time [s] | us/step | RSS after warm-up [MiB] | RSS growth [KiB] |")
    print("|---|---|---|---|---|---|")
    for folder, version in ((models, "2.0"), (models / "fmi3", "3.0")):
        for path in sorted(folder.glob("*.fmu")):
            seconds, warm, end = soak(path, steps)
            print(f"| {path.stem} | {version} | {seconds:.1f} | {seconds / steps * 1e6:.1f} | "
                  f"{warm / 2**20:.1f} | {(end - warm) / 2**10:.0f} |", flush=True)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000, Path(sys.argv[2]) if len(sys.argv) > 2 else Path("models"))
