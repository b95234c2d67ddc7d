"""Declarative description of a model's interface and of its valid values.

One :class:`ModelSpec` per model feeds the FMI 2.0 and FMI 3.0 builds alike: the
adapters register these variables, and the build writes units, display units,
ranges and descriptions from them into the model description. What makes a value valid
is declared here once, as data: each variable's bounds (inclusive or exclusive) and the
:class:`Relation` s between variables; :class:`driveline.model.SteppedModel` enforces them.
The model description carries the bounds as FMI's inclusive ``min``/``max``; an exclusive
bound is refused by the model alone. What each output is computed from is declared here too
(``depends_on``, :class:`State`): the build writes it as the ``dependencies`` of the model
structure, and a test perturbs every parameter and input of the FMUs against it.
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass, field
from typing import Literal

Causality = Literal["parameter", "input", "output", "local"]
Variability = Literal["constant", "fixed", "tunable", "discrete", "continuous"]
VarType = Literal["Real", "Integer", "Boolean", "String"]
Operator = Literal["<", "<=", ">", ">="]

#: The causalities of what a model computes (after each step, checked finite and within bounds; read, never set):
#: an output, for others to use, and a local, the model's own (an internal state no host wires)
COMPUTED: tuple[Causality, ...] = ("output", "local")

OPERATORS = {"<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge}


@dataclass(frozen=True)
class DisplayUnit:
    """A display unit: ``display_value = factor * value + offset``."""

    name: str
    factor: float
    offset: float = 0.0


@dataclass(frozen=True)
class Unit:
    """An SI unit with its base-unit exponents and optional display units."""

    name: str
    exponents: dict[str, int] = field(default_factory=dict)
    display_units: tuple[DisplayUnit, ...] = ()


UNITS: dict[str, Unit] = {
    u.name: u
    for u in (
        Unit("s", {"s": 1}),
        Unit("Hz", {"s": -1}),
        Unit("1/s", {"s": -1}),
        Unit("m", {"m": 1}, (DisplayUnit("mm", 1e3),)),
        Unit("kg", {"kg": 1}),
        Unit("rad", {"rad": 1}, (DisplayUnit("deg", 180.0 / math.pi),)),
        Unit("rad/s", {"rad": 1, "s": -1}, (DisplayUnit("rpm", 30.0 / math.pi),)),
        Unit("rad/s2", {"rad": 1, "s": -2}),
        Unit("N", {"kg": 1, "m": 1, "s": -2}),
        Unit("N.m", {"kg": 1, "m": 2, "s": -2}),
        Unit("N/m", {"kg": 1, "s": -2}),
        Unit("N.s/m", {"kg": 1, "s": -1}),
        Unit("N.m/rad", {"kg": 1, "m": 2, "s": -2, "rad": -1}),
        Unit("N.m.s/rad", {"kg": 1, "m": 2, "s": -1, "rad": -1}),
        Unit("m2", {"m": 2}),
        Unit("N/s", {"kg": 1, "m": 1, "s": -3}),
        Unit("N.m/s", {"kg": 1, "m": 2, "s": -3}),
        Unit("kg.m", {"kg": 1, "m": 1}, (DisplayUnit("g.mm", 1e6),)),
        Unit("Pa", {"kg": 1, "m": -1, "s": -2}, (DisplayUnit("MPa", 1e-6),)),
        Unit("kg/m3", {"kg": 1, "m": -3}),
        Unit("kg.m2", {"kg": 1, "m": 2}),
        Unit("m/s", {"m": 1, "s": -1}, (DisplayUnit("km/h", 3.6),)),
        Unit("m/s2", {"m": 1, "s": -2}),
        Unit("W", {"kg": 1, "m": 2, "s": -3}),
        Unit("1", {}),
    )
}


@dataclass(frozen=True)
class Variable:
    """One FMU variable: the single source of its name, causality, unit, range and start.

    ``min`` and ``max`` are inclusive unless ``min_exclusive`` / ``max_exclusive`` say otherwise.
    """

    name: str
    causality: Causality
    start: float | int | bool | str
    description: str
    unit: str | None = None
    display_unit: str | None = None
    min: float | None = None
    max: float | None = None
    type: VarType = "Real"
    variability: Variability | None = None
    min_exclusive: bool = False
    max_exclusive: bool = False
    #: An input that is the time derivative of the input named here (FMI 3.0's ``derivative``
    #: attribute; the native FMI 2.0 FMUs take it from ``fmi2SetRealInputDerivatives``).
    derivative: str | None = None
    #: An output's direct dependencies: the inputs, parameters and states (:class:`State`) its value
    #: is computed from at one instant, whatever their values (a friction coefficient that acts with
    #: the exact kinematics only is named). Every output that is no state declares them.
    depends_on: tuple[str, ...] | None = None
    #: What the output's value at initialisation depends on, where that differs from ``depends_on``
    #: (a difference of two samples is zero until the second sample).
    initial_depends_on: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        if self.unit is not None and self.unit not in UNITS:
            raise ValueError(f"{self.name}: unknown unit {self.unit!r}")
        if self.display_unit is not None:
            names = [d.name for d in UNITS[self.unit].display_units] if self.unit else []
            if self.display_unit not in names:
                raise ValueError(f"{self.name}: {self.display_unit!r} is no display unit of {self.unit!r}")
        if (self.min_exclusive and self.min is None) or (self.max_exclusive and self.max is None):
            raise ValueError(f"{self.name}: an exclusive bound needs its value")

    @property
    def article(self) -> str:
        """The causality with its article, as a message names it: ``an output``, ``a local``."""
        return f"{'an' if self.causality[0] in 'aeiou' else 'a'} {self.causality}"

    def shown(self, value: float) -> str:
        """``value`` (SI) as a message shows it: in the display unit if there is one."""
        if self.display_unit is not None:
            display = next(d for d in UNITS[self.unit].display_units if d.name == self.display_unit)
            return f"{display.factor * value + display.offset:.6g} {display.name}"
        return f"{value!r} {self.unit}" if self.unit not in (None, "1") else repr(value)

    @property
    def effective_variability(self) -> Variability:
        """Variability as written to the model description."""
        if self.variability is not None:
            return self.variability
        if self.causality == "parameter":
            return "fixed"
        return "continuous" if self.type == "Real" else "discrete"


@dataclass(frozen=True)
class Relation:
    """A declared constraint ``lhs op scale * rhs + offset`` (SI values).

    ``lhs`` names a variable, ``rhs`` names one of the same unit or is a constant; ``reason``
    (optional) is added to the refusal message. A relation involving an input is checked
    with the inputs, one between parameters with the parameters.
    """

    lhs: str
    op: Operator
    rhs: str | float
    scale: float = 1.0
    offset: float = 0.0
    reason: str = ""

    def holds(self, left: float, right: float) -> bool:
        """Whether ``left op scale * right + offset`` (``right``: the rhs variable's value, or the constant)."""
        return OPERATORS[self.op](left, self.bound(right))

    def bound(self, right: float) -> float:
        """The value ``lhs`` is compared with (``right`` itself, an integer stays one, when
        neither scaled nor offset)."""
        return right if self.scale == 1.0 and not self.offset else self.scale * right + self.offset

    def right_side(self) -> str:
        """The right side as written: ``z1``, ``-omega_max``, ``2 L1 + 0.001``, ``3.14159``."""
        if not isinstance(self.rhs, str):
            return f"{self.bound(self.rhs):.6g}"
        factor = {1.0: "", -1.0: "-"}.get(self.scale, f"{self.scale:g} ")
        shift = f" {'+' if self.offset > 0 else '-'} {abs(self.offset):g}" if self.offset else ""
        return f"{factor}{self.rhs}{shift}"

    def __str__(self) -> str:
        return f"{self.lhs} {self.op} {self.right_side()}"


def decade(value: float) -> float:
    """The power of ten at or below ``value`` (> 0): the order of magnitude a nominal is given."""
    return 10.0 ** math.floor(math.log10(value))


#: The nominal of a shaft's angle (State.nominal): a radian, the angle's own scale; a shaft that turns
#: winds it past that at once, where the solver's relative tolerance governs.
SHAFT_ANGLE_NOMINAL = 1.0  # rad


@dataclass(frozen=True)
class State:
    """An output or local the model integrates over time (an input shaft's angle): its value at one instant
    is its own, ``initial`` names the parameters and inputs its value at initialisation is computed
    from (inputs: a start in the equilibrium under the start inputs) and ``derivative`` the input
    or output that is its time derivative (a Model Exchange FMU's continuous state, whose
    derivative is the variable ``der(<name>)``). ``nominal`` is its typical magnitude in SI units
    (the model description's ``nominal`` attribute and ``GetNominalsOfContinuousStates``), declared
    by every state: a host's solver scales its absolute tolerance by it."""

    name: str
    initial: tuple[str, ...]
    derivative: str
    nominal: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.nominal) and self.nominal > 0.0):
            raise ValueError(f"state {self.name}: the nominal must be finite and positive, got {self.nominal!r}")

    @property
    def derivative_name(self) -> str:
        return f"der({self.name})"


