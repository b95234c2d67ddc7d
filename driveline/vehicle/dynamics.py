"""Equations of motion of the front-wheel drive between the motor and the road, and their integration
over one communication step (docs/vehicle_driveline.md, eqs V1-V9).

Degrees of freedom: the differential case (speed ``omega_case``; the motor turns ``ratio`` times as
fast), the differential's internal one (``omega_diff``: the left side gear turns at
``omega_case + omega_diff``, the right at ``omega_case - omega_diff``), each wheel's angle and speed,
the car's speed and travel, and each tyre's transient slip. The joints are outside: each side gear is
a joint's input shaft (torque ``T_in`` on it from the joint), each joint's output angle and speed
(``phi_out``, ``omega_out``) twist the halfshaft against the wheel.

Scalar code in a fixed order of operations: ``fmu_src/native/models/vehicle_driveline/vehicle_driveline.c`` ports it line for
line.
"""

from __future__ import annotations

import math
from typing import NamedTuple

#: Standard gravity [m/s2].
GRAVITY = 9.80665
#: The internal step h_int of the Runge-Kutta method keeps ``RATE_STEP`` >= lambda h_int, where lambda
#: bounds the magnitude of the equations' eigenvalues (:func:`rate_bound`): well inside the classical
#: fourth-order method's stability region (|lambda h| < 2.78 on the real and imaginary axes), and
#: accurate to about (lambda h)^5 / 120 = 8e-6 of an oscillation's amplitude per internal step.
RATE_STEP = 0.25
#: Most internal steps in one communication step: a longer step is refused (bounded work).
MAX_SUBSTEPS = 10_000
TOO_LONG = f"the communication step needs more than {MAX_SUBSTEPS} internal steps of the drive's fastest mode"

#: The longest communication step h of a Jacobi master coupling the drive with its two joints, for the
#: differential's internal mode on each side (a side gear against its halfshaft, angular frequency omega,
#: damping ratio zeta, :func:`internal_modes`): ``omega h <= min(JACOBI_OMEGA_STEP, JACOBI_DAMPING_STEP zeta)``.
#: The joints pass the halfshaft's torque back one step late: held over the step, an undamped spring gives
#: a step map of determinant 1 + (omega h)^2 / 2, unstable at any step, so the limit falls with the
#: damping. Measured in the vehicle launch (J_side 0.0075 to 0.03 kg.m2, k_left and the dampings halved
#: and doubled): the loop diverges above omega h = 0.25 at zeta = 0.12, 0.29 to 0.32 at zeta = 0.16,
#: 0.31 to 0.34 from zeta = 0.23 on; the constants keep below every one (docs/vehicle_launch.md).
JACOBI_OMEGA_STEP = 0.28
JACOBI_DAMPING_STEP = 1.5
#: Above ``omega h = DIVERGENCE_OMEGA_STEP`` on either side the loop diverges whatever the master's order:
#: measured in the launch over 0.6 s (the parameter changes above), a Gauss-Seidel master stepping the drive
#: before its joints (the joints take the drive's outputs of the same step, the drive their torques one
#: step late) diverged from omega h = 0.53 (damping doubled) to 0.65 to 0.7 (stiffness doubled), Jacobi
#: from 0.25: the FMU refuses such a step rather than diverge (docs/vehicle_driveline.md).
DIVERGENCE_OMEGA_STEP = 0.7

#: Positions in the state tuple.
CASE, DIFF, PHI_WHEEL_LEFT, WHEEL_LEFT, PHI_WHEEL_RIGHT, WHEEL_RIGHT, SPEED, TRAVEL, SLIP_LEFT, SLIP_RIGHT = range(10)
STATE_SIZE = 10


class Drive(NamedTuple):
    """The parameters, as the spec names them (SI units)."""

    ratio: float
    J_motor: float
    J_diff: float
    J_side: float
    k_left: float
    k_right: float
    c_left: float
    c_right: float
    J_wheel: float
    r_wheel: float
    m_vehicle: float
    front_share: float
    C_slip: float
    sigma_slip: float
    mu_road_left: float
    mu_road_right: float
    f_roll: float
    rho_air: float
    c_drag: float
    A_front: float
    grade: float
    v_low: float


class Joints(NamedTuple):
    """What the two joints give at the communication point: torque on each side gear, output angle and
    speed; the output angle moves on at the output speed over the step (first-order hold)."""

    T_in_left: float
    T_in_right: float
    phi_out_left: float
    phi_out_right: float
    omega_out_left: float
    omega_out_right: float


def case_inertia(drive: Drive) -> float:
    """Inertia of the common motion at the case's speed: motor (ratio^2), case, both side gears (eq V1)."""
    return drive.ratio * drive.ratio * drive.J_motor + drive.J_diff + 2.0 * drive.J_side


