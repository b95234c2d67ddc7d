"""The tripod joint in a moving housing (docs/tripod_coupling.md, "The moving housing", eqs M1-M8): the bend
plane turned by psi about Z' with its rates, and the spider plunging at plunge_dot, against independent
computations:

* a constant psi is today's joint at ``phi_in - psi``, its output angle and the input bearing's vectors
  turned by psi (closed form of M1, M2, M8);
* the plungers' axial speeds and accelerations and the output angle's rate against central differences of
  the pose along a motion phi_in(t), psi(t), beta(t), plunge(t) (M3-M5, M7);
* the power balance of the massless, frictionless joint whose output bearing turns with the bend plane:
  ``T_in omega_in + R_out . Sdot = T_load omega_spin`` (M6);
* the groove friction of a straight joint plunging in its housing against a hand computation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from driveline.tripod.outputs import coupling_outputs
from driveline.tripod.reactions import mechanism
from driveline.tripod.rollers import _skewed_slips, roller_reactions
from driveline.tripod.spec import CLOSED_FORM, DOUBLE_ROLLER, EXACT, PLAIN_TRIPOD, SINGLE_ROLLER

R, L, M = 0.026, 0.7, 0.2
ROLLERS = {"mu_roll": 0.0025, "roller_radius": 0.0165}
JOINT = {"beta": 0.35, "omega_in": 60.0, "T_load": 120.0, "r": R, "l": L, "m": M, "alpha_in": 15.0,
         "beta_dot": 0.4, "beta_ddot": 2.0, **ROLLERS}
VECTORS = (("Rx_in", "Ry_in"), ("Mx_in", "My_in"))
# every other output is a scalar or in the output shaft's own frame, the same with the shifted phi_in
SAME = ("omega_out", "omega_spin", "T_in", "F_pin", "rho", "theta", "a_plunger_sum", "Rz_out",
        "Rx_out", "Ry_out", "Rz_in", "P_friction", "efficiency", "F_arm1", "F_arm2", "F_arm3", "F_plunger1",
        "F_plunger2", "F_plunger3")
MODES = [(CLOSED_FORM, PLAIN_TRIPOD, 0.0, 0), (CLOSED_FORM, PLAIN_TRIPOD, 0.0, 1), (EXACT, PLAIN_TRIPOD, 0.05, 0),
         (EXACT, PLAIN_TRIPOD, 0.05, 1), (EXACT, SINGLE_ROLLER, 0.05, 0), (EXACT, DOUBLE_ROLLER, 0.05, 0)]


def _outputs(**values) -> dict:
    return coupling_outputs(**{**JOINT, **values})[0]


@pytest.mark.parametrize("kinematics, tripod_type, mu, seed", MODES)
@pytest.mark.parametrize("psi", [0.4, -2.5, 7.0])
def test_a_constant_bend_plane_is_the_joint_at_the_shifted_input_angle(kinematics, tripod_type, mu, seed, psi):
    """(M1, M2, M8) with psi_dot = psi_ddot = 0: the joint turned by psi. The shifted joint gets the very
    float phi_in - psi, so the scalars agree bit for bit; phi_out and delta_phi carry the rounding of adding
    psi back and of subtracting phi_in, and the turned vectors that of a 2x2 rotation (2 ulp of their size)."""
    phi_in, common = 0.9, {"kinematics": kinematics, "tripod_type": tripod_type, "mu": mu, "seed_reactions": seed}
    moved = _outputs(phi_in=phi_in, psi=psi, **common)
    today = _outputs(phi_in=phi_in - psi, **common)
    assert {name: moved[name] for name in SAME} == {name: today[name] for name in SAME}
    rounding = 4.5e-16 * (abs(phi_in) + abs(psi) + abs(moved["phi_out"]))  # two additions, half an ulp each
    assert moved["phi_out"] == pytest.approx(today["phi_out"] + psi, rel=0, abs=rounding)
    assert moved["delta_phi"] == pytest.approx(today["delta_phi"], rel=0, abs=rounding)
    c, s = math.cos(psi), math.sin(psi)
    for x, y in VECTORS:
        size = math.hypot(today[x], today[y])
        assert moved[x] == pytest.approx(c * today[x] - s * today[y], rel=0, abs=5e-16 * size)
        assert moved[y] == pytest.approx(s * today[x] + c * today[y], rel=0, abs=5e-16 * size)


def _motion(t: float) -> dict:
    """A joint whose input turns, bend plane turns, bend changes and spider plunges, all with accelerations."""
    return {"phi_in": 0.9 + 60.0 * t + 7.5 * t * t, "psi": 0.3 + 6.0 * t - 20.0 * t * t,
            "beta": 0.35 + 0.4 * t + 1.0 * t * t, "plunge": 0.002 + 0.03 * t}


def _rates(t: float) -> dict:
    return {"omega_in": 60.0 + 15.0 * t, "alpha_in": 15.0, "psi_dot": 6.0 - 40.0 * t, "psi_ddot": -40.0,
            "beta_dot": 0.4 + 2.0 * t, "beta_ddot": 2.0, "plunge_dot": 0.03}


def _pose(t: float) -> tuple[np.ndarray, float, object]:
    """The plungers' heights along Z' in the housing (the pose of M1 plus the plunge), phi_out, the state."""
    at, rates = _motion(t), _rates(t)
    values, solution = coupling_outputs(at["phi_in"], at["beta"], rates["omega_in"], 0.0, R, L, M, EXACT,
                                        psi=at["psi"])
    state = mechanism(at["phi_in"] - at["psi"], at["beta"], rates["omega_in"], rates["alpha_in"], 0.0, R, L, M,
                      solution.x, solution.y, rates["beta_dot"], rates["beta_ddot"], rates["psi_dot"],
                      rates["psi_ddot"], rates["plunge_dot"])
    heights = np.array([arm[2] for arm in state.arms]) + at["plunge"]
    return heights, values["phi_out"], state


def test_the_plungers_speeds_and_accelerations_are_the_rates_of_their_heights_in_the_housing():
    """(M3-M5): zdot_j (the sliding speed in the housing, plunge included) and zddot_j against central
    differences of the heights over +-h = 1e-5 s: truncation h^2 z'''/6 ~ 4e-8 m/s and h^2 z''''/12 ~
    3e-5 m/s^2 (z''' ~ r tan(beta) omega^3 ~ 2e3 m/s^3, one omega more for z''''), rounding of the second
    difference 4 eps |z| / h^2 ~ 1e-7 m/s^2."""
    h = 1e-5
    (before, _, _), (now, _, state), (after, _, _) = (_pose(t) for t in (-h, 0.0, h))
    zdot = np.array([slide[0] for slide in state.slides])
    np.testing.assert_allclose(zdot, (after - before) / (2 * h), rtol=0, atol=1e-7)
    np.testing.assert_allclose(state.zddot, (after - 2 * now + before) / h**2, rtol=0, atol=2e-4)
    assert np.abs(zdot).max() > 0.05 and np.abs(state.zddot).max() > 10.0  # the checks are not vacuous


def test_the_output_speed_is_the_output_angles_rate_while_the_bend_stays():
    """(M7): omega_out = psi_dot + (omega_in - psi_dot) d(phi_out)/d(phi_in) is d(phi_out)/dt at constant
    beta, here with the bend plane turning at 6 rad/s: central differences over +-1e-5 s (truncation
    ~1e-10 rad/s, rounding 1e-16 / 1e-5)."""
    h, phi_in, psi = 1e-5, 0.9, 0.3

    def angle(t: float) -> float:
        return _outputs(phi_in=phi_in + 60.0 * t, psi=psi + 6.0 * t, kinematics=EXACT)["phi_out"]

    speed = _outputs(phi_in=phi_in, psi=psi, psi_dot=6.0, kinematics=EXACT)["omega_out"]
    assert speed == pytest.approx((angle(h) - angle(-h)) / (2 * h), rel=0, abs=1e-8)
    # the turning plane's share, psi_dot (1 - d(phi_out)/d(phi_in)), 8.7e-4 rad/s here
    assert abs(speed - _outputs(phi_in=phi_in, psi=psi, kinematics=EXACT)["omega_out"]) > 5e-4


@pytest.mark.parametrize("psi_dot, beta_dot", [(7.0, 0.0), (7.0, 0.4), (-3.0, -0.6)])
def test_the_power_balance_holds_with_a_turning_bend_plane(psi_dot, beta_dot):
    """(M6): massless plungers, no friction: the input torque's power and the output bearing's force on
    the moving bearing centre S are the load's power, T_in omega_in + R_out . Sdot = T_load omega_spin, with
    Sdot = l beta_dot de_out/dbeta + psi_dot e_z x S in the bend plane's frame (rounding: 1e-12 of the
    7.2 kW the input gives)."""
    beta, omega, T_load = 0.35, 60.0, 120.0
    common = {"phi_in": 0.9, "beta": beta, "omega_in": omega, "T_load": T_load, "m": 0.0, "kinematics": EXACT,
              "beta_dot": beta_dot, "beta_ddot": 1.0, "psi": 0.3, "psi_dot": psi_dot, "psi_ddot": 4.0}
    values, solution = coupling_outputs(**{**JOINT, **common})
    state = mechanism(0.9 - 0.3, beta, omega, JOINT["alpha_in"], T_load, R, L, 0.0, solution.x, solution.y,
                      beta_dot, 1.0, psi_dot, 4.0)
    E1, E2, U = (np.array(v) for v in (state.E1, state.E2, state.U))
    force = values["Rx_out"] * E1 + values["Ry_out"] * E2 + values["Rz_out"] * U
    c, s = math.cos(beta), math.sin(beta)
    S_dot = np.array([-L * c * beta_dot, -L * s * psi_dot, -L * s * beta_dot])
    balance = values["T_in"] * omega + force @ S_dot - T_load * values["omega_spin"]
    assert abs(balance) <= 1e-12 * abs(values["T_in"] * omega)
    assert abs(force @ S_dot) > 1.0  # the moving bearing's power takes part


@pytest.mark.parametrize("omega_in, psi_dot", [(0.0, 0.0), (80.0, 0.0), (80.0, 25.0)])
@pytest.mark.parametrize("plunge_dot", [0.02, -0.0004])
def test_the_groove_friction_of_a_straight_joint_plunging_in_its_housing(omega_in, psi_dot, plunge_dot):
    """Hand computation: at beta = 0 the plungers do not slide kinematically and the ball does not slide
    on its arm, so each groove's friction is -mu |N_j| s(plunge_dot / v_slip) with s(u) = u / sqrt(1 + u^2)
    and the groove's horizontal force on the plunger |N_j| = sqrt((T_load / 3r)^2 + (m omega_in^2 r)^2)
    (the arm's force about Z' and the plunger's centripetal force at the input speed in the housing, what a
    turning bend plane does not change): Rz_in = 3 times that, P_friction = -Rz_in plunge_dot."""
    mu, v_slip, T_load = 0.08, 1e-3, 150.0
    values = _outputs(phi_in=0.7, beta=0.0, omega_in=omega_in, alpha_in=0.0, T_load=T_load, beta_dot=0.0,
                      beta_ddot=0.0, kinematics=EXACT, mu=mu, v_slip=v_slip, psi=1.1, psi_dot=psi_dot,
                      plunge_dot=plunge_dot)
    normal = math.hypot(T_load / (3 * R), M * omega_in**2 * R)
    groove = -mu * normal * plunge_dot / v_slip / math.sqrt(1.0 + (plunge_dot / v_slip) ** 2)
    assert values["Rz_in"] == pytest.approx(3 * groove, rel=1e-13)
    assert values["P_friction"] == pytest.approx(-3 * groove * plunge_dot, rel=1e-13)
    assert values["T_in"] == pytest.approx(T_load, rel=1e-13)


@pytest.mark.parametrize("tripod_type", [SINGLE_ROLLER, DOUBLE_ROLLER])
def test_the_rollers_roll_and_skew_on_the_speed_in_the_housing(tripod_type):
    """The rollers' track contacts take each roller's axial speed in the housing, its speed on the input
    shaft plus the plunge rate: the double roller rolls at that speed (R11); the single roller's rolling
    and skew speeds are R8's at its contact normal with that speed."""
    phi, beta, omega, plunge_dot = 0.6, 0.35, 60.0, 0.03
    _, solution = coupling_outputs(phi, beta, omega, 120.0, R, L, M, EXACT)
    still, plunging = (mechanism(phi, beta, omega, 15.0, 120.0, R, L, M, solution.x, solution.y, 0.4, 2.0, 5.0,
                                 10.0, rate) for rate in (0.0, plunge_dot))
    speed = np.array([slide[0] for slide in still.slides]) + plunge_dot
    contacts = roller_reactions(plunging, omega, 120.0, M, tripod_type, 0.05, 0.0025, 1e-3, 0.0165, 0.0115)[1]
    if tripod_type == DOUBLE_ROLLER:
        np.testing.assert_allclose(contacts.v_roll, speed, rtol=0, atol=1e-15)
        return
    arms = np.array([a[3:6] for a in still.arms])
    axis = arms / np.linalg.norm(arms, axis=1)[:, None]
    spin = np.array(still.Omega) - omega * np.array([0.0, 0.0, 1.0])
    _, (v_roll, v_skew) = _skewed_slips(contacts.normal, axis, speed, spin, 0.0165)
    np.testing.assert_allclose(contacts.v_roll, v_roll, rtol=0, atol=1e-15)
    np.testing.assert_allclose(contacts.v_skew, v_skew, rtol=0, atol=1e-15)
    assert np.all(np.abs(speed) > 50 * 1e-3)  # every contact slips well beyond v_slip
