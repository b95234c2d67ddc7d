"""VehicleDriveline: the stepping against solve_ivp of the equations written again here, and the
equations closed by ideal joints (T_in = T_load, phi_out = the side gear's angle) against analytic
limits: steady acceleration on a grade, coast-down, torsional frequencies, the open differential's
split on equal and on split friction.

The closed loop is one monolithic ODE of the core's :func:`dynamics.rates` with the side gears'
angles added, solved by scipy's Radau at tight tolerances.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from driveline.vehicle import compact_car as car
from driveline.vehicle import dynamics
from driveline.vehicle.dynamics import Drive, Joints
from driveline.vehicle.model import VehicleDrivelineModel
from driveline.vehicle.spec import SPEC

from support import model_checks

G = 9.80665
DEFAULTS = {v.name: v.start for v in SPEC.of("parameter")}


def drive(**changes: float) -> Drive:
    return Drive(**{name: changes.get(name, DEFAULTS[name]) for name in Drive._fields})


def closed_loop(d: Drive, T_motor: float, v_start: float, t_end: float, points: int = 2):
    """The drive with ideal joints as one ODE: state plus both side gears' angles; returns the
    solution and a function giving rates and halfshaft torques at a row of it."""

    def joints(y: np.ndarray) -> Joints:
        case, diff = y[dynamics.CASE], y[dynamics.DIFF]
        free = Joints(0.0, 0.0, y[10], y[11], case + diff, case - diff)
        T_left, T_right = dynamics.halfshaft_torques(d, tuple(y[:10]), free, 0.0)
        return free._replace(T_in_left=T_left, T_in_right=T_right)

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        j = joints(y)
        return [*dynamics.rates(d, tuple(y[:10]), T_motor, j, 0.0), j.omega_out_left, j.omega_out_right]

    y0 = [*dynamics.start_state(d, v_start, Joints(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)), 0.0, 0.0]
    solution = solve_ivp(rhs, (0.0, t_end), y0, method="LSODA", rtol=1e-10, atol=1e-10,
                         t_eval=np.linspace(0.0, t_end, points))
    assert solution.success
    return solution, lambda y: (rhs(0.0, y), joints(y))


def test_steady_acceleration_on_a_grade_and_the_equal_split():
    """No drag, a 5 deg grade, 150 N.m: after the torsional transients the acceleration a solves
    (m_eq + (1 + kappa) (J_case + 2 J_wheel) / r^2) a = ratio T / r - f m g cos - m g sin, the steady
    slip kappa (0.025) letting the driven parts turn (1 + kappa) times as fast as the car over r, with
    kappa from the tyre law at the force each front tyre transmits (fixed point). Tolerance 1e-6: the
    transients decayed (the slip's, the slowest, at 1.4e-5 of a at 4 s, 2e-9 at 6 s). Both halfshafts carry
    the same torque although their stiffnesses differ by 56 %, (ratio T - J_case d(omega_case)/dt) / 2."""
    grade, T = math.radians(5.0), 150.0
    d = drive(c_drag=0.0, grade=grade)
    solution, at = closed_loop(d, T, 0.0, 6.0)
    y = solution.y[:, -1]
    rate, joints = at(y)
    r = d.r_wheel
    rotating = (d.ratio**2 * d.J_motor + d.J_diff + 2.0 * d.J_side + 2.0 * d.J_wheel) / r**2
    force = d.ratio * T / r - d.f_roll * d.m_vehicle * G * math.cos(grade) - d.m_vehicle * G * math.sin(grade)
    m_eq = d.m_vehicle + 2.0 * d.J_wheel / r**2
    limit = d.mu_road_left * d.m_vehicle * G * math.cos(grade) * d.front_share / 2.0
    kappa = 0.0
    for _ in range(50):
        expected = force / (m_eq + (1.0 + kappa) * rotating)
        tyre = (m_eq * expected + d.ratio * T / r - force) / 2.0
        kappa = limit * math.atanh(tyre / limit) / d.C_slip
    assert rate[dynamics.SPEED] == pytest.approx(expected, rel=1e-6)
    each = (d.ratio * T - dynamics.case_inertia(d) * rate[dynamics.CASE]) / 2.0
    assert joints.T_in_left == pytest.approx(each, rel=1e-7)
    assert joints.T_in_right == pytest.approx(each, rel=1e-7)


def test_coast_down_against_the_closed_form():
    """No motor torque from 30 m/s: m_total dv/dt = -(F_r + c v^2) gives
    v(t) = sqrt(F_r / c) tan(atan(v0 sqrt(c / F_r)) - sqrt(F_r c) t / m_total), the driveline's
    inertia in m_total. Tolerance 1e-5: the tyres' slip while they decelerate the rotating parts,
    kappa = 2e-4, changes the rotating share (3 %) of m_total by that much, 6e-6."""
    d = drive()
    v0, t_end = 30.0, 40.0
    solution, _ = closed_loop(d, 0.0, v0, t_end, points=5)
    r = d.r_wheel
    rotating = 2.0 * d.J_wheel + d.ratio**2 * d.J_motor + d.J_diff + 2.0 * d.J_side + 2.0 * d.J_wheel
    m_total = d.m_vehicle + rotating / r**2
    F_r, c = d.f_roll * d.m_vehicle * G, 0.5 * d.rho_air * d.c_drag * d.A_front
    t = solution.t
    expected = math.sqrt(F_r / c) * np.tan(math.atan(v0 * math.sqrt(c / F_r)) - math.sqrt(F_r * c) * t / m_total)
    np.testing.assert_allclose(solution.y[dynamics.SPEED], expected, rtol=1e-5)
    assert expected[-1] < 0.7 * v0  # long enough to test drag and rolling resistance


def _frequencies(d: Drive) -> np.ndarray:
    """Undamped natural frequencies [rad/s] of the closed loop at standstill: the imaginary parts of
    the eigenvalues of its Jacobian (central differences; the equations are linear there)."""
    _, at = closed_loop(d, 0.0, 0.0, 1e-6)
    y0 = np.zeros(12)
    columns = []
    for i in range(12):
        e = np.zeros(12)
        e[i] = 1e-6
        columns.append((np.array(at(y0 + e)[0]) - np.array(at(y0 - e)[0])) / 2e-6)
    eigenvalues = np.linalg.eigvals(np.array(columns).T)
    return np.unique(np.round(np.abs(eigenvalues.imag[eigenvalues.imag > 1.0]), 9))


def test_side_gear_modes_against_the_two_by_two_formula():
    """Wheels held (J_wheel huge), no damping: the common mode J_case and the differential's mode 2 J_side
    against the halfshafts, M = diag(J_case, 2 J_side), K = [[kL + kR, kL - kR], [kL - kR, kL + kR]];
    with equal shafts the differential's mode is sqrt(k / J_side) and the common one sqrt(2 k / J_case)."""
    d = drive(J_wheel=1e9, c_left=0.0, c_right=0.0)
    kL, kR = d.k_left, d.k_right
    M = np.diag([dynamics.case_inertia(d), 2.0 * d.J_side])
    K = np.array([[kL + kR, kL - kR], [kL - kR, kL + kR]])
    expected = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    found = _frequencies(d)
    np.testing.assert_allclose(found[-2:], expected, rtol=1e-6)
    equal = drive(J_wheel=1e9, c_left=0.0, c_right=0.0, k_right=kL)
    np.testing.assert_allclose(_frequencies(equal)[-2:],
                               [math.sqrt(2.0 * kL / dynamics.case_inertia(equal)), math.sqrt(kL / d.J_side)],
                               rtol=1e-6)


def test_wheel_mode_on_halfshaft_and_tyre():
    """Side gears held (their inertia huge), the car held (its mass huge), v_low tiny: each wheel
    swings on its halfshaft and the tyre's torsional stiffness C_slip r^2 / sigma_slip,
    omega = sqrt((k + C_slip r^2 / sigma_slip) / J_wheel)."""
    d = drive(J_motor=1e9, J_diff=1e9, J_side=1e9, m_vehicle=1e12, c_left=0.0, c_right=0.0, v_low=1e-12,
              f_roll=0.0)
    tyre = d.C_slip * d.r_wheel**2 / d.sigma_slip
    expected = sorted(math.sqrt((k + tyre) / d.J_wheel) for k in (d.k_left, d.k_right))
    np.testing.assert_allclose(_frequencies(d)[-2:], expected, rtol=1e-6)


def test_split_friction_limits_both_sides_to_the_low_one():
    """mu 0.1 under the left wheel, 1.0 under the right, 150 N.m: the left wheel spins up at the friction
    limit and the open differential gives the right side the same torque but for the side gears'
    inertia. The linear equations of that state (V1, V2, V4 per side, V7 with the left force at
    mu F_z and the right wheel rolling with the car) solved here give a, both torques and the left
    wheel's acceleration; tolerance 2e-3 for the right tyre's slip (0.3 %) the rolling assumption
    leaves out."""
    d = drive(mu_road_left=0.1, c_drag=0.0)
    T = 150.0
    solution, at = closed_loop(d, T, 0.0, 3.0)
    y = solution.y[:, -1]
    rate, joints = at(y)
    r, Jw, Jc, Js = d.r_wheel, d.J_wheel, dynamics.case_inertia(d), d.J_side
    F_low = 0.1 * dynamics.wheel_load(d)
    F_road = d.f_roll * d.m_vehicle * G
    # unknowns: T_L, T_R, left wheel acceleration wL, car acceleration a (right wheel a / r), right force F_R
    A = np.array([
        [1.0, 1.0, Jc / 2.0, Jc / (2.0 * r), 0.0],  # V1: J_case (wL + wR) / 2 = ratio T - T_L - T_R
        [1.0, -1.0, Js, -Js / r, 0.0],  # V2: 2 J_side (wL - wR) / 2 = T_R - T_L
        [1.0, 0.0, -Jw, 0.0, 0.0],  # V4 left: J_w wL = T_L - r F_low
        [0.0, 1.0, 0.0, -Jw / r, -r],  # V4 right: J_w a / r = T_R - r F_R
        [0.0, 0.0, 0.0, dynamics.equivalent_mass(d), -1.0],  # V7
    ])
    b = np.array([d.ratio * T, 0.0, r * F_low, 0.0, F_low - F_road])
    T_L, T_R, wL, a, F_R = np.linalg.solve(A, b)
    assert rate[dynamics.SPEED] == pytest.approx(a, rel=2e-3)
    assert joints.T_in_left == pytest.approx(T_L, rel=2e-3)
    assert joints.T_in_right == pytest.approx(T_R, rel=2e-3)
    assert rate[dynamics.WHEEL_LEFT] == pytest.approx(wL, rel=2e-3)
    assert y[dynamics.WHEEL_LEFT] > 3.0 * y[dynamics.WHEEL_RIGHT]  # the left wheel spins


def _independent_rates(p: dict[str, float], u: dict[str, float], tau: float, y: np.ndarray) -> np.ndarray:
    """The equations once more, from the doc page's V1-V8, in vector form."""
    wc, wd, pL, wL, pR, wR, v, _x, sL, sR = y
    Jc = p["ratio"] ** 2 * p["J_motor"] + p["J_diff"] + 2 * p["J_side"]
    wheel = np.array([wL, wR])
    angle = np.array([pL, pR])
    out_speed = np.array([u["omega_out_left"], u["omega_out_right"]])
    out_angle = np.array([u["phi_out_left"], u["phi_out_right"]]) + out_speed * tau
    stiffness, damping = np.array([p["k_left"], p["k_right"]]), np.array([p["c_left"], p["c_right"]])
    torque = stiffness * (out_angle - angle) + damping * (out_speed - wheel)
    load = p["m_vehicle"] * G * np.cos(p["grade"]) * p["front_share"] / 2
    mu = np.array([p["mu_road_left"], p["mu_road_right"]])
    slip = np.array([sL, sR])
    force = mu * load * np.tanh(p["C_slip"] * slip / (mu * load))
    road = (p["f_roll"] * p["m_vehicle"] * G * np.cos(p["grade"]) * np.tanh(v / p["v_low"])
            + 0.5 * p["rho_air"] * p["c_drag"] * p["A_front"] * v * abs(v) + p["m_vehicle"] * G * np.sin(p["grade"]))
    m_eq = p["m_vehicle"] + 2 * p["J_wheel"] / p["r_wheel"] ** 2
    d_wheel = (torque - p["r_wheel"] * force) / p["J_wheel"]
    d_slip = (p["r_wheel"] * wheel - v - (abs(v) + p["v_low"]) * slip) / p["sigma_slip"]
    return np.array([(p["ratio"] * u["T_motor"] - u["T_in_left"] - u["T_in_right"]) / Jc,
                     (u["T_in_right"] - u["T_in_left"]) / (2 * p["J_side"]),
                     wL, d_wheel[0], wR, d_wheel[1], (force.sum() - road) / m_eq, v, d_slip[0], d_slip[1]])


@pytest.mark.parametrize("step", [1e-4, 2e-3])
def test_stepping_against_solve_ivp_of_the_equations_written_again(step):
    """Random inputs held over each communication step (the joints' angles moving at their speeds),
    on a 3 deg grade at mu 0.6: the model's Runge-Kutta steps against DOP853 (rtol 1e-12) of the
    equations written here independently, the whole state over 150 steps. Tolerance: 5e-5 of each
    variable's largest magnitude, the Runge-Kutta error at lambda h_int <= 0.25 (measured 2.6e-5 at
    2 ms, in the slip, the fastest variable). The side gears four times the default's inertia lower
    the differential's internal mode to 337 rad/s, where 2 ms is a step the drive takes (below
    dynamics.divergence_step_limit, 2.08 ms)."""
    rng = np.random.default_rng(29)
    model = model_checks.started(VehicleDrivelineModel, grade=math.radians(3.0), mu_road_left=0.6,
                                 mu_road_right=0.6, v_start=4.0, J_side=4 * car.SIDE_INERTIA)
    p = {name: getattr(model, name) for name in Drive._fields}
    y = np.array(model._state)
    t, rows, reference = 0.0, [], []
    while t < 150 * step - 1e-12:
        wheel = y[[dynamics.PHI_WHEEL_LEFT, dynamics.PHI_WHEEL_RIGHT]]
        u = {"T_motor": rng.uniform(-100, 250), "T_in_left": rng.uniform(0, 900), "T_in_right": rng.uniform(0, 900),
             "phi_out_left": wheel[0] + rng.uniform(-0.1, 0.1), "phi_out_right": wheel[1] + rng.uniform(-0.1, 0.1),
             "omega_out_left": rng.uniform(10, 20), "omega_out_right": rng.uniform(10, 20)}
        for name, value in u.items():  # the right joint's quantities in its own frame, turning the other way
            setattr(model, name, -value if name.endswith("_right") else value)
        assert model.step(t, step) == []
        y = solve_ivp(lambda tau, s: _independent_rates(p, u, tau, s), (0.0, step), y, method="DOP853",
                      rtol=1e-12, atol=1e-12).y[:, -1]
        rows.append(model._state)
        reference.append(y)
        t += step
    rows, reference = np.array(rows), np.array(reference)
    worst = (np.abs(rows - reference) / np.abs(reference).max(axis=0)).max()
    assert worst <= 5e-5


def test_reaction_torque_is_the_momentum_balance():
    """T_reaction + T_L + T_R = -(ratio J_motor + J_diff + 2 J_side) d(omega_case)/dt, with
    d(omega_case)/dt from V1 (T_R = -T_in_right: the right joint's frame turns the other way): checked
    on the model's outputs after a step with torques in."""
    model = model_checks.started(VehicleDrivelineModel, T_motor=200.0, T_in_left=500.0, T_in_right=-700.0)
    assert model.step(0.0, 1e-3) == []
    d = model._drive()
    case_rate = (d.ratio * 200.0 - 1200.0) / dynamics.case_inertia(d)
    momentum = d.ratio * d.J_motor + d.J_diff + 2 * d.J_side
    assert model.T_reaction == pytest.approx(-1200.0 - momentum * case_rate, rel=1e-14)
    # the right joint's frame turns the other way: its acceleration and torque change sign
    assert model.alpha_in_left + model.alpha_in_right == pytest.approx((700.0 - 500.0) / d.J_side, rel=1e-12)


def test_a_step_needing_unbounded_work_is_refused():
    """Halfshafts without stiffness (no differential mode, no step limit): the tyres' modes bound the work."""
    model = model_checks.started(VehicleDrivelineModel, k_left=0.0, k_right=0.0)
    errors = model.step(0.0, 1e4)
    assert len(errors) == 1 and "more than 10000 internal steps" in errors[0]
    assert model.step(0.0, 1e-3) == []


def test_the_step_limits_follow_the_differential_mode():
    """omega h <= min(0.28, 1.5 zeta) (Jacobi) and omega h <= 0.7 (any order) on the faster side: at the
    defaults left 674.2 rad/s, zeta 0.232 (sqrt(k_left / J_side), c_left / (2 sqrt(k_left J_side))); a step
    between the two is taken with a notice, a longer one refused; halfshafts without stiffness have no limit."""
    model = model_checks.started(VehicleDrivelineModel)
    drive = model._drive()
    omega = math.sqrt(car.TORSIONAL_STIFFNESS_LEFT / car.SIDE_INERTIA)
    zeta = car.TORSIONAL_DAMPING / (2.0 * math.sqrt(car.TORSIONAL_STIFFNESS_LEFT * car.SIDE_INERTIA))
    assert dynamics.jacobi_step_limit(drive) == pytest.approx(min(0.28, 1.5 * zeta) / omega, rel=1e-14)
    assert dynamics.divergence_step_limit(drive) == pytest.approx(0.7 / omega, rel=1e-14)
    assert model.step_notice(4e-4) is None and model.step_size_errors(1.03e-3) == []
    assert "communication steps above 0.000415 s" in model.step_notice(5e-4)
    errors = model.step(0.0, 1.05e-3)
    assert errors == ["communication step 0.00105 s is above 0.00104 s, where the differential's internal mode "
                      "(left 674.2 rad/s, damping ratio 0.232; right 540.5 rad/s, damping ratio 0.29) diverges "
                      "coupled to the joints in any master's order (omega h > 0.7; a Jacobi master needs 0.000415 s "
                      "or less): take a shorter step"]
    assert model.step(0.0, 1.03e-3) == []
    free = model_checks.started(VehicleDrivelineModel, k_left=0.0, k_right=0.0)._drive()
    assert dynamics.jacobi_step_limit(free) == dynamics.divergence_step_limit(free) == math.inf


def test_a_start_speed_beyond_any_road_car_is_refused_as_a_parameter():
    """1e300 m/s made the drag v |v| and a_x -inf at initialisation (found by the random runs): the bound
    of v_start refuses it, and the fastest start allowed gives finite outputs."""
    fast = VehicleDrivelineModel()
    fast.v_start = 1e300
    assert fast.initialize(0.0) == ["parameter v_start = 1e+300 m/s is above its maximum 150.0 m/s"]
    fastest = VehicleDrivelineModel()
    fastest.v_start = -150.0
    assert fastest.initialize(0.0) == [] and math.isfinite(fastest.a_x) and fastest.a_x > 0.0