@dataclass(frozen=True)
class DefaultExperiment:
    start_time: float
    stop_time: float
    step_size: float
    tolerance: float | None = None


@dataclass(frozen=True)
class ModelSpec:
    """The interface of one model: its FMU name, description, variables, default experiment, the
    relations its parameters and inputs must satisfy and the outputs that are states."""

    name: str
    description: str
    variables: tuple[Variable, ...]
    default_experiment: DefaultExperiment
    relations: tuple[Relation, ...] = ()
    states: tuple[State, ...] = ()

    def __post_init__(self) -> None:
        names = [v.name for v in self.variables]
        duplicates = {n for n in names if names.count(n) > 1}
        if duplicates:
            raise ValueError(f"{self.name}: duplicate variable names {sorted(duplicates)}")
        for relation in self.relations:
            sides = [relation.lhs] + ([relation.rhs] if isinstance(relation.rhs, str) else [])
            if any(side not in names for side in sides) or relation.op not in OPERATORS:
                raise ValueError(f"{self.name}: relation {relation} names no variable of the model or no operator")
            variables = [self[side] for side in sides]
            if any(v.causality in COMPUTED or v.type not in ("Real", "Integer") for v in variables):
                raise ValueError(f"{self.name}: relation {relation} must relate numeric parameters or inputs")
            if len({v.unit for v in variables}) > 1:
                raise ValueError(f"{self.name}: relation {relation} relates different units")
        self._check_dependencies()

    def _check_dependencies(self) -> None:
        """Every output or local is a state or declares ``depends_on``, naming inputs, parameters and states."""
        states = {state.name for state in self.states}
        knowns = {v.name for v in self.of("input", "parameter")}
        computed = {v.name for v in self.of(*COMPUTED)}
        for state in self.states:
            if state.name not in computed or not set(state.initial) <= knowns:
                raise ValueError(f"{self.name}: state {state.name} must be an output or local and its initial "
                                 f"values must name parameters or inputs, got {state.initial}")
            if state.derivative not in computed | {v.name for v in self.of("input")}:
                raise ValueError(f"{self.name}: the derivative of state {state.name} must be an input, output or "
                                 f"local, got {state.derivative!r}")
        for v in self.of(*COMPUTED):
            if v.depends_on is None and v.name not in states:
                raise ValueError(
                    f"{self.name}: {v.causality} {v.name} declares no dependencies: give its Variable "
                    f"depends_on=(...), the inputs, parameters and states (ModelSpec.states) it is computed "
                    f"from, or () for none (docs/development.md, Add a model)")
            for names in (v.depends_on or (), v.initial_depends_on or ()):
                unknown = [name for name in names if name not in knowns | states]
                if unknown:
                    raise ValueError(f"{self.name}: {v.causality} {v.name} depends on {unknown}, which are no "
                                     f"input, parameter or state of the model")

    def output_dependencies(self, name: str, states: bool = False) -> tuple[str, ...]:
        """The inputs output ``name`` depends on directly (FMI ``<Outputs>``), and with ``states`` the
        states (Model Exchange: a state depends on itself), in the spec's order."""
        declared = set(self[name].depends_on or ()) | {name}
        known = [v.name for v in self.of("input")] + [s.name for s in self.states if states]
        return tuple(v.name for v in self.variables if v.name in known and v.name in declared)

    def derivative_dependencies(self, state: State, initial: bool = False) -> tuple[str, ...]:
        """What ``der(state)`` depends on: its derivative's dependencies, an input depending on itself."""
        if self[state.derivative].causality == "input":
            return (state.derivative,)
        if initial:
            return self.initial_dependencies(state.derivative)
        return self.output_dependencies(state.derivative, states=True)

    def initial_dependencies(self, name: str) -> tuple[str, ...]:
        """The parameters and inputs output ``name`` depends on at initialisation (FMI
        ``<InitialUnknowns>``), a state's through its initial values, in the spec's order."""
        variable = self[name]
        declared = variable.initial_depends_on if variable.initial_depends_on is not None else variable.depends_on
        names = set(declared or ())
        for state in self.states:
            if state.name in names or state.name == name:
                names |= set(state.initial)
        return tuple(v.name for v in self.of("parameter", "input") if v.name in names)

    def involves_input(self, relation: Relation) -> bool:
        """Whether ``relation`` is checked with the inputs (it involves one) rather than the parameters."""
        return any(isinstance(side, str) and self[side].causality == "input" for side in (relation.lhs, relation.rhs))

    def of(self, *causalities: Causality) -> tuple[Variable, ...]:
        return tuple(v for v in self.variables if v.causality in causalities)

    def __getitem__(self, name: str) -> Variable:
        for v in self.variables:
            if v.name == name:
                return v
        raise KeyError(name)

    @property
    def units(self) -> tuple[Unit, ...]:
        used = {v.unit for v in self.variables if v.unit is not None}
        return tuple(UNITS[name] for name in UNITS if name in used)
