"""CardanJoint and UniversalReducer FMUs against their closed forms, through fmpy."""

from __future__ import annotations

import math

import numpy as np
import pytest

from driveline.cardan import kinematics
from driveline.reducer.mechanics import transmission_ratio
from fmu_harness.runs.runner import StepRefused, simulate


@pytest.mark.parametrize("beta_deg", [0.0, 10.0, 30.0, 44.0])
@pytest.mark.parametrize("omega", [300.0, -120.0])
def test_cardan_follows_the_seed_over_many_turns(fmu_path, beta_deg, omega):
    beta, phase = math.radians(beta_deg), 0.4
    result = simulate(
        fmu_path("CardanJoint"), 1.0, 1e-3,
        inputs={"omega_in": omega, "beta": beta, "T_load": 50.0}, start_values={"phase": phase},
    )  # 48 turns at 300 rad/s
    np.testing.assert_allclose(result["phi_in"], omega * result["time"], rtol=1e-12)
    phi = result["phi_in"]  # the FMU's running sum; the closed forms are checked at it
    gamma1 = phi - phase
    turns = np.round((gamma1 - np.arctan2(np.sin(gamma1), math.cos(beta) * np.cos(gamma1))) / (2 * np.pi))
    expected = phase + np.arctan2(np.sin(gamma1), math.cos(beta) * np.cos(gamma1)) + 2 * np.pi * turns
    np.testing.assert_allclose(result["phi_out"], expected, atol=1e-9)  # seed: tan g1 = cos b tan g2
    assert np.all(np.abs(np.diff(result["phi_out"])) < 2 * abs(omega) * 1e-3 / math.cos(beta))  # no wrap jumps
    omega_out = omega * math.cos(beta) / (1 - math.sin(beta) ** 2 * np.cos(gamma1) ** 2)
    np.testing.assert_allclose(result["omega_out"], omega_out, rtol=1e-12)
    alpha_out = -(omega**2) * math.cos(beta) * math.sin(beta) ** 2 * np.sin(2 * gamma1) / (
        1 - math.sin(beta) ** 2 * np.cos(gamma1) ** 2) ** 2
    np.testing.assert_allclose(result["alpha_out"], alpha_out, rtol=1e-9, atol=1e-9 * omega**2)
    np.testing.assert_allclose(result["T_in"] * omega, 50.0 * result["omega_out"], rtol=1e-12)
    np.testing.assert_allclose(result["speed_fluctuation"], kinematics.speed_fluctuation(beta), rtol=1e-12)




@pytest.mark.parametrize("alpha_deg", [95.0, 135.0, 160.0, 170.0])
def test_reducer_ratio_is_exact_at_any_angle(fmu_path, alpha_deg):
    result = simulate(fmu_path("UniversalReducer"), 0.5, 1e-3, inputs={"intersection_angle": math.radians(alpha_deg), "T_load": 68.0})
    i = transmission_ratio(34, 29)
    assert i == pytest.approx(6.8)
    np.testing.assert_allclose(result["omega_out"], result["omega_out"][0], rtol=1e-15)
    np.testing.assert_allclose(result["phi_out"] * i, result["phi_in"], rtol=1e-14)
    np.testing.assert_allclose(result["T_in"] * (1000 * math.pi / 30), 68.0 * result["omega_out"], rtol=1e-14)


def test_reducer_ratio_holds_while_the_angle_and_speed_change(fmu_path):
    result = simulate(
        fmu_path("UniversalReducer"), 1.0, 1e-3,
        inputs={"intersection_angle": lambda t: math.radians(130 + 35 * math.sin(7 * t)), "omega_in": lambda t: 100 + 50 * math.sin(3 * t)},
    )
    np.testing.assert_allclose(result["phi_out"] * 6.8, result["phi_in"], rtol=1e-14)
    assert np.ptp(result["omega_out"]) > 1.0  # the speed did change


@pytest.mark.parametrize("values, fragment", [({"z1": 29}, "z1"), ({"z2": 0}, "z2"), ({"module": 0.0}, "module")])
def test_reducer_refuses_bad_gearing(family, values, fragment):
    with pytest.raises(StepRefused) as refused:
        simulate(family.path("UniversalReducer"), 0.01, 1e-3, start_values=values)
    assert any(fragment in m for m in refused.value.messages)


def test_cardan_refuses_beta_above_its_guard(family):
    with pytest.raises(StepRefused) as refused:
        simulate(family.path("CardanJoint"), 0.01, 1e-3, inputs={"beta": math.radians(46.0)})
    assert "beta_max" in refused.value.messages[0]
