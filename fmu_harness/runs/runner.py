"""Low-level fmpy driving of one FMU instance, with its log and refused steps surfaced.

fmpy's ``simulate_fmu`` ends a run quietly when a co-simulation step is discarded;
:class:`FmuInstance` raises :class:`StepRefused` with the FMU's logged reasons instead.

``FmuInstance(path)`` opens an FMI 2.0 FMU as :class:`Fmi2Instance` and an FMI 3.0 one as
:class:`Fmi3Instance` (fmpy's own ``FMU2Slave``/``FMU3Slave`` underneath): the version's calls are
chosen once, when the instance is created. Values are read and written in batches, one FMI call
per variable type, with the value references and ctypes buffers prepared once per list of names.
Every instance receives its own log messages, also with several FMI 2.0 instances in one process
(:class:`Fmi2LogRouter`).
"""

from __future__ import annotations

import ctypes
import itertools
import shutil
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
from fmpy import calloc, extract, free, read_model_description
from fmpy.fmi1 import FMICallException, printLogMessage
from fmpy.fmi2 import (
    FMU2Model,
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2True,
)
from fmpy.fmi3 import FMU3Model, FMU3Slave
from fmpy.logging import addLoggerProxy
from fmpy.model_description import ModelDescription

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


def _text(value: bytes | str | None) -> str:
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else "" if value is None else str(value)


def status_name(status: int) -> str:
    """An FMI status's name ("Discard"), or its number if it is none."""
    return STATUS_NAMES[status] if 0 <= status < len(STATUS_NAMES) else str(status)


@dataclass(frozen=True)
class ValueType:
    """How one FMI variable type travels: its ctypes element, fmpy's get/set functions that take
    ctypes arrays, the conversion of a Python value for the buffer and, unless the buffer's
    values are already what the caller wants, the conversion back."""

    ctype: type
    getter: str
    setter: str
    to_c: Callable[[Any], Any]
    from_c: Callable[[Any], Any] | None = None


def _bytes(value: Any) -> bytes:
    return str(value).encode("utf-8")


def _value_types(prefix: str, rows: Mapping[str, tuple]) -> dict[str, ValueType]:
    """Each FMI type name's :class:`ValueType` from (ctype, function suffix, to_c[, from_c])."""
    return {
        name: ValueType(ctype, f"{prefix}Get{suffix}", f"{prefix}Set{suffix}", *conversions)
        for name, (ctype, suffix, *conversions) in rows.items()
    }


class Fmi2LogRouter:
    """Hands each FMI 2.0 message to the instance that logged it.

    fmpy formats FMI 2.0 messages (printf-style, with variadic arguments ctypes cannot read) in
    a native proxy, ``fmpy.logging.addLoggerProxy``, that keeps the Python logger to forward to in
    one static variable: the logger registered last receives the messages of every instance in
    the process. The router therefore registers one logger for all instances and gives each
    instance its own callback structure whose ``componentEnvironment``, which the FMU passes back
    with every message, names the instance. Messages with an environment the router does not
    know (an fmpy instance with fmpy's default callbacks) are printed as fmpy prints them.
    """

    def __init__(self) -> None:
        self._receivers: dict[int, Callable[[int, bytes, bytes], None]] = {}
        self._keys = itertools.count(1)
        self._logger = fmi2CallbackLoggerTYPE(self._deliver)
        self._allocate = fmi2CallbackAllocateMemoryTYPE(calloc)
        self._free = fmi2CallbackFreeMemoryTYPE(free)

    def _deliver(self, environment: int | None, instance: bytes, status: int, category: bytes, message: bytes) -> None:
        receiver = self._receivers.get(environment or 0)
        if receiver is None:
            printLogMessage(environment, instance, status, category, message)
        else:
            receiver(status, category, message)

    def callbacks(self, receiver: Callable[[int, bytes, bytes], None]) -> tuple[int, fmi2CallbackFunctions]:
        """(key, callback structure) for a new instance whose messages go to ``receiver``; keep
        the structure alive as long as the instance."""
        key = next(self._keys)
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = self._logger
        callbacks.allocateMemory = self._allocate
        callbacks.freeMemory = self._free
        callbacks.componentEnvironment = key
        addLoggerProxy(ctypes.byref(callbacks))
        self._receivers[key] = receiver
        return key, callbacks

    def release(self, key: int) -> None:
        self._receivers.pop(key, None)


