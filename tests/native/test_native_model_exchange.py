"""Model Exchange in the native FMUs, both FMI versions: the interface is declared beside
co-simulation, FMPy's solvers (CVODE and explicit Euler) reproduce the co-simulation results and
converge to them as the tolerance or the step tightens, the states' perturbations change exactly the
outputs that declare the state, and a refused input is refused with co-simulation's words.

Tolerances: with the default inputs held constant every state but the source's phase grows
linearly, which both solvers integrate exactly (the difference is rounding, below 1e-9 relative);
the source's phase integrates a sine: CVODE's error stays below 100 times its relative tolerance
(the global error of an error-per-step control, measured 2026-11-27 at 2 to 6 times) and Euler's
shrinks with its step (first order: a tenth of the step, at most a fifth of the error).
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException

from driveline.catalog import MODELS
from fmu_harness.packaging import native
from fmu_harness.runs.runner import FmuInstance, StepRefused
from support.model_exchange import ModelExchange

NATIVE = [name for name in native.native_models() if not MODELS[name].co_simulation_only]
ROUNDING = 1e-9  # relative: what two exact integrations of a linear state differ by


def _path(native_dir, name: str, fmi: str):
    return native.fmu_path(native_dir, name, fmi)


def _relative_error(name: str, reference: np.ndarray, result: np.ndarray) -> float:
    """Largest difference of the Real outputs, relative to each output's largest magnitude."""
    outputs = [v.name for v in MODELS[name].spec.of("output") if v.type == "Real"]
    return max(float(np.max(np.abs(result[o] - reference[o])) / max(np.max(np.abs(reference[o])), 1e-300))
               for o in outputs)


@pytest.mark.parametrize("name", NATIVE)
def test_fmpy_info_lists_both_interfaces(native_dir, name, fmi):
    path = _path(native_dir, name, fmi)
    info = subprocess.run([sys.executable, "-m", "fmpy.cli", "info", str(path)], capture_output=True,
                          text=True, check=True).stdout
    assert "Model Exchange, Co-Simulation" in info
    description = read_model_description(str(path))
    assert description.modelExchange.modelIdentifier == description.coSimulation.modelIdentifier == name
    assert description.numberOfContinuousStates == len(MODELS[name].spec.states)
    assert [u.variable.name for u in description.derivatives] == [s.derivative_name for s in MODELS[name].spec.states]


@pytest.mark.parametrize("name", NATIVE)
def test_model_exchange_converges_to_co_simulation(native_dir, name, fmi):
    path = str(_path(native_dir, name, fmi))
    step = MODELS[name].spec.default_experiment.step_size
    intervals = (10 * step, step)  # FMPy's Euler takes one step per output interval
    cs = {interval: simulate_fmu(path, fmi_type="CoSimulation", step_size=step, output_interval=interval)
          for interval in intervals}
    cvode = [_relative_error(name, cs[intervals[0]], simulate_fmu(
        path, fmi_type="ModelExchange", solver="CVode", relative_tolerance=tolerance, output_interval=intervals[0]))
        for tolerance in (1e-5, 1e-8)]
    euler = [_relative_error(name, cs[interval], simulate_fmu(
        path, fmi_type="ModelExchange", solver="Euler", step_size=interval, output_interval=interval))
        for interval in intervals]
    spec = MODELS[name].spec
    if all(spec[state.derivative].causality == "input" for state in spec.states):
        assert max(cvode + euler) < ROUNDING, (cvode, euler)  # states growing linearly with held inputs, or none
    else:
        assert cvode[0] < 100 * 1e-5 and cvode[1] < 100 * 1e-8 and cvode[1] < cvode[0], cvode
        assert euler[1] < euler[0] / 5, euler


WITH_STATES = [name for name in NATIVE if MODELS[name].spec.states]


@pytest.mark.parametrize("name", WITH_STATES)
def test_a_state_changes_exactly_the_outputs_that_declare_it(native_dir, tmp_path, name, fmi):
    """Each state moved by 0.1 rad (at the start values and the dependency points): the outputs whose
    ``dependencies`` name it change, no other output does, and no derivative."""
    description = read_model_description(str(_path(native_dir, name, fmi)))
    spec = MODELS[name].spec
    outputs = [v.name for v in spec.of("output") if v.type == "Real"]
    declared = {u.variable.name: {known.name for known in u.dependencies} for u in description.outputs}
    observed: dict[str, set[str]] = {output: set() for output in outputs}
    for n, point in enumerate([{}, *MODELS[name].dependency_points]):
        model = ModelExchange(_path(native_dir, name, fmi), fmi, point, tmp_path / str(n))
        base, states, derivatives = model.get(outputs), model.get_states(), model.derivatives()
        for k, state in enumerate(spec.states):
            model.set_states(states + 0.1 * (np.arange(states.size) == k))
            for output, before, after in zip(outputs, base, model.get(outputs)):
                if after != before:
                    observed[output].add(state.name)
            assert np.array_equal(model.derivatives(), derivatives)
        model.close()
    states = {state.name for state in spec.states}
    assert observed == {output: declared[output] & states for output in outputs}


def test_a_refused_input_is_refused_as_in_co_simulation(native_dir, tmp_path, fmi):
    """beta beyond beta_max: the derivatives and outputs are refused with fmi2Discard / fmi3Discard and
    the co-simulation step's reason, word for word; a corrected input is taken."""
    path = _path(native_dir, "CardanJoint", fmi)
    with FmuInstance(path) as cs:
        cs.initialize()  # a start value beyond beta_max is refused at initialisation already
        cs.set({"beta": 1.0})
        with pytest.raises(StepRefused) as refused:
            cs.step(1e-3)
    model = ModelExchange(path, fmi, {}, tmp_path)
    model.set({"beta": 1.0})
    with pytest.raises(FMICallException) as discarded:
        model.derivatives()
    assert discarded.value.status == 2  # fmi2Discard / fmi3Discard
    assert model.log[-1] == refused.value.messages[0] == "input beta = 57.2958 deg must not exceed beta_max = 45 deg"
    with pytest.raises(FMICallException):
        model.get(["T_in"])
    model.set({"beta": 0.5})
    assert model.derivatives()[0] == MODELS["CardanJoint"].spec["omega_in"].start
    model.close()
