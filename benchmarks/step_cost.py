"""Per-step cost of every FMU against its minimal twin built the same way, and the harness's
cost against the plain batched fmpy loop.

``python -m benchmarks.step_cost``: for each catalog model and FMI version, the FMU and a twin
with the same variables but no physics (:mod:`minimal_models`) are built with
:func:`fmu_harness.packaging.build`; both are stepped through fmpy's low-level API (set the Real inputs, doStep,
get the Real outputs, each one batched call) at their default inputs. The FMU is also stepped
by :meth:`fmu_harness.runs.runner.FmuInstance.run` for the same Real outputs, with the inputs given
as constants (set once) and as functions of time (sampled and set at every step). All run in
alternating rounds within one run; the best round of each gives microseconds per step, in
CPU time of this process (the FMUs run inside it), which other work on the machine disturbs
less than wall time.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from benchmarks import minimal_models, report
from driveline.catalog import MODELS
from fmu_harness.packaging import build
from fmu_harness.runs.runner import Fmi3Instance, FmuInstance
from fmu_harness.console import summary

STEPS, ROUNDS = 2000, 7
VARIANTS = {"TripodCoupling": {"closed form": {"kinematics": 0}, "exact": {"kinematics": 1}}}


class Stepper:
    """One FMU instance, stepped with one batched set of the Real inputs, doStep and one
    batched get of the Real outputs per step."""

    def __init__(self, path: Path, start_values: dict[str, float], inputs: list[str]):
        self.instance = FmuInstance(path)
        self.instance.initialize(start_values)
        references = lambda names: [self.instance.variables[n].valueReference for n in names]  # noqa: E731
        self.inputs = references(inputs)
        self.outputs = references(real_outputs(self.instance))
        self.values = self.instance.get(inputs)
        self.step_size = float(self.instance.description.defaultExperiment.stepSize)
        self.time = 0.0

    def round(self) -> float:
        """Microseconds per step over ``STEPS`` steps."""
        fmu = self.instance.fmu
        fmi3 = isinstance(self.instance, Fmi3Instance)
        set_real = fmu.setFloat64 if fmi3 else fmu.setReal
        get_real = fmu.getFloat64 if fmi3 else fmu.getReal
        start = time.process_time()
        for _ in range(STEPS):
            set_real(self.inputs, self.values)
            fmu.doStep(self.time, self.step_size)
            get_real(self.outputs)
            self.time += self.step_size
        return (time.process_time() - start) / STEPS * 1e6


def real_outputs(instance: FmuInstance) -> list[str]:
    return [n for n in instance.outputs() if instance.variables[n].type in ("Real", "Float64")]


class HarnessStepper:
    """One FMU instance stepped by the harness's ``run`` for the Real outputs; ``varying``
    passes the inputs as functions of time, else as constants."""

    def __init__(self, path: Path, start_values: dict[str, float], inputs: list[str], varying: bool):
        self.instance = FmuInstance(path)
        self.instance.initialize(start_values)
        values = dict(zip(inputs, self.instance.get(inputs)))
        self.inputs = {k: (lambda t, v=v: v) for k, v in values.items()} if varying else values
        self.outputs = real_outputs(self.instance)
        self.step_size = float(self.instance.description.defaultExperiment.stepSize)

    def round(self) -> float:
        """Microseconds per step over ``STEPS`` steps."""
        stop = self.instance.time + STEPS * self.step_size
        start = time.process_time()
        self.instance.run(stop, self.step_size, self.inputs, self.outputs)
        return (time.process_time() - start) / STEPS * 1e6


def compare(fmu: Path, twin: Path, start_values: dict[str, float], inputs: list[str]) -> list[float]:
    """Best round of each of: the FMU in the batched fmpy loop, the minimal twin in the same loop,
    the FMU through the harness with constant inputs and with inputs as functions of time; their
    rounds alternate so that all see the same load."""
    return best_alternating([
        Stepper(fmu, start_values, inputs),
        Stepper(twin, start_values, inputs),
        HarnessStepper(fmu, start_values, inputs, varying=False),
        HarnessStepper(fmu, start_values, inputs, varying=True),
    ])


def best_alternating(steppers: list[Stepper | HarnessStepper]) -> list[float]:
    """Each stepper's best of ``ROUNDS`` rounds, the rounds alternating between them; closes them."""
    try:
        rounds = [[stepper.round() for stepper in steppers] for _ in range(ROUNDS)]
    finally:
        for stepper in steppers:
            stepper.instance.close()
    return [min(column) for column in zip(*rounds)]


def main() -> None:
    args = report.parser(summary(__doc__)).parse_args()
    measurement = report.Measurement()
    lines = ["| FMU | FMI | variant | fmpy batched µs/step | minimal twin µs/step | model/twin | "
             "harness, constant inputs µs/step | harness/fmpy | harness, inputs f(t) µs/step | harness/fmpy |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    twin_ratios, harness_ratios = [], []
    with tempfile.TemporaryDirectory() as folder:
        dest = Path(folder)
        for fmi in ("2", "3"):
            for name, model in MODELS.items():
                fmu = build(name, dest, fmi)
                twin_name = f"Minimal{name}"
                twin = build(twin_name, dest, fmi, getattr(minimal_models, twin_name))
                inputs = [v.name for v in model.spec.of("input")]
                for variant, start_values in VARIANTS.get(name, {"": {}}).items():
                    ours, floor, constant, varying = compare(fmu, twin, start_values, inputs)
                    twin_ratios.append(ours / floor)
                    harness_ratios += [constant / ours, varying / ours]
                    lines.append(f"| {name} | {fmi}.0 | {variant} | {ours:.1f} | {floor:.1f} | {ours / floor:.2f} | "
                                 f"{constant:.1f} | {constant / ours:.2f} | {varying:.1f} | {varying / ours:.2f} |")
    lines.append(f"\nA step costs {min(twin_ratios):.2f} to {max(twin_ratios):.2f} times the minimal twin's; through "
                 f"the harness {min(harness_ratios):.2f} to {max(harness_ratios):.2f} times the batched fmpy loop.")
    report.publish("benchmark-step-cost", measurement.stamp(f"CPU time, best of {ROUNDS} alternating rounds "
                                                            f"of {STEPS} steps"), "\n".join(lines), args.update_docs)


if __name__ == "__main__":
    main()
