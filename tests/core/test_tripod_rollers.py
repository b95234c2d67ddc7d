"""The roller tripods (driveline.tripod.rollers): every contact force and slip speed against an
independent computation (support.roller_tripod_reference) on random configurations, the power
balance in drive and coast, limits, and the generated axial force against the plain tripod's."""

from __future__ import annotations

import math

import numpy as np
import pytest

from driveline.tripod import plane_solver
from driveline.tripod.outputs import coupling_outputs, efficiency
from driveline.tripod.reactions import exact_reactions, mechanism
from driveline.tripod.rollers import roller_reactions
from driveline.tripod.spec import DOUBLE_ROLLER, ROLLING_RESISTANCE, SINGLE_ROLLER
from support.roller_tripod_reference import random_case, solve
from support.tripod_mechanism import OMEGA, PHI, Mechanism, R, L, M

ROLLER, BORE = 0.0165, 0.0115
# Both computations solve to the last digits of float64: the reference's root to a residual of
# 1e-12 of the forces (measured 5e-13 N for loads of 1e4 N), this model's balance to 1e-13 of the
# forces; their difference, measured up to 5e-10 N (forces) and 2e-12 m/s (slips), is rounding
# times the balance's conditioning. The bounds are the issue's.
FORCE_TOLERANCE = 1e-6  # N
SPEED_TOLERANCE = 1e-9  # m/s


def roller_forces(case):
    _, _, solution = plane_solver.solve(case.phi_in, case.beta, case.r, case.l, None)
    state = mechanism(case.phi_in, case.beta, case.omega, case.omega_dot, case.T_load, case.r, case.l, case.m,
                      solution.x, solution.y, case.beta_dot, case.beta_ddot)
    return roller_reactions(state, case.omega, case.T_load, case.m, case.tripod_type, case.mu, case.mu_roll,
                            case.slip_speed, case.roller_radius, case.roller_bore_radius)


@pytest.mark.parametrize("tripod_type", [SINGLE_ROLLER, DOUBLE_ROLLER])
def test_contacts_against_an_independent_computation(tripod_type):
    rng = np.random.default_rng(41 + tripod_type)
    for _ in range(24):
        case = random_case(rng, tripod_type)
        reference = solve(case)
        assert reference["residual"] < 1e-9
        forces, contacts = roller_forces(case)
        for name in ("N_track", "N_trunnion", "F_trunnion", "F_roll", "F_skew"):
            np.testing.assert_allclose(getattr(contacts, name), reference[name], rtol=0, atol=FORCE_TOLERANCE,
                                       err_msg=name)
        for name in ("v_trunnion", "v_roll", "v_skew"):
            np.testing.assert_allclose(getattr(contacts, name), reference[name], rtol=0, atol=SPEED_TOLERANCE,
                                       err_msg=name)
        ours = [forces.Rx_in, forces.Ry_in, forces.Rz_in, forces.Mx_in, forces.My_in, forces.T_in]
        np.testing.assert_allclose(ours, np.concatenate([reference["R_in"], reference["M_in"]]), rtol=0,
                                   atol=FORCE_TOLERANCE)
        # the output bearing's force: its axial part along the shaft and its size (the radial frame is the core's)
        assert abs(forces.Rz_out - reference["R_out"] @ reference["U"]) < FORCE_TOLERANCE
        assert abs(math.hypot(forces.Rx_out, forces.Ry_out, forces.Rz_out) - np.linalg.norm(reference["R_out"])) \
            < FORCE_TOLERANCE
        assert forces.P_friction == pytest.approx(reference["P_friction"], abs=FORCE_TOLERANCE * SPEED_TOLERANCE * 1e6)
        assert forces.omega_spin == pytest.approx(reference["Omega"] @ reference["U"], abs=1e-9)


def over_a_turn(tripod_type, beta, T_load, omega=OMEGA, mu=0.05, mu_roll=ROLLING_RESISTANCE, m=M):
    betas = np.full_like(PHI, beta)
    _, _, solution = plane_solver.solve(PHI, betas, R, L)
    if tripod_type == 0:
        return exact_reactions(PHI, betas, omega, 0.0, T_load, R, L, m, solution.x, solution.y, mu, 1e-3)
    state = mechanism(PHI, betas, omega, 0.0, T_load, R, L, m, solution.x, solution.y)
    return roller_reactions(state, omega, T_load, m, tripod_type, mu, mu_roll, 1e-3, ROLLER, BORE)[0]


