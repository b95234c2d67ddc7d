"""Generic FMI 3.0 co-simulation adapter (pythonfmu3) around a :class:`SteppedModel`.

Shipped inside every FMI 3.0 FMU next to the model's modules and ``model_adapter``. FMI 3.0
wants an independent variable: ``time``, after the spec's variables. A refused step returns
``Fmi3StepResult(status=discard)``: pythonfmu3's native ``fmi3DoStep`` returns that status,
**fmi3Discard**, with ``lastSuccessfulTime`` = ``currentCommunicationPoint`` and
``terminateSimulation`` true (the same step would be refused again: the importer stops; one that
corrects its inputs may step again); misuse and the error state return **fmi3Error**. The reasons go to the FMI logger with status fmi3Error (category
``logStatusError``); pythonfmu3 forwards them whether or not logging was switched on.

pythonfmu3 0.3.4 drops the ``startTime`` of ``fmi3EnterInitializationMode``: its C++ entry
point (``pythonfmu-export/src/cppfmu/fmi_functions.cpp``) leaves the tolerance, start and stop
time unnamed and calls ``EnterInitializationMode()``, which calls the slave's
``enter_initialization_mode`` with no argument (``PySlaveInstance::SetupExperiment``, which
would pass it, is never called in FMI 3.0). In a Python host the call is made from a Python
frame of the same thread, which the slave's frame continues: :func:`host_start_time` reads the
``startTime`` argument there, where the binding names its call after the standard's function
(fmpy does), and the model is initialised at it. A host written in C hides it: the model is
initialised at t = 0 and, if the first ``fmi3DoStep`` starts elsewhere, initialised again at
that time before the step. pythonfmu3's loader imports the FMU script once per process, so it
has no counterpart of pythonfmu 0.7's globals-reference defect (tested with many instances in
one process).
"""

from __future__ import annotations

import sys
from types import FrameType
from typing import Any

from pythonfmu3 import Boolean, Fmi3Causality, Fmi3Slave, Fmi3Status, Fmi3StepResult, Fmi3Variability, Float64, Int32, String
from pythonfmu3.default_experiment import DefaultExperiment

from driveline.variables import Variable
from .model_adapter import ModelAdapter, Phase, StepOutcome

#: The standard's name of the call whose ``startTime`` pythonfmu3 withholds.
_ENTER_INITIALIZATION = "fmi3EnterInitializationMode"

_STATUS = {StepOutcome.OK: Fmi3Status.ok, StepOutcome.DISCARD: Fmi3Status.discard, StepOutcome.ERROR: Fmi3Status.error}


class ModelSlave(ModelAdapter, Fmi3Slave):
    """FMI 3.0 slave of ``model_class``."""

    default_experiment_class = DefaultExperiment
    variable_types = {"Real": Float64, "Integer": Int32, "Boolean": Boolean, "String": String}
    causalities = Fmi3Causality
    variabilities = Fmi3Variability
    error_status = Fmi3Status.error
    warning_status = Fmi3Status.warning
    ok_status = Fmi3Status.ok
    deploy_command = "pythonfmu3 deploy"

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        time = Float64("time", causality=Fmi3Causality.independent, variability=Fmi3Variability.continuous,
                       description="Simulation time", getter=lambda: self.model.time)
        self.register_variable(time)
        self._spec_of_reference[time.value_reference] = Variable("time", "independent", 0.0, "Simulation time")

    def enter_initialization_mode(self) -> None:
        start_time = self._guarded("enterInitializationMode", lambda: host_start_time(sys._getframe()))
        if start_time is not None and self.phase is Phase.INSTANTIATED:
            self.take_start_time("enterInitializationMode", start_time)
        super().enter_initialization_mode()

    def do_step(self, current_time: float, step_size: float) -> Fmi3StepResult:
        first_step_elsewhere = not self.stepped and current_time != self.start_time
        if first_step_elsewhere and self.phase is Phase.STEPPING and self.fault is None and current_time - current_time == 0.0:
            self.start_time = current_time
            self.initialize_model()
        outcome = self.step_outcome(current_time, step_size)
        return Fmi3StepResult(status=_STATUS[outcome], terminateSimulation=outcome is not StepOutcome.OK)


def host_start_time(frame: FrameType | None) -> float | None:
    """The ``startTime`` the host passed to the ``fmi3EnterInitializationMode`` call being served:
    the argument of that name in the nearest calling frame of a function so named (a Python
    host's binding), as a float or a ctypes ``c_double``; None where no such frame is (a host
    written in C).
    ``frame`` is one of the slave's own, which the wrapper's C++ continues from the caller's."""
    while frame is not None:
        if frame.f_code.co_name == _ENTER_INITIALIZATION:
            value = frame.f_locals.get("startTime")
            value = getattr(value, "value", value)  # a ctypes fmi3Float64
            return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None
        frame = frame.f_back
    return None
