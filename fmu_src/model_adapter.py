"""FMI-version-independent half of the FMU adapters: forwards FMI calls to a :class:`SteppedModel`.

Shipped inside every FMU next to the model's modules. ``fmi2_slave`` (pythonfmu) and
``fmi3_slave`` (pythonfmu3) mix :class:`ModelAdapter` into their slave base class and supply
the version's variable classes, enumerations and statuses.

No Python exception leaves an entry point: both wrappers turn one into a Fatal status and
then keep using the objects they released, which crashes the host a few calls later. Every
failure therefore becomes a logged reason with the error status (category ``logStatusError``)
and one of two outcomes (docs/robustness.md lists them per call):

* a **refused step**: ``do_step`` reports Discard (bad input or parameter, the model cannot
  evaluate the step); nothing of the step is kept and the host may retry;
* the **error state** of the standard, for misuse (a call in the wrong life-cycle phase, an
  unknown value reference or wrong type, setting an output or a fixed parameter after
  initialisation, a non-finite time, a refused serialised state, a model failure outside
  its checks): the call itself returns OK (the wrappers have no other non-fatal status
  outside ``do_step``), and every later step is refused with the reason (FMI 3.0: Error,
  FMI 2.0: Discard) until the host resets the instance or restores a saved state.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from typing import Any, Callable, ClassVar

from driveline import __version__
from driveline.model import SteppedModel
from driveline.variables import COMPUTED

from . import saved_state

#: Kinds of value per getter/setter name of both FMI versions.
_KIND_OF = {"real": "Real", "float64": "Real", "integer": "Integer", "int32": "Integer",
            "boolean": "Boolean", "string": "String"}
_PLACEHOLDER = {"Real": float("nan"), "Integer": 0, "Boolean": False, "String": ""}
#: Distinct log texts kept for reuse: the wrappers leak one reference to every message text
#: they forward, so a repeated refusal reuses its text instead of leaking a new copy.
_LOG_TEXTS_KEPT = 1024
#: One category object for every message (the wrappers would build, and leak, a new one each time).
_ERROR_CATEGORY = "logStatusError"
_WARNING_CATEGORY = "logStatusWarning"
_INFO_CATEGORY = "logAll"  # an information line: a default in use, said once


class Phase(Enum):
    """Life-cycle phases of the FMI co-simulation state machine that the adapter checks."""

    INSTANTIATED = "instantiated"
    INITIALIZATION = "initialization mode"
    STEPPING = "step mode"
    TERMINATED = "terminated"


class StepOutcome(Enum):
    OK = "ok"
    DISCARD = "discard"
    ERROR = "error"


@dataclass(frozen=True)
class Snapshot:
    """An FMU state: the model's state and the adapter's life-cycle data."""

    model_name: str
    model: dict[str, Any]
    start_time: float
    stepped: bool
    phase: Phase


@dataclass(frozen=True)
class RefusedState:
    """What deserialising bytes that are no state of this model gives; setting it is refused."""

    reason: str


class ModelAdapter:
    """Registers a model's variables from its spec and forwards life cycle, steps and state."""

    model_class: ClassVar[type[SteppedModel]]
    default_experiment_class: ClassVar[type]
    variable_types: ClassVar[dict[str, type]]
    causalities: ClassVar[type[Enum]]
    variabilities: ClassVar[type[Enum]]
    error_status: ClassVar[Enum]
    warning_status: ClassVar[Enum]
    ok_status: ClassVar[Enum]
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
        self.phase = Phase.INSTANTIATED
        self.fault: str | None = None
        self._refusal: str | None = None  # the first reason of the last refused step
        self._notice: str | None = None  # the model's last step notice: a repeat is not logged
        self._initial: SteppedModel | None = None  # Initialization Mode: the values read, None when stale
        self._log_texts: dict[str, str] = {}
        self._spec_of_reference: dict[int, Any] = {}
        for variable in spec.variables:
            fmi_variable = self.variable_types[variable.type](
                variable.name,
                causality=self.causalities[variable.causality],
                variability=self.variabilities[variable.effective_variability],
                description=variable.description,
                getter=self._getter(variable.name),
                setter=None if variable.causality in COMPUTED else self._setter(variable.name),
            )
            self.register_variable(fmi_variable)
            self._spec_of_reference[fmi_variable.value_reference] = variable

    def _getter(self, name: str):
        return lambda: getattr(self.model, name)

    def _setter(self, name: str):
        return lambda value: setattr(self.model, name, value)

    # -- logging and the error state ----------------------------------------------
    def wire_text(self, message: str) -> str:
        """``message`` as the FMI version's logger must receive it to show it unchanged."""
        return message

    def log_text(self, message: str) -> str:
        """The one point where log text leaves the adapter: :meth:`wire_text`, and the same
        object again for a repeated message."""
        kept = self._log_texts.get(message)
        if kept is None:
            kept = self.wire_text(message)
            if len(self._log_texts) < _LOG_TEXTS_KEPT:
                self._log_texts[message] = kept
        return kept

    def _report(self, errors: list[str]) -> bool:
        """Log every reason with the error status; True when there was none."""
        for message in errors:
            self.log(self.log_text(message), self.error_status, _ERROR_CATEGORY)
        return not errors

    def _fail(self, call: str, reason: str) -> None:
        """Misuse or an unexpected failure: log it and enter the error state."""
        message = f"{call}: {reason}"
        self.fault = self.fault or message
        self._report([message])

    def _guarded(self, call: str, action: Callable[[], Any], fallback: Any = None) -> Any:
        """Run an entry point's work; any exception becomes the error state (never reaches the wrapper)."""
        try:
            return action()
        except Exception as error:  # noqa: BLE001 - an escaping exception crashes the host later
            self._fail(call, f"{type(error).__name__}: {str(error)[:500]}")
            return fallback

    def _in_phase(self, call: str, *phases: Phase) -> bool:
        if self.phase in phases:
            return True
        allowed = " or ".join(phase.value for phase in phases)
        self._fail(call, f"not allowed in {self.phase.value} (only in {allowed})")
        return False

    # -- life cycle --------------------------------------------------------------
    def setup_experiment(self, start_time: float, stop_time: float | None = None, tolerance: float | None = None) -> None:
        if self._in_phase("setupExperiment", Phase.INSTANTIATED):
            self.take_start_time("setupExperiment", start_time)

    def take_start_time(self, call: str, start_time: float) -> None:
        """The host's start time, the time the model is initialised at; one not finite is misuse."""
        if _finite(start_time):
            self.start_time = start_time
            self._initial = None
        else:
            self._fail(call, f"start time {start_time!r} is not finite")

    def enter_initialization_mode(self) -> None:
        if self._in_phase("enterInitializationMode", Phase.INSTANTIATED):
            self.phase = Phase.INITIALIZATION

    def readable_model(self) -> SteppedModel:
        """The model whose values a get reads. In Initialization Mode, a copy initialised at the start
        time from what has been set so far, as ``exitInitializationMode`` initialises the model itself
        (so a value read there is the first one read after it, bit for bit); recomputed after a set.
        Values it cannot compute (refused parameters or start values) are the start values, the
        reasons logged as a warning: the refusal itself comes at ``exitInitializationMode``."""
        if self.phase is not Phase.INITIALIZATION:
            return self.model
        if self._initial is None:
            trial = type(self.model)()
            trial.set_state(self.model.get_state())
            errors = trial.parameter_errors() or trial.initialize(self.start_time)
            self._initial = self.model if errors else trial
            for reason in errors:
                self.log(self.log_text(f"values read in initialization mode are the start values: {reason}"),
                         self.warning_status, _WARNING_CATEGORY)
        return self._initial

    def exit_initialization_mode(self) -> None:
        """Initialise the model at the start time. Parameters that no input can make valid, and
        start values the model refuses (an input beyond its bounds, outputs it cannot compute),
        enter the error state here, each reason logged once (the wrappers can only return OK:
        every step is then refused)."""
        if self._in_phase("exitInitializationMode", Phase.INITIALIZATION):
            self.phase = Phase.STEPPING
            errors = self._guarded("exitInitializationMode", self.model.parameter_errors, [])
            for reason in errors:
                self._fail("exitInitializationMode", reason)
            if not errors:
                self.initialize_model()

    def initialize_model(self) -> None:
        errors = self._guarded("exitInitializationMode", lambda: self.model.initialize(self.start_time))
        for reason in errors or ():
            self._fail("exitInitializationMode", reason)
        if errors == []:
            notice = self.model.start_notice()
            if notice is not None:  # a default in use: information, not a warning
                self.log(self.log_text(notice), self.ok_status, _INFO_CATEGORY)

    def terminate(self) -> None:
        if self._in_phase("terminate", Phase.STEPPING):
            self.phase = Phase.TERMINATED

    def step_outcome(self, current_time: float, step_size: float) -> StepOutcome:
        """One step of the model: OK, DISCARD (refused, reasons logged) or ERROR (misuse or the
        error state)."""
        if self.fault is not None:
            refusal = f"doStep: refused in the error state ({self.fault}); reset the instance or restore a state"
            if refusal != self._refusal:  # logged once, however often a host that ignores it steps again
                self._refusal = refusal
                self._report([refusal])
            return StepOutcome.ERROR
        if not self._in_phase("doStep", Phase.STEPPING):
            return StepOutcome.ERROR
        if not _finite(current_time):
            self._fail("doStep", f"currentCommunicationPoint {current_time!r} is not finite")
            return StepOutcome.ERROR
        if self.model.goes_back(current_time):
            self._fail("doStep", f"currentCommunicationPoint {current_time!r} is before the time the FMU reached, "
                                 f"{self.model.time!r}")
            return StepOutcome.ERROR
        errors = self._guarded("doStep", lambda: self.model.step(current_time, step_size))
        if errors is None:
            return StepOutcome.ERROR
        self.stepped = self.stepped or not errors
        if not errors:
            self._refusal = None
            notice = self.model.step_notice(step_size)
            if notice is not None and notice != self._notice:
                self._notice = notice
                self.log(self.log_text(notice), self.warning_status, _WARNING_CATEGORY)
            return StepOutcome.OK
        if errors[0] != self._refusal:  # the same step is refused again: its reasons are logged once
            self._refusal = errors[0]
            self._report(errors)
        return StepOutcome.DISCARD

    # -- values ------------------------------------------------------------------
    def _variable(self, call: str, reference: int, kind: str):
        variable = self._spec_of_reference.get(reference)
        if variable is None:
            self._fail(call, f"value reference {reference} is not a variable of {self.modelName}")
        elif variable.type != kind:
            self._fail(call, f"value reference {reference} ({variable.name}) is a {variable.type}, not a {kind}")
        else:
            return variable
        return None

    def _get(self, call: str, references: list[int], kind: str) -> list[Any]:
        values = []
        model = self.readable_model()
        for reference in references:
            variable = self._variable(call, reference, kind)
            value = None
            if variable is not None:
                value = self._guarded(call, lambda name=variable.name: _KIND_TYPE[kind](getattr(model, name)))
            values.append(_PLACEHOLDER[kind] if value is None else value)
        return values

    def _set(self, call: str, references: list[int], values: list[Any], kind: str) -> None:
        if self.phase is Phase.TERMINATED:
            self._fail(call, "not allowed after terminate")
            return
        for reference, value in zip(references, values):
            variable = self._variable(call, reference, kind)
            if variable is None:
                continue
            if variable.causality in (*COMPUTED, "independent"):
                self._fail(call, f"{variable.name} is {variable.article} variable and cannot be set")
            elif variable.effective_variability == "fixed" and self.phase is Phase.STEPPING:
                self._fail(call, f"{variable.name} is a fixed parameter and cannot change after initialisation")
            elif kind == "String" and len(value) > MAX_STRING:
                self._fail(call, f"{variable.name} is {len(value)} characters long (at most {MAX_STRING})")
            else:
                setattr(self.model, variable.name, _KIND_TYPE[kind](value))
                self._initial = None

    def get_real(self, vrs: list[int]) -> list[float]:
        return self._guarded("getReal", lambda: self._get("getReal", vrs, "Real"), [_PLACEHOLDER["Real"]] * len(vrs))

    def get_integer(self, vrs: list[int]) -> list[int]:
        return self._guarded("getInteger", lambda: self._get("getInteger", vrs, "Integer"), [0] * len(vrs))

    def get_boolean(self, vrs: list[int]) -> list[bool]:
        return self._guarded("getBoolean", lambda: self._get("getBoolean", vrs, "Boolean"), [False] * len(vrs))

    def get_string(self, vrs: list[int]) -> list[str]:
        return self._guarded("getString", lambda: self._get("getString", vrs, "String"), [""] * len(vrs))

    def set_real(self, vrs: list[int], values: list[float]) -> None:
        self._guarded("setReal", lambda: self._set("setReal", vrs, values, "Real"))

    def set_integer(self, vrs: list[int], values: list[int]) -> None:
        self._guarded("setInteger", lambda: self._set("setInteger", vrs, values, "Integer"))

    def set_boolean(self, vrs: list[int], values: list[bool]) -> None:
        self._guarded("setBoolean", lambda: self._set("setBoolean", vrs, values, "Boolean"))

    def set_string(self, vrs: list[int], values: list[str]) -> None:
        self._guarded("setString", lambda: self._set("setString", vrs, values, "String"))

    # FMI 3.0 names of the same calls
    get_float64, get_int32, set_float64, set_int32 = get_real, get_integer, set_real, set_integer

    # -- FMU state ---------------------------------------------------------------
    def _get_fmu_state(self) -> Snapshot | None:
        return self._guarded("getFMUState", lambda: Snapshot(
            self.modelName, self.model.get_state(), self.start_time, self.stepped, self.phase))

    def _set_fmu_state(self, state: Any) -> None:
        if isinstance(state, RefusedState):
            self._fail("setFMUState", state.reason)
        elif not isinstance(state, Snapshot) or state.model_name != self.modelName:
            self._fail("setFMUState", f"the state was not saved by {self.modelName}")
        else:
            self._guarded("setFMUState", lambda: self._restore(state))

    def _restore(self, state: Snapshot) -> None:
        self.model.set_state(state.model)
        self._initial = None
        self.start_time, self.stepped = state.start_time, state.stepped
        if self.phase is not Phase.TERMINATED:
            self.phase = state.phase
        self.fault = self._refusal = None

    @classmethod
    def _fmu_state_to_bytes(cls, state: Any) -> bytes:
        """Plain values, versioned and checksummed (:mod:`fmu_src.saved_state`); no pickle."""
        try:
            model = cls.model_class()
            adapter = {"start_time": state.start_time, "stepped": state.stepped, "phase": state.phase.value}
            return saved_state.encode(model.spec, {"model": model.saved_values(state.model), "adapter": adapter})
        except Exception:  # noqa: BLE001 - not a Snapshot: bytes that deserialise to a refused state
            return b""

    @classmethod
    def _fmu_state_from_bytes(cls, data: bytes) -> Snapshot | RefusedState:
        """The state in ``data``, or a :class:`RefusedState` naming why the bytes are not one."""
        try:
            model = cls.model_class()
            saved = saved_state.decode(model.spec, bytes(data))
            adapter = saved.get("adapter")
            if set(saved) != {"model", "adapter"} or not isinstance(adapter, dict):
                raise saved_state.StateRefused("the saved state lacks the model or the adapter part")
            phase = Phase(adapter.get("phase"))
            start_time, stepped = adapter.get("start_time"), adapter.get("stepped")
            if not (isinstance(start_time, float) and _finite(start_time) and isinstance(stepped, bool)):
                raise saved_state.StateRefused("the saved start time or step flag is malformed")
            return Snapshot(model.spec.name, model.state_from_saved(saved["model"]), start_time, stepped, phase)
        except Exception as error:  # noqa: BLE001 - refused, reported when the host sets it
            return RefusedState(f"deserialised bytes refused: {str(error)[:300]}")


#: Longest String value accepted (a layout path or a list of orders).
MAX_STRING = 4096
_KIND_TYPE: dict[str, Callable[[Any], Any]] = {"Real": float, "Integer": int, "Boolean": bool, "String": str}


def _finite(value: float) -> bool:
    return isinstance(value, float) and value - value == 0.0

