"""Checks shared by the tests of the FMI-free models (driveline.model.SteppedModel)."""

from __future__ import annotations

from typing import Any, TypeVar

from driveline.model import SteppedModel

Model = TypeVar("Model", bound=SteppedModel)


def started(model_class: type[Model], **values: Any) -> Model:
    """A model with the given variable values, initialised at t = 0."""
    model = model_class()
    for name, value in values.items():
        setattr(model, name, value)
    assert model.initialize(0.0) == []
    return model


def assert_refused_without_trace(model: SteppedModel, name: str, value: Any, fragment: str) -> None:
    """A bad ``value`` of ``name`` is refused with one reason containing ``fragment``, the model
    keeps its state, and the corrected model steps on."""
    assert model.step(0.0, 1e-3) == []
    before = model.get_state()
    setattr(model, name, value)
    errors = model.step(1e-3, 1e-3)
    assert len(errors) == 1 and fragment in errors[0]
    setattr(model, name, before[name])
    assert model.get_state() == before  # nothing moved but the offending value
    assert model.step(1e-3, 1e-3) == []  # corrected, the host carries on
