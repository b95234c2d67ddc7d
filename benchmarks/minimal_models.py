"""Minimal twins of the catalog's models, the floor of the framework for the step-cost benchmark.

Each twin has its model's variables (same names, ranges, start values, so the same generic
validation and FMI traffic) and does no physics: every output takes the first input's
value. Shipped inside the twin FMUs; the benchmark builds them with :func:`fmu_harness.packaging.build`.
"""

from __future__ import annotations

import dataclasses

from driveline.catalog import MODELS
from driveline.model import SteppedModel


class MinimalModel(SteppedModel):
    """Copies the first input to every output."""

    def start(self, start_time: float) -> None:
        self.advance(start_time, 0.0)

    def advance(self, current_time: float, step_size: float) -> None:
        value = float(getattr(self, self._inputs[0].name)) if self._inputs else current_time
        for name in self._real_outputs:
            setattr(self, name, value)


def _twin(model: type[SteppedModel]) -> type[SteppedModel]:
    spec = dataclasses.replace(model.spec, name=f"Minimal{model.spec.name}")
    return type(spec.name, (MinimalModel,), {"spec": spec, "__module__": __name__})


for _model in MODELS.values():
    globals()[f"Minimal{_model.spec.name}"] = _twin(_model)