FMI2_LOG_ROUTER = Fmi2LogRouter()


class LoggedInstance:
    """fmpy's instance of an extracted FMU (FMI 2.0 or 3.0, ``interface`` "ModelExchange" or "CoSimulation"),
    its messages' text handed to ``log``: FMI 2.0 through :data:`FMI2_LOG_ROUTER` (fmpy's ``instantiate_fmu``
    with a logger of its own leaves fmpy's proxy forwarding every later instance's messages to that logger
    once it is freed: a segfault at the next message); ``release()`` once the instance is freed."""

    def __init__(self, unzipdir: str, description: ModelDescription, interface: str, instance_name: str,
                 log: Callable[[str], None]) -> None:
        fmi3 = description.fmiVersion.startswith("3")
        classes = {"ModelExchange": (FMU2Model, FMU3Model), "CoSimulation": (FMU2Slave, FMU3Slave)}[interface]
        identifier = (description.modelExchange if interface == "ModelExchange" else description.coSimulation)
        self.fmu = classes[fmi3](guid=description.guid, unzipDirectory=unzipdir,
                                 modelIdentifier=identifier.modelIdentifier, instanceName=instance_name)
        self._key = None
        if fmi3:
            self.fmu.instantiate(loggingOn=True, logMessage=lambda _environment, *message: log(_text(message[-1])))
        else:
            self._key, self._callbacks = FMI2_LOG_ROUTER.callbacks(lambda status, category, text: log(_text(text)))
            try:
                self.fmu.instantiate(callbacks=self._callbacks, loggingOn=True)
            except Exception:
                self.release()
                raise

    def release(self) -> None:
        if self._key is not None:
            FMI2_LOG_ROUTER.release(self._key)
            self._key = None


