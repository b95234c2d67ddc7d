"""The model structure's ``dependencies`` (``depends_on`` and ``states`` in each spec) against the
FMUs, both families and FMI versions: every parameter and input is perturbed, and exactly the
outputs that declare it change.

Initial unknowns: the outputs after ``exitInitializationMode`` at a start time that is not zero
(the speed source's ramp and sine show only there), with each parameter and input perturbed; an
undeclared change is any change (the same inputs give the same bits), but for an output that is a
sum of terms cancelling at initialisation (PowertrainMounts' accelerations, zero in the equilibrium
it starts in: ``SteppedModel.rounding_scales``), whose value there is rounding: ROUNDING times the
sum of its terms' magnitudes. Outputs in step mode: each
input perturbed at a communication point, then one step of h and one of h * 1e-6 from the same
saved state; an output depends directly on the input when its change does not shrink with the
step (a change through a state, the input angle, shrinks with h: by 1e-6 here, below the 1e-3
drawn between them).

Each declared dependency of a Real output must show at one of the model's dependency points (the
start values and ``dependency_points`` of its class); an Integer or Boolean output changes only
where a perturbation crosses a threshold, so for those an undeclared change alone is checked.
"""

from __future__ import annotations

import functools
import math
from typing import Any

from fmpy import read_model_description

from driveline.catalog import MODELS
from driveline.model import SteppedModel
from driveline.variables import Variable
from support.dependency_points import points

START_TIME = 0.0123  # s: sin and cos of the source's 5 Hz sine are far from 0 and 1 here
STEP = 1e-4  # s
SHRINK = 1e-6  # the short step, h * SHRINK
DIRECT = 1e-3  # a change that keeps this share of itself on the short step is direct
RELATIVE_STEP = 1e-3  # the small perturbation of a Real value, relative (absolute for zero)
# A sum of n terms rounds within n eps of the sum of their magnitudes (12 terms: 2.7e-15), the
# equilibrium it is taken at within cond(K) eps (PowertrainMounts' layouts: 28 and below 1e3),
# so rounding stays below 3e-13 of that scale (measured: 6e-17); a model that failed to start in
# its equilibrium would be off by the scale times the input's relative step, 1e-3
ROUNDING = 1e-12


def small_step(variable: Variable, value: Any) -> Any:
    """``value`` moved a little within the variable's bounds (None for a String)."""
    if variable.type == "Boolean":
        return not value
    if variable.type == "String":
        return None
    delta = 1 if variable.type == "Integer" else RELATIVE_STEP * (abs(value) or 1.0)
    if variable.max is not None and value + delta >= variable.max:
        return value - delta
    return value + delta


def perturbations(model: str, variable: Variable, point: dict[str, Any]) -> list[Any]:
    """A small step, and the value the variable has at each other dependency point."""
    value = point.get(variable.name, variable.start)
    others = [other.get(variable.name, variable.start) for other in points(model)]
    found = [small_step(variable, value), *others]
    return [v for i, v in enumerate(found) if v is not None and v != value and v not in found[:i]]


def core_at(model: str, values: dict[str, Any]) -> SteppedModel:
    core = MODELS[model]()
    for name, value in values.items():
        setattr(core, name, value)
    return core


def valid(model: str, values: dict[str, Any]) -> bool:
    """Whether the core accepts these parameters and inputs (a refused set shows nothing); asked
    once per set of values in a process (the FMUs of a model ask alike: for CriticalSpeeds, an
    analysis each)."""
    return _valid(model, tuple(sorted(values.items())))


@functools.cache
def _valid(model: str, values: tuple[tuple[str, Any], ...]) -> bool:
    core = core_at(model, dict(values))
    return not (core.parameter_errors() or core.input_errors())


def rounding(model: str, values: dict[str, Any]) -> dict[str, float]:
    """The largest rounding error of each output summing cancelling terms at initialisation (only
    an output computed from something but declaring nothing at initialisation can be one)."""
    if not any(v.depends_on and v.initial_depends_on == () for v in MODELS[model].spec.of("output")):
        return {}
    core = core_at(model, values)
    assert not core.initialize(START_TIME)
    found = {name: ROUNDING * scale for name, scale in core.rounding_scales().items()}
    # a state's der() is its derivative's value (Model Exchange: the accelerations are der(<velocity>))
    states = MODELS[model].spec.states
    return {**found, **{s.derivative_name: found[s.derivative] for s in states if s.derivative in found}}


def declared(path, initial: bool) -> dict[str, set[str]]:
    description = read_model_description(str(path))
    unknowns = description.initialUnknowns if initial else description.outputs
    return {unknown.variable.name: {known.name for known in unknown.dependencies} for unknown in unknowns}


