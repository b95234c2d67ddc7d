"""A Model Exchange instance of a native FMU through FMPy's low-level API, for the tests of Model
Exchange and of directional derivatives."""

from __future__ import annotations

from ctypes import POINTER, c_double

import numpy as np
from fmpy import extract, read_model_description

from driveline.catalog import MODELS
from fmu_harness.runs.runner import LoggedInstance


class ModelExchange:
    """A Model Exchange instance of a native FMU through FMPy, in continuous-time mode after
    initialisation with ``start_values`` (``interface="CoSimulation"``: a co-simulation instance, in
    step mode); the messages it logs in ``log``."""

    def __init__(self, path, fmi: str, start_values: dict, unzipdir, interface: str = "ModelExchange") -> None:
        self.description = read_model_description(str(path))
        self.log: list[str] = []
        self._instance = LoggedInstance(extract(str(path), unzipdir=str(unzipdir)), self.description, interface,
                                        "instance", self.log.append)
        self.fmu = self._instance.fmu
        self.references = {v.name: v.valueReference for v in self.description.modelVariables}
        self.fmi3 = fmi == "3"
        if self.fmi3:
            self.fmu.enterInitializationMode(startTime=0.0)
        else:
            self.fmu.setupExperiment(startTime=0.0)
            self.fmu.enterInitializationMode()
        self.set(start_values)
        self.fmu.exitInitializationMode()
        if interface == "ModelExchange":
            self.fmu.enterContinuousTimeMode()
        self.states = np.zeros(len(MODELS[self.description.modelName].spec.states))

    def set(self, values: dict) -> None:
        for name, value in values.items():
            kind = {float: "Float64" if self.fmi3 else "Real", int: "Int32" if self.fmi3 else "Integer",
                    bool: "Boolean", str: "String"}[type(value)]
            getattr(self.fmu, f"set{kind}")([self.references[name]], [value])

    def get(self, names: list[str]) -> list[float]:
        return (self.fmu.getFloat64 if self.fmi3 else self.fmu.getReal)([self.references[n] for n in names])

    def get_states(self) -> np.ndarray:
        self.fmu.getContinuousStates(self.states.ctypes.data_as(POINTER(c_double)), self.states.size)
        return self.states.copy()

    def set_states(self, states: np.ndarray) -> None:
        values = np.array(states, dtype=float)
        self.fmu.setContinuousStates(values.ctypes.data_as(POINTER(c_double)), values.size)

    def derivatives(self) -> np.ndarray:
        values = np.zeros(self.states.size)
        get = self.fmu.getContinuousStateDerivatives if self.fmi3 else self.fmu.getDerivatives
        get(values.ctypes.data_as(POINTER(c_double)), values.size)
        return values

    def nominals(self) -> np.ndarray:
        values = np.zeros(self.states.size)
        self.fmu.getNominalsOfContinuousStates(values.ctypes.data_as(POINTER(c_double)), values.size)
        return values

    def close(self) -> None:
        self.fmu.terminate()
        self.free()

    def free(self) -> None:
        """Frees the instance without terminating it (the way out of the Error state)."""
        self.fmu.freeInstance()
        self._instance.release()