class FmuInstance(ABC):
    """One instantiated FMU (FMI 2.0 or 3.0 co-simulation), stepped explicitly.

    ``FmuInstance(path)`` returns an :class:`Fmi2Instance` or :class:`Fmi3Instance`. Pass an
    already parsed ``description`` and an extracted ``unzipdir`` to open many instances of one
    FMU without parsing or extracting it again (the folder is then kept on close).
    """

    fmi_version: str
    slave_class: type[FMU2Slave] | type[FMU3Slave]
    value_types: dict[str, ValueType]
    state_functions: tuple[str, str, str, str, str]
    """fmpy's names of get, set, free, serialize and deserialize FMU state."""

    def __new__(cls, path: str | Path, instance_name: str = "instance", unzipdir: str | None = None,
                description: ModelDescription | None = None) -> FmuInstance:
        # the arguments of __init__, positional too: a description passed so was read again (0.015 s a launch)
        if cls is not FmuInstance:
            return super().__new__(cls)
        description = description or read_model_description(str(path))
        version = next((c for c in (Fmi2Instance, Fmi3Instance) if c.fmi_version == description.fmiVersion), None)
        if version is None:
            raise ValueError(f"{path}: FMI {description.fmiVersion} co-simulation is not supported (2.0 and 3.0 are)")
        instance = super().__new__(version)
        instance.description = description
        return instance

    def __init__(
        self,
        path: str | Path,
        instance_name: str = "instance",
        unzipdir: str | None = None,
        description: ModelDescription | None = None,
    ):
        self.path = Path(path)
        # FmuInstance(path) has parsed the description already to choose the version's class
        self.description = description or vars(self).get("description") or read_model_description(str(path))
        self._owns_unzipdir = unzipdir is None
        self.unzipdir = unzipdir or extract(str(self.path))
        self.variables = {v.name: v for v in self.description.modelVariables}
        self.log: list[LogRecord] = []
        self.fatal = False
        self.time = 0.0
        self._readers: dict[tuple[str, ...], Callable[[], list[Any]]] = {}
        self._writers: dict[tuple[str, ...], Callable[[Sequence[Any]], None]] = {}
        self.fmu = self._instantiate(instance_name)
        self._do_step, self._step_flags = self._prepare_step()

    # -- what each FMI version provides --------------------------------------------
    @abstractmethod
    def _instantiate(self, instance_name: str) -> Any:
        """fmpy's instance of this FMU, instantiated with logging on and this instance's logger."""

    @abstractmethod
    def _prepare_step(self) -> tuple[Callable[..., Any], tuple]:
        """(doStep bound to this instance, its arguments after the step size)."""

    @abstractmethod
    def _enter_initialization_mode(self, start_time: float) -> None: ...

    @abstractmethod
    def _batch_arguments(self, references: Any, values: Any) -> tuple:
        """The arguments of a get/set call after the instance."""

    def _slave(self, instance_name: str) -> Any:
        """fmpy's instance of this FMU, not yet instantiated."""
        return self.slave_class(
            guid=self.description.guid,
            unzipDirectory=self.unzipdir,
            modelIdentifier=self.description.coSimulation.modelIdentifier,
            instanceName=instance_name,
        )

    # -- FMU state ---------------------------------------------------------------
    def get_state(self) -> Any:
        return getattr(self.fmu, self.state_functions[0])()

    def set_state(self, state: Any) -> None:
        getattr(self.fmu, self.state_functions[1])(state)

    def free_state(self, state: Any) -> None:
        getattr(self.fmu, self.state_functions[2])(state)

    def serialize_state(self, state: Any) -> bytes:
        return bytes(getattr(self.fmu, self.state_functions[3])(state))

    def deserialize_state(self, serialized: bytes) -> Any:
        return getattr(self.fmu, self.state_functions[4])(serialized)

    # -- logging -----------------------------------------------------------------
    def _record(self, status: int, category: bytes, message: bytes) -> None:
        self.log.append(LogRecord(status_name(status), _text(category), _text(message)))

    def messages_since(self, start: int) -> list[str]:
        return [record.message for record in self.log[start:]]

    # -- values ------------------------------------------------------------------
    def _batches(self, names: Sequence[str], function: str) -> list[tuple[Callable[[], Any], Any, ValueType, list[int]]]:
        """One prepared call per value type: (call, ctypes buffer, value type, positions in ``names``)."""
        groups: dict[str, list[int]] = {}
        for position, name in enumerate(names):
            kind = self.variables[name].type
            if kind not in self.value_types:
                raise TypeError(f"{name}: variables of type {kind} are not supported")
            groups.setdefault(kind, []).append(position)
        batches = []
        for kind, positions in groups.items():
            value_type = self.value_types[kind]
            references = (ctypes.c_uint * len(positions))(*(self.variables[names[p]].valueReference for p in positions))
            buffer = (value_type.ctype * len(positions))()
            call = partial(getattr(self.fmu, getattr(value_type, function)), self.fmu.component,
                           *self._batch_arguments(references, buffer))
            batches.append((call, buffer, value_type, positions))
        return batches

    def reader(self, names: Sequence[str]) -> Callable[[], list[Any]]:
        """A prepared read of the variables ``names``: ``reader()`` returns their values."""
        key = tuple(names)
        if key not in self._readers:
            batches = self._batches(key, "getter")
            if len(batches) == 1 and batches[0][2].from_c is None:
                call, buffer = batches[0][:2]

                def read() -> list[Any]:
                    call()
                    return buffer[:]

            else:

                def read() -> list[Any]:
                    values: list[Any] = [None] * len(key)
                    for call, buffer, value_type, positions in batches:
                        call()
                        convert = value_type.from_c or (lambda value: value)
                        for position, value in zip(positions, buffer):
                            values[position] = convert(value)
                    return values

            self._readers[key] = read
        return self._readers[key]

    def writer(self, names: Sequence[str]) -> Callable[[Sequence[Any]], None]:
        """A prepared write of the variables ``names``: ``writer(values)`` sets them in that order."""
        key = tuple(names)
        if key not in self._writers:
            batches = self._batches(key, "setter")
            if len(batches) == 1:
                call, buffer, value_type, _ = batches[0]
                convert = value_type.to_c

                def write(values: Sequence[Any]) -> None:
                    buffer[:] = list(map(convert, values))
                    call()

            else:

                def write(values: Sequence[Any]) -> None:
                    for call, buffer, value_type, positions in batches:
                        buffer[:] = [value_type.to_c(values[p]) for p in positions]
                        call()

            self._writers[key] = write
        return self._writers[key]

    def set(self, values: Mapping[str, Any]) -> None:
        if values:
            self.writer(tuple(values))(list(values.values()))

    def get(self, names: Iterable[str]) -> list[Any]:
        return self.reader(tuple(names))()

    # -- life cycle --------------------------------------------------------------
    def _refused(self, call: str, error: FMICallException, first_message: int) -> StepRefused:
        status = status_name(error.status)
        self.fatal = self.fatal or status == "Fatal"
        return StepRefused(call, status, self.time, self.messages_since(first_message))

    def initialize(self, start_values: Mapping[str, Any] | None = None, start_time: float = 0.0) -> None:
        self.enter_initialization(start_values, start_time)
        self.exit_initialization()

    def enter_initialization(self, start_values: Mapping[str, Any] | None = None, start_time: float = 0.0) -> None:
        """Enter initialisation mode and set start values (a master may set more before exiting)."""
        self.time = start_time
        self._enter_initialization_mode(start_time)
        self.set(start_values or {})

    def exit_initialization(self) -> None:
        first_message = len(self.log)
        try:
            self.fmu.exitInitializationMode()
        except FMICallException as error:
            raise self._refused("exitInitializationMode", error, first_message) from None

    def step(self, step_size: float) -> None:
        """One communication step; raises :class:`StepRefused` unless the FMU says OK."""
        first_message = len(self.log)
        try:
            self._do_step(self.time, step_size, *self._step_flags)
        except FMICallException as error:
            raise self._refused("doStep", error, first_message) from None
        self.time += step_size

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
        """Step from the current time to ``stop_time``; inputs are constants (set once) or
        functions of time (sampled at the start of each step and held). Returns a structured
        array of floats, time first, one row per communication point."""
        names = list(outputs or self.outputs())
        inputs = inputs or {}
        read = self.reader(names)
        self.set({k: v for k, v in inputs.items() if not callable(v)})
        signals = {k: v for k, v in inputs.items() if callable(v)}
        write, functions = self.writer(tuple(signals)), list(signals.values())
        if functions:
            write([f(self.time) for f in functions])
        times, rows = [self.time], [read()]
        for _ in range(int(round((stop_time - self.time) / step_size))):
            if functions:
                write([f(self.time) for f in functions])
            self.step(step_size)
            times.append(self.time)
            rows.append(read())
        table = np.column_stack([times, np.array(rows, dtype=float).reshape(len(times), len(names))])
        return table.view([("time", float)] + [(n, float) for n in names]).reshape(-1)