def equivalent_mass(drive: Drive) -> float:
    """Car mass with the two free-rolling rear wheels' inertia (each J_wheel) added (eq V7)."""
    return drive.m_vehicle + 2.0 * drive.J_wheel / (drive.r_wheel * drive.r_wheel)


def wheel_load(drive: Drive) -> float:
    """Static normal load of one front wheel (no load transfer) [N]."""
    return drive.m_vehicle * GRAVITY * math.cos(drive.grade) * drive.front_share / 2.0


def tyre_force(drive: Drive, slip: float, mu: float) -> float:
    """Longitudinal force of a front tyre: slip stiffness at small slip, saturating at mu F_z (eq V5)."""
    limit = mu * wheel_load(drive)
    return limit * math.tanh(drive.C_slip * slip / limit)


def halfshaft_torques(drive: Drive, state: tuple[float, ...], joints: Joints, elapsed: float) -> tuple[float, float]:
    """Torque in each halfshaft, ``elapsed`` after the communication point (eq V3)."""
    twist_left = joints.phi_out_left + joints.omega_out_left * elapsed - state[PHI_WHEEL_LEFT]
    twist_right = joints.phi_out_right + joints.omega_out_right * elapsed - state[PHI_WHEEL_RIGHT]
    return (drive.k_left * twist_left + drive.c_left * (joints.omega_out_left - state[WHEEL_LEFT]),
            drive.k_right * twist_right + drive.c_right * (joints.omega_out_right - state[WHEEL_RIGHT]))


def road_load(drive: Drive, v: float) -> float:
    """Rolling resistance (its sign regularised below v_low), aerodynamic drag and grade [N] (eq V8)."""
    weight = drive.m_vehicle * GRAVITY
    rolling = drive.f_roll * weight * math.cos(drive.grade) * math.tanh(v / drive.v_low)
    drag = 0.5 * drive.rho_air * drive.c_drag * drive.A_front * v * abs(v)
    return rolling + drag + weight * math.sin(drive.grade)


def rates(drive: Drive, state: tuple[float, ...], T_motor: float, joints: Joints, elapsed: float) -> tuple[float, ...]:
    """Time derivative of the state (eqs V1-V9)."""
    T_left, T_right = halfshaft_torques(drive, state, joints, elapsed)
    v = state[SPEED]
    F_left = tyre_force(drive, state[SLIP_LEFT], drive.mu_road_left)
    F_right = tyre_force(drive, state[SLIP_RIGHT], drive.mu_road_right)
    slip_speed = abs(v) + drive.v_low
    return (
        (drive.ratio * T_motor - joints.T_in_left - joints.T_in_right) / case_inertia(drive),  # V1
        (joints.T_in_right - joints.T_in_left) / (2.0 * drive.J_side),  # V2
        state[WHEEL_LEFT],
        (T_left - drive.r_wheel * F_left) / drive.J_wheel,  # V4
        state[WHEEL_RIGHT],
        (T_right - drive.r_wheel * F_right) / drive.J_wheel,
        (F_left + F_right - road_load(drive, v)) / equivalent_mass(drive),  # V7
        v,
        (drive.r_wheel * state[WHEEL_LEFT] - v - slip_speed * state[SLIP_LEFT]) / drive.sigma_slip,  # V6
        (drive.r_wheel * state[WHEEL_RIGHT] - v - slip_speed * state[SLIP_RIGHT]) / drive.sigma_slip,
    )


def rate_bound(drive: Drive, v: float) -> float:
    """An upper bound of the magnitude of the equations' eigenvalues near speed ``v`` [1/s]: per wheel
    the halfshaft's and the tyre's torsional rates, the damping's and the slip's decay rates; for the
    car the tyres against its mass, rolling resistance's regularised slope and drag's."""
    J, r = drive.J_wheel, drive.r_wheel
    tyre = math.sqrt(drive.C_slip * r * r / (J * drive.sigma_slip))
    slip_decay = (abs(v) + drive.v_low) / drive.sigma_slip
    wheel = max(math.sqrt(drive.k_left / J) + drive.c_left / J, math.sqrt(drive.k_right / J) + drive.c_right / J)
    mass = equivalent_mass(drive)
    car = (math.sqrt(2.0 * drive.C_slip / (drive.sigma_slip * mass))
           + drive.f_roll * drive.m_vehicle * GRAVITY / (drive.v_low * mass)
           + drive.rho_air * drive.c_drag * drive.A_front * abs(v) / mass)
    return wheel + tyre + slip_decay + car


def substeps(drive: Drive, v: float, step_size: float) -> int:
    """Internal steps over a communication step: the fewest with ``rate_bound * h_int <= RATE_STEP``."""
    count = math.ceil(step_size * rate_bound(drive, v) / RATE_STEP)
    if not count <= MAX_SUBSTEPS:
        raise ValueError(TOO_LONG)
    return max(count, 1)


def _moved(state: tuple[float, ...], slope: tuple[float, ...], h: float) -> tuple[float, ...]:
    return tuple(x + h * dx for x, dx in zip(state, slope))


