"""Cardan joint: exact kinematics against an independent numerical solution, and the model.

The reference solves the gimbal constraint ``x1 . x2 = 0`` for the output angle with a
bracketing root finder, building the yokes from rotation matrices (scipy), not from
the seed's closed forms; speed and acceleration come from finite differences of it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

from driveline.cardan import kinematics
from driveline.cardan.model import ACCELERATION_ESTIMATED, CardanJointModel

from support import model_checks

E_X, E_Y = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
BETAS = (0.0, 0.1, 0.5, 1.0, 1.4)
# Root-finder tolerance: a few ulp of angles up to ~130 rad (40 turns).
ROOT_XTOL = 1e-13


def reference_output_angle(phi_in: float, beta: float, phase: float = 0.0) -> float:
    """phi_out from ``x1 . x2 = 0``: input yoke Rz(g1) x, output yoke R_bend Rz(g2) y.

    Output and input angles differ by less than a quarter turn, and the constraint
    changes sign between ``g1 - pi/2`` and ``g1 + pi/2`` (roots are pi apart), so the
    bracket holds exactly the continuous (unwrapped) root.
    """
    gamma1 = phi_in - phase
    x1 = Rotation.from_euler("z", gamma1).apply(E_X)
    bend = Rotation.from_euler("y", beta).as_matrix()

    def constraint(gamma2: float) -> float:
        return float(x1 @ bend @ np.array([-math.sin(gamma2), math.cos(gamma2), 0.0]))

    quarter = 0.5 * math.pi
    return phase + brentq(constraint, gamma1 - quarter, gamma1 + quarter, xtol=ROOT_XTOL, rtol=1e-15)


@pytest.mark.parametrize("beta", BETAS)
@pytest.mark.parametrize("phase", (0.0, 0.7, -2.0))
def test_output_angle_matches_constraint_over_many_turns(beta: float, phase: float) -> None:
    # 20 turns each way, off-grid so that no sample sits on a half-turn boundary by design.
    phi = np.linspace(-40.0 * math.pi, 40.0 * math.pi, 1601) + 0.123
    reference = np.array([reference_output_angle(p, beta, phase) for p in phi])
    # Both sides are round-off limited: ~1e-14 relative on |phi| <= 126 rad.
    np.testing.assert_allclose(kinematics.output_angle(phi, beta, phase), reference, rtol=0, atol=1e-11)


def test_output_angle_is_continuous_and_monotonic_on_half_turn_boundaries() -> None:
    beta = 1.2
    for boundary in np.arange(-12, 13) * 0.5 * math.pi:
        phi = boundary + np.array([-1e-9, 0.0, 1e-9])
        out = kinematics.output_angle(phi, beta)
        assert np.all(np.diff(out) > 0.0)
        # d(phi_out)/d(phi_in) <= 1/cos(beta) bounds the jump across the boundary.
        assert out[2] - out[0] <= 2e-9 / math.cos(beta) + 1e-12
        assert out[1] == pytest.approx(boundary, abs=1e-12)  # phi_out = phi_in at multiples of pi/2


@pytest.mark.parametrize("beta", BETAS)
def test_speed_is_the_derivative_of_the_angle(beta: float) -> None:
    phi = np.linspace(-7.0, 7.0, 141)
    h = 1e-5  # central difference: truncation ~h^2 |phi_out'''| < 1e-8, round-off ~1e-14/h = 1e-9
    numeric = np.array(
        [(reference_output_angle(p + h, beta) - reference_output_angle(p - h, beta)) / (2 * h) for p in phi]
    )
    omega_in = -3.7
    np.testing.assert_allclose(kinematics.output_speed(phi, beta, omega_in), omega_in * numeric, rtol=1e-6)


@pytest.mark.parametrize("beta", BETAS)
def test_acceleration_with_input_acceleration_matches_second_difference(beta: float) -> None:
    omega0, a1 = 2.5, -4.0  # input angle phi(t) = 0.3 + omega0 t + a1 t^2 / 2

    def angle(t: float) -> float:
        return reference_output_angle(0.3 + omega0 * t + 0.5 * a1 * t**2, beta)

    # 4th-order stencil. Truncation ~h^4 |d6 phi_out| grows like 1/cos(beta)^6 (4e-6 relative
    # at beta = 1.4 with h = 1e-3); round-off ~1e-14 / h^2. h = 3e-4 keeps both below 5e-8.
    h = 3e-4
    for t in np.linspace(-1.5, 1.5, 31):
        samples = np.array([angle(t + k * h) for k in (-2, -1, 0, 1, 2)])
        numeric = (-samples[0] + 16 * samples[1] - 30 * samples[2] + 16 * samples[3] - samples[4]) / (12 * h**2)
        phi, omega = 0.3 + omega0 * t + 0.5 * a1 * t**2, omega0 + a1 * t
        exact = kinematics.output_acceleration(phi, beta, omega, a1)
        # Scale: the acceleration terms reach (omega^2 + |a1|) / cos(beta)^2 ~ 1e3 at beta = 1.4.
        assert exact == pytest.approx(numeric, abs=1e-6 * (omega**2 + abs(a1)) / math.cos(beta) ** 2)


@pytest.mark.parametrize("beta", (0.05, 0.3, 0.7, 1.2))
def test_speed_fluctuation_matches_sampled_extremes(beta: float) -> None:
    # 4k samples per turn hit the extremes at g1 = 0 and pi/2 exactly.
    phi = np.linspace(0.0, 2.0 * math.pi, 4001)
    ratio = kinematics.speed_ratio(phi, beta)
    turn = reference_output_angle(2.0 * math.pi, beta) - reference_output_angle(0.0, beta)
    mean = turn / (2.0 * math.pi)  # time mean of the ratio at constant input speed
    assert mean == pytest.approx(1.0, abs=1e-12)
    sampled = (ratio.max() - ratio.min()) / mean
    assert float(kinematics.speed_fluctuation(beta)) == pytest.approx(sampled, rel=1e-12)


@settings(max_examples=200, deadline=None)
@given(
    phi=st.floats(-1e3, 1e3),
    beta=st.floats(0.0, 1.45),
    phase=st.floats(-10.0, 10.0),
)
def test_two_joints_phased_a_quarter_turn_apart_are_homokinetic(phi: float, beta: float, phase: float) -> None:
    # Coplanar yokes on the intermediate shaft: the second joint's input yoke is in the
    # bend plane a quarter turn after the first joint's.
    middle = kinematics.output_angle(phi, beta, phase)
    out = kinematics.output_angle(middle, beta, phase + 0.5 * math.pi)
    assert float(out) == pytest.approx(phi, abs=1e-12 * max(1.0, abs(phi)))


def test_straight_joint_is_the_identity() -> None:
    phi = np.linspace(-20.0, 20.0, 201)
    np.testing.assert_allclose(kinematics.output_angle(phi, 0.0, 0.4), phi, rtol=0, atol=1e-13)
    np.testing.assert_array_equal(kinematics.speed_ratio(phi, 0.0), 1.0)
    np.testing.assert_array_equal(kinematics.output_acceleration(phi, 0.0, 5.0, 2.0), 2.0)


# -- the model through the SteppedModel interface --------------------------------------------


def started(**values: float) -> CardanJointModel:
    return model_checks.started(CardanJointModel, **values)


def test_constant_speed_steps_follow_the_exact_kinematics() -> None:
    model = started(omega_in=-50.0, beta=0.6, phase=0.3, phi_in_start=1.0, T_load=80.0)
    h = 1e-3
    for k in range(2000):  # 100 rad backwards: ~16 turns
        assert model.step(k * h, h) == []
    phi = model.phi_in
    assert phi == pytest.approx(1.0 - 50.0 * 2000 * h, rel=1e-12)  # summation round-off only
    assert model.phi_out == float(kinematics.output_angle(phi, 0.6, 0.3))
    assert model.omega_out == pytest.approx(-50.0 * float(kinematics.speed_ratio(phi, 0.6, 0.3)), rel=1e-15)
    assert model.alpha_out == pytest.approx(float(kinematics.output_acceleration(phi, 0.6, -50.0, 0.0, 0.3)))
    assert model.speed_fluctuation == pytest.approx(math.tan(0.6) * math.sin(0.6), rel=1e-15)
    assert model.T_in * model.omega_in == pytest.approx(model.T_load * model.omega_out, rel=1e-14)


def test_torque_at_standstill_uses_the_kinematic_ratio() -> None:
    model = started(omega_in=0.0, beta=0.5, phi_in_start=0.0, T_load=100.0)
    # At g1 = 0 the ratio is cos b / (1 - sin^2 b) = 1 / cos b.
    assert model.speed_ratio == pytest.approx(1.0 / math.cos(0.5), rel=1e-15)
    assert model.T_in == pytest.approx(100.0 / math.cos(0.5), rel=1e-15)
    assert model.omega_out == 0.0


def estimate_of_a1(model: CardanJointModel) -> float:
    """The input acceleration a_1 the model put into alpha_out, (C4) solved for it (D / cos b)."""
    phi, beta, phase = model.phi_in, model.beta, model.phase
    without = float(kinematics.output_acceleration(phi, beta, model.omega_in, 0.0, phase))
    return (model.alpha_out - without) / float(kinematics.speed_ratio(phi, beta, phase))


def test_ramp_input_without_alpha_in_is_estimated_from_the_samples() -> None:
    omega0, a1, beta, h = 10.0, 40.0, 0.5, 1e-4
    model = started(omega_in=omega0, beta=beta)
    t = 0.0
    for k in range(2000):
        model.omega_in = omega0 + a1 * t  # the host samples a ramp at each step start
        assert model.step(t, h) == []
        t += h
        # round-off of the difference, and of (C4)'s centripetal term (omega^2 ~ 8e3) solved back
        assert estimate_of_a1(model) == pytest.approx(a1 if k > 0 else 0.0, rel=1e-9, abs=1e-9)
    # Against the exact ramp trajectory at the end time: the held input lags by half a
    # step in angle and a whole step in speed, so agreement is O(h) (~1e-3 relative here).
    phi_exact, omega_exact = omega0 * t + 0.5 * a1 * t**2, omega0 + a1 * t
    exact = float(kinematics.output_acceleration(phi_exact, beta, omega_exact, a1))
    assert model.alpha_out == pytest.approx(exact, rel=5e-3)
    assert model.phi_in == pytest.approx(phi_exact, rel=1e-3)


def test_speed_change_at_the_start_time_is_an_initial_condition() -> None:
    model = started(omega_in=10.0)
    model.omega_in = 30.0  # set after initialisation, before the first step
    assert model.step(0.0, 1e-3) == []
    assert estimate_of_a1(model) == pytest.approx(0.0, abs=1e-9)
    model.omega_in = 20.0
    assert model.step(1e-3, 1e-3) == []
    assert estimate_of_a1(model) == pytest.approx(-1e4)


def test_alpha_in_set_is_taken_exactly_from_then_on() -> None:
    """The host's alpha_in is a_1 in (C4) bit for bit once set non-zero, the samples' difference
    until then (the log's notice at the start says so, and is gone when it is set at the start)."""
    omega0, a1, beta, h = 10.0, 40.0, 0.5, 1e-4
    estimated = started(omega_in=omega0, beta=beta)
    assert estimated.start_notice() == ACCELERATION_ESTIMATED
    exact = started(omega_in=omega0, beta=beta, alpha_in=a1)
    assert exact.start_notice() is None
    assert exact.alpha_out == float(kinematics.output_acceleration(0.0, beta, omega0, a1))
    for k in range(50):
        exact.omega_in = omega0 + a1 * k * h
        exact.alpha_in = a1 if k % 2 == 0 else 0.0  # set once: 0 later is a value, not the estimate's cue
        assert exact.step(k * h, h) == []
        assert exact.alpha_out == float(kinematics.output_acceleration(exact.phi_in, beta, exact.omega_in,
                                                                       exact.alpha_in))


def test_varying_bend_angle_keeps_the_angle_exact() -> None:
    model = started(omega_in=100.0, beta=0.0, beta_max=1.0)
    h = 1e-3
    for k in range(300):
        model.beta = 0.4 + 0.3 * math.sin(20.0 * k * h)
        assert model.step(k * h, h) == []
        assert model.phi_out == float(kinematics.output_angle(model.phi_in, model.beta))
        assert model.speed_fluctuation == pytest.approx(math.tan(model.beta) * math.sin(model.beta))


@pytest.mark.parametrize(
    ("name", "value", "fragment"),
    [
        ("beta", math.radians(50.0), "input beta = 50 deg must not exceed beta_max = 45 deg"),
        ("beta", -0.01, "input beta = -0.01 rad is below its minimum"),
        ("beta", math.nan, "input beta = nan is not finite"),
        ("omega_in", math.inf, "input omega_in = inf is not finite"),
        ("T_load", math.nan, "input T_load = nan is not finite"),
    ],
)
def test_invalid_input_is_refused_and_leaves_the_state(name: str, value: float, fragment: str) -> None:
    model = started(omega_in=30.0)
    model_checks.assert_refused_without_trace(model, name, value, fragment)


@pytest.mark.parametrize(
    ("value", "fragment"),
    [(0.5 * math.pi, "beta_max = 90 deg must be below 90 deg"), (2.0, "beta_max = 114.592 deg must be below 90 deg")],
)
def test_invalid_beta_max_is_refused(value: float, fragment: str) -> None:
    model = CardanJointModel()
    model.beta_max = value
    errors = model.initialize(0.0)
    assert len(errors) == 1 and fragment in errors[0]


def test_non_positive_step_is_refused() -> None:
    model = started()
    before = model.get_state()
    assert "step size" in model.step(0.0, 0.0)[0]
    assert model.get_state() == before