class Fmi2Instance(FmuInstance):
    """An FMI 2.0 co-simulation instance (fmpy's ``FMU2Slave``) with its own log callbacks."""

    fmi_version = "2.0"
    slave_class = FMU2Slave
    state_functions = ("getFMUstate", "setFMUstate", "freeFMUstate", "serializeFMUstate", "deSerializeFMUstate")
    value_types = _value_types("fmi2", {
        "Real": (ctypes.c_double, "Real", float), "Integer": (ctypes.c_int, "Integer", int),
        "Enumeration": (ctypes.c_int, "Integer", int), "Boolean": (ctypes.c_int, "Boolean", bool, bool),
        "String": (ctypes.c_char_p, "String", _bytes, _text),
    })

    def _instantiate(self, instance_name: str) -> FMU2Slave:
        fmu = self._slave(instance_name)
        self._log_key, self._callbacks = FMI2_LOG_ROUTER.callbacks(self._record)
        try:
            fmu.instantiate(callbacks=self._callbacks, loggingOn=True)
        except Exception:
            FMI2_LOG_ROUTER.release(self._log_key)
            raise
        return fmu

    def _prepare_step(self) -> tuple[Callable[..., Any], tuple]:
        return partial(self.fmu.fmi2DoStep, self.fmu.component), (fmi2True,)

    def _enter_initialization_mode(self, start_time: float) -> None:
        self.fmu.setupExperiment(startTime=start_time)
        self.fmu.enterInitializationMode()

    def _batch_arguments(self, references: Any, values: Any) -> tuple:
        return references, len(references), values

    def close(self) -> None:
        super().close()
        FMI2_LOG_ROUTER.release(self._log_key)


