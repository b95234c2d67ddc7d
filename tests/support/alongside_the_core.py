"""An FMU driven in step with its FMI-free core through random runs, for the property tests of
both families: the runs (parameters, inputs and step sizes, bad ones included), and the promise that
a step is refused exactly when the core refuses it, with the core's reasons."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import pytest
from hypothesis import strategies as st

from driveline.catalog import MODELS
from driveline.model import SteppedModel
from driveline.variables import Variable
from fmu_harness.runs.runner import FmuInstance, StepRefused

INT32 = (-(2**31), 2**31 - 1)
NON_FINITE = (math.nan, math.inf, -math.inf)
ODD_STEPS = (0.0, -1e-3, math.nan, math.inf, -math.inf, 5e-324, 1e-300)

Run = tuple[dict[str, Any], list[tuple[dict[str, Any], float]]]


def _plausible(variable: Variable) -> st.SearchStrategy[Any]:
    """Values within 5 % of the start value (or 0.1 of it when it is 0)."""
    start = variable.start
    if variable.type == "String":
        return st.just(start)
    if variable.type == "Integer":
        spread = max(1, abs(start) // 20)
        return st.integers(max(start - spread, int(variable.min) if variable.min is not None else INT32[0]),
                           min(start + spread, int(variable.max) if variable.max is not None else INT32[1]))
    spread = abs(start) * 0.05 or 0.1
    return st.floats(start - spread, start + spread)


def _bad(variable: Variable) -> st.SearchStrategy[Any]:
    """Out-of-range values of ``variable``, and for a Real also non-finite or huge ones."""
    if variable.type == "String":
        return st.sampled_from(["x", "missing.toml"])
    below = [variable.min - 1] if variable.min is not None else []
    above = [variable.max + 1] if variable.max is not None else []
    if variable.type == "Integer":
        low, high = (below or [INT32[0]])[0], (above or [INT32[1]])[0]
        return st.one_of(st.integers(INT32[0], low), st.integers(high, INT32[1]))
    return st.sampled_from([*NON_FINITE, 1e300, -1e300, *below, *above])


@st.composite
def random_runs(draw: st.DrawFn, model_name: str) -> Run:
    """Parameters (one bad in about a quarter of the runs), then steps of (input values, step
    size), each with no fault, one bad input or an odd step size; every step sets all inputs,
    so a good step follows a refused one."""
    spec = MODELS[model_name].spec
    parameters = {v.name: draw(_plausible(v)) for v in spec.of("parameter")}
    if parameters and draw(st.integers(0, 3)) == 0:
        bad = draw(st.sampled_from(spec.of("parameter")))
        parameters[bad.name] = draw(_bad(bad))
    default = spec.default_experiment.step_size
    steps = []
    for _ in range(draw(st.integers(2, 8))):
        inputs = {v.name: draw(_plausible(v)) for v in spec.of("input")}
        step_size = draw(st.floats(default * 1e-3, default * 10.0))
        fault = draw(st.sampled_from(("none", "input", "step size")))
        if fault == "input" and inputs:
            bad = draw(st.sampled_from(spec.of("input")))
            inputs[bad.name] = draw(_bad(bad))
        elif fault == "step size":
            step_size = draw(st.sampled_from(ODD_STEPS))
        steps.append((inputs, step_size))
    return parameters, steps


def expect_refused_parameters(fmu: FmuInstance, values: dict[str, Any], errors: list[str],
                              reason: Callable[[str], str] = str) -> None:
    """Values whose parameters or start values the core refuses (``errors``) are refused at
    initialisation with the core's reasons (as ``reason`` keeps them): Error from the native FMUs;
    the Python FMUs' wrappers return OK there, so they log the reasons after the call's name and
    refuse every step."""
    first = len(fmu.log)
    expected = [reason(error) for error in errors]
    try:
        fmu.initialize(values)
    except StepRefused as refused:
        assert (refused.status, [reason(m) for m in refused.messages]) == ("Error", expected)
        return
    assert [reason(m) for m in fmu.messages_since(first)] == [reason(f"exitInitializationMode: {e}") for e in errors]
    with pytest.raises(StepRefused):
        fmu.step(1e-3)


def run_alongside_the_core(fmu: FmuInstance, model_class: type[SteppedModel], run: Run,
                           reason: Callable[[str], str] = str) -> tuple[list, list]:
    """Drive ``fmu`` and a fresh core of ``model_class`` through ``run`` in step. A step must be
    refused by both, with the core's reasons (as ``reason`` keeps them) logged as Discard (once: the
    same refusal repeated logs nothing), or by neither; returns the outputs
    after each accepted step, the FMU's and the core's."""
    parameters, steps = run
    outputs = [v.name for v in model_class.spec.of("output")]
    core = model_class()
    for name, value in parameters.items():
        setattr(core, name, value)
    # the parameters, or the start values with them (outputs the core cannot compute: L1 = 1e300 m puts the
    # reducer's stresses beyond their bounds), refused at initialisation
    errors = core.parameter_errors() or core.initialize(0.0)
    if errors:
        expect_refused_parameters(fmu, parameters, errors, reason)
        return [], []
    fmu.initialize(parameters)
    fmu_rows, core_rows = [], []
    repeated = None  # the first reason of the last refusal: the same refusal again is not logged again
    for inputs, step_size in steps:
        fmu.set(inputs)
        for name, value in inputs.items():
            setattr(core, name, value)
        errors = core.step(fmu.time, step_size)
        if errors:
            with pytest.raises(StepRefused) as refused:
                fmu.step(step_size)
            assert refused.value.status == "Discard"
            assert [reason(m) for m in refused.value.messages] == ([] if errors[0] == repeated else
                                                                   [reason(e) for e in errors])
            repeated = errors[0]
        else:
            repeated = None
            fmu.step(step_size)
            fmu_rows.append(fmu.get(outputs))
            core_rows.append([getattr(core, name) for name in outputs])
    return fmu_rows, core_rows
