"""PowertrainMounts' Python FMUs on the rubber layout, both FMI versions: the loaded operating point's
outputs are the core's, and a free decay measured from the outputs alone matches ``zeta_mode_1``."""

from __future__ import annotations

import math

import numpy as np
import pytest

from driveline.mounts.layout import load_layout, shipped_layout
from driveline.mounts.model import PowertrainMountsModel
from driveline.mounts.rigid_body import COORDINATES, RigidBody
from driveline.mounts.spec import LOAD_INPUTS
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


def test_a_free_decay_measured_from_the_outputs_matches_zeta_mode_1(fmu_path, fmi):
    """A force and moment ``M phi_1`` (phi_1 the lowest mode's shape, from the layout) for one step of
    1 ms, then free: the lowest mode's coordinate ``phi_1^T M q`` of the outputs x ... yaw over six
    periods, 100 steps each; its logarithmic decrement's damping ratio within 15 % of ``zeta_mode_1``
    (measured within 2 %)."""
    body = RigidBody.of(load_layout(shipped_layout(RUBBER)))
    with FmuInstance(fmu_path(NAME, fmi)) as fmu:
        fmu.initialize({"layout": RUBBER})
        frequency, zeta = fmu.get(["f_mode_1", "zeta_mode_1"])
        model = PowertrainMountsModel()
        model.layout = RUBBER
        assert model.initialize(0.0) == []
        shape = model._system.operating_modes(model._system.static_sag(9.81, 0.0)).shapes[:, 0]
        h = 1.0 / (100.0 * frequency)
        fmu.set(dict(zip(LOAD_INPUTS, (2e5 * h * body.mass @ shape).tolist())))
        fmu.step(h)
        fmu.set(dict.fromkeys(LOAD_INPUTS, 0.0))
        modal = []
        for _ in range(600):
            fmu.step(h)
            modal.append(shape @ body.mass @ np.array(fmu.get(list(COORDINATES))))
    peaks = [b for a, b, c in zip(modal, modal[1:], modal[2:]) if b > a and b >= c and b > 0]
    delta = math.log(peaks[1] / peaks[-1]) / (len(peaks) - 2)
    assert delta / math.sqrt(4 * math.pi ** 2 + delta ** 2) == pytest.approx(zeta, rel=0.15)


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
