"""PowertrainMounts' Python FMUs on the rubber layout, both FMI versions: the loaded operating point's
outputs are the core's, and a saved state carries the branches' forces (the free decay of the layout, the
default, through both families: test_mounts_default_fmu.py)."""

from __future__ import annotations

import math

import pytest

from driveline.mounts.model import PowertrainMountsModel
from driveline.mounts.rigid_body import COORDINATES
from fmu_harness.runs.runner import FmuInstance

NAME, RUBBER = "PowertrainMounts", "transverse_fwd_powertrain_rubber"
ANALYSIS = ["wind_up", *(f"{kind}_mode_{j}" for kind in ("f", "zeta") for j in range(1, 7)),
            *(f"{name}_static" for name in COORDINATES)]


@pytest.mark.parametrize("torque", [0.0, 1100.0])
def test_the_operating_point_is_the_core_s(fmu_path, fmi, torque):
    """Wind-up, modes, damping ratios and static sag at idle and under 1.1 kN.m: the core's, bit for bit."""
    model = PowertrainMountsModel()
    model.layout, model.T_mean = RUBBER, torque
    assert model.initialize(0.0) == []
    with FmuInstance(fmu_path(NAME, fmi)) as fmu:
        fmu.initialize({"layout": RUBBER, "T_mean": torque})
        assert fmu.get(ANALYSIS) == [getattr(model, name) for name in ANALYSIS]
    if torque:
        assert 0.0 < math.degrees(model.wind_up) <= 1.5


def test_a_saved_state_carries_the_branch_forces(fmu_path, fmi):
    """On the stops under the drive reaction, a state saved after 50 steps, serialised and restored after
    50 more repeats those 50 steps bit for bit: the Maxwell branches' forces travel with it."""
    with FmuInstance(fmu_path(NAME, fmi)) as fmu:
        fmu.initialize({"layout": RUBBER, "T_mean": 1100.0, "T_motor": 1100.0})
        fmu.set({"F_x": 500.0, "M_y": -200.0})
        for _ in range(50):
            fmu.step(1e-3)
        saved = fmu.get_state()
        first = []
        for _ in range(50):
            fmu.step(1e-3)
            first.append(fmu.get(list(COORDINATES)))
        fmu.set_state(fmu.deserialize_state(fmu.serialize_state(saved)))
        again = []
        for _ in range(50):
            fmu.step(1e-3)
            again.append(fmu.get(list(COORDINATES)))
    assert again == first
