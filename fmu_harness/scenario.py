"""A standard run of any catalog model, shared by the FMI 2.0/3.0 comparison, the importers,
the cross-check references and the physics-core replay.

Parameters keep their spec start values; every Real input follows a piecewise-linear
signal through its start value, 3 % below it at half time and 2 % above it at the end.
Inputs are sampled at the communication points and held over each step, so every
importer that interpolates the table linearly feeds the FMU the same values.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from driveline.model import SteppedModel
from driveline.variables import ModelSpec

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

    @property
    def times(self) -> np.ndarray:
        """The communication points, start and stop included."""
        return np.arange(self.steps + 1) * self.step_size

    def input_values(self, time: float) -> dict[str, float]:
        return {name: float(np.interp(time, self.breakpoints, values)) for name, values in self.inputs.items()}

    def signals(self) -> dict[str, Callable[[float], float]]:
        """The inputs as functions of time (for :meth:`fmu_harness.runner.FmuInstance.run`)."""
        return {name: (lambda t, v=values: float(np.interp(t, self.breakpoints, v))) for name, values in self.inputs.items()}

    @property
    def outputs(self) -> list[str]:
        """The compared outputs: the first :data:`MAX_SIGNALS` Real outputs of the spec."""
        return [v.name for v in self.spec.of("output") if v.type == "Real"][:MAX_SIGNALS]


def scenario(spec: ModelSpec) -> Scenario:
    """The standard run of ``spec``: its default stop time in :data:`STEPS` steps."""
    stop = spec.default_experiment.stop_time
    breakpoints = np.array([0.0, 0.5 * stop, stop])
    inputs = {v.name: v.start * np.array(INPUT_FACTORS) for v in spec.of("input") if v.type == "Real"}
    return Scenario(spec, stop, stop / STEPS, breakpoints, inputs)


def run_core(model_class: type[SteppedModel], case: Scenario, parameters: Mapping[str, Any] | None = None) -> np.ndarray:
    """Step the FMI-free model through ``case`` like an importer would; rows of time and outputs."""
    model = model_class()
    for name, value in {**(parameters or {}), **case.input_values(0.0)}.items():
        setattr(model, name, value)
    errors = model.initialize(0.0)
    rows = [[0.0, *(getattr(model, n) for n in case.outputs)]]
    time = 0.0
    for _ in range(case.steps):
        for name, value in case.input_values(time).items():
            setattr(model, name, value)
        errors += model.step(time, case.step_size)
        time += case.step_size
        rows.append([time, *(getattr(model, n) for n in case.outputs)])
    if errors:
        raise ValueError(f"{case.spec.name}: the standard run was refused: {errors}")
    return np.array(rows)
