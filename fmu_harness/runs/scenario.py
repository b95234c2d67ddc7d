"""A standard run of any catalog model, shared by the FMI 2.0/3.0 comparison, the importers
and the cross-check references (:func:`standard_run` runs it through fmpy).

Parameters keep their spec start values; every Real input follows a piecewise-linear
signal through its start value, 3 % below it at half time and 2 % above it at the end.
Inputs are sampled at the communication points and held over each step, so every
importer that interpolates the table linearly feeds the FMU the same values.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from driveline.catalog import MODELS
from driveline.variables import ModelSpec

from .runner import FmuInstance

INPUT_FACTORS = (1.0, 0.97, 1.02)
STEPS = 100
MAX_SIGNALS = 10


@dataclass(frozen=True)
class Scenario:
    """Stop time, step size and input breakpoints of one model's standard run."""

    spec: ModelSpec
    stop_time: float
    step_size: float
    breakpoints: np.ndarray
    inputs: Mapping[str, np.ndarray]

    @property
    def steps(self) -> int:
        return int(round(self.stop_time / self.step_size))

    def input_values(self, time: float) -> dict[str, float]:
        return {name: float(np.interp(time, self.breakpoints, values)) for name, values in self.inputs.items()}

    def signals(self) -> dict[str, Callable[[float], float]]:
        """The inputs as functions of time (for :meth:`fmu_harness.runs.runner.FmuInstance.run`)."""
        return {name: (lambda t, v=values: float(np.interp(t, self.breakpoints, v))) for name, values in self.inputs.items()}

    @property
    def outputs(self) -> list[str]:
        """The compared outputs: the first :data:`MAX_SIGNALS` Real outputs of the spec."""
        return [v.name for v in self.spec.of("output") if v.type == "Real"][:MAX_SIGNALS]


def scenario(spec: ModelSpec) -> Scenario:
    """The standard run of ``spec``: its default stop time (or its model's ``scenario_stop_time``) in
    :data:`STEPS` steps."""
    stop = MODELS[spec.name].scenario_stop_time or spec.default_experiment.stop_time
    breakpoints = np.array([0.0, 0.5 * stop, stop])
    inputs = {v.name: v.start * np.array(INPUT_FACTORS) for v in spec.of("input") if v.type == "Real"}
    return Scenario(spec, stop, stop / STEPS, breakpoints, inputs)


def standard_run(
    instance: FmuInstance, outputs: Sequence[str] | None = None, stop_time: float | None = None
) -> np.ndarray:
    """Initialise ``instance`` and run its model's standard scenario through fmpy, up to
    ``stop_time`` (default: the whole run); rows of time and ``outputs`` (default: all outputs)."""
    case = scenario(MODELS[instance.description.modelName].spec)
    instance.initialize(case.input_values(0.0))
    return instance.run(stop_time or case.stop_time, case.step_size, case.signals(), outputs)
