"""Serialised model states: exact round trips of every catalog model, and every kind of foreign,
truncated, corrupt or hostile bytes refused with the reason (never unpickled, never run)."""

from __future__ import annotations

import hashlib
import math
import os
import pickle

import pytest

from driveline.catalog import MODELS
from fmu_src import saved_state
from fmu_src.saved_state import StateRefused


def _stepped(model_name: str):
    model = MODELS[model_name]()
    assert model.initialize(0.0) == []
    for _ in range(3):
        assert model.step(model.time, model.spec.default_experiment.step_size) == []
    return model


def _resealed(body: bytes) -> bytes:
    return body + hashlib.sha256(body).digest()


def test_a_saved_state_restores_and_continues_bit_identically(model_name):
    model = _stepped(model_name)
    data = saved_state.encode(model.spec, model.saved_values(model.get_state()))
    reference = [model.step(model.time, 1e-3) or model.outputs() for _ in range(3)]
    restored = MODELS[model_name]()
    restored.set_state(restored.state_from_saved(saved_state.decode(model.spec, data)))
    assert [restored.step(restored.time, 1e-3) or restored.outputs() for _ in range(3)] == reference


def test_non_finite_values_round_trip_exactly():
    spec = MODELS["SpeedSource"].spec
    values = {"a": math.nan, "b": -math.inf, "c": 5e-324, "d": (1, True, "x", None, (2.5,))}
    decoded = saved_state.decode(spec, saved_state.encode(spec, values))
    assert math.isnan(decoded["a"]) and decoded["b"] == -math.inf and decoded["c"] == 5e-324
    assert decoded["d"] == (1, True, "x", None, (2.5,)) and type(decoded["d"][1]) is bool


class _RunsCommand:
    def __reduce__(self):
        return (os.system, ("touch pickle_ran",))


def _good() -> bytes:
    model = _stepped("SpeedSource")
    return saved_state.encode(model.spec, model.saved_values(model.get_state()))


@pytest.mark.parametrize("make, reason", [
    (lambda good: pickle.dumps(_RunsCommand()), "not a serialised state"),
    (lambda good: b"", "not a serialised state"),
    (lambda good: good[:-1], "truncated or corrupt"),
    (lambda good: good[: len(good) // 2], "truncated or corrupt"),
    (lambda good: good[:40] + bytes([good[40] ^ 1]) + good[41:], "truncated or corrupt"),
    (lambda good: good + b"\0", "truncated or corrupt"),
    (lambda good: saved_state.MAGIC + b"\0" * (saved_state.MAX_BYTES + 1), "more than a state"),
    (lambda good: _resealed(saved_state.MAGIC + b"[" * 100000 + b"]" * 100000), "malformed"),
    (lambda good: _resealed(saved_state.MAGIC + b'{"format": 2}'), "format 2 is not supported"),
    (lambda good: _resealed(good[:-32].replace(b'"SpeedSource"', b'"CardanJoint"')), "saved by model 'CardanJoint'"),
    (lambda good: _resealed(good[:-32].replace(b'"spec":"', b'"spec":"0')), "another version"),
    (lambda good: _resealed(good[:-32].replace(b'["f","', b'["x","', 1)), "malformed value"),
    (lambda good: _resealed(good[:-32].replace(b'["f","', b'["f","zz', 1)), "malformed float"),
])
def test_foreign_or_damaged_bytes_are_refused_with_the_reason(make, reason, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(StateRefused, match=reason):
        saved_state.decode(MODELS["SpeedSource"].spec, make(_good()))
    assert not (tmp_path / "pickle_ran").exists()


@pytest.mark.parametrize("change, reason", [
    (lambda values: values.pop("omega_out"), r"differs in \['omega_out'\]"),
    (lambda values: values.update(extra=1.0), r"differs in \['extra'\]"),
    (lambda values: values.update(omega_out="fast"), "omega_out is a str, not a float"),
    (lambda values: values.update(time=True), "time is a bool, not a float"),
    (lambda values: values.update(_initialized=1), "_initialized is a int, not a bool"),
])
def test_saved_values_that_do_not_fit_the_model_are_refused(change, reason):
    model = _stepped("SpeedSource")
    values = model.saved_values(model.get_state())
    change(values)
    with pytest.raises(ValueError, match=reason):
        model.state_from_saved(values)


def test_restored_parameters_are_validated_again_at_the_next_step():
    model = _stepped("SpeedSource")
    values = model.saved_values(model.get_state())
    values["sine_frequency"] = -1.0
    model.set_state(model.state_from_saved(values))
    assert any("sine_frequency" in reason for reason in model.step(model.time, 1e-3))


def test_tripod_warm_start_is_rebuilt_or_refused():
    model = _stepped("TripodCoupling")
    values = model.saved_values(model.get_state())
    values["_solution"] = (1.0, "x")
    with pytest.raises(ValueError, match="warm start"):
        model.state_from_saved(values)


@pytest.mark.parametrize("name, change, reason", [
    ("SpeedSource", {"omega_out": math.nan}, "output omega_out = nan is not finite"),
    ("SpeedSource", {"phi_out": -math.inf, "omega_out": 1e300}, "output phi_out = -inf is not finite"),
    ("SpeedSource", {"time": math.inf}, "time = inf is not finite"),
    ("UniversalReducer", {"sigma_eq": 2e10}, "output sigma_eq = 20000000000.0 Pa is above its maximum 10000000000.0 Pa"),
])
def test_restored_values_the_model_cannot_leave_are_refused(name, change, reason):
    """A state whose checksum a host remade by hand: its time and outputs are checked as the model leaves them
    (finite, within their bounds), the first reason named."""
    model = _stepped(name)
    values = model.saved_values(model.get_state())
    values.update(change)
    with pytest.raises(ValueError) as refused:
        model.state_from_saved(values)
    assert str(refused.value) == f"the state holds an impossible value ({reason})"
