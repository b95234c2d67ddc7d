"""A model that fails the way no model check anticipates, for the robustness suite's FMUs.

Parameter ``failure`` selects what its step raises: 0 nothing (y = u), 1 ``MemoryError`` (a
bytearray of 2^60 bytes), 2 ``RecursionError`` (unbounded recursion), 3 ``OverflowError``
(``math.exp(1000)``, an ``ArithmeticError`` the model's own guard turns into a refused step),
4 ``KeyError``. Built by :func:`build_failing_fmus` with the project's adapters.
"""

from __future__ import annotations

import math
from pathlib import Path

from driveline.model import SteppedModel
from driveline.variables import DefaultExperiment, ModelSpec, Variable

FAILURES = {1: "MemoryError", 2: "RecursionError", 3: "OverflowError", 4: "KeyError"}


def _recurse(depth: int) -> int:
    return _recurse(depth + 1) + 1


class FailingModel(SteppedModel):
    spec = ModelSpec(
        name="FailingModel",
        description="Raises the exception its parameter failure selects in every step (robustness suite).",
        variables=(
            Variable("failure", "parameter", 0, "0 none, 1 MemoryError, 2 RecursionError, 3 OverflowError, "
                     "4 KeyError", type="Integer", min=0, max=4, variability="tunable"),
            Variable("u", "input", 1.0, "Input copied to y"),
            Variable("y", "output", 0.0, "Output", depends_on=("u",)),
        ),
        default_experiment=DefaultExperiment(0.0, 1.0, 1e-3),
    )

    def start(self, start_time: float) -> None:
        self.y = self.u

    def advance(self, current_time: float, step_size: float) -> None:
        if self.failure == 1:
            bytearray(1 << 60)
        elif self.failure == 2:
            _recurse(0)
        elif self.failure == 3:
            math.exp(1000.0)
        elif self.failure == 4:
            {}["missing"]
        self.y = self.u


def build_failing_fmus(dest: Path) -> None:
    """FMI 2.0 and 3.0 FMUs of :class:`FailingModel` under ``dest`` (where ``build.fmu_path`` finds them)."""
    from ..packaging import build

    for fmi in ("2", "3"):
        build(FailingModel.spec.name, dest, fmi, FailingModel)
