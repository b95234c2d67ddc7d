"""Low-level fmpy driving of one FMU instance, with its log and refused steps surfaced.

fmpy's ``simulate_fmu`` ends a run quietly when a co-simulation step is discarded;
:class:`FmuInstance` raises :class:`StepRefused` with the FMU's logged reasons instead.
"""

from __future__ import annotations

import shutil
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.simulation import instantiate_fmu

STATUS_NAMES = ("OK", "Warning", "Discard", "Error", "Fatal", "Pending")


@dataclass(frozen=True)
class LogRecord:
    status: str
    category: str
    message: str


class StepRefused(RuntimeError):
    """An FMU call returned a non-OK status; ``messages`` holds what the FMU logged."""

    def __init__(self, call: str, status: str, time: float, messages: list[str]):
        self.call, self.status, self.time, self.messages = call, status, time, messages
        super().__init__(f"{call} at t = {time:.9g} s returned {status}: {'; '.join(messages) or 'no message'}")


Signal = float | int | bool | str | Callable[[float], Any]


class FmuInstance:
    """One instantiated FMU (FMI 2.0 or 3.0 co-simulation), stepped explicitly."""

    def __init__(self, path: str | Path, instance_name: str = "instance", unzipdir: str | None = None):
        self.path = Path(path)
        self.description = read_model_description(str(self.path))
        self._owns_unzipdir = unzipdir is None
        self.unzipdir = unzipdir or extract(str(self.path))
        self.variables = {v.name: v for v in self.description.modelVariables}
        self.log: list[LogRecord] = []
        self.fatal = False
        self.fmu = instantiate_fmu(
            self.unzipdir, self.description, "CoSimulation", debug_logging=True, logger=self._on_log
        )
        self.fmu.instanceName = instance_name
        self.fmi3 = self.description.fmiVersion.startswith("3")
        self.time = 0.0

    # -- logging -----------------------------------------------------------------
    def _on_log(self, *args: Any) -> None:
        status, category, message = args[-3:]  # FMI 2.0 passes five arguments, FMI 3.0 four
        decode = lambda b: b.decode("utf-8", "replace") if isinstance(b, bytes) else str(b)  # noqa: E731
        name = STATUS_NAMES[status] if isinstance(status, int) and status < len(STATUS_NAMES) else str(status)
        self.log.append(LogRecord(name, decode(category), decode(message)))

    def messages_since(self, start: int) -> list[str]:
        return [record.message for record in self.log[start:]]

    # -- values ------------------------------------------------------------------
    def set(self, values: Mapping[str, Any]) -> None:
        for name, value in values.items():
            variable = self.variables[name]
            reference = [variable.valueReference]
            kind = variable.type
            if kind in ("Real", "Float64", "Float32"):
                (self.fmu.setFloat64 if self.fmi3 else self.fmu.setReal)(reference, [float(value)])
            elif kind in ("Integer", "Int32", "Int64", "Enumeration"):
                (self.fmu.setInt32 if self.fmi3 else self.fmu.setInteger)(reference, [int(value)])
            elif kind == "Boolean":
                self.fmu.setBoolean(reference, [bool(value)])
            else:
                self.fmu.setString(reference, [str(value)])

    def get(self, names: Iterable[str]) -> list[Any]:
        values = []
        for name in names:
            variable = self.variables[name]
            reference = [variable.valueReference]
            kind = variable.type
            if kind in ("Real", "Float64", "Float32"):
                values.append((self.fmu.getFloat64 if self.fmi3 else self.fmu.getReal)(reference)[0])
            elif kind in ("Integer", "Int32", "Int64", "Enumeration"):
                values.append((self.fmu.getInt32 if self.fmi3 else self.fmu.getInteger)(reference)[0])
            elif kind == "Boolean":
                values.append(self.fmu.getBoolean(reference)[0])
            else:
                text = self.fmu.getString(reference)[0]
                values.append(text.decode("utf-8") if isinstance(text, bytes) else text)
        return values

    # -- FMU state (FMI 2.0 and 3.0 spell the calls differently) -----------------
    def get_state(self) -> Any:
        return self.fmu.getFMUState() if self.fmi3 else self.fmu.getFMUstate()

    def set_state(self, state: Any) -> None:
        (self.fmu.setFMUState if self.fmi3 else self.fmu.setFMUstate)(state)

    def free_state(self, state: Any) -> None:
        (self.fmu.freeFMUState if self.fmi3 else self.fmu.freeFMUstate)(state)

    def serialize_state(self, state: Any) -> bytes:
        return bytes(self.fmu.serializeFMUState(state) if self.fmi3 else self.fmu.serializeFMUstate(state))

    def deserialize_state(self, serialized: bytes) -> Any:
        return (self.fmu.deserializeFMUState if self.fmi3 else self.fmu.deSerializeFMUstate)(serialized)

    # -- life cycle --------------------------------------------------------------
    def _call(self, name: str, function: Callable[[], Any]) -> None:
        start = len(self.log)
        try:
            function()
        except FMICallException as error:
            status = STATUS_NAMES[error.status] if error.status < len(STATUS_NAMES) else str(error.status)
            self.fatal = self.fatal or status == "Fatal"
            raise StepRefused(name, status, self.time, self.messages_since(start)) from None

    def initialize(self, start_values: Mapping[str, Any] | None = None, start_time: float = 0.0) -> None:
        self.enter_initialization(start_values, start_time)
        self.exit_initialization()

    def enter_initialization(self, start_values: Mapping[str, Any] | None = None, start_time: float = 0.0) -> None:
        """Enter initialisation mode and set start values (a master may set more before exiting)."""
        self.time = start_time
        if self.fmi3:
            self.fmu.enterInitializationMode(startTime=start_time)
        else:
            self.fmu.setupExperiment(startTime=start_time)
            self.fmu.enterInitializationMode()
        self.set(start_values or {})

    def exit_initialization(self) -> None:
        self._call("exitInitializationMode", self.fmu.exitInitializationMode)

    def step(self, step_size: float) -> None:
        """One communication step; raises :class:`StepRefused` unless the FMU says OK."""
        time = self.time
        if self.fmi3:
            self._call("doStep", lambda: self.fmu.doStep(time, step_size))
        else:
            self._call("doStep", lambda: self.fmu.doStep(currentCommunicationPoint=time, communicationStepSize=step_size))
        self.time = time + step_size

    def reset(self) -> None:
        self.fmu.reset()
        self.time = 0.0

    def close(self) -> None:
        """Terminate (unless the FMU reported Fatal: then only freeing is allowed) and free."""
        if not self.fatal:
            try:
                self.fmu.terminate()
            except FMICallException:
                pass
        self.fmu.freeInstance()
        if self._owns_unzipdir:
            shutil.rmtree(self.unzipdir, ignore_errors=True)

    def __enter__(self) -> FmuInstance:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- runs --------------------------------------------------------------------
    def outputs(self) -> list[str]:
        return [v.name for v in self.description.modelVariables if v.causality == "output"]

    def run(
        self,
        stop_time: float,
        step_size: float,
        inputs: Mapping[str, Signal] | None = None,
        outputs: Iterable[str] | None = None,
    ) -> np.ndarray:
        """Step from the current time to ``stop_time``; inputs are constants or functions of time
        (sampled at the start of each step and held). Returns a structured array with time first."""
        names = list(outputs or self.outputs())
        steps = int(round((stop_time - self.time) / step_size))
        rows = []

        def apply(time: float) -> None:
            self.set({k: (v(time) if callable(v) else v) for k, v in (inputs or {}).items()})

        apply(self.time)
        rows.append((self.time, *self.get(names)))
        for _ in range(steps):
            apply(self.time)
            self.step(step_size)
            rows.append((self.time, *self.get(names)))
        return np.array(rows, dtype=[("time", float)] + [(n, float) for n in names])


def simulate(
    path: str | Path,
    stop_time: float,
    step_size: float,
    inputs: Mapping[str, Signal] | None = None,
    start_values: Mapping[str, Any] | None = None,
    outputs: Iterable[str] | None = None,
    start_time: float = 0.0,
    unzipdir: str | None = None,
) -> np.ndarray:
    """Instantiate, initialise and run one FMU; raises :class:`StepRefused` on any refused call.

    ``unzipdir`` reuses an already extracted FMU (kept after the run) instead of extracting it."""
    with FmuInstance(path, unzipdir=unzipdir) as instance:
        first = {k: (v(start_time) if callable(v) else v) for k, v in (inputs or {}).items()}
        instance.initialize({**(start_values or {}), **first}, start_time)
        return instance.run(stop_time, step_size, inputs, outputs)
