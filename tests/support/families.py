"""The two families of FMUs every catalog model is built as, for the tests that hold both to one
promise: ``python``, the pythonfmu wrappers over the Python core, and ``native``, its C port. The
``family`` fixture (``tests/conftest.py``) runs such a test once for each."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from pathlib import Path

import numpy as np
from fmpy import extract

from fmu_harness.runs.runner import FmuInstance

from .native_agreement import rows_beyond_tolerance, up_to_the_toml_reason, within_the_agreement_range


class Family(ABC):
    """The FMUs of one family: :meth:`path` builds (once) and finds a model's FMU, :meth:`open`
    instantiates it from a copy extracted once; what the family promises against the core is in
    :meth:`reason` and :meth:`assert_outputs_agree`."""

    name = ""

    def __init__(self, fmu_path: Callable[[str, str], Path], scratch: Path) -> None:
        self._fmu_path = fmu_path
        self._scratch = scratch
        self._extracted: dict[tuple[str, str], Path] = {}

    def __repr__(self) -> str:
        return f"{self.name} FMUs"

    def path(self, model: str, fmi: str = "2") -> Path:
        """The FMU of catalog model ``model`` for FMI ``fmi`` ("2" or "3")."""
        return self._fmu_path(model, fmi)

    def open(self, model: str, fmi: str = "2", instance_name: str = "instance") -> FmuInstance:
        """A new instance of the model's FMU (use it as a context manager)."""
        if (model, fmi) not in self._extracted:
            target = self._scratch / f"{model}_fmi{fmi}"
            self._extracted[model, fmi] = Path(extract(str(self.path(model, fmi)), unzipdir=str(target)))
        return FmuInstance(self.path(model, fmi), instance_name, unzipdir=str(self._extracted[model, fmi]))

    def reason(self, message: str) -> str:
        """The part of a logged reason that must be the core's word for word."""
        return message

    @abstractmethod
    def assert_outputs_agree(self, outputs: list[str], rows: list[list[float]], core_rows: list[list[float]]) -> None:
        """The FMU's outputs after each accepted step (``rows``) are the core's."""


class PythonFamily(Family):
    """The Python FMUs run the core's own code on the same float64 values: bit for bit."""

    name = "python"

    def assert_outputs_agree(self, outputs: list[str], rows: list[list[float]], core_rows: list[list[float]]) -> None:
        assert rows == core_rows


class NativeFamily(Family):
    """The native FMUs agree within each output's tolerance (:mod:`.native_agreement`) while the
    core's outputs stay within its agreement range, and word for word up to a malformed TOML text's
    reason and a failed plausibility check's frequency."""

    name = "native"

    def reason(self, message: str) -> str:
        return up_to_the_toml_reason(message)

    def assert_outputs_agree(self, outputs: list[str], rows: list[list[float]], core_rows: list[list[float]]) -> None:
        compared = within_the_agreement_range(core_rows)
        if compared:
            beyond = rows_beyond_tolerance(outputs, core_rows[:compared], rows[:compared])
            assert not np.any(beyond), {outputs[j]: (int(np.flatnonzero(beyond[:, j])[0]), float(np.abs(beyond[:, j]).max()))
                                        for j in np.flatnonzero(np.any(beyond, axis=0))}  # first row, largest
