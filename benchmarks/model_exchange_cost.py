"""Cost of the native FMUs' Model Exchange interface: one evaluation and one Jacobian as a host
without directional derivatives forms it.

``python -m benchmarks.model_exchange_cost``: for each model with a C port and each FMI version,
builds the native FMU and runs it through fmpy's low-level API in continuous-time mode. One
evaluation is what a solver's right-hand side and the outputs cost: set the time, set the states,
get the derivatives, get the Real outputs (four calls). One Jacobian of the derivatives and outputs
with respect to the states and Real inputs, by forward differences: the evaluation at the point
and one per state and input moved (CPU time of this process, best of alternating rounds).
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable, Iterator
from ctypes import POINTER, c_double
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description

from benchmarks import report
from driveline.catalog import MODELS
from fmu_harness.packaging import native
from fmu_harness.console import summary
from fmu_harness.runs.runner import LoggedInstance

CALLS, ROUNDS = 2000, 7


class ContinuousTime:
    """A Model Exchange instance in continuous-time mode at its start values."""

    def __init__(self, fmu: Path, fmi: str, unzipdir: Path) -> None:
        description = read_model_description(str(fmu))
        self.fmu = LoggedInstance(extract(str(fmu), unzipdir=str(unzipdir)), description, "ModelExchange", "instance",
                                  lambda text: None).fmu
        if fmi == "3":
            self.fmu.enterInitializationMode(startTime=0.0)
        else:
            self.fmu.setupExperiment(startTime=0.0)
            self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()
        self.fmu.enterContinuousTimeMode()
        spec = MODELS[description.modelName].spec
        references = {v.name: v.valueReference for v in description.modelVariables}
        self.outputs = [references[v.name] for v in spec.of("output") if v.type == "Real"]
        self.inputs = [references[v.name] for v in spec.of("input") if v.type == "Real"]
        self.states = np.zeros(len(spec.states))
        self.derivatives = np.zeros(len(spec.states))
        self.fmu.getContinuousStates(self._pointer(self.states), self.states.size)
        self.get_derivatives = self.fmu.getContinuousStateDerivatives if fmi == "3" else self.fmu.getDerivatives
        self.get_real = self.fmu.getFloat64 if fmi == "3" else self.fmu.getReal
        self.set_real = self.fmu.setFloat64 if fmi == "3" else self.fmu.setReal
        self.input_values = self.get_real(self.inputs)
        self.time = 0.0

    @staticmethod
    def _pointer(values: np.ndarray):
        return values.ctypes.data_as(POINTER(c_double))

    def evaluate(self, states: np.ndarray) -> None:
        """Derivatives and outputs at ``states`` and the next time."""
        self.time += 1e-6
        self.fmu.setTime(self.time)
        self.fmu.setContinuousStates(self._pointer(states), states.size)
        self.get_derivatives(self._pointer(self.derivatives), self.derivatives.size)
        self.get_real(self.outputs)

    def jacobian(self) -> None:
        """Forward differences: the evaluation at the point, then one per state and Real input moved."""
        self.evaluate(self.states)
        for k in range(self.states.size):
            self.evaluate(self.states + 1e-7 * (np.arange(self.states.size) == k))
        for k, reference in enumerate(self.inputs):
            self.set_real([reference], [self.input_values[k] * (1.0 + 1e-7) + 1e-7])
            self.evaluate(self.states)
            self.set_real([reference], [self.input_values[k]])

    def rounds(self) -> tuple[float, float]:
        """Microseconds per evaluation and per Jacobian, best of ``ROUNDS`` rounds of ``CALLS``."""
        return best_microseconds(lambda: self.evaluate(self.states)), best_microseconds(self.jacobian)


def best_microseconds(work: Callable[[], object], calls: int = CALLS) -> float:
    """Microseconds per call of ``work``, best of ``ROUNDS`` rounds of ``calls``."""
    times = []
    for _ in range(ROUNDS):
        start = time.process_time()
        for _ in range(calls):
            work()
        times.append((time.process_time() - start) / calls * 1e6)
    return min(times)


def instances(dest: Path, names: list[str]) -> Iterator[tuple[str, str, ContinuousTime]]:
    """A continuous-time instance of each of the native FMUs of ``names``, FMI 2.0 then 3.0, built into ``dest``."""
    for fmi in ("2", "3"):
        for name in names:
            fmu = native.build(name, dest, fmi, release=False)
            yield name, fmi, ContinuousTime(fmu, fmi, dest / f"{name}_{fmi}")


def main() -> None:
    args = report.parser(summary(__doc__)).parse_args()
    measurement = report.Measurement()
    lines = ["| FMU | FMI | states | Real inputs | one evaluation µs | one Jacobian (forward differences) µs |",
             "|---|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as folder:
        for name, fmi, model in instances(Path(folder), native.native_models()):
            evaluation, jacobian = model.rounds()
            lines.append(f"| {name} | {fmi}.0 | {model.states.size} | {len(model.inputs)} | {evaluation:.2f} "
                         f"| {jacobian:.2f} |")
    stamp = measurement.stamp(f"CPU time through fmpy, best of {ROUNDS} rounds of {CALLS} calls")
    report.publish("benchmark-model-exchange-cost", stamp, "\n".join(lines), args.update_docs)


if __name__ == "__main__":
    main()
