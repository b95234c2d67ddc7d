"""TorqueSource: the ramp and hold against its closed form, at the communication points of a run."""

from __future__ import annotations

import numpy as np
import pytest

from driveline.torque.model import TorqueSourceModel

from support import model_checks


@pytest.mark.parametrize("ramp_time", [0.0, 0.3])
def test_ramp_then_hold(ramp_time):
    """From 20 N.m, the ramp starting at 0.1 s to 150 N.m: before, on and after the ramp the output is
    the straight line through (t_ramp, T_start) and (t_ramp + ramp_time, T_level), clipped; exact to
    one rounding of the share (1e-13 of the level)."""
    model = model_checks.started(TorqueSourceModel, T_start=20.0, T_level=150.0, t_ramp=0.1, ramp_time=ramp_time)
    times, values = [0.0], [model.T_motor]
    for n in range(60):
        assert model.step(n * 0.01, 0.01) == []
        times.append(n * 0.01 + 0.01)  # the time the model reaches
        values.append(model.T_motor)
    t = np.array(times)
    share = np.clip((t - 0.1) / ramp_time, 0.0, 1.0) if ramp_time else (t >= 0.1).astype(float)
    np.testing.assert_allclose(values, 20.0 + 130.0 * share, rtol=0.0, atol=150.0 * 1e-13)
    assert values[0] == 20.0 and values[-1] == 150.0


def test_a_negative_ramp_time_is_refused():
    model = TorqueSourceModel()
    model.ramp_time = -0.1
    errors = model.initialize(0.0)
    assert len(errors) == 1 and "ramp_time" in errors[0]
