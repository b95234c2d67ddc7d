"""Generic FMI 2.0 co-simulation adapter (pythonfmu) around a :class:`SteppedModel`.

Shipped inside every FMI 2.0 FMU next to the model's modules and ``model_adapter``. A
refused step returns False, which pythonfmu reports as fmi2Discard; the reasons go to the
FMI logger with status fmi2Error (category ``logStatusError``). pythonfmu has no fmi2Error
outside an exception (which it turns into fmi2Fatal), so misuse is refused with fmi2Discard
too (``model_adapter``).
"""

from __future__ import annotations

import sys
from typing import Any

from pythonfmu import Boolean, Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real, String
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Status

from .model_adapter import ModelAdapter, StepOutcome

# pythonfmu 0.7's native loader re-executes the FMU script on every fmi2Instantiate and
# then releases one reference to the script module's globals that it never owned. A
# script with no functions of its own then loses its globals after the first instance
# is freed and the next fmi2Instantiate crashes the host. Every class statement of a
# model slave takes one reference here, which balances the one the loader drops.
_PINNED_GLOBALS: list[dict[str, Any]] = []


class ModelSlave(ModelAdapter, Fmi2Slave):
    """FMI 2.0 slave of ``model_class``."""

    default_experiment_class = DefaultExperiment
    variable_types = {"Real": Real, "Integer": Integer, "Boolean": Boolean, "String": String}
    causalities = Fmi2Causality
    variabilities = Fmi2Variability
    error_status = Fmi2Status.error
    warning_status = Fmi2Status.warning
    ok_status = Fmi2Status.ok
    deploy_command = "pythonfmu deploy"

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        _PINNED_GLOBALS.append(sys.modules[cls.__module__].__dict__)

    def wire_text(self, message: str) -> str:
        """pythonfmu passes the text to the FMI 2.0 logger as its printf format: '%' must be '%%'."""
        return message.replace("%", "%%")

    def do_step(self, current_time: float, step_size: float) -> bool:
        """True: fmi2OK; False: fmi2Discard (a refused step, or misuse, reasons logged)."""
        return self.step_outcome(current_time, step_size) is StepOutcome.OK
