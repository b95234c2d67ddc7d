"""Model Exchange in the native FMUs, both FMI versions: the interface is declared beside
co-simulation, FMPy's solvers (CVODE and explicit Euler) reproduce the co-simulation results and
converge to them as the tolerance or the step tightens, the states' perturbations change exactly the
outputs that declare the state, and a refused input is refused with co-simulation's words.

Tolerances: with the default inputs held constant every state but the source's phase and
VehicleDriveline's grows linearly, which both solvers integrate exactly (the difference is rounding,
below 1e-9 relative); the source's phase integrates a sine, VehicleDriveline its wheels' and car's
motion (:data:`RUNS`): CVODE's error stays below :data:`GLOBAL_ERROR` times its relative tolerance
(the global error of an error-per-step control) and Euler's shrinks with its step (first order: a
tenth of the step, at most a fifth of the error).
PowertrainMounts starts at rest in its equilibrium under the start inputs: its loads step from
zero at LOAD_STEP_TIME (:data:`LOAD_STEPS`), so that its damped modes ring, then stay. FMPy takes
such a step as an input event in Model Exchange (the solver restarted there) and at the communication
point in co-simulation; a load varying in time would not do: FMPy sets Model Exchange's inputs at
the output points only, with no restart. At the step's instant an output with direct feedthrough
(the accelerations) is either side's value: that instant is left out. Euler steps it at 1 and 0.1 ms
(:data:`EULER_INTERVALS`).
"""

from __future__ import annotations

import math
import subprocess
import sys
from ctypes import POINTER, c_double
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException

from driveline.catalog import MODELS
from driveline.mounts.spec import SHARED_LAYOUT
from fmu_harness.packaging import native
from fmu_harness.runs.runner import FmuInstance, LoggedInstance, StepRefused
from support.dependency_points import points
from support.model_exchange import ModelExchange

NATIVE = [name for name in native.native_models() if not MODELS[name].co_simulation_only]
ROUNDING = 1e-9  # relative: what two exact integrations of a linear state differ by
#: Inputs stepped from 0 at LOAD_STEP_TIME where held start inputs leave the states at rest: a load at
#: the centre of gravity, the joints' and the motor's
LOAD_STEPS = {"PowertrainMounts": {"F_z": 4000.0, "M_y": 800.0, "Rx_in_left": -900.0, "Rz_in_left": 1500.0,
                                   "T_in_right": -600.0, "T_motor": 300.0}}
LOAD_STEP_TIME = 0.1  # s
#: Euler's output intervals where ten default steps are beyond its stability: explicit Euler on a mode
#: of damping ratio zeta and angular frequency w grows for h > 2 zeta / (w (1 + zeta^2)), for
#: PowertrainMounts' linear layout 1.76e-3 s (its 9.1 Hz mode, zeta 0.050)
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


#: Runs that excite a model its start values leave at rest, (start values, stop time): VehicleDriveline
#: rolling at 5 m/s into its joints' output shafts held at rest (the halfshafts twist, the wheels oscillate
#: against their tyres' slip, the car slows) while the motor drives the side gears, over 0.5 s.
#: PowertrainMounts on its linear layout, whose co-simulation steps exactly (matrix exponential), the reference this
#: test needs; on the rubber default co-simulation's implicit midpoint rule errs by O(h^2) itself (6.9e-3 of an
#: output's largest at 0.5 ms under LOAD_STEPS), and tests/native/test_native_mounts_model_exchange.py checks that
#: it converges to Model Exchange at second order.
RUNS = {"VehicleDriveline": ({"v_start": 5.0, "T_motor": 100.0}, 0.5),
        "PowertrainMounts": ({"layout": SHARED_LAYOUT}, None)}
#: CVODE's global error in units of its relative tolerance, at 1e-5 and 1e-8 (FMPy's CVODE takes its
#: absolute tolerance as the relative one times each state's nominal, State.nominal): the source's phase
#: 2 to 6; PowertrainMounts 73 and 219 (measured 2026-12-07; 33 and 118 before its 96 Maxwell-branch states,
#: idle on the linear layout: CVODE's root-mean-square error norm averages over 108 states instead of 12, which
#: loosens its control by sqrt(108 / 12) = 3; 230 and 800 with the nominal 1 its millimetres and milliradians had
#: before); VehicleDriveline 80 and 272 (measured 2026-11-27; 140 and 270
#: with nominals 1: the largest in the wheels' accelerations, 20 periods of the 200 rad/s wheel-on-tyre
#: mode, an error-per-step control's phase error adding up; against CVODE at 1e-12 the same, 80 and 270),
#: its co-simulation at 1 ms differing from that at 0.1 ms by 1.4e-6 besides.
GLOBAL_ERROR = {"VehicleDriveline": (120.0, 400.0), "PowertrainMounts": (150.0, 600.0)}


