"""FMI-version-independent half of the FMU adapters: forwards FMI calls to a :class:`SteppedModel`.

Shipped inside every FMU next to the model's modules. ``fmi2_slave`` (pythonfmu)
and ``fmi3_slave`` (pythonfmu3) mix :class:`ModelAdapter` into their slave base class
and supply the version's variable classes, enumerations and error status. No Python
exception leaves an adapter on a bad input: a refused step logs its reasons with the
error status (category ``logStatusError``) and reports failure to the native layer.
"""

from __future__ import annotations

import pickle
from enum import Enum
from typing import Any, ClassVar

from driveline import __version__
from driveline.model import SteppedModel


class ModelAdapter:
    """Registers a model's variables from its spec and forwards life cycle, steps and state."""

    model_class: ClassVar[type[SteppedModel]]
    default_experiment_class: ClassVar[type]
    variable_types: ClassVar[dict[str, type]]
    causalities: ClassVar[type[Enum]]
    variabilities: ClassVar[type[Enum]]
    error_status: ClassVar[Enum]
    author = "driveline-fmus contributors"
    license = "MIT"
    version = __version__

    def __init__(self, **kwargs: Any) -> None:
        """Create the model and register one FMI variable per spec variable."""
        super().__init__(**kwargs)
        self.model = self.model_class()
        spec = self.model.spec
        self.modelName = spec.name
        self.description = spec.description
        experiment = spec.default_experiment
        self.default_experiment = self.default_experiment_class(
            experiment.start_time, experiment.stop_time, experiment.step_size, experiment.tolerance
        )
        self.start_time = 0.0
        self.stepped = False
        for variable in spec.variables:
            self.register_variable(
                self.variable_types[variable.type](
                    variable.name,
                    causality=self.causalities[variable.causality],
                    variability=self.variabilities[variable.effective_variability],
                    description=variable.description,
                    getter=self._getter(variable.name),
                    setter=None if variable.causality == "output" else self._setter(variable.name),
                )
            )

    def _getter(self, name: str):
        return lambda: getattr(self.model, name)

    def _setter(self, name: str):
        return lambda value: setattr(self.model, name, value)

    def _report(self, errors: list[str]) -> bool:
        """Log every reason with the error status; True when there was none."""
        for message in errors:
            self.log(message, self.error_status)
        return not errors

    def do_step(self, current_time: float, step_size: float) -> bool:
        """One step of the model; False (pythonfmu: fmi2Discard) if it refused, reasons logged."""
        self.stepped = True
        return self._report(self.model.step(current_time, step_size))

    def setup_experiment(self, start_time: float, stop_time: float | None = None, tolerance: float | None = None) -> None:
        self.start_time = start_time

    def exit_initialization_mode(self) -> None:
        self._report(self.model.initialize(self.start_time))

    def _get_fmu_state(self) -> dict[str, Any]:
        return {"model": self.model.get_state(), "start_time": self.start_time, "stepped": self.stepped}

    def _set_fmu_state(self, state: dict[str, Any]) -> None:
        self.model.set_state(state["model"])
        self.start_time, self.stepped = state["start_time"], state["stepped"]

    @staticmethod
    def _fmu_state_to_bytes(state: dict[str, Any]) -> bytes:
        return pickle.dumps(state)

    @staticmethod
    def _fmu_state_from_bytes(state: bytes) -> dict[str, Any]:
        return pickle.loads(state)
