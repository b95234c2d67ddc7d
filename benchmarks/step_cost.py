"""Per-step cost of every FMU against its minimal twin built the same way.

``python -m benchmarks.step_cost [MODELS_DIR]``: for each catalog model and FMI version, the
FMU and a twin with the same variables but no physics (:mod:`minimal_models`) are built
with :func:`fmu_harness.build.build`; both are stepped through fmpy's low-level API (set
the Real inputs, doStep, get the Real outputs, each one batched call) at their default inputs,
in alternating rounds within one run; the best round of each gives microseconds per step and the ratio.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from benchmarks import minimal_models
from benchmarks.timing import machine
from driveline.catalog import MODELS
from fmu_harness.build import build
from fmu_harness.runner import FmuInstance

STEPS, ROUNDS = 2000, 7
VARIANTS = {"TripodCoupling": {"closed form": {"kinematics": 0}, "exact": {"kinematics": 1}}}


class Stepper:
    """One FMU instance, stepped with one batched set of the Real inputs, doStep and one
    batched get of the Real outputs per step."""

    def __init__(self, path: Path, start_values: dict[str, float], inputs: list[str]):
        self.instance = FmuInstance(path)
        self.instance.initialize(start_values)
        real = ("Real", "Float64")
        references = lambda names: [self.instance.variables[n].valueReference for n in names]  # noqa: E731
        self.inputs = references(inputs)
        self.outputs = references([n for n in self.instance.outputs() if self.instance.variables[n].type in real])
        self.values = self.instance.get(inputs)
        self.step_size = float(self.instance.description.defaultExperiment.stepSize)
        self.time = 0.0

    def round(self) -> float:
        """Microseconds per step over ``STEPS`` steps."""
        fmu, fmi3 = self.instance.fmu, self.instance.fmi3
        set_real = fmu.setFloat64 if fmi3 else fmu.setReal
        get_real = fmu.getFloat64 if fmi3 else fmu.getReal
        start = time.perf_counter()
        for _ in range(STEPS):
            set_real(self.inputs, self.values)
            fmu.doStep(self.time, self.step_size)
            get_real(self.outputs)
            self.time += self.step_size
        return (time.perf_counter() - start) / STEPS * 1e6


def compare(fmu: Path, twin: Path, start_values: dict[str, float], inputs: list[str]) -> tuple[float, float]:
    """Best round of each, the two FMUs' rounds alternating so that both see the same load."""
    ours, floor = Stepper(fmu, start_values, inputs), Stepper(twin, start_values, inputs)
    try:
        rounds = [(ours.round(), floor.round()) for _ in range(ROUNDS)]
    finally:
        ours.instance.close()
        floor.instance.close()
    return min(r[0] for r in rounds), min(r[1] for r in rounds)


def main() -> None:
    print(f"Per-step cost (set inputs, doStep, get outputs) via fmpy; {machine()}")
    print("| FMU | FMI | variant | us/step | minimal twin us/step | ratio |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        dest = Path(folder)
        for fmi in ("2", "3"):
            for name, model in MODELS.items():
                fmu = build(name, dest, fmi)
                twin_name = f"Minimal{name}"
                twin = build(twin_name, dest, fmi, getattr(minimal_models, twin_name))
                inputs = [v.name for v in model.spec.of("input")]
                for variant, start_values in VARIANTS.get(name, {"default": {}}).items():
                    ours, floor = compare(fmu, twin, start_values, inputs)
                    print(f"| {name} | {fmi}.0 | {variant} | {ours:.1f} | {floor:.1f} | {ours / floor:.2f} |", flush=True)


if __name__ == "__main__":
    main()
