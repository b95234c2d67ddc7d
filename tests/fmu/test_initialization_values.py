"""Values read in Initialization Mode (FMI 2.0 and 3.0: computed from the parameters, start values and
inputs set so far), every catalog model, both families, both FMI versions: each output, and in Model
Exchange each state and state derivative, read before ``ExitInitializationMode`` is the value read
first after it with nothing set in between, bit for bit; set more and read again, and the values
follow. The values set are not the start values: every parameter and input moved off its start value
where the model accepts the move (``shifted``), at a start time that is not zero."""

from __future__ import annotations

from ctypes import POINTER, c_double
from typing import Any

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException

from driveline.catalog import MODELS
from fmu_harness.runs.runner import LoggedInstance
from support.dependency_points import points

START_TIME = 0.0123  # s: the speed source's ramp and sine show only away from zero
MOVE = 0.037  # relative move of each Real value: far from any rounding, inside every model's bounds


def moved(variable, value: Any) -> Any:
    """``value`` moved off itself within the variable's bounds (None: a String, left as it is)."""
    if variable.type == "String":
        return None
    if variable.type == "Boolean":
        return not value
    delta = 1 if variable.type == "Integer" else MOVE * (abs(value) or 1.0)
    for candidate in (value + delta, value - delta):
        if (variable.min is None or candidate >= variable.min) and (variable.max is None or candidate <= variable.max):
            return candidate
    return None


def accepted(model: str, values: dict[str, Any]) -> bool:
    core = MODELS[model]()
    for name, value in values.items():
        setattr(core, name, value)
    return not (core.parameter_errors() or core.input_errors()) and not core.initialize(START_TIME)


def shifted(model: str) -> tuple[dict[str, Any], dict[str, Any]]:
    """Two sets of values: the model's last dependency point with every parameter and input but the
    Strings moved off it where the core accepts the move, one at a time; and a further move of the
    Real ones alone (set after a first read)."""
    spec = MODELS[model].spec
    values = dict(points(model)[-1])
    for variable in spec.of("parameter", "input"):
        value = moved(variable, values.get(variable.name, variable.start))
        if value is not None and accepted(model, {**values, variable.name: value}):
            values[variable.name] = value
    later = dict(values)
    for variable in spec.of("parameter", "input"):
        value = moved(variable, later.get(variable.name, variable.start)) if variable.type == "Real" else None
        if value is not None and accepted(model, {**later, variable.name: value}):
            later[variable.name] = value
    assert later != values
    return values, {name: value for name, value in later.items() if values.get(name) != value}


class Instance:
    """An fmpy instance of an FMU in Initialization Mode at START_TIME; co-simulation or Model Exchange."""

    def __init__(self, path, fmi: str, unzipdir, interface: str) -> None:
        self.description = read_model_description(str(path))
        self.log: list[str] = []
        self._instance = LoggedInstance(unzipdir, self.description, interface, "instance", self.log.append)
        self.fmu, self.fmi3 = self._instance.fmu, fmi == "3"
        self.interface = interface
        self.variables = {v.name: v for v in self.description.modelVariables}
        if self.fmi3:
            self.fmu.enterInitializationMode(startTime=START_TIME)
        else:
            self.fmu.setupExperiment(startTime=START_TIME)
            self.fmu.enterInitializationMode()

    def set(self, values: dict[str, Any]) -> None:
        for name, value in values.items():
            kind = {"Real": "Real", "Float64": "Real", "Integer": "Integer", "Int32": "Integer",
                    "Boolean": "Boolean", "String": "String"}[self.variables[name].type]
            if self.fmi3:
                kind = {"Real": "Float64", "Integer": "Int32"}.get(kind, kind)
            getattr(self.fmu, f"set{kind}")([self.variables[name].valueReference], [value])

    def read(self) -> dict[str, Any]:
        """Every output, and in Model Exchange every state and state derivative."""
        values = {}
        for variable in self.description.modelVariables:
            if variable.causality != "output":
                continue
            kind = {"Float64": "Real", "Int32": "Integer"}.get(variable.type, variable.type)
            if self.fmi3:
                kind = {"Real": "Float64", "Integer": "Int32"}.get(kind, kind)
            values[variable.name] = getattr(self.fmu, f"get{kind}")([variable.valueReference])[0]
        if self.interface == "ModelExchange":
            count = len(self.description.derivatives)
            states, derivatives = np.zeros(count), np.zeros(count)
            self.fmu.getContinuousStates(states.ctypes.data_as(POINTER(c_double)), count)
            get = self.fmu.getContinuousStateDerivatives if self.fmi3 else self.fmu.getDerivatives
            get(derivatives.ctypes.data_as(POINTER(c_double)), count)
            values.update({f"state {k}": x for k, x in enumerate(states)})
            values.update({f"derivative {k}": x for k, x in enumerate(derivatives)})
        return values

    def close(self) -> None:
        self.fmu.freeInstance()
        self._instance.release()


def interfaces(family, model: str) -> list[str]:
    ported = family.name == "native" and not MODELS[model].co_simulation_only
    return ["CoSimulation", "ModelExchange"] if ported else ["CoSimulation"]


def same_bits(read: dict[str, Any], after: dict[str, Any]) -> dict[str, tuple[Any, Any]]:
    """The values that differ in their bits (a NaN equal to itself)."""
    return {name: (value, after[name]) for name, value in read.items()
            if np.asarray(value).tobytes() != np.asarray(after[name]).tobytes()}


def test_values_read_in_initialization_mode_are_the_first_after_it(family, model_name, fmi, tmp_path):
    values, later = shifted(model_name)
    path = family.path(model_name, fmi)
    unzipdir = extract(str(path), unzipdir=str(tmp_path / "fmu"))
    for interface in interfaces(family, model_name):
        fmu = Instance(path, fmi, unzipdir, interface)
        try:
            fmu.set(values)
            first = fmu.read()
            fmu.set(later)
            read = fmu.read()
            assert fmu.read() == read or not same_bits(fmu.read(), read)  # a second read, nothing set: the same
            fmu.fmu.exitInitializationMode()
            after = fmu.read()
            assert not same_bits(read, after), (interface, same_bits(read, after))
            assert not fmu.log, fmu.log
        finally:
            fmu.close()
        moved_outputs = [name for name in first if name in read and first[name] != read[name]]
        assert moved_outputs, f"{interface}: no value read followed the values set after the first read"


def test_values_the_model_refuses_read_as_the_start_values_with_a_warning(family, fmi, tmp_path):
    """A parameter the model refuses: the values read in Initialization Mode are those set so far, the
    reason logged once as a warning, and the refusal comes at ``ExitInitializationMode`` as before."""
    path = family.path("TripodCoupling", fmi)
    unzipdir = extract(str(path), unzipdir=str(tmp_path / "fmu"))
    fmu = Instance(path, fmi, unzipdir, "CoSimulation")
    try:
        fmu.set({"l": 0.02})  # below the bearing radius r
        read = fmu.read()
        fmu.read()
        spec = MODELS["TripodCoupling"].spec
        assert read == {v.name: v.start for v in spec.of("output")}
        assert len(fmu.log) == 1 and "values read in initialization mode are the start values: " in fmu.log[0]
        assert "parameter l = 20 mm must exceed r" in fmu.log[0]
        try:  # the Python FMUs return OK and enter the error state, the native ones return Error
            fmu.fmu.exitInitializationMode()
        except FMICallException:
            pass
        assert len(fmu.log) == 2 and "parameter l = 20 mm must exceed r" in fmu.log[1]
    finally:
        fmu.close()
