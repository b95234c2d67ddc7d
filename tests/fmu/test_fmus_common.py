"""Behaviour every FMU of the catalog shares, Python and native, through fmpy: a clean description,
a default experiment that runs, and refusals."""

from __future__ import annotations

import ctypes
import math
import sys

import pytest
from fmpy.validation import validate_fmu

from driveline.catalog import MODELS
from fmu_harness.packaging import native
from fmu_harness.runs.runner import FmuInstance, StepRefused
from fmu_src.fmi3_slave import host_start_time
from support.native_agreement import rows_beyond_tolerance

INPUTS = [(name, v.name) for name, model in MODELS.items() for v in model.spec.of("input") if v.type == "Real"]
PARAMETERS = [(name, v.name) for name, model in MODELS.items() for v in model.spec.of("parameter") if v.type == "Real"]
#: A start time other than 0, at which SpeedSource's outputs differ from those at t = 0.
START_TIME = 5.0


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


@pytest.mark.parametrize("name", list(MODELS))
def test_a_step_whose_end_time_is_not_finite_is_refused(family, name):
    """DoStep(1e308, 1e308) ends beyond the largest double: refused like a step size out of range, the model
    left as it was; the time it reached stays finite, so the next step's check of time going backwards holds."""
    with family.open(name) as fmu:
        fmu.initialize()
        fmu.step(1e-3)
        before = fmu.get(fmu.outputs())
        fmu.time = 1e308
        with pytest.raises(StepRefused) as refused:
            fmu.step(1e308)
        assert (refused.value.status, refused.value.messages) == (
            "Discard", ["the communication step from t = 1e+308 s by 1e+308 s ends at a time that is not finite"])
        assert fmu.get(fmu.outputs()) == before
        fmu.time = 0.0
        with pytest.raises(StepRefused) as backwards:
            fmu.step(1e-3)
        assert "is before the time the FMU reached, 0.001" in backwards.value.messages[0]


@pytest.mark.parametrize("name", list(MODELS))
def test_initial_outputs_are_those_at_the_start_time(family, name, fmi, native_dir):
    """Initialised at t0 = 5 s (FMI 2.0: fmi2SetupExperiment, FMI 3.0: fmi3EnterInitializationMode),
    the outputs read before the first step are the core's at t0, and the native FMI 2.0 FMU's
    within the native tolerances (docs/robustness.md, issue 33: pythonfmu3 withholds the start time)."""
    outputs = [v.name for v in MODELS[name].spec.of("output") if v.type == "Real"]
    core = MODELS[name]()
    assert core.initialize(START_TIME) == []
    with family.open(name, fmi) as fmu:
        fmu.initialize(start_time=START_TIME)
        initial = fmu.get(outputs)
    with FmuInstance(native.fmu_path(native_dir, name, "2"), "reference") as reference:
        reference.initialize(start_time=START_TIME)
        native_initial = reference.get(outputs)
    family.assert_outputs_agree(outputs, [initial], [[getattr(core, output) for output in outputs]])
    assert not rows_beyond_tolerance(outputs, [native_initial], [initial]).any()


def test_the_fmi3_start_time_is_read_from_a_python_hosts_call_only():
    """pythonfmu3 withholds startTime: the adapter reads it from the calling frame named after the
    standard's function (a float or a ctypes fmi3Float64), and finds none where no such frame is."""
    def fmi3EnterInitializationMode(instance, toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime):
        return host_start_time(sys._getframe())

    assert fmi3EnterInitializationMode(None, False, 0.0, ctypes.c_double(2.5), False, 0.0) == 2.5
    assert fmi3EnterInitializationMode(None, False, 0.0, 7, False, 0.0) == 7.0
    assert math.isnan(fmi3EnterInitializationMode(None, False, 0.0, math.nan, False, 0.0))
    assert host_start_time(sys._getframe()) is None  # a host written in C leaves no such frame


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
