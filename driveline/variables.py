"""Declarative description of a model's interface.

One :class:`ModelSpec` per model feeds the FMI 2.0 and FMI 3.0 builds alike: the
adapters register these variables, and the build writes units, display units,
ranges and descriptions from them into the model description.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

Causality = Literal["parameter", "input", "output"]
Variability = Literal["constant", "fixed", "tunable", "discrete", "continuous"]
VarType = Literal["Real", "Integer", "Boolean", "String"]


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
        Unit("m", {"m": 1}, (DisplayUnit("mm", 1e3),)),
        Unit("kg", {"kg": 1}),
        Unit("rad", {"rad": 1}, (DisplayUnit("deg", 180.0 / math.pi),)),
        Unit("rad/s", {"rad": 1, "s": -1}, (DisplayUnit("rpm", 30.0 / math.pi),)),
        Unit("rad/s2", {"rad": 1, "s": -2}),
        Unit("N", {"kg": 1, "m": 1, "s": -2}),
        Unit("N.m", {"kg": 1, "m": 2, "s": -2}),
        Unit("N/m", {"kg": 1, "s": -2}),
        Unit("Pa", {"kg": 1, "m": -1, "s": -2}, (DisplayUnit("MPa", 1e-6),)),
        Unit("kg/m3", {"kg": 1, "m": -3}),
        Unit("kg.m2", {"kg": 1, "m": 2}),
        Unit("m/s2", {"m": 1, "s": -2}),
        Unit("1", {}),
    )
}


@dataclass(frozen=True)
class Variable:
    """One FMU variable: the single source of its name, causality, unit, range and start."""

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

    def __post_init__(self) -> None:
        if self.unit is not None and self.unit not in UNITS:
            raise ValueError(f"{self.name}: unknown unit {self.unit!r}")
        if self.display_unit is not None:
            names = [d.name for d in UNITS[self.unit].display_units] if self.unit else []
            if self.display_unit not in names:
                raise ValueError(f"{self.name}: {self.display_unit!r} is no display unit of {self.unit!r}")

    @property
    def effective_variability(self) -> Variability:
        """Variability as written to the model description."""
        if self.variability is not None:
            return self.variability
        if self.causality == "parameter":
            return "fixed"
        return "continuous" if self.type == "Real" else "discrete"


@dataclass(frozen=True)
class DefaultExperiment:
    start_time: float
    stop_time: float
    step_size: float
    tolerance: float | None = None


@dataclass(frozen=True)
class ModelSpec:
    """The interface of one model: its FMU name, description, variables and default experiment."""

    name: str
    description: str
    variables: tuple[Variable, ...]
    default_experiment: DefaultExperiment

    def __post_init__(self) -> None:
        names = [v.name for v in self.variables]
        duplicates = {n for n in names if names.count(n) > 1}
        if duplicates:
            raise ValueError(f"{self.name}: duplicate variable names {sorted(duplicates)}")

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
