"""Time-stepping base class shared by every model; the FMU adapters wrap it.

A model holds one attribute per variable of its :class:`~driveline.variables.ModelSpec`.
``step`` validates parameters, inputs and the step size, advances the model and
checks its outputs. A refused step leaves the model exactly as it was and returns
the reasons, so a host can correct the input and carry on.
"""

from __future__ import annotations

import copy
import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from pathlib import Path
from typing import Any, ClassVar

from .variables import COMPUTED, ModelSpec, Relation, Variable

#: How far, relative to the time reached (at least 1 s), a step may start before that time: a host
#: that adds step sizes and one that multiplies them differ in the last bits. Earlier is time going
#: backwards, which the adapters refuse as misuse.
TIME_TOLERANCE = 1e-9

RULES = {"<": "must be below", "<=": "must not exceed", ">": "must exceed", ">=": "must not be below"}


class SteppedModel(ABC):
    """Base of all co-simulation models: start values, validation, stepping, state."""

    spec: ClassVar[ModelSpec]

    def __init__(self) -> None:
        self.reset()

    # -- life cycle ---------------------------------------------------------
    def reset(self) -> None:
        """Return every variable to its start value and clear the internal state."""
        for v in self.spec.variables:
            setattr(self, v.name, v.start)
        self.time = 0.0
        self._initialized = False
        self._valid_parameters: tuple[Any, ...] | None = None
        self.reset_internal_state()

    def reset_internal_state(self) -> None:
        """Hook for models that keep state beyond their variables."""

    def initialize(self, start_time: float) -> list[str]:
        """Validate parameters and inputs and compute the outputs at ``start_time``."""
        self.time = start_time
        errors = self.parameter_errors() + self.input_errors()
        if errors:
            return errors
        errors = self._undoable(lambda: self.start(start_time), "the start values")
        self._initialized = not errors
        return errors

    def goes_back(self, current_time: float) -> bool:
        """Whether a step from ``current_time`` would start before the time the model reached."""
        return current_time < self.time - TIME_TOLERANCE * max(1.0, abs(self.time))

    def step(self, current_time: float, step_size: float) -> list[str]:
        """Advance from ``current_time`` by ``step_size``; return the reasons for a refusal."""
        if not self._initialized:
            errors = self.initialize(current_time)
            if errors:
                return errors
        if not (math.isfinite(step_size) and step_size > 0.0):
            return [f"communication step size must be positive and finite, got {step_size!r}"]
        if not math.isfinite(current_time + step_size):
            return [f"the communication step from t = {current_time!r} s by {step_size!r} s ends at a time that is "
                    f"not finite"]
        parameters = tuple(getattr(self, name) for name in self._parameter_names)
        errors = (self.parameter_errors() if parameters != self._valid_parameters else []) + self.input_errors()
        if errors:
            return errors
        self._valid_parameters = parameters  # NaN never compares equal, so it is always re-checked
        errors = self._guarded(lambda: self.step_size_errors(step_size), "the step size")
        if errors:
            return errors
        errors = self._undoable(lambda: self.advance(current_time, step_size), f"the step from t = {current_time!r} s")
        if not errors:
            self.time = current_time + step_size
        return errors

    def _undoable(self, action: Callable[[], None], what: str) -> list[str]:
        """Run ``action``; if it fails arithmetically or leaves a non-finite output, undo it and say why.

        A shallow copy suffices: models replace values, never mutate them in place.
        """
        snapshot = dict(self.__dict__)
        try:
            action()
            errors = self.output_errors()
        except (ArithmeticError, ValueError) as error:
            errors = [f"{what} could not be computed ({type(error).__name__}: {error})"]
        if errors:
            self.__dict__.update(snapshot)
        return errors

    # -- model specific ------------------------------------------------------
    @abstractmethod
    def start(self, start_time: float) -> None:
        """Set internal state and outputs at the start time (parameters and inputs are valid)."""

    @abstractmethod
    def advance(self, current_time: float, step_size: float) -> None:
        """Advance internal state and outputs over one valid step, assigning new values
        (never mutating held objects in place: a refused step is undone from a shallow copy)."""

    def extra_parameter_errors(self) -> list[str]:
        """Checks the spec cannot declare (e.g. a structural analysis that fails), run once the
        declared bounds and relations hold."""
        return []

    #: Parameter values that break each check of :meth:`extra_parameter_errors` once, by a name
    #: for its message; the first value named is the one the message shows. The native build cuts
    #: the messages from the check run on these values, so their wording exists once.
    extra_parameter_probes: ClassVar[dict[str, dict[str, float]]] = {}

    #: Constants the native port of the model shares with it (``#define`` name and value, a
    #: string as a C string), generated into its variable header so they are written once.
    native_constants: ClassVar[dict[str, str | int | float]] = {}

    #: The parts of the model's derived data and the parameters each is built for: a changed
    #: parameter redoes the parts that list it and keeps the others. The native build writes the
    #: table into the model's variable header (``PART_<NAME>``, ``model_part_values``).
    derived_parts: ClassVar[dict[str, tuple[str, ...]]] = {}

    #: Parameter and input values, besides the start values, at which the dependency test perturbs
    #: every parameter and input (``tests/fmu/test_dependencies.py``): where an output's declared
    #: dependency (``depends_on`` in the spec) shows only at other values (friction only with the
    #: exact kinematics, a phase only away from the bend plane). A variable is perturbed by a small
    #: step and to the value it has at each other point.
    dependency_points: ClassVar[tuple[dict[str, Any], ...]] = ()

    #: The stop time of the model's standard run (``fmu_harness/runs/scenario.py``: 100 steps), where
    #: the default experiment's would make a step the model refuses (None: the default experiment's).
    scenario_stop_time: ClassVar[float | None] = None

    #: Why the model's native FMU offers co-simulation only ("": Model Exchange beside it, its states
    #: the spec's ``states``): a state the spec cannot name as an output.
    co_simulation_only: ClassVar[str] = ""

    def rounding_scales(self) -> dict[str, float]:
        """After :meth:`initialize`, the outputs whose initial value is a sum of terms that cancel
        (an equilibrium's accelerations, declared ``initial_depends_on=()``), each with the sum of
        its terms' magnitudes: the scale of its rounding error, by which the dependency test tells
        rounding from a dependency."""
        return {}

    #: Files a native FMU of the model ships in its ``resources/`` folder, by their path here (the
    #: rotor's shipped layouts); the model finds them by name in the FMU's resources folder.
    resource_files: ClassVar[tuple[Path, ...]] = ()

    def start_notice(self) -> str | None:
        """What the log says once, at initialisation, of how the model reads inputs the host left at
        their start values (a default it may not expect), or None; an information line (FMI status OK,
        category ``logAll``), not a warning: the default gives the right answer."""
        return None

    def step_size_errors(self, step_size: float) -> list[str]:
        """Why a positive, finite communication step is too long for the model (checked once the
        parameters and inputs are valid), or []."""
        return []

    def step_notice(self, step_size: float) -> str | None:
        """What the log says of a step the model took but that a host should not take (a warning; the
        adapters log one text once), or None."""
        return None

    def extra_input_errors(self) -> list[str]:
        """Input checks the spec cannot declare, run once the declared ones pass."""
        return []

    # -- validation ------------------------------------------------------------
    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        spec = getattr(cls, "spec", None)
        if spec is not None:
            cls._parameter_names = tuple(v.name for v in spec.of("parameter"))
            cls._inputs = spec.of("input")
            cls._computed = spec.of(*COMPUTED)
            cls._real_computed = tuple(v for v in cls._computed if v.type == "Real")
            cls._input_relations = tuple(r for r in spec.relations if spec.involves_input(r))
            cls._parameter_relations = tuple(r for r in spec.relations if not spec.involves_input(r))

    def parameter_errors(self) -> list[str]:
        """The declared checks (:meth:`declared_parameter_errors`), then the model's own: each stage
        only once the one before it passed."""
        return self.declared_parameter_errors() or self._guarded(self.extra_parameter_errors, "the parameters")

    def declared_parameter_errors(self) -> list[str]:
        """Each parameter against its bounds, then the relations between parameters (the spec's
        rules alone, without the model's own checks, which may analyse the structure)."""
        errors = [e for v in self.spec.of("parameter") if (e := self._range_error(v))]
        return errors or [e for r in self._parameter_relations if (e := self._relation_error(r))]

    def input_errors(self) -> list[str]:
        """As :meth:`parameter_errors`, for the inputs and the relations involving them."""
        return self.declared_input_errors() or self._guarded(self.extra_input_errors, "the inputs")

    def declared_input_errors(self) -> list[str]:
        """Each input against its bounds, then the relations involving inputs (the spec's rules alone)."""
        errors = [e for v in self._inputs if (e := self._range_error(v))]
        return errors or [e for r in self._input_relations if (e := self._relation_error(r))]

    @staticmethod
    def _guarded(check: Callable[[], list[str]], what: str) -> list[str]:
        """A model-specific check; one that fails arithmetically refuses with the reason."""
        try:
            return check()
        except (ArithmeticError, ValueError) as error:
            return [f"{what} could not be checked ({type(error).__name__}: {error})"]

    def output_errors(self) -> list[str]:
        """Outputs and locals that are not finite, then beyond their declared bounds (a physical bound
        the model's equations no longer describe): the step is not taken."""
        values = [getattr(self, v.name) for v in self._real_computed]
        if math.isfinite(math.fsum(values)):
            return [e for v in self._computed if (e := self._range_error(v))]
        return [
            f"{v.causality} {v.name} is not finite ({value!r}); the step was not taken"
            for v, value in zip(self._real_computed, values)
            if not math.isfinite(value)
        ]

    def _range_error(self, v: Variable) -> str | None:
        value = getattr(self, v.name)
        if v.type == "Real" and not math.isfinite(value):
            return f"{v.causality} {v.name} = {value!r} is not finite"
        if v.type not in ("Real", "Integer"):
            return None
        if v.min_exclusive and not value > v.min:
            return f"{v.causality} {v.name} = {v.shown(value)} must be " + (
                "positive" if v.min == 0 else f"above {v.shown(v.min)}")
        if v.max_exclusive and not value < v.max:
            return f"{v.causality} {v.name} = {v.shown(value)} must be below {v.shown(v.max)}"
        unit = f" {v.unit}" if v.unit else ""
        if v.min is not None and value < v.min:
            return f"{v.causality} {v.name} = {value!r}{unit} is below its minimum {v.min!r}{unit}"
        if v.max is not None and value > v.max:
            return f"{v.causality} {v.name} = {value!r}{unit} is above its maximum {v.max!r}{unit}"
        return None

    def _relation_error(self, relation: Relation) -> str | None:
        left = self.spec[relation.lhs]
        value = getattr(self, left.name)
        right = getattr(self, relation.rhs) if isinstance(relation.rhs, str) else relation.rhs
        if relation.holds(value, right):
            return None
        bound = relation.bound(right)
        named = f"{relation.right_side()} = " if isinstance(relation.rhs, str) else ""
        reason = f" ({relation.reason})" if relation.reason else ""
        return (f"{left.causality} {left.name} = {left.shown(value)} {RULES[relation.op]} "
                f"{named}{left.shown(bound)}{reason}")

    # -- state ---------------------------------------------------------------------
    def get_state(self) -> dict[str, Any]:
        """A deep copy of everything the model holds (variables and internal state)."""
        return copy.deepcopy(self.__dict__)

    def set_state(self, state: dict[str, Any]) -> None:
        self.__dict__.clear()
        self.__dict__.update(copy.deepcopy(state))

    #: Internal attributes that the next step rebuilds from the parameters; never saved.
    derived_state: ClassVar[tuple[str, ...]] = ()

    def saved_values(self, state: dict[str, Any]) -> dict[str, Any]:
        """What of ``state`` (from :meth:`get_state`) a serialised state keeps: plain values only."""
        return {name: value for name, value in state.items() if name not in self.derived_state}

    def state_from_saved(self, values: dict[str, Any]) -> dict[str, Any]:
        """A state for :meth:`set_state` from untrusted :meth:`saved_values`; ValueError naming what does
        not fit. Parameters are validated again at the next step, inputs at every step."""
        fresh = type(self)().__dict__
        expected = set(fresh) - set(self.derived_state)
        if set(values) != expected:
            odd = sorted(set(values) ^ expected)
            raise ValueError(f"the saved state does not hold the values of {self.spec.name} (differs in {odd[:5]})")
        state = dict(values)
        for variable in self.spec.variables:
            state[variable.name] = _saved_value(variable.name, values[variable.name], _SAVED_TYPES[variable.type])
        state["time"] = _saved_value("time", values["time"], _SAVED_TYPES["Real"])
        _saved_value("_initialized", values["_initialized"], (bool,))
        state.update(self.internal_from_saved(state))
        reason = self._restored_error(state)
        if reason is not None:
            raise ValueError(f"the state holds an impossible value ({reason})")
        for name in self.derived_state:
            state.pop(name, None)
            if name in fresh:
                state[name] = fresh[name]
        state["_valid_parameters"] = None
        return state

    def _restored_error(self, state: dict[str, Any]) -> str | None:
        """Why the values a saved state restores are none the model could have left: the time not finite,
        then a Real output or local not finite, then one beyond its bounds (as :meth:`_range_error` says it)."""
        if not math.isfinite(state["time"]):
            return f"time = {state['time']!r} is not finite"
        not_finite = (f"{v.causality} {v.name} = {state[v.name]!r} is not finite" for v in self._real_computed
                      if not math.isfinite(state[v.name]))
        probe = type(self).__new__(type(self))
        probe.__dict__.update(state)
        beyond = (error for v in self._computed if (error := probe._range_error(v)) is not None)
        return next(not_finite, None) or next(beyond, None)

    def internal_from_saved(self, state: dict[str, Any]) -> dict[str, Any]:
        """Hook: internal values of a saved state rebuilt as the model holds them (ValueError if odd)."""
        return {}

    def outputs(self) -> dict[str, Any]:
        return {v.name: getattr(self, v.name) for v in self.spec.of("output")}