def continuous(model: str) -> set[str]:
    return {v.name for v in MODELS[model].spec.of("output") if v.type == "Real"}


def check(model: str, declared: dict[str, set[str]], observed: dict[str, set[str]]) -> None:
    undeclared = {name: sorted(observed[name] - known) for name, known in declared.items() if observed[name] - known}
    assert not undeclared, f"outputs changed by variables they do not declare in depends_on: {undeclared}"
    unseen = {name: sorted(known - observed[name]) for name, known in declared.items()
              if name in continuous(model) and known - observed[name]}
    assert not unseen, (f"declared dependencies that changed nothing at any of the dependency points: {unseen}; "
                        "drop them from depends_on or add a point where they act to the model's dependency_points")


def test_every_fmu_of_a_model_declares_the_same_dependencies(family, model_name, fmi_versions):
    """The model structures of both FMI versions, Python and native, name the same variables; with
    Model Exchange (the native FMUs) the outputs depend on the states too, and the states that are locals are
    initial unknowns (their initial values are calculated)."""
    spec = MODELS[model_name].spec
    for version in fmi_versions:
        path = family.path(model_name, version)
        states = read_model_description(str(path)).modelExchange is not None
        assert states == (family.name == "native" and not MODELS[model_name].co_simulation_only)
        assert declared(path, initial=False) == {v.name: set(spec.output_dependencies(v.name, states))
                                                 for v in spec.of("output")}
        derivatives = {s.derivative_name: set(spec.derivative_dependencies(s, initial=True))
                       for s in (spec.states if states else ())}
        local_states = {s.name: set(spec.initial_dependencies(s.name))
                        for s in (spec.states if states else ()) if spec[s.name].causality == "local"}
        assert declared(path, initial=True) == {**{v.name: set(spec.initial_dependencies(v.name))
                                                   for v in spec.of("output")}, **local_states, **derivatives}


def test_initial_unknowns_change_with_exactly_their_declared_dependencies(family, model_name, fmi):
    path = family.path(model_name, fmi)
    expected = declared(path, initial=True)
    observed: dict[str, set[str]] = {name: set() for name in expected}
    spec = MODELS[model_name].spec

    def initial_outputs(values: dict[str, Any]) -> dict[str, Any]:
        with family.open(model_name, fmi) as fmu:
            fmu.initialize(values, START_TIME)
            return dict(zip(expected, fmu.get(expected)))

    for point in points(model_name):
        base, base_rounding = initial_outputs(point), rounding(model_name, point)
        for variable in spec.of("parameter", "input"):
            for value in perturbations(model_name, variable, point):
                values = {**point, variable.name: value}
                if valid(model_name, values):
                    changed, changed_rounding = initial_outputs(values), rounding(model_name, values)
                    observed_now = {name for name, y in changed.items() if y != base[name] and abs(y - base[name])
                                    > base_rounding.get(name, 0.0) + changed_rounding.get(name, 0.0)}
                    for name in observed_now:
                        observed[name].add(variable.name)
    check(model_name, expected, observed)


def test_outputs_change_directly_with_exactly_their_declared_inputs(family, model_name, fmi):
    path = family.path(model_name, fmi)
    spec = MODELS[model_name].spec
    inputs = {v.name for v in spec.of("input")}  # the states' part: tests/native/test_native_model_exchange.py
    expected = {name: known & inputs for name, known in declared(path, initial=False).items()}
    observed: dict[str, set[str]] = {name: set() for name in expected}
    for point in points(model_name):
        with family.open(model_name, fmi) as fmu:
            fmu.initialize(point, START_TIME)
            fmu.step(STEP)
            state, time = fmu.get_state(), fmu.time

            def outputs_after(values: dict[str, Any], step: float) -> list[float]:
                fmu.set_state(state)
                fmu.time = time
                fmu.set(values)
                fmu.step(step)
                return fmu.get(expected)

            for variable in spec.of("input"):
                for value in perturbations(model_name, variable, point):
                    if not valid(model_name, {**point, variable.name: value}):
                        continue
                    changes = [[abs(float(b) - float(a)) for a, b in zip(outputs_after({}, h),
                                                                      outputs_after({variable.name: value}, h))]
                               for h in (STEP, STEP * SHRINK)]
                    for name, long, short in zip(expected, *changes):
                        assert math.isfinite(long) and math.isfinite(short), (name, variable.name)
                        if short > DIRECT * long:
                            observed[name].add(variable.name)
            fmu.free_state(state)
    check(model_name, expected, observed)
