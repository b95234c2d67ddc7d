"""An independent monolithic model of the vehicle launch, written from the model pages, not the code.

The closed loop of ``VehicleLaunch.ssp`` as one ODE, each part re-derived from its page and none of the
project's physics modules imported (the layout file is read as data, with ``tomllib``):

* the motor (docs/torque_source.md): a straight ramp to ``T_level`` over ``ramp_time``;
* the drive (docs/vehicle_driveline.md, eqs V1-V8): the differential's case and internal speeds, each
  halfshaft a spring and damper from its joint's output to its wheel, the wheels, the tyres with their
  transient slip, the car with rolling resistance and drag;
* each tripod joint at leading order in r/l (docs/tripod_coupling.md, "Leading order in r/l" and
  "Friction"): the output turns with the input (the kinematic deviation is arcminutes); the input
  torque is the load plus the plungers' inertia ``3 m r^2 (1 + tan^2 beta / 2) alpha``; each plunger
  travels ``z_j = r tan beta cos(phi_j - psi)`` along its groove (``psi`` the bend plane's angle) and
  presses on it with the pin force ``T / (3 r)``, so the groove friction, regularised as
  ``u / sqrt(1 + u^2)``, ``u`` the plunger's sliding speed relative to the housing over ``v_slip``,
  pushes the housing along Z' with ``-Rz_in = mu T / (3 r) sum_j s(u_j)``, the generated axial force;
  the tripod can take the balls' push only along its own axis U (into the output bearing), so the
  housing carries the generated force along U: ``-tan beta`` of it across Z', towards -X' in the bend
  plane (``Rx_in = tan beta Rz_in``-like in the page's frame, a third order as large as the bend);
  the drags act at radius r, so they also load the housing with the moment ``r sum_j d_j (e_j x e_z)``
  about O (``d_j`` plunger j's drag along Z', ``e_j`` its radial direction), and tilt the tripod about
  the output bearing S; the pins answer that tilt with an in-plane force of ``r / l`` of it, which the
  input bearing carries as ``-(r / l) sum_j d_j e_j`` (the tripod massless: the force balance of the
  page's "Bearing reactions" with the grooves' friction); the mean side force ``Ry_in = -T tan(beta /
  2) / l`` and moment ``Mx_in = -T tan(beta / 2)`` and the drive torque's reaction ``-T_in`` about Z'
  complete the housing's load. Left out: the ball's friction along its arm, whose tilt the pins answer
  among themselves (it changes the pin forces, and the grooves' friction only at second order in mu;
  the page's full model gives 329 N of third-order generated force at 25 deg, 500 N.m, mu 0.05, where
  this leading order gives 4/pi mu T/(3r) = 408 N; 362 N at 5 deg: this model's generated force lies
  10 to 25 % above the full one's), and the friction's power loss in the input torque (under 1 %);
* the powertrain (docs/powertrain_mounts.md, eq 1): ``M q'' + C q' + K q = G u`` with the mounts'
  viscous damping ``eta k / (2 pi f_eta)``, each joint's housing load applied at its centre O; with
  ``drive_reaction`` the drive's reaction torque about y (docs/vehicle_driveline.md, eq V9) in place of the
  joints' ``-T_in`` about their axes;
* with ``housing_motion``, each halfshaft's geometry on the moving powertrain, from the page's
  equations H1-H4 (docs/vehicle_launch.md, "The halfshafts' geometry on a moving powertrain") computed
  here as plain vectors: the wheel centre W fixed to the body at the design position (the shaft of
  length ``l`` bent ``beta`` in the vertical plane, leaning to -X'), the housing frame turned by the
  powertrain's rotation (Rodrigues) and carried by its translation, ``a = F^T (W - O)``, its rate
  ``F^T (s' - omega x s)``; the bend angle, the plane angle and the plunge follow, and their rates enter
  the plungers' sliding speed relative to the housing, ``z_j' + p'``.

The joints' input angles, each in its own frame (the right joint turns negatively), are the side
gears' angles plus each joint's ``phi_in_start``; the halfshafts start untwisted at rest, the
powertrain in its equilibrium. ``solve_ivp`` (LSODA) integrates it.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import eigh

#: The linear layout (viscous mounts, equation (1)), not PowertrainMounts' rubber default: its comparison binds it
LAYOUT = Path(__file__).resolve().parents[2] / "driveline" / "mounts" / "data" / "transverse_fwd_powertrain.toml"
G = 9.80665  # the launch's one value of g [m/s2]
COORDINATES = ("x", "y", "z", "roll", "pitch", "yaw")


@dataclass(frozen=True)
class Joint:
    """One inboard joint with its halfshaft (docs/tripod_coupling.md's variables; the launch's bindings)."""

    beta: float  # bend angle at the design position [rad]
    l: float  # halfshaft length between the joints' centres [m]
    centre: tuple[float, float, float]  # O, vehicle axes [m] (docs/powertrain_mounts.md's defaults)
    shaft: tuple[float, float, float]  # Z', towards the wheel
    bend: tuple[float, float, float] = (0.0, 0.0, 1.0)  # X': the shaft leans towards -X'
    sense: float = 1.0  # +1: the joint turns positively about its Z' driving forward, -1 the right one
    phase: float = 0.0  # phi_in_start [rad]
    k: float = 6817.69  # halfshaft stiffness [N.m/rad]
    c: float = 4.69993  # halfshaft damping [N.m.s/rad]
    r: float = 0.026
    m: float = 0.2  # plunger mass [kg]
    mu: float = 0.05
    v_slip: float = 1e-3

    @property
    def frame(self) -> np.ndarray:
        """Columns X', Y', Z' in vehicle axes."""
        z = np.array(self.shaft, float) / np.linalg.norm(self.shaft)
        x = np.array(self.bend, float) - np.dot(self.bend, z) * z
        x /= np.linalg.norm(x)
        return np.column_stack([x, np.cross(z, x), z])

    @property
    def wheel(self) -> np.ndarray:
        """The outboard joint's centre W at the design position, vehicle axes."""
        frame = self.frame
        return np.array(self.centre) + self.l * (math.cos(self.beta) * frame[:, 2] - math.sin(self.beta) * frame[:, 0])

    @property
    def plunger_inertia(self) -> float:
        """The plungers' share of the input shaft's inertia [kg m2] (the page's leading-order T_in)."""
        return 3.0 * self.m * self.r**2 * (1.0 + 0.5 * math.tan(self.beta) ** 2)


