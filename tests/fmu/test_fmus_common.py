"""Behaviour every FMU of the catalog shares, Python and native, through fmpy: a clean description,
a default experiment that runs, and refusals."""

from __future__ import annotations

import math

import pytest
from fmpy.validation import validate_fmu

from driveline.catalog import MODELS
from fmu_harness.runs.runner import StepRefused

INPUTS = [(name, v.name) for name, model in MODELS.items() for v in model.spec.of("input") if v.type == "Real"]
PARAMETERS = [(name, v.name) for name, model in MODELS.items() for v in model.spec.of("parameter") if v.type == "Real"]


@pytest.mark.parametrize("name", list(MODELS))
def test_validates_clean(family, name):
    assert validate_fmu(str(family.path(name))) == []


@pytest.mark.parametrize("name", list(MODELS))
def test_default_experiment_runs(family, name):
    experiment = MODELS[name].spec.default_experiment
    with family.open(name) as fmu:
        fmu.initialize()
        result = fmu.run(experiment.stop_time, experiment.step_size)
    assert len(result) == round(experiment.stop_time / experiment.step_size) + 1


@pytest.mark.parametrize("name, variable", INPUTS)
@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_non_finite_input_is_refused_and_the_run_goes_on(family, name, variable, value):
    with family.open(name) as fmu:
        fmu.initialize()
        fmu.step(1e-3)
        good = fmu.get([variable])[0]
        before = fmu.get(fmu.outputs())
        fmu.set({variable: value})
        with pytest.raises(StepRefused) as refused:
            fmu.step(1e-3)
        assert refused.value.status == "Discard"
        assert any(variable in m and "not finite" in m for m in refused.value.messages)
        assert fmu.get(fmu.outputs()) == before
        fmu.set({variable: good})
        fmu.step(1e-3)


@pytest.mark.parametrize("name, variable", PARAMETERS)
def test_non_finite_parameter_is_refused(family, name, variable):
    with family.open(name) as fmu:
        with pytest.raises(StepRefused) as refused:  # native: at initialisation; Python: the first step
            fmu.initialize({variable: math.nan})
            fmu.step(1e-3)
    assert any(variable in m for m in refused.value.messages)


@pytest.mark.parametrize("name", list(MODELS))
@pytest.mark.parametrize("step", [0.0, -1e-3, math.inf])
def test_bad_step_size_is_refused(family, name, step):
    with family.open(name) as fmu:
        fmu.initialize()
        with pytest.raises(StepRefused) as refused:
            fmu.step(step)
    assert "step size" in refused.value.messages[0]


#: Start values beyond what the model accepts with its default parameters, and a fragment of the reason.
REFUSED_STARTS = [
    ("TripodCoupling", {"beta": 0.9}, "input beta = 51.5662 deg must not exceed beta_max = 45 deg"),
    ("CardanJoint", {"beta": 0.9}, "input beta = 51.5662 deg must not exceed beta_max = 45 deg"),
    ("TripodCoupling", {"omega_in": math.nan}, "input omega_in = nan is not finite"),
]


@pytest.mark.parametrize("name, start, reason", REFUSED_STARTS)
def test_a_start_value_the_model_refuses_is_refused_at_initialisation_with_one_message(family, fmi, name, start,
                                                                                      reason):
    """Before: beta = 0.9 rad under beta_max = 45 deg passed ExitInitializationMode with OK and
    outputs 0, the reason logged there and again at the first step. Now the native FMUs return
    Error there, the Python FMUs (whose wrappers return OK) enter the error state; either way the
    reason is logged once, at initialisation, and no step is taken."""
    with family.open(name, fmi) as fmu:
        try:
            fmu.initialize(start)
        except StepRefused as refused:
            assert family.name == "native" and refused.status == "Error"
        at_initialisation = [record.message for record in fmu.log]
        assert len(at_initialisation) == 1 and reason in at_initialisation[0], at_initialisation
        with pytest.raises(StepRefused):
            fmu.step(1e-3)
