"""Every model of the project, by FMU name; the build and the test harness iterate this."""

from __future__ import annotations

from .model import SteppedModel
from .tripod.model import TripodCouplingModel

MODELS: dict[str, type[SteppedModel]] = {
    model.spec.name: model
    for model in (TripodCouplingModel,)
}
