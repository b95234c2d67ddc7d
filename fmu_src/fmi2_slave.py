"""Generic FMI 2.0 co-simulation adapter (pythonfmu) around a :class:`SteppedModel`.

Shipped inside every FMU next to the ``driveline`` package. Refused steps return
False, which pythonfmu reports as fmi2Discard; the reasons go to the FMI logger with
status fmi2Error (category ``logStatusError``). No Python exception leaves this class
on a bad input, so the host never sees fmi2Fatal for one.
"""

from __future__ import annotations

import pickle
import sys
from typing import Any

from pythonfmu import Boolean, Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real, String
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Status

from driveline import __version__
from driveline.model import SteppedModel

VARIABLE_TYPES = {"Real": Real, "Integer": Integer, "Boolean": Boolean, "String": String}

# pythonfmu 0.7's native loader re-executes the FMU script on every fmi2Instantiate and
# then releases one reference to the script module's globals that it never owned. A
# script with no functions of its own then loses its globals after the first instance
# is freed and the next fmi2Instantiate crashes the host. Every class statement of a
# model slave takes one reference here, which balances the one the loader drops.
_PINNED_GLOBALS: list[dict[str, Any]] = []


class ModelSlave(Fmi2Slave):
    """Registers the model's variables from its spec and forwards the FMI calls to it."""

    model_class: type[SteppedModel]
    author = "driveline-fmus contributors"
    license = "MIT"
    version = __version__

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        _PINNED_GLOBALS.append(sys.modules[cls.__module__].__dict__)

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.model = self.model_class()
        spec = self.model.spec
        self.modelName = spec.name
        self.description = spec.description
        experiment = spec.default_experiment
        self.default_experiment = DefaultExperiment(
            experiment.start_time, experiment.stop_time, experiment.step_size, experiment.tolerance
        )
        self.start_time = 0.0
        for variable in spec.variables:
            self.register_variable(
                VARIABLE_TYPES[variable.type](
                    variable.name,
                    causality=Fmi2Causality[variable.causality],
                    variability=Fmi2Variability[variable.effective_variability],
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
        for message in errors:
            self.log(message, Fmi2Status.error)
        return not errors

    def setup_experiment(self, start_time: float, stop_time: float | None, tolerance: float | None) -> None:
        self.start_time = start_time

    def exit_initialization_mode(self) -> None:
        self._report(self.model.initialize(self.start_time))

    def do_step(self, current_time: float, step_size: float) -> bool:
        return self._report(self.model.step(current_time, step_size))

    def _get_fmu_state(self) -> dict[str, Any]:
        return {"model": self.model.get_state(), "start_time": self.start_time}

    def _set_fmu_state(self, state: dict[str, Any]) -> None:
        self.model.set_state(state["model"])
        self.start_time = state["start_time"]

    @staticmethod
    def _fmu_state_to_bytes(state: dict[str, Any]) -> bytes:
        return pickle.dumps(state)

    @staticmethod
    def _fmu_state_from_bytes(state: bytes) -> dict[str, Any]:
        return pickle.loads(state)
