"""Local variables (``Variable`` causality ``local``): PowertrainMounts' Maxwell branches' forces and rates, internal
states no host wires. Both families and FMI versions describe them as locals (no start value, in no list of
outputs; with Model Exchange the states among the initial unknowns, their derivatives among the derivatives),
give their values to a get, and refuse to set them, with the reason logged."""

from __future__ import annotations

import math

import pytest
from fmpy import read_model_description
from fmpy.fmi1 import FMICallException

from driveline.mounts.spec import BRANCH_FORCES, BRANCH_RATES, RUBBER_LAYOUT, SPEC

MODEL = "PowertrainMounts"


def test_the_specs_locals_are_the_branches():
    assert [v.name for v in SPEC.of("local")] == [name for pair in zip(BRANCH_FORCES, BRANCH_RATES) for name in pair]
    assert not set(BRANCH_FORCES + BRANCH_RATES) & {v.name for v in SPEC.of("output")}


def test_the_model_description_lists_the_locals_as_locals(family, fmi):
    description = read_model_description(str(family.path(MODEL, fmi)))
    variables = {v.name: v for v in description.modelVariables}
    locals_ = {v.name for v in SPEC.of("local")}
    assert {name for name, v in variables.items() if v.causality == "local" and not name.startswith("der(")} == locals_
    assert all(variables[name].start is None and variables[name].variability == "continuous" for name in locals_)
    assert not locals_ & {unknown.variable.name for unknown in description.outputs}
    initial = {unknown.variable.name for unknown in description.initialUnknowns}
    model_exchange = description.modelExchange is not None
    assert initial & locals_ == (set(BRANCH_FORCES) if model_exchange else set())
    if model_exchange:  # each branch force a continuous state: der(F) among the derivatives, its variable F
        derivatives = {unknown.variable.derivative.name for unknown in description.derivatives}
        assert set(BRANCH_FORCES) <= derivatives


def test_a_local_is_read_and_never_set(family, fmi):
    """A step on the rubber layout under a load moves the branches: their values are got, finite and not all 0;
    setting one is misuse (native: Error; Python: the step after it is refused), naming the variable."""
    with family.open(MODEL, fmi) as fmu:
        fmu.initialize({"layout": RUBBER_LAYOUT, "F_z": 2000.0})
        for _ in range(5):
            fmu.step(1e-3)
        values = fmu.get(BRANCH_FORCES + BRANCH_RATES)
        assert all(math.isfinite(value) for value in values) and any(value != 0.0 for value in values)
        reference = fmu.variables[BRANCH_FORCES[0]].valueReference
        setter = fmu.fmu.setFloat64 if fmi == "3" else fmu.fmu.setReal
        if family.name == "native":
            with pytest.raises(FMICallException):
                setter([reference], [1.0])
        else:
            setter([reference], [1.0])
        assert any(f"{BRANCH_FORCES[0]}" in entry.message and "is a local variable and cannot be set" in entry.message
                   for entry in fmu.log)