@pytest.mark.parametrize("tripod_type", [SINGLE_ROLLER, DOUBLE_ROLLER])
@pytest.mark.parametrize("T_load", [300.0, -300.0, 0.0])
def test_power_balance_is_the_dissipation(tripod_type, T_load):
    """T_in omega_in - T_load omega_spin - dKE/dt = P_friction (KE of the rollers from the Newton
    closure), drive and coast; the efficiency stays within [0, 1]. The residual is rounding of
    terms of T_load omega (6e4 W) and m r^2 omega^3: 1e-6 of the supplied power is 6e-2 W."""
    mech = Mechanism(math.radians(20.0))
    f = over_a_turn(tripod_type, mech.beta, T_load)
    supplied = np.abs(f.T_in * OMEGA)
    residual = f.T_in * OMEGA - T_load * f.omega_spin - mech.kinetic_energy_rate(OMEGA, 0.0) - f.P_friction
    assert np.abs(residual).max() < 1e-6 * max(supplied.max(), M * R**2 * OMEGA**3)
    assert f.P_friction.min() >= 0.0
    eff = efficiency(T_load * f.omega_spin, f.P_friction)
    assert eff.max() <= 1.0 and eff.min() >= 0.0


def third_order(force):
    return 2.0 * np.abs(np.fft.rfft(force))[3] / len(force)


def test_generated_axial_force_against_the_plain_tripod():
    """At 300 N.m, mu = 0.05 and the default rolling resistance: both roller tripods' third-order
    generated axial force lies below the plain tripod's at 4, 8 and 12 deg and grows with the angle (the
    single roller's skew, the double roller's needles); the double roller's is its rolling resistance and
    the share r_b / R of its needles' friction along the track, Rz_in = sum (F_roll + r_b / R sin(gamma) F_n)."""
    amplitudes = {}
    for tripod_type in (0, SINGLE_ROLLER, DOUBLE_ROLLER):
        amplitudes[tripod_type] = [third_order(over_a_turn(tripod_type, math.radians(deg), 300.0).Rz_in)
                                   for deg in (4.0, 8.0, 12.0)]
    for roller in (SINGLE_ROLLER, DOUBLE_ROLLER):
        assert all(a < p for a, p in zip(amplitudes[roller], amplitudes[0]))
        assert amplitudes[roller][0] < amplitudes[roller][1] < amplitudes[roller][2]
    betas = np.full_like(PHI, math.radians(8.0))
    _, _, solution = plane_solver.solve(PHI, betas, R, L)
    state = mechanism(PHI, betas, OMEGA, 0.0, 300.0, R, L, M, solution.x, solution.y)
    forces, contacts = roller_reactions(state, OMEGA, 300.0, M, DOUBLE_ROLLER, 0.05, ROLLING_RESISTANCE, 1e-3, ROLLER,
                                        BORE)
    along = contacts.F_roll + BORE / ROLLER * np.sin(contacts.gamma) * contacts.F_skew
    np.testing.assert_allclose(forces.Rz_in, along.sum(axis=-1), rtol=0, atol=1e-9)


@pytest.mark.parametrize("tripod_type", [SINGLE_ROLLER, DOUBLE_ROLLER])
def test_without_friction_every_type_is_the_plain_tripod(tripod_type):
    """mu = mu_roll = 0: the rollers carry the plain tripod's forces (the same balance, solved
    again: equal within rounding, 1e-10 of the largest force)."""
    plain = over_a_turn(0, math.radians(25.0), 400.0, mu=0.0)
    roller = over_a_turn(tripod_type, math.radians(25.0), 400.0, mu=0.0, mu_roll=0.0)
    scale = np.abs(plain.F_arm).max()
    for name in ("Rx_in", "Ry_in", "Mx_in", "My_in", "T_in", "Rx_out", "Ry_out", "Rz_out", "Rz_in", "P_friction"):
        np.testing.assert_allclose(getattr(roller, name), getattr(plain, name), rtol=0, atol=1e-10 * scale,
                                   err_msg=name)


def test_straight_joint_generates_only_rolling_resistance():
    """At beta = 0 nothing skews or slides on the trunnions; the rollers stand still on their tracks
    (zdot = 0), so no friction acts at all."""
    for tripod_type in (SINGLE_ROLLER, DOUBLE_ROLLER):
        f = over_a_turn(tripod_type, 0.0, 300.0)
        assert np.abs(f.Rz_in).max() < 1e-9 and np.abs(f.P_friction).max() < 1e-9


def test_the_outputs_take_the_type():
    """coupling_outputs dispatches on tripod_type; the plain tripod's outputs are those of before."""
    args = (0.3, math.radians(10.0), OMEGA, 300.0, R, L, M, 1)
    plain, _ = coupling_outputs(*args, mu=0.05)
    same, _ = coupling_outputs(*args, mu=0.05, tripod_type=0, mu_roll=0.01, roller_radius=0.02)
    assert plain == same
    single, _ = coupling_outputs(*args, mu=0.05, tripod_type=SINGLE_ROLLER, mu_roll=ROLLING_RESISTANCE,
                                 roller_radius=ROLLER)
    assert abs(single["Rz_in"]) < abs(plain["Rz_in"]) and 0.0 < single["efficiency"] <= 1.0
    assert isinstance(single["Rz_in"], float)
