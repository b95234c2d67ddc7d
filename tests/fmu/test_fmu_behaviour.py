"""What every importer relies on, for every catalog model, both FMI versions and (most of it) both
families, Python and native, through fmpy: identical FMI 2.0 and 3.0 results, state round trips, independent instances, reset, and many
instances in one process."""

from __future__ import annotations

import math

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException

from driveline.catalog import MODELS
from fmu_harness.runs.scenario import scenario, standard_run


def test_fmi2_and_fmi3_give_identical_outputs(family, model_name):
    """Both versions run the same model code (Python or C) on the same float64 values, so every
    output must agree bit for bit (measured difference: 0)."""
    runs = []
    for fmi in ("2", "3"):
        with family.open(model_name, fmi) as fmu:
            runs.append(standard_run(fmu))
    assert runs[0].dtype.names == runs[1].dtype.names
    assert runs[0].tobytes() == runs[1].tobytes()


def test_state_round_trips_and_continues_bit_identically(family, model_name, fmi):
    case = scenario(MODELS[model_name].spec)
    with family.open(model_name, fmi) as fmu:
        standard_run(fmu, stop_time=case.stop_time / 2)
        middle = fmu.time
        state = fmu.get_state()
        serialized = fmu.serialize_state(state)
        reference = fmu.run(case.stop_time, case.step_size, case.signals())
        for restored in (state, fmu.deserialize_state(serialized)):
            fmu.set_state(restored)
            fmu.time = middle
            assert fmu.run(case.stop_time, case.step_size, case.signals()).tobytes() == reference.tobytes()
        fmu.free_state(state)


def test_instances_are_independent(family, model_name, fmi):
    """Two instances stepped in turn, one with the standard inputs and one with all inputs at
    their start values, each give bit for bit what it gives alone."""
    case = scenario(MODELS[model_name].spec)
    signals = (case.signals(), {})
    alone = []
    for inputs in signals:
        with family.open(model_name, fmi, "alone") as fmu:
            fmu.initialize({name: signal(0.0) for name, signal in inputs.items()})
            alone.append(fmu.run(case.stop_time, case.step_size, inputs))
    with family.open(model_name, fmi, "a") as a, family.open(model_name, fmi, "b") as b:
        pair = (a, b)
        for fmu, inputs in zip(pair, signals):
            fmu.initialize({name: signal(0.0) for name, signal in inputs.items()})
        together = [[fmu.run(0.0, case.step_size)] for fmu in pair]
        for _ in range(case.steps):
            for fmu, inputs, rows in zip(pair, signals, together):
                rows.append(fmu.run(fmu.time + case.step_size, case.step_size, inputs)[-1:])
    for rows, reference in zip(together, alone):
        assert np.concatenate(rows).tobytes() == reference.tobytes()


def test_reset_returns_to_the_start_values(family, model_name, fmi):
    spec = MODELS[model_name].spec
    with family.open(model_name, fmi) as fmu:
        first = standard_run(fmu)
        fmu.reset()
        settable = [v.name for v in spec.variables if v.causality != "output"]
        assert fmu.get(settable) == [v.start for v in spec.variables if v.causality != "output"]
        assert standard_run(fmu).tobytes() == first.tobytes()


def test_many_instances_in_one_process(fmi, fmu_path):
    """pythonfmu 0.7's loader crashed the host on a second instance without the FMI 2.0
    adapter's workaround; pythonfmu3's needs none. 21 fmpy runs of one FMU (the catalog's first),
    each instantiating it afresh, must all complete."""
    name, model = next(iter(MODELS.items()))
    for _ in range(21):
        result = simulate_fmu(str(fmu_path(name, fmi)), stop_time=model.spec.default_experiment.stop_time / 10)
        assert result["time"][-1] > 0.0


WITH_INPUTS = [name for name, model in MODELS.items() if model.spec.of("input")]


@pytest.mark.parametrize("name", WITH_INPUTS)
def test_what_plain_simulate_fmu_sees_of_a_refused_step(name, fmi, fmu_path):
    """fmpy's simulate_fmu ends an FMI 2.0 run early and quietly on fmi2Discard, but raises on
    fmi3Discard (documented in docs/hosting.md)."""
    stop = MODELS[name].spec.default_experiment.stop_time
    first = MODELS[name].spec.of("input")[0]
    signal = np.array([(0.0, first.start), (stop / 2, first.start), (stop / 2, math.nan)],
                      dtype=[("time", float), (first.name, float)])

    def run() -> np.ndarray:
        return simulate_fmu(str(fmu_path(name, fmi)), stop_time=stop, step_size=stop / 10,
                            output_interval=stop / 10, input=signal)

    if fmi == "2":
        assert run()["time"][-1] < stop
    else:
        with pytest.raises(FMICallException) as refused:
            run()
        assert refused.value.status == 2  # fmi3Discard