class Fmi3Instance(FmuInstance):
    """An FMI 3.0 co-simulation instance (fmpy's ``FMU3Slave``); FMI 3.0 passes each instance
    its own log callback."""

    fmi_version = "3.0"
    slave_class = FMU3Slave
    state_functions = ("getFMUState", "setFMUState", "freeFMUState", "serializeFMUState", "deserializeFMUState")
    value_types = _value_types("fmi3", {
        "Float64": (ctypes.c_double, "Float64", float), "Int32": (ctypes.c_int32, "Int32", int),
        "Boolean": (ctypes.c_bool, "Boolean", bool), "String": (ctypes.c_char_p, "String", _bytes, _text),
    })

    def _instantiate(self, instance_name: str) -> FMU3Slave:
        fmu = self._slave(instance_name)
        fmu.instantiate(loggingOn=True, logMessage=lambda _environment, *message: self._record(*message))
        return fmu

    def _prepare_step(self) -> tuple[Callable[..., Any], tuple]:
        # eventHandlingNeeded, terminateSimulation, earlyReturn, lastSuccessfulTime: read by nobody yet
        self._step_results = (ctypes.c_bool(), ctypes.c_bool(), ctypes.c_bool(), ctypes.c_double())
        return partial(self.fmu.fmi3DoStep, self.fmu.component), (True, *map(ctypes.byref, self._step_results))

    def _enter_initialization_mode(self, start_time: float) -> None:
        self.fmu.enterInitializationMode(startTime=start_time)

    def _batch_arguments(self, references: Any, values: Any) -> tuple:
        return references, len(references), values, len(values)


def simulate(
    path: str | Path,
    stop_time: float,
    step_size: float,
    inputs: Mapping[str, Signal] | None = None,
    start_values: Mapping[str, Any] | None = None,
    outputs: Iterable[str] | None = None,
    start_time: float = 0.0,
    unzipdir: str | None = None,
    description: ModelDescription | None = None,
) -> np.ndarray:
    """Instantiate, initialise and run one FMU; raises :class:`StepRefused` on any refused call.

    ``unzipdir`` reuses an already extracted FMU (kept after the run) instead of extracting it,
    ``description`` its parsed model description."""
    with FmuInstance(path, unzipdir=unzipdir, description=description) as instance:
        first = {k: (v(start_time) if callable(v) else v) for k, v in (inputs or {}).items()}
        instance.initialize({**(start_values or {}), **first}, start_time)
        return instance.run(stop_time, step_size, inputs, outputs)