@pytest.mark.parametrize("name", NATIVE)
def test_model_exchange_converges_to_co_simulation(native_dir, name, fmi):
    path = str(_path(native_dir, name, fmi))
    step = MODELS[name].spec.default_experiment.step_size
    start, stop = RUNS.get(name, ({}, None))
    run = {"start_values": start, "stop_time": stop, "input": _load_steps(name)}
    intervals = EULER_INTERVALS.get(name, (10 * step, step))  # FMPy's Euler takes one step per output interval
    cs = {interval: simulate_fmu(path, fmi_type="CoSimulation", step_size=min(step, interval),
                                 output_interval=interval, **run)
          for interval in intervals}
    cvode = [_relative_error(name, cs[intervals[0]], simulate_fmu(
        path, fmi_type="ModelExchange", solver="CVode", relative_tolerance=tolerance, output_interval=intervals[0],
        **run)) for tolerance in (1e-5, 1e-8)]
    euler = [_relative_error(name, cs[interval], simulate_fmu(
        path, fmi_type="ModelExchange", solver="Euler", step_size=interval, output_interval=interval, **run))
        for interval in intervals]
    spec = MODELS[name].spec
    if all(spec[state.derivative].causality == "input" for state in spec.states):
        assert max(cvode + euler) < ROUNDING, (cvode, euler)  # states growing linearly with held inputs, or none
    else:
        bounds = GLOBAL_ERROR.get(name, (100.0, 100.0))
        assert cvode[0] < bounds[0] * 1e-5 and cvode[1] < bounds[1] * 1e-8 and cvode[1] < cvode[0], cvode
        assert euler[1] < euler[0] / 5, euler


WITH_STATES = [name for name in NATIVE if MODELS[name].spec.states]
#: Models whose outputs show a state's dependency only in motion: every state moved by this first (PowertrainMounts'
#: halfshaft rates are linear in the velocities, zero at rest whatever the displacements; 0.01 m keeps the wheels
#: within their shafts' reach)
IN_MOTION = {"PowertrainMounts": 0.01}
#: Points beyond the dependency points: PowertrainMounts on eight rubber mounts turned off the axes, where each of its
#: 96 branch states acts (on the default layout they are idle)
STATE_POINTS = {"PowertrainMounts": (
    {"layout": str(Path(__file__).parents[1] / "support" / "eight_rubber_mounts.toml")},)}


@pytest.mark.parametrize("name", WITH_STATES)
def test_a_state_changes_exactly_the_outputs_that_declare_it(native_dir, tmp_path, name, fmi):
    """Each state moved by 0.1 (at the start values, the dependency points and STATE_POINTS, in motion where IN_MOTION
    says):
    the outputs and the derivatives whose ``dependencies`` name it change, no other does."""
    description = read_model_description(str(_path(native_dir, name, fmi)))
    spec = MODELS[name].spec
    outputs = [v.name for v in spec.of("output") if v.type == "Real"]
    derivatives = [state.derivative_name for state in spec.states]
    declared = {u.variable.name: {known.name for known in u.dependencies}
                for u in (*description.outputs, *description.derivatives)}
    observed: dict[str, set[str]] = {unknown: set() for unknown in (*outputs, *derivatives)}
    for n, point in enumerate((*points(name), *STATE_POINTS.get(name, ()))):
        model = ModelExchange(_path(native_dir, name, fmi), fmi, point, tmp_path / str(n))
        states = model.get_states() + IN_MOTION.get(name, 0.0)
        model.set_states(states)
        base = [*model.get(outputs), *model.derivatives()]
        for k, state in enumerate(spec.states):
            model.set_states(states + 0.1 * (np.arange(states.size) == k))
            for unknown, before, after in zip(observed, base, [*model.get(outputs), *model.derivatives()]):
                if after != before:
                    observed[unknown].add(state.name)
        model.close()
    states = {state.name for state in spec.states}
    assert observed == {unknown: declared[unknown] & states for unknown in observed}


@pytest.mark.parametrize("name", WITH_STATES)
def test_the_states_nominals_are_the_specs(native_dir, tmp_path, name, fmi):
    """fmi2GetNominalsOfContinuousStates / fmi3GetNominalsOfContinuousStates and the states'
    ``nominal`` attributes give the nominals the spec declares (State.nominal), state by state."""
    path = _path(native_dir, name, fmi)
    declared = [state.nominal for state in MODELS[name].spec.states]
    variables = {v.name: v for v in read_model_description(str(path)).modelVariables}
    assert [float(variables[state.name].nominal) for state in MODELS[name].spec.states] == declared
    model = ModelExchange(path, fmi, {}, tmp_path)
    assert list(model.nominals()) == declared
    model.close()


