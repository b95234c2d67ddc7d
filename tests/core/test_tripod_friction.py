"""Coulomb friction in the tripod's sliding pairs (driveline.tripod.reactions, friction > 0):
power balance against the dissipation, a second formulation of the frictional statics
(scipy's fsolve on the force vectors, pose and rates from the Newton closure), the
regularisation's convergence, limits, and the FMU end to end."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import fsolve

from driveline.tripod import exact, plane_solver
from driveline.tripod.outputs import efficiency
from driveline.tripod.reactions import exact_reactions, slip_sign
from fmu_harness.runs.runner import StepRefused, simulate
from support.tripod_mechanism import OMEGA, PHI, Mechanism, R, L, M, spectral_derivatives

MU = 0.05


def frictional(beta, T_load, mu=MU, slip=1e-3, omega=OMEGA, m=M):
    _, _, solution = plane_solver.solve(PHI, np.full_like(PHI, beta), R, L)
    return exact_reactions(PHI, beta, omega, 0.0, T_load, R, L, m, solution.x, solution.y, mu, slip)


@pytest.mark.parametrize("beta_deg, T_load, mu", [(25.0, 500.0, 0.05), (45.0, 500.0, 0.15), (10.0, 0.0, 0.1), (30.0, -300.0, 0.05)])
def test_power_balance_is_the_dissipation(beta_deg, T_load, mu):
    """T_in omega_in - T_load omega_spin - dKE/dt = P_friction >= 0, KE from the Newton closure."""
    mech = Mechanism(math.radians(beta_deg))
    f = frictional(mech.beta, T_load, mu)
    residual = f.T_in * OMEGA - T_load * f.omega_spin - mech.kinetic_energy_rate(OMEGA, 0.0) - f.P_friction
    assert np.abs(residual).max() < 1e-9 * (abs(T_load) * OMEGA + M * R**2 * OMEGA**3)
    assert f.P_friction.min() > 0.0


def second_formulation(mech: Mechanism, T_load: float, mu: float, slip: float, k: int) -> dict[str, np.ndarray]:
    """Force vectors F_j (ball on arm j, 9 unknowns) from 9 equations: the tripod's moments
    about S, the friction law along each arm, each plunger's axial balance with groove friction."""
    pose = exact.exact_pose(PHI, mech.beta, R, L)
    arm_rate = spectral_derivatives(pose.arm_lengths)[0][k] * OMEGA
    zdot = mech.dz[k] * OMEGA
    acc = mech.accelerations(OMEGA, 0.0)[k]
    balls, U, S = mech.balls[k], mech.U[k], mech.S
    arms = (balls - pose.tripod_centre[k]) / pose.arm_lengths[k][:, None]

    def residual(unknowns):
        F = unknowns.reshape(3, 3)
        moment = np.sum(np.cross(balls - S, F), axis=0) - T_load * U
        along = np.sum(F * arms, axis=1)
        normal = np.linalg.norm(F - along[:, None] * arms, axis=1)
        arm_law = along - mu * normal * slip_sign(arm_rate, slip)
        groove_normal = np.linalg.norm(M * acc[:, :2] + F[:, :2], axis=1)
        groove = -mu * groove_normal * slip_sign(zdot, slip)
        plunger = groove - F[:, 2] - M * acc[:, 2]
        return np.concatenate([moment / L, arm_law, plunger])

    start = np.zeros(9)
    start[[0, 3, 6]] = T_load / (3 * R)
    F = fsolve(residual, start, xtol=1e-12).reshape(3, 3)
    assert np.abs(residual(F.ravel())).max() < 1e-8 * max(abs(T_load) / R, M * OMEGA**2 * R)
    groove = -mu * np.linalg.norm(M * acc[:, :2] + F[:, :2], axis=1) * slip_sign(zdot, slip)
    R_in = np.sum(M * acc + F, axis=0) + 0.0
    R_in[2] = groove.sum()
    moment_in = np.sum(np.cross(balls, M * acc + F), axis=0)  # groove force N_j = m a_j + F_j
    return {"R_in": R_in, "R_out": -F.sum(axis=0), "moment_in": moment_in}


@pytest.mark.parametrize("beta_deg, T_load", [(25.0, 500.0), (45.0, 0.0)])
def test_second_formulation_of_the_frictional_statics(beta_deg, T_load):
    mech = Mechanism(math.radians(beta_deg))
    f = frictional(mech.beta, T_load)
    for k in (0, 37, 101, 200):
        other = second_formulation(mech, T_load, MU, 1e-3, k)
        R_out = f.Rx_out[k] * mech.E1[k] + f.Ry_out[k] * mech.E2[k] + f.Rz_out[k] * mech.U[k]
        ours = np.concatenate([[f.Rx_in[k], f.Ry_in[k], f.Rz_in[k]], R_out, [f.Mx_in[k], f.My_in[k], f.T_in[k]]])
        theirs = np.concatenate([other["R_in"], other["R_out"], other["moment_in"]])
        assert np.abs(ours - theirs).max() < 1e-3 * np.abs(theirs).max() * 1e-3  # measured ~1e-9 relative