def advance(drive: Drive, state: tuple[float, ...], T_motor: float, joints: Joints,
            step_size: float) -> tuple[float, ...]:
    """The state one communication step later: classical Runge-Kutta, :func:`substeps` equal steps,
    the joints' inputs held (their output angles moving at their output speeds)."""
    count = substeps(drive, state[SPEED], step_size)
    h = step_size / count
    for n in range(count):
        t = n * h
        k1 = rates(drive, state, T_motor, joints, t)
        k2 = rates(drive, _moved(state, k1, 0.5 * h), T_motor, joints, t + 0.5 * h)
        k3 = rates(drive, _moved(state, k2, 0.5 * h), T_motor, joints, t + 0.5 * h)
        k4 = rates(drive, _moved(state, k3, h), T_motor, joints, t + h)
        state = tuple(x + h / 6.0 * (a + 2.0 * b + 2.0 * c + d) for x, a, b, c, d in zip(state, k1, k2, k3, k4))
    return state


def start_state(drive: Drive, v_start: float, joints: Joints) -> tuple[float, ...]:
    """Rolling at ``v_start`` without slip, halfshafts untwisted (each wheel at its joint's output angle)."""
    omega = v_start / drive.r_wheel
    return (omega, 0.0, joints.phi_out_left, omega, joints.phi_out_right, omega, v_start, 0.0, 0.0, 0.0)


def reaction_torque(drive: Drive, joints: Joints, case_acceleration: float) -> float:
    """Torque of the drive's rotating parts on the powertrain housing about the axle direction (eq V9):
    minus the torque leaving through the side gears, minus the rate of the parts' angular momentum
    (the motor turning the wheels' way, ``ratio`` times as fast as the case)."""
    momentum_inertia = drive.ratio * drive.J_motor + drive.J_diff + 2.0 * drive.J_side
    return -(joints.T_in_left + joints.T_in_right) - momentum_inertia * case_acceleration


def internal_modes(drive: Drive) -> tuple[tuple[float, float], tuple[float, float]]:
    """Angular frequency [rad/s] and damping ratio of the differential's internal mode on each side with the
    joints outside: a side gear (``J_side``) against its halfshaft (the wheel held); a side without
    stiffness has no oscillation (0 rad/s, damping ratio inf)."""
    return tuple((math.sqrt(k / drive.J_side), c / (2.0 * math.sqrt(k * drive.J_side)) if k > 0.0 else math.inf)
                 for k, c in ((drive.k_left, drive.c_left), (drive.k_right, drive.c_right)))


def jacobi_step_limit(drive: Drive) -> float:
    """The longest communication step of a Jacobi master coupling the drive with its joints [s] (inf
    without stiffness on either side)."""
    return min((min(JACOBI_OMEGA_STEP, JACOBI_DAMPING_STEP * zeta) / omega
                for omega, zeta in internal_modes(drive) if omega > 0.0), default=math.inf)


def modes_text(drive: Drive) -> str:
    """The differential's internal modes as a message shows them."""
    (omega_left, zeta_left), (omega_right, zeta_right) = internal_modes(drive)
    return (f"left {omega_left:.4g} rad/s, damping ratio {zeta_left:.3g}; "
            f"right {omega_right:.4g} rad/s, damping ratio {zeta_right:.3g}")


def divergence_step_limit(drive: Drive) -> float:
    """The step above which the drive coupled to its joints diverges in any master's order [s]."""
    return min((DIVERGENCE_OMEGA_STEP / omega for omega, _ in internal_modes(drive) if omega > 0.0), default=math.inf)


def step_limit_notice(drive: Drive, step_size: float) -> str | None:
    """What the log says once of a communication step above the Jacobi limit, or None."""
    limit = jacobi_step_limit(drive)
    if not step_size > limit:
        return None
    return (f"communication steps above {limit:.3g} s let the differential's internal mode ({modes_text(drive)}) "
            f"diverge in a Jacobi master, the joints' torques one step late (omega h <= min({JACOBI_OMEGA_STEP}, "
            f"{JACOBI_DAMPING_STEP} zeta)); a Gauss-Seidel master stepping the drive before its joints may hold "
            f"longer, never beyond {divergence_step_limit(drive):.3g} s (omega h = {DIVERGENCE_OMEGA_STEP})")


def step_limit_errors(drive: Drive, step_size: float) -> list[str]:
    """A communication step at which the drive coupled to its joints diverges in any master's order: refused."""
    limit = divergence_step_limit(drive)
    if not step_size > limit:
        return []
    return [f"communication step {step_size!r} s is above {limit:.3g} s, where the differential's internal mode "
            f"({modes_text(drive)}) diverges coupled to the joints in any master's order (omega h > "
            f"{DIVERGENCE_OMEGA_STEP}; a Jacobi master needs {jacobi_step_limit(drive):.3g} s or less): take a "
            "shorter step"]