def test_vehicle_driveline_derivatives_are_the_cores(native_dir, tmp_path, fmi):
    """At random states and inputs (rolling at 12 m/s, twisted halfshafts, slipping tyres, torques in): the
    native FMU's derivatives and outputs are the core's (``VehicleDrivelineModel.evaluate``, the same
    operations in the same order: bit for bit but for the compiler's contraction, within 1e-13)."""
    spec, rng = MODELS["VehicleDriveline"].spec, np.random.default_rng(30)
    outputs = [v.name for v in spec.of("output")]
    model = ModelExchange(_path(native_dir, "VehicleDriveline", fmi), fmi, {"v_start": 12.0}, tmp_path)
    for _ in range(5):
        inputs = {"T_motor": rng.uniform(-100, 250), "T_in_left": rng.uniform(0, 900),
                  "T_in_right": -rng.uniform(0, 900), "phi_out_left": rng.uniform(-3, 3),
                  "phi_out_right": rng.uniform(-3, 3), "omega_out_left": rng.uniform(30, 45),
                  "omega_out_right": -rng.uniform(30, 45)}
        states = np.array([39.0, -39.0, 0.0, 39.0, 0.0, 39.0, 12.0, 5.0, 0.0, 0.0]) + rng.uniform(-1, 1, 10) * (
            [2.0, 2.0, 3.0, 2.0, 3.0, 2.0, 1.0, 1.0, 0.05, 0.05])
        model.set(inputs)
        model.set_states(states)
        core = MODELS["VehicleDriveline"]()
        for name, value in {**inputs, **dict(zip([s.name for s in spec.states], states))}.items():
            setattr(core, name, float(value))
        core.evaluate(0.0)
        expected = [getattr(core, name) for name in outputs]
        assert model.get(outputs) == pytest.approx(expected, rel=1e-13, abs=1e-13)
        assert list(model.derivatives()) == pytest.approx([getattr(core, s.derivative) for s in spec.states],
                                                          rel=1e-13, abs=1e-13)
    model.close()


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


def _instance(path, fmi: str, folder) -> tuple[LoggedInstance, list[str]]:
    """A Model Exchange instance of ``path`` in Initialization Mode, and its log."""
    log: list[str] = []
    instance = LoggedInstance(extract(str(path), unzipdir=str(folder)), read_model_description(str(path)),
                              "ModelExchange", "instance", log.append)
    enter_initialization_mode(instance.fmu, fmi)
    return instance, log


def enter_initialization_mode(fmu, fmi: str) -> None:
    if fmi == "3":
        fmu.enterInitializationMode(startTime=0.0)
    else:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()


@pytest.mark.parametrize("mode", ["InitializationMode", "EventMode"])
@pytest.mark.parametrize("value", [0.3, math.nan])
def test_the_states_are_set_in_the_modes_the_standard_allows(native_dir, tmp_path, fmi, mode, value):
    """fmi2SetContinuousStates in continuous-time mode only, fmi3SetContinuousStates in event mode too: in
    Initialization Mode (where ExitInitializationMode would replace them) and FMI 2.0's event mode, Error with
    the reason, NaN included, nothing set; in FMI 3.0's event mode a finite state is taken, NaN refused."""
    instance, log = _instance(_path(native_dir, "CardanJoint", fmi), fmi, tmp_path)
    fmu, states = instance.fmu, np.zeros(1)
    if mode == "EventMode":
        fmu.exitInitializationMode()
    fmu.getContinuousStates(states.ctypes.data_as(POINTER(c_double)), 1)
    if mode == "EventMode" and fmi == "3":
        if math.isfinite(value):
            assert fmu.setContinuousStates((c_double * 1)(value), 1) == 0
            states[0] = value
        else:
            with pytest.raises(FMICallException) as refused:
                fmu.setContinuousStates((c_double * 1)(value), 1)
            assert (refused.value.status, log[-1]) == (
                2, "the continuous state x[0] (phi_in) = nan is not finite; the states were not set")
    else:
        only = " (only in ContinuousTimeMode)" if fmi == "2" else " (only in ContinuousTimeMode or EventMode)"
        with pytest.raises(FMICallException) as refused:
            fmu.setContinuousStates((c_double * 1)(value), 1)
        assert (refused.value.status, log[-1]) == (3, f"fmi{fmi}SetContinuousStates is not allowed in {mode}{only}")
        fmu.reset()  # the Error state's way out: the states are the start values' again
        enter_initialization_mode(fmu, fmi)
        if mode == "EventMode":
            fmu.exitInitializationMode()
    got = np.zeros(1)
    fmu.getContinuousStates(got.ctypes.data_as(POINTER(c_double)), 1)
    assert got[0] == states[0]
    fmu.freeInstance()
    instance.release()


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_a_state_that_is_not_finite_is_refused_and_never_echoed(native_dir, tmp_path, fmi, value):
    """In continuous-time mode a state that is not finite is refused (Discard, the reason logged), the states
    left as they were; after an error the values got are still the last ones taken, never the refused state."""
    model = ModelExchange(_path(native_dir, "CardanJoint", fmi), fmi, {}, tmp_path)
    before, outputs = model.get_states(), model.get(["phi_in", "phi_out"])
    with pytest.raises(FMICallException) as refused:
        model.set_states(np.array([value]))
    assert refused.value.status == 2
    assert model.log[-1] == f"the continuous state x[0] (phi_in) = {value!r} is not finite; the states were not set"
    assert np.array_equal(model.get_states(), before)
    with pytest.raises(FMICallException):
        model.fmu.setTime(math.nan)  # misuse: the Error state
    assert model.get(["phi_in", "phi_out"]) == outputs
    model.free()
