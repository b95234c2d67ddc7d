"""Tripod coupling forces (seed 000 eqs 20-34) and the eq 20 check against exact kinematics."""

from __future__ import annotations

import numpy as np
import pytest

from driveline.tripod import dynamics, geometry

R, L, M = 0.026, 0.700, 0.2
OMEGA = 2000.0 * np.pi / 30.0
PHI = np.linspace(0.0, 2.0 * np.pi, 360, endpoint=False)


def harmonic_amplitudes(signal: np.ndarray) -> np.ndarray:
    return 2.0 * np.abs(np.fft.rfft(signal)) / len(signal)


@pytest.mark.parametrize("beta_deg", [10.0, 30.0, 45.0])
def test_eq20_overstates_the_exact_plunger_acceleration_sum(beta_deg):
    beta = np.radians(beta_deg)
    phi, accelerations = dynamics.exact_plunger_accelerations(beta, R, L, OMEGA)
    single = harmonic_amplitudes(accelerations[:, 0])
    # each plunger follows its groove: a ~ omega^2 r tan(beta) cos(phi), to O(r/l)
    assert single[1] == pytest.approx(OMEGA**2 * R * np.tan(beta), rel=R / L)
    exact_sum = harmonic_amplitudes(accelerations.sum(axis=1))
    paper_sum = harmonic_amplitudes(dynamics.reactions(phi, beta, OMEGA, geometry.orbit_radius(beta, R), L, M).a_plunger_sum)
    assert paper_sum[3] == pytest.approx(6 * OMEGA**2 * geometry.orbit_radius(beta, R) * np.sin(beta))
    # measured ratios 4e4 (10 deg), 2.7e3 (30 deg), 5.5e2 (45 deg)
    assert exact_sum[3] < 0.01 * paper_sum[3]


def test_reactions_vanish_without_bend():
    for reaction in dynamics.reactions(PHI, 0.0, OMEGA, geometry.orbit_radius(0.0, R), L, M):
        assert np.abs(reaction).max() == 0.0


def test_reaction_orders_and_amplitudes():
    beta = np.radians(30.0)
    rho = geometry.orbit_radius(beta, R)
    _, rz, rx, ry = (harmonic_amplitudes(f) for f in dynamics.reactions(PHI, beta, OMEGA, geometry.orbit_radius(beta, R), L, M))
    assert np.argmax(rz) == 3 and np.argmax(rx) == 3 and np.argmax(ry) == 6
    assert rz[3] == pytest.approx(6 * M * rho * OMEGA**2 * np.tan(beta))
    assert rx[3] == pytest.approx(6 * M * rho * OMEGA**2 * np.sin(beta) * np.tan(beta))
    assert ry[6] == pytest.approx(3 * M * rho**2 * OMEGA**2 * np.tan(beta) / L)


def test_pin_force_balances_the_load_torque():
    beta = np.radians(25.0)
    force = dynamics.pin_force(100.0, geometry.orbit_radius(beta, R), R)
    torque = force * geometry.arm_lengths(PHI, beta, R).sum(axis=1)
    np.testing.assert_allclose(torque, 100.0, rtol=1e-12)


def test_power_balance():
    ratio = np.array([0.99, 1.0, 1.01])
    torque = dynamics.input_torque(50.0, ratio)
    np.testing.assert_allclose(torque * OMEGA, 50.0 * OMEGA * ratio)