def generated_axial_force(f) -> tuple[float, float, float]:
    """Mean, 3rd-order amplitude of -Rz_in, and the mean efficiency over the turn."""
    force = -f.Rz_in
    spectrum = 2 * np.abs(np.fft.rfft(force)) / len(force)
    return force.mean(), spectrum[3], np.argmax(spectrum[1:]) + 1


def test_regularisation_converges_as_the_slip_speed_shrinks():
    beta = math.radians(25.0)
    results = [frictional(beta, 500.0, slip=slip) for slip in (1e-2, 1e-3, 1e-4, 1e-5)]
    amplitude = [generated_axial_force(f)[1] for f in results]
    loss = [f.P_friction.mean() for f in results]
    # each tenfold smaller slip speed changes the result ten to a hundred times less
    differences = np.abs(np.diff(amplitude)), np.abs(np.diff(loss))
    for diff in differences:
        assert diff[1] < 0.2 * diff[0] and diff[2] < 0.2 * diff[1]
    assert differences[0][-1] < 1e-5 * amplitude[-1] and differences[1][-1] < 1e-5 * loss[-1]


def test_limits():
    # no bend: nothing slides, no generated axial force, no loss
    straight = frictional(0.0, 500.0)
    assert np.abs(straight.Rz_in).max() < 1e-12 and np.abs(straight.P_friction).max() < 1e-9
    # mu = 0 is the frictionless balance, bit for bit
    beta = math.radians(30.0)
    _, _, solution = plane_solver.solve(PHI, np.full_like(PHI, beta), R, L)
    plain = exact_reactions(PHI, beta, OMEGA, 0.0, 500.0, R, L, M, solution.x, solution.y)
    zero = exact_reactions(PHI, beta, OMEGA, 0.0, 500.0, R, L, M, solution.x, solution.y, 0.0, 1e-3)
    for a, b in zip(plain, zero):
        assert np.array_equal(a, b)
    # torque reversal without plunger mass (drive to coast): friction keeps opposing the same
    # slip, so the generated axial force keeps its sign; both directions dissipate
    forward, reverse = frictional(beta, 400.0, m=0.0), frictional(beta, -400.0, m=0.0)
    assert np.corrcoef(forward.Rz_in, reverse.Rz_in)[0, 1] > 0.9
    np.testing.assert_allclose((forward.T_in + reverse.T_in) * OMEGA, forward.P_friction + reverse.P_friction,
                               rtol=1e-9)
    # with massless plungers (m = 0) only, reversing torque and rotation together mirrors every
    # force: the generated axial force flips, the loss stays
    backward = frictional(beta, -400.0, omega=-OMEGA, m=0.0)
    for name in ("Rz_in", "Rx_in", "Ry_in", "Rz_out", "T_in"):
        np.testing.assert_allclose(getattr(backward, name), -getattr(forward, name), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(backward.P_friction, forward.P_friction, rtol=1e-9)


def test_reversal_keeps_the_plungers_inertia_forces():
    """With plunger mass the inertia terms (omega^2) keep their sign when torque and rotation
    reverse: at 0.2 kg, 25 deg, 500 N.m, mu = 0.05 the reversed run differs from the mirrored one
    by up to 21.6 N on Rx_in and 10.4 N on Rz_in; without friction the sum of both runs is twice
    the unloaded run's reactions (the load's part flips, the inertia's stays)."""
    beta = math.radians(25.0)
    forward, backward = frictional(beta, 500.0), frictional(beta, -500.0, omega=-OMEGA)
    assert np.abs(forward.Rx_in + backward.Rx_in).max() == pytest.approx(21.58, abs=0.01)
    assert np.abs(forward.Rz_in + backward.Rz_in).max() == pytest.approx(10.40, abs=0.01)
    forward, backward, unloaded = (frictional(beta, T, 0.0, omega=w) for T, w in ((500.0, OMEGA), (-500.0, -OMEGA),
                                                                                   (0.0, OMEGA)))
    for name in ("Rx_in", "Ry_in", "Mx_in", "My_in", "Rx_out", "Ry_out", "Rz_out", "T_in"):
        total = getattr(forward, name) + getattr(backward, name)
        np.testing.assert_allclose(total, 2 * getattr(unloaded, name), rtol=0, atol=1e-9, err_msg=name)
    assert np.abs(unloaded.Rx_in).max() > 5.0  # the inertia's part is not small


def test_generated_axial_force_through_the_fmu(tripod_fmu):
    """mu = 0.05, beta = 25 deg, 500 N.m, 2000 rpm: the closing numbers of the friction issue,
    and the power balance through the FMU."""
    period = 2 * math.pi / OMEGA
    result = simulate(tripod_fmu, period, period / 240, inputs={"omega_in": OMEGA, "beta": math.radians(25.0),
                                                                "T_load": 500.0},
                      start_values={"kinematics": 1, "mu": MU})[:-1]
    force = -result["Rz_in"]
    spectrum = 2 * np.abs(np.fft.rfft(force)) / len(force)
    assert np.argmax(spectrum[1:]) + 1 == 3
    assert spectrum[3] == pytest.approx(328.77, abs=0.01)
    mean_efficiency = np.mean(500.0 * result["omega_spin"]) / np.mean(500.0 * result["omega_spin"] + result["P_friction"])
    assert mean_efficiency == pytest.approx(0.97780, abs=1e-5)
    mech = Mechanism(math.radians(25.0))
    np.testing.assert_allclose(result["phi_in"], PHI, atol=1e-9)
    residual = result["T_in"] * OMEGA - 500.0 * result["omega_spin"] - mech.kinetic_energy_rate(OMEGA, 0.0)
    np.testing.assert_allclose(residual, result["P_friction"], rtol=0, atol=1e-6 * 500.0 * OMEGA)
    assert result["P_friction"].min() > 0 and np.all(result["efficiency"] < 1.0)


def test_efficiency_in_drive_coast_and_between(tripod_fmu):
    """efficiency = delivered / supplied power, whichever shaft drives (outputs.efficiency), through
    the FMU at mu = 0.05, 25 deg, 2000 rpm while T_load sweeps from 500 to -500 N.m over two turns:
    drive P_out / (P_out + P_friction), coast (P_out + P_friction) / P_out (the issue's coast at
    -500 N.m gave 1.019-1.022 with the drive formula), 0 while both shafts feed the friction."""
    period = 2 * math.pi / OMEGA
    result = simulate(tripod_fmu, 2 * period, period / 240,
                      inputs={"omega_in": OMEGA, "beta": math.radians(25.0),
                              "T_load": lambda t: 500.0 - 500.0 * t / period},
                      start_values={"kinematics": 1, "mu": MU})
    load = 500.0 - 500.0 * np.maximum(result["time"] - period / 240, 0.0) / period  # held over each step
    load[0] = 500.0
    out, loss, ratio = load * result["omega_spin"], result["P_friction"], result["efficiency"]
    drive, coast = out > 0, out + loss < 0
    assert drive.sum() > 100 and coast.sum() > 100 and (~drive & ~coast).sum() > 0
    np.testing.assert_allclose(ratio[drive], out[drive] / (out[drive] + loss[drive]), rtol=1e-12)
    np.testing.assert_allclose(ratio[coast], (out[coast] + loss[coast]) / out[coast], rtol=1e-12)
    assert np.all(ratio[~drive & ~coast] == 0.0)
    assert np.all((ratio >= 0.0) & (ratio < 1.0))
    # coast at -500 N.m, means over a turn: T_load omega_spin = -104.72 kW supplied, T_in omega =
    # -102.53 kW delivered (the issue: -104.8 and -102.7 kW); the efficiency is their ratio (the
    # plungers' kinetic energy averages out over the turn)
    coast_run = simulate(tripod_fmu, period, period / 240, inputs={"omega_in": OMEGA, "beta": math.radians(25.0),
                                                                   "T_load": -500.0},
                         start_values={"kinematics": 1, "mu": MU})[:-1]
    supplied, delivered = np.mean(-500.0 * coast_run["omega_spin"]), np.mean(coast_run["T_in"]) * OMEGA
    assert (supplied / 1e3, delivered / 1e3) == pytest.approx((-104.72, -102.53), abs=0.01)
    assert np.mean(coast_run["efficiency"]) == pytest.approx(delivered / supplied, abs=2e-4)


def test_efficiency_is_continuous_through_the_change_of_direction():
    """Near zero power: drive falls to 0 at P_out = 0, stays 0 down to P_out = -P_friction, and
    coast rises from 0 there; 1 only where no power flows at all; never NaN or infinite."""
    loss = 2000.0
    power = np.linspace(-3 * loss, 3 * loss, 60001)
    values = efficiency(power, np.full_like(power, loss))
    assert np.all(np.isfinite(values)) and np.all((values >= 0.0) & (values <= 1.0))
    assert np.abs(np.diff(values)).max() < 2e-3  # grid step 0.1 W: slope at most 1 / loss
    assert np.all(values[(power <= 0.0) & (power >= -loss)] == 0.0)
    assert [efficiency(p, q) for p, q in ((0.0, 0.0), (0.0, loss), (-loss, loss), (-2 * loss, loss), (loss, loss))] == [
        1.0, 0.0, 0.0, 0.5, 0.5]


def test_friction_needs_the_exact_kinematics(tripod_fmu):
    with pytest.raises(StepRefused) as refused:
        simulate(tripod_fmu, 0.01, 1e-3, start_values={"kinematics": 0, "mu": 0.1})
    assert any("exact kinematics" in message for message in refused.value.messages)
    with pytest.raises(StepRefused) as refused:
        simulate(tripod_fmu, 0.01, 1e-3, start_values={"kinematics": 1, "mu": 0.1, "v_slip": 0.0})
    assert any("v_slip" in message for message in refused.value.messages)