_SAVED_TYPES: dict[str, tuple[type, ...]] = {"Real": (float, int), "Integer": (int,), "Boolean": (bool,), "String": (str,)}


def _saved_value(name: str, value: Any, kinds: tuple[type, ...]) -> Any:
    if isinstance(value, bool) != (bool in kinds) or not isinstance(value, kinds):
        raise ValueError(f"the saved value of {name} is a {type(value).__name__}, not a {kinds[0].__name__}")
    return float(value) if kinds[0] is float else value


class DrivenShaftModel(SteppedModel):
    """A model driven by an input shaft: ``phi_in`` integrates the held ``omega_in`` exactly.

    Subclasses have the variables ``phi_in_start``, ``omega_in`` and ``phi_in`` and compute
    their outputs in :meth:`evaluate`.
    """

    def start(self, start_time: float) -> None:
        self.phi_in = self.phi_in_start
        self.evaluate(start_time)

    def advance(self, current_time: float, step_size: float) -> None:
        self.phi_in = self.phi_in + self.omega_in * step_size
        self.evaluate(current_time)

    @abstractmethod
    def evaluate(self, input_time: float) -> None:
        """Outputs from the current ``phi_in``, inputs and parameters; ``input_time`` is the
        communication point at which the host set the inputs (the start of the step)."""


class TimeSourceModel(SteppedModel):
    """A model whose outputs are exact functions of time: :meth:`at_time` at the start time and at the
    end of each step, so they do not depend on the communication step."""

    def start(self, start_time: float) -> None:
        self.at_time(start_time)

    def advance(self, current_time: float, step_size: float) -> None:
        self.at_time(current_time + step_size)

    @abstractmethod
    def at_time(self, t: float) -> None:
        """The outputs at time ``t`` from the parameters."""
