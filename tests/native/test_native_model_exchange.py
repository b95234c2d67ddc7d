"""Model Exchange in the native FMUs, both FMI versions: the interface is declared beside
co-simulation, FMPy's solvers (CVODE and explicit Euler) reproduce the co-simulation results and
converge to them as the tolerance or the step tightens, the states' perturbations change exactly the
outputs that declare the state, and a refused input is refused with co-simulation's words.

Tolerances: with the default inputs held constant every state but the source's phase grows
linearly, which both solvers integrate exactly (the difference is rounding, below 1e-9 relative);
the source's phase integrates a sine: CVODE's error stays below 100 times its relative tolerance
(the global error of an error-per-step control, measured 2026-11-27 at 2 to 6 times) and Euler's
shrinks with its step (first order: a tenth of the step, at most a fifth of the error).
PowertrainMounts starts at rest in its equilibrium under the start inputs: its loads step from
zero at LOAD_STEP_TIME (:data:`LOAD_STEPS`), so that its damped modes ring, then stay. FMPy takes
such a step as an input event in Model Exchange (the solver restarted there) and at the communication
point in co-simulation; a load varying in time would not do: FMPy sets Model Exchange's inputs at
the output points only, with no restart. At the step's instant an output with direct feedthrough
(the accelerations) is either side's value: that instant is left out. Its states are millimetres
and milliradians, a thousandth of the nominal 1 the FMU gives them (FMPy's CVODE takes its absolute
tolerance as the relative one times the nominal): the absolute tolerance governs, and CVODE's bounds
are a thousand times wider (:data:`STATE_SCALE`; measured 2026-11-27: 2.3e-3 at 1e-5 and 8.0e-6 at
1e-8). Euler: a tenth of the step brings 0.95 down to 0.066.
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
from support.dependency_points import points
from support.model_exchange import ModelExchange

NATIVE = [name for name in native.native_models() if not MODELS[name].co_simulation_only]
ROUNDING = 1e-9  # relative: what two exact integrations of a linear state differ by
#: Inputs stepped from 0 at LOAD_STEP_TIME where held start inputs leave the states at rest: a load at
#: the centre of gravity, the joints' and the motor's
LOAD_STEPS = {"PowertrainMounts": {"F_z": 4000.0, "M_y": 800.0, "Rx_in_left": -900.0, "Rz_in_left": 1500.0,
                                   "T_in_right": -600.0, "T_motor": 300.0}}
LOAD_STEP_TIME = 0.1  # s
#: The states' magnitude against their nominal 1 where it is far below (see the module's docstring)
STATE_SCALE = {"PowertrainMounts": 1e-3}
#: Euler's output intervals where ten default steps are beyond its stability: explicit Euler on a mode
#: of damping ratio zeta and angular frequency w grows for h > 2 zeta / (w (1 + zeta^2)), for
#: PowertrainMounts' default layout 1.76e-3 s (its 9.1 Hz mode, zeta 0.050)
EULER_INTERVALS = {"PowertrainMounts": (1e-3, 1e-4)}


def _path(native_dir, name: str, fmi: str):
    return native.fmu_path(native_dir, name, fmi)


def _relative_error(name: str, reference: np.ndarray, result: np.ndarray) -> float:
    """Largest difference of the Real outputs, relative to each output's largest magnitude (the
    instant of a load step left out: Model Exchange records it before and after the event)."""
    outputs = [v.name for v in MODELS[name].spec.of("output") if v.type == "Real"]
    if name in LOAD_STEPS:
        reference, result = (rows[~np.isclose(rows["time"], LOAD_STEP_TIME, rtol=0.0, atol=1e-12)]
                             for rows in (reference, result))
    assert np.array_equal(reference["time"], result["time"])
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


def _load_steps(name: str) -> np.ndarray | None:
    """FMPy's input signal of :data:`LOAD_STEPS` (0 until LOAD_STEP_TIME, the load from then on, the
    other inputs 0); None for a model without them."""
    if name not in LOAD_STEPS:
        return None
    spec = MODELS[name].spec
    names = [v.name for v in spec.of("input")]
    rows = [(t, *(LOAD_STEPS[name].get(n, 0.0) * loaded for n in names))
            for t, loaded in ((0.0, 0), (LOAD_STEP_TIME, 0), (LOAD_STEP_TIME, 1),
                              (spec.default_experiment.stop_time, 1))]
    return np.array(rows, dtype=[("time", float), *((n, float) for n in names)])


@pytest.mark.parametrize("name", NATIVE)
def test_model_exchange_converges_to_co_simulation(native_dir, name, fmi):
    path = str(_path(native_dir, name, fmi))
    step = MODELS[name].spec.default_experiment.step_size
    intervals = EULER_INTERVALS.get(name, (10 * step, step))  # FMPy's Euler takes one step per output interval
    signals = _load_steps(name)
    cs = {interval: simulate_fmu(path, fmi_type="CoSimulation", step_size=min(step, interval),
                                 output_interval=interval, input=signals)
          for interval in intervals}
    cvode = [_relative_error(name, cs[intervals[0]], simulate_fmu(
        path, fmi_type="ModelExchange", solver="CVode", relative_tolerance=tolerance, output_interval=intervals[0],
        input=signals)) for tolerance in (1e-5, 1e-8)]
    euler = [_relative_error(name, cs[interval], simulate_fmu(
        path, fmi_type="ModelExchange", solver="Euler", step_size=interval, output_interval=interval,
        input=signals)) for interval in intervals]
    spec = MODELS[name].spec
    if all(spec[state.derivative].causality == "input" for state in spec.states):
        assert max(cvode + euler) < ROUNDING, (cvode, euler)  # states growing linearly with held inputs, or none
    else:
        scale = STATE_SCALE.get(name, 1.0)
        assert cvode[0] < 100 * 1e-5 / scale and cvode[1] < 100 * 1e-8 / scale and cvode[1] < cvode[0], cvode
        assert euler[1] < euler[0] / 5, euler


WITH_STATES = [name for name in NATIVE if MODELS[name].spec.states]


@pytest.mark.parametrize("name", WITH_STATES)
def test_a_state_changes_exactly_the_outputs_that_declare_it(native_dir, tmp_path, name, fmi):
    """Each state moved by 0.1 (rad, m, rad/s or m/s; at the start values and the dependency points):
    the outputs and derivatives whose ``dependencies`` name it change, no other does."""
    description = read_model_description(str(_path(native_dir, name, fmi)))
    spec = MODELS[name].spec
    outputs = [v.name for v in spec.of("output") if v.type == "Real"]
    derivative_names = [state.derivative_name for state in spec.states]
    declared = {u.variable.name: {known.name for known in u.dependencies}
                for u in (*description.outputs, *description.derivatives)}
    observed: dict[str, set[str]] = {name: set() for name in (*outputs, *derivative_names)}
    for n, point in enumerate(points(name)):
        model = ModelExchange(_path(native_dir, name, fmi), fmi, point, tmp_path / str(n))
        base, states = [*model.get(outputs), *model.derivatives()], model.get_states()
        for k, state in enumerate(spec.states):
            model.set_states(states + 0.1 * (np.arange(states.size) == k))
            for changed, before, after in zip(observed, base, [*model.get(outputs), *model.derivatives()]):
                if after != before:
                    observed[changed].add(state.name)
        model.close()
    states = {state.name for state in spec.states}
    assert observed == {changed: declared[changed] & states for changed in observed}


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