def launch_joints(phase_right: float = 0.0, phase_left: float = 0.0) -> tuple[Joint, Joint]:
    """The package's joints: left 8 deg on 0.45 m, right 6 deg on 0.70 m, mu 0.05, at the given phases."""
    return (Joint(math.radians(8.0), 0.45, (0.0, 0.22, 0.0), (0.0, 1.0, 0.0), phase=phase_left),
            Joint(math.radians(6.0), 0.70, (0.0, -0.28, 0.0), (0.0, -1.0, 0.0), sense=-1.0, phase=phase_right,
                  k=4382.8))


@dataclass(frozen=True)
class Car:
    """docs/vehicle_driveline.md's defaults (a 2011 Nissan Leaf)."""

    ratio: float = 7.9377
    J_motor: float = 0.035
    J_diff: float = 0.06
    J_side: float = 0.015
    J_wheel: float = 0.9
    r_wheel: float = 0.306472
    mass: float = 1595.0
    front_share: float = 0.58
    C_slip: float = 81649.2
    sigma: float = 0.2
    mu_road: float = 1.0
    f_roll: float = 0.01
    rho_air: float = 1.204
    c_drag: float = 0.28
    A_front: float = 2.30454
    v_low: float = 0.1


def _skew(a: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


@dataclass
class Powertrain:
    """Mass, damping and stiffness of the layout file (docs/powertrain_mounts.md, eq 1)."""

    path: Path = LAYOUT
    M: np.ndarray = field(init=False)
    C: np.ndarray = field(init=False)
    K: np.ndarray = field(init=False)
    cg: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        layout = tomllib.loads(self.path.read_text())
        self.cg = np.array(layout["centre_of_gravity"], float)
        ixx, iyy, izz, ixy, ixz, iyz = layout["inertia"]
        J = np.array([[ixx, -ixy, -ixz], [-ixy, iyy, -iyz], [-ixz, -iyz, izz]])
        self.M = np.zeros((6, 6))
        self.M[:3, :3] = layout["mass"] * np.eye(3)
        self.M[3:, 3:] = J
        self.K, self.C = np.zeros((6, 6)), np.zeros((6, 6))
        for mount in layout["mounts"]:
            A = np.array(mount.get("orientation", np.eye(3)), float)
            T = np.hstack([np.eye(3), -_skew(np.array(mount["position"]) - self.cg)])
            k = np.array(mount["stiffness"], float)
            c = np.array(mount["damping"], float) if "damping" in mount else \
                mount["loss_factor"] * k / (2.0 * math.pi * layout["loss_factor_frequency"])
            self.K += T.T @ A.T @ np.diag(k) @ A @ T
            self.C += T.T @ A.T @ np.diag(c) @ A @ T

    def modes(self) -> tuple[np.ndarray, np.ndarray]:
        """Natural frequencies [Hz] ascending and mass-normalised shapes (columns)."""
        values, shapes = eigh(self.K, self.M)
        return np.sqrt(values) / (2.0 * math.pi), shapes

    def generalised(self, point: np.ndarray, force: np.ndarray, moment: np.ndarray) -> np.ndarray:
        return np.concatenate([force, np.cross(point - self.cg, force) + moment])


def rotation(theta: np.ndarray) -> np.ndarray:
    """Rodrigues' rotation by the vector ``theta``."""
    angle = float(np.linalg.norm(theta))
    if angle == 0.0:
        return np.eye(3)
    k = _skew(theta / angle)
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * k @ k


def halfshaft(joint: Joint, cg: np.ndarray, q: np.ndarray, q_dot: np.ndarray) -> tuple[float, ...]:
    """Bend angle, plane angle, plunge and their rates of ``joint``'s halfshaft with the powertrain at
    ``q`` moving at ``q_dot`` (H1-H4 as vectors): the housing frame ``R F0`` at ``O = c + t + R (O0 - c)``,
    the wheel fixed; ``a = F^T (W - O)``, ``a' = F^T (s' - w x s)``."""
    R = rotation(q[3:])
    frame = R @ joint.frame
    arm = R @ (np.array(joint.centre) - cg)
    centre = cg + q[:3] + arm
    omega = q_dot[3:]  # small rotations: the angular velocity is the rotation's rate
    s = joint.wheel - centre
    s_dot = -(q_dot[:3] + np.cross(omega, arm))
    a = frame.T @ s
    a_dot = frame.T @ (s_dot - np.cross(omega, s))
    rho = math.hypot(a[0], a[1])
    h = math.sqrt(joint.l**2 - rho**2)
    beta = math.asin(rho / joint.l)
    psi = math.atan2(-a[1], -a[0])
    rho_dot = (a[0] * a_dot[0] + a[1] * a_dot[1]) / rho
    beta_dot = rho_dot / (joint.l * math.cos(beta))
    psi_dot = (a[0] * a_dot[1] - a[1] * a_dot[0]) / rho**2
    plunge, plunge_dot = a[2] - h, a_dot[2] + rho * rho_dot / h
    return beta, psi, plunge, beta_dot, psi_dot, plunge_dot


def regularised_sign(u: float) -> float:
    return u / math.sqrt(1.0 + u * u)


@dataclass
class Launch:
    """The closed loop. State: case and internal speeds, both side gears' angles (forward), both wheels'
    angles and speeds (forward), the car's speed, both tyres' slips, the powertrain's q and q'."""

    joints: tuple[Joint, Joint] = field(default_factory=launch_joints)
    housing_motion: bool = False
    drive_reaction: bool = False
    """The powertrain takes the drive's reaction torque about y (eq V9: ``-(T_L + T_R)`` minus the rate of
    the rotating parts' angular momentum) instead of each joint's ``-T_in`` about its Z'."""
    T_level: float = 140.0
    ramp_time: float = 0.3
    car: Car = field(default_factory=Car)
    powertrain: Powertrain = field(default_factory=Powertrain)

    def __post_init__(self) -> None:
        self.M_inv = np.linalg.inv(self.powertrain.M)
        self.F_z = self.car.mass * G * self.car.front_share / 2.0

    def joint_loads(self, joint: Joint, side_angle: float, side_speed: float, torque: float,
                    q: np.ndarray, q_dot: np.ndarray) -> tuple[np.ndarray, float]:
        """The generalised force of the joint's housing load on the powertrain, and the generated force."""
        phi, omega = joint.phase + joint.sense * side_angle, joint.sense * side_speed
        T = joint.sense * torque  # T_in in the joint's frame
        if self.housing_motion:
            beta, psi, _, beta_dot, psi_dot, plunge_dot = halfshaft(joint, self.powertrain.cg, q, q_dot)
        else:
            beta, psi, beta_dot, psi_dot, plunge_dot = joint.beta, 0.0, 0.0, 0.0, 0.0
        r, tb = joint.r, math.tan(beta)
        pin = abs(T) / (3.0 * r)
        generated = tilt_x = tilt_y = 0.0
        for j in range(3):
            position = phi + 2.0 * math.pi * j / 3.0  # the plunger's angle in the housing frame
            angle = position - psi  # from the bend plane
            sliding = (r / math.cos(beta) ** 2 * beta_dot * math.cos(angle)
                       - r * tb * math.sin(angle) * (omega - psi_dot) + plunge_dot)
            friction = joint.mu * pin * regularised_sign(sliding / joint.v_slip)  # the plunger's drag on the housing
            generated += friction
            tilt_x += friction * math.cos(position)
            tilt_y += friction * math.sin(position)
        half = math.tan(joint.beta / 2.0)
        frame = joint.frame
        Ry, Mx = -T * half / joint.l, -T * half
        # the drags at radius r tilt the tripod; its pins answer with an in-plane force r/l of their moment
        # the balls pass the drags to the tripod, which takes them along its own axis U (to the output bearing
        # S): the housing gets the generated force along U, -tan(beta) of it across the axis, in the bend plane
        along_shaft = -generated * math.tan(beta)
        force = ((along_shaft * math.cos(psi) - (r / joint.l) * tilt_x) * frame[:, 0]
                 + (along_shaft * math.sin(psi) - (r / joint.l) * tilt_y - Ry) * frame[:, 1] + generated * frame[:, 2])
        moment = r * (tilt_y * frame[:, 0] - tilt_x * frame[:, 1]) - Mx * frame[:, 0]
        if not self.drive_reaction:
            moment -= T * frame[:, 2]
        return self.powertrain.generalised(np.array(joint.centre), force, moment), generated

    def torque(self, t: float) -> float:
        return self.T_level * min(1.0, t / self.ramp_time) if self.ramp_time > 0.0 else self.T_level

    def rates(self, t: float, y: np.ndarray, detail: bool = False):
        car, (left, right) = self.car, self.joints
        w_case, w_diff, th_l, th_r, pw_l, pw_r, w_l, w_r, v, k_l, k_r = y[:11]
        q, q_dot = y[11:17], y[17:23]
        side_l, side_r = w_case + w_diff, w_case - w_diff
        load_l = left.k * (th_l - pw_l) + left.c * (side_l - w_l)
        load_r = right.k * (th_r - pw_r) + right.c * (side_r - w_r)
        # V1, V2 with T_X = load_X + J_pl,X alpha_X, alpha_l = a + d, alpha_r = a - d: a 2x2 system
        J_case = car.ratio**2 * car.J_motor + car.J_diff + 2.0 * car.J_side
        jl, jr = left.plunger_inertia, right.plunger_inertia
        matrix = np.array([[J_case + jl + jr, jl - jr], [jl - jr, 2.0 * car.J_side + jl + jr]])
        rhs = np.array([car.ratio * self.torque(t) - load_l - load_r, load_r - load_l])
        a_case, a_diff = np.linalg.solve(matrix, rhs)
        T_l, T_r = load_l + jl * (a_case + a_diff), load_r + jr * (a_case - a_diff)
        forces = []
        for slip, mu in ((k_l, car.mu_road), (k_r, car.mu_road)):
            limit = mu * self.F_z
            forces.append(limit * math.tanh(car.C_slip * slip / limit))
        road = (car.f_roll * car.mass * G * math.tanh(v / car.v_low)
                + 0.5 * car.rho_air * car.c_drag * car.A_front * v * abs(v))
        m_eq = car.mass + 2.0 * car.J_wheel / car.r_wheel**2
        loads_l, gen_l = self.joint_loads(left, th_l, side_l, T_l, q, q_dot)
        loads_r, gen_r = self.joint_loads(right, th_r, side_r, T_r, q, q_dot)
        loads = loads_l + loads_r
        if self.drive_reaction:  # V9 about vehicle y
            loads[4] += -(T_l + T_r) - (car.ratio * car.J_motor + car.J_diff + 2.0 * car.J_side) * a_case
        q_ddot = self.M_inv @ (loads - self.powertrain.C @ q_dot - self.powertrain.K @ q)
        slip_rate = [(car.r_wheel * w - v - (abs(v) + car.v_low) * s) / car.sigma for w, s in ((w_l, k_l), (w_r, k_r))]
        rates = np.concatenate([[a_case, a_diff, side_l, side_r, w_l, w_r,
                                 (load_l - car.r_wheel * forces[0]) / car.J_wheel,
                                 (load_r - car.r_wheel * forces[1]) / car.J_wheel,
                                 (forces[0] + forces[1] - road) / m_eq, *slip_rate], q_dot, q_ddot])
        if detail:
            return rates, {"T_load_left": load_l, "T_load_right": load_r, "generated_left": gen_l,
                           "generated_right": gen_r}
        return rates

    def run(self, stop_time: float = 4.0, every: float = 2e-4, rtol: float = 1e-7) -> dict[str, np.ndarray]:
        """The launch sampled every ``every`` s: time, the left joint's input angle, the powertrain's
        accelerations by coordinate, the halfshaft torques, the generated axial forces."""
        times = np.arange(0.0, stop_time + 0.5 * every, every)
        solution = solve_ivp(self.rates, (0.0, stop_time), np.zeros(23), method="LSODA", t_eval=times, rtol=rtol,
                             atol=1e-9, max_step=1e-3)
        if not solution.success:
            raise RuntimeError(solution.message)
        found: dict[str, list[float]] = {}
        for t, y in zip(solution.t, solution.y.T):
            rates, detail = self.rates(t, y, detail=True)
            for k, name in enumerate(COORDINATES):
                found.setdefault(f"{name}_ddot", []).append(rates[17 + k])
            for name, value in detail.items():
                found.setdefault(name, []).append(value)
        result = {name: np.array(values) for name, values in found.items()}
        result["time"] = solution.t
        result["phi_in_left"] = self.joints[0].phase + solution.y[2]
        frequencies, shapes = self.powertrain.modes()
        accelerations = np.column_stack([result[f"{name}_ddot"] for name in COORDINATES])
        dominant = int(np.argmax(shapes[:, 0] * (self.powertrain.M @ shapes[:, 0])))  # its largest energy share
        result["mode_1"] = (accelerations @ (self.powertrain.M @ shapes[:, 0])) * shapes[dominant, 0]
        return result
