"""An independent multibody model of the frictionless tripod coupling in Exudyn.

Bodies: the input shaft and the tripod with its output shaft (negligible mass: the reactions
are those of the coupling, not of the shafts' own inertia) and three plungers (mass m,
negligible rotational inertia). Joints, all generic joints of Exudyn:

* input shaft: a spherical support at the joint centre O, a radial support at Z' = -a
  (together the input bearing) and a drive that locks its rotation about Z' to a prescribed
  angle (a smooth run-up from rest over one turn, then the constant speed);
* plunger j: prismatic along its groove (rotations locked to the input shaft);
* ball j: the plunger's centre stays on tripod arm j (both normal offsets locked, sliding
  along the arm and all rotations free: sliding ball and spherical joint in one);
* tripod: spherical support at S = l e_out(beta), load torque -T_load about its own axis.

A case may ramp the bend angle or the speed after the run-up: the output bearing's support then
moves along S(t) = l e_out(beta(t)) (a prescribed offset of the spherical joint), with beta(t)
rising as ``beta + delta (s - sin(2 pi s) / (2 pi))`` over the ramp (rate ``2 delta / T sin^2(pi s)``,
zero rate and acceleration at both ends), or the speed rises linearly.

Only the initial pose at phi_in = 0 comes from this project (the Newton closure of
``driveline.tripod.exact``); Exudyn integrates the motion from rest and returns the joint
forces, from which the reactions are assembled here in the FMU's conventions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import exudyn as exu
import exudyn.itemInterface as items
import numpy as np
from exudyn.rigidBodyUtilities import RigidBodyInertia

from driveline.tripod import exact
from driveline.tripod.geometry import THIRD_TURN

SUPPORT_SPACING = 0.2  # a: distance of the radial input support from O [m]
TINY_MASS = 1e-9  # kg, for the massless shafts; their inertia forces stay below 1e-6 N
TINY_INERTIA = 1e-12  # kg m^2


@dataclass(frozen=True)
class Case:
    beta: float  # rad
    T_load: float  # N.m
    omega: float  # rad/s
    r: float = 0.026
    l: float = 0.700
    m: float = 0.2
    beta_end: float | None = None  # rad: the bend ramps from beta to beta_end over ramp_time ...
    omega_end: float | None = None  # rad/s: ... or the speed from omega to omega_end, linearly
    ramp_time: float = 0.0  # s, starting once the run-up is over

    def bend(self, t: float, start: float) -> tuple[float, float, float]:
        """Bend angle, its rate and acceleration at time t for a ramp starting at ``start``."""
        if self.beta_end is None or not start < t:
            return self.beta, 0.0, 0.0
        delta, T = self.beta_end - self.beta, self.ramp_time
        if t >= start + T:
            return self.beta_end, 0.0, 0.0
        s = (t - start) / T
        return (self.beta + delta * (s - math.sin(2 * math.pi * s) / (2 * math.pi)),
                2 * delta / T * math.sin(math.pi * s) ** 2, 2 * math.pi * delta / T**2 * math.sin(2 * math.pi * s))


@dataclass(frozen=True)
class Result:
    """Reactions over a third of a turn at constant speed (or over a ramp's window), sampled
    every step (FMU names), from ``time[0]`` on."""

    phi_in: np.ndarray
    step: float
    values: dict[str, np.ndarray]
    time: np.ndarray | None = None


def _rotation_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _tripod_start(case: Case) -> tuple[np.ndarray, np.ndarray]:
    """Tripod centre and rotation matrix (columns: arm 1, in-plane normal, shaft axis) at phi_in = 0."""
    pose = exact.exact_pose(np.zeros(1), case.beta, case.r, case.l)
    spin = _rotation_z(float(pose.phi_out[0]))
    columns = exact._bend_apply(np.full(1, case.beta), exact._swing_apply(pose.swing, spin.T[None]))[0]
    return pose.tripod_centre[0], columns.T


def _run_up(turn_time: float, case: Case) -> tuple:
    """Input angle and speed: a run-up from rest during ``turn_time`` whose speed follows
    ``6 s^5 - 15 s^4 + 10 s^3`` (acceleration and jerk zero at both ends), then ``case.omega``,
    rising linearly to ``case.omega_end`` over ``case.ramp_time`` if given."""
    omega = case.omega
    rate = 0.0 if case.omega_end is None else (case.omega_end - omega) / case.ramp_time

    def angle(t: float) -> float:
        s = min(t / turn_time, 1.0)
        ramp = turn_time * (s**6 - 3 * s**5 + 2.5 * s**4)
        after = max(t - turn_time, 0.0)
        rising = min(after, case.ramp_time) if rate else 0.0
        return omega * (ramp + after) + rate * (0.5 * rising**2 + rising * (after - rising))

    def speed(t: float) -> float:
        s = min(t / turn_time, 1.0)
        rising = min(max(t - turn_time, 0.0), case.ramp_time) if rate else 0.0
        return omega * (6 * s**5 - 15 * s**4 + 10 * s**3) + rate * rising

    return angle, speed


def simulate(case: Case, steps_per_turn: int = 1500, window: float | None = None) -> Result:
    """Run the model up to speed over a third of a turn's time, then record a third of a turn:
    the bearing reactions repeat every third of a turn, and the three arms' forces together
    cover each arm's whole turn. A ramp is recorded from its start over ``window`` (default:
    the whole ramp)."""
    period = 2 * math.pi / case.omega / 3
    step = 3 * period / steps_per_turn
    record = period if case.ramp_time == 0.0 else (case.ramp_time if window is None else window)
    steps = round((period + record) / step)
    angle, speed = _run_up(period, case)
    system = exu.SystemContainer()
    mbs = system.AddSystem()
    ground = mbs.CreateGround(referencePosition=[0.0, 0.0, 0.0])

    def marker(body, position, rotation=None) -> int:
        if rotation is None:
            return mbs.AddMarker(items.MarkerBodyRigid(bodyNumber=body, localPosition=list(position)))
        frame = exu.HT(rotation=rotation, translation=list(position))
        return mbs.AddMarker(items.MarkerBodyRigid(bodyNumber=body, localHT=frame))

    def joint(m0, m1, axes, **extra) -> int:
        return mbs.AddObject(items.ObjectJointGeneric(markerNumbers=[m0, m1], constrainedAxes=axes, **extra))

    shaft = mbs.CreateRigidBody(inertia=RigidBodyInertia(TINY_MASS, TINY_INERTIA * np.eye(3)),
                                referencePosition=[0.0, 0.0, 0.0])
    sphere_in = joint(marker(ground, (0, 0, 0)), marker(shaft, (0, 0, 0)), [1, 1, 1, 0, 0, 0])
    radial_in = joint(marker(ground, (0, 0, -SUPPORT_SPACING)), marker(shaft, (0, 0, -SUPPORT_SPACING)),
                      [1, 1, 0, 0, 0, 0])
    drive = joint(marker(ground, (0, 0, 0)), marker(shaft, (0, 0, 0)), [0, 0, 0, 0, 0, 1],
                  offsetUserFunction=lambda mbs, t, item, p: [0, 0, 0, 0, 0, angle(t)],
                  offsetUserFunction_t=lambda mbs, t, item, p: [0, 0, 0, 0, 0, speed(t)])

    centre, rotation = _tripod_start(case)
    tripod = mbs.CreateRigidBody(inertia=RigidBodyInertia(TINY_MASS, TINY_INERTIA * np.eye(3)),
                                 referencePosition=list(centre), referenceRotationMatrix=rotation)
    tripod_marker = marker(tripod, (0, 0, 0))
    S = case.l * np.array([-math.sin(case.beta), 0.0, math.cos(case.beta)])

    def bearing_offset(t: float) -> list[float]:
        beta = case.bend(t, period)[0]
        return [-case.l * math.sin(beta) - S[0], 0.0, case.l * math.cos(beta) - S[2], 0.0, 0.0, 0.0]

    def bearing_velocity(t: float) -> list[float]:
        beta, rate, _ = case.bend(t, period)
        return [-case.l * math.cos(beta) * rate, 0.0, -case.l * math.sin(beta) * rate, 0.0, 0.0, 0.0]

    sphere_out = joint(marker(ground, S), marker(tripod, (0, 0, case.l)), [1, 1, 1, 0, 0, 0],
                       offsetUserFunction=lambda mbs, t, item, p: bearing_offset(t),
                       offsetUserFunction_t=lambda mbs, t, item, p: bearing_velocity(t))
    mbs.AddLoad(items.LoadTorqueVector(markerNumber=tripod_marker, loadVector=[0, 0, -case.T_load], bodyFixed=True))

    arm_joints = []
    for j in range(3):
        groove = case.r * np.array([math.cos(THIRD_TURN * j), math.sin(THIRD_TURN * j), 0.0])
        arm = rotation @ np.array([math.cos(THIRD_TURN * j), math.sin(THIRD_TURN * j), 0.0])
        # the ball centre: groove line meets arm line (projections on X'Y')
        along = np.dot(groove[:2] - centre[:2], arm[:2]) / np.dot(arm[:2], arm[:2])
        ball = centre + along * arm
        plunger = mbs.CreateRigidBody(inertia=RigidBodyInertia(case.m, TINY_INERTIA * np.eye(3)),
                                      referencePosition=list(ball))
        joint(marker(shaft, ball), marker(plunger, (0, 0, 0)), [1, 1, 0, 1, 1, 1])
        arm_frame = marker(tripod, rotation.T @ (ball - centre), _rotation_z(THIRD_TURN * j))
        arm_joints.append(joint(arm_frame, marker(plunger, (0, 0, 0)), [0, 1, 1, 0, 0, 0]))

    def sensor(**kwargs) -> int:
        kind = items.SensorObject if "objectNumber" in kwargs else items.SensorBody
        return mbs.AddSensor(kind(writeToFile=False, storeInternal=True, **kwargs))

    force = exu.OutputVariableType.ForceLocal
    sensors = {
        "sphere_in": sensor(objectNumber=sphere_in, outputVariableType=force),
        "radial_in": sensor(objectNumber=radial_in, outputVariableType=force),
        "drive": sensor(objectNumber=drive, outputVariableType=exu.OutputVariableType.TorqueLocal),
        "sphere_out": sensor(objectNumber=sphere_out, outputVariableType=force),
        "tripod_rotation": sensor(bodyNumber=tripod, outputVariableType=exu.OutputVariableType.RotationMatrix),
        **{f"arm{j}": sensor(objectNumber=arm_joints[j], outputVariableType=force) for j in range(3)},
    }
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.timeIntegration.endTime = steps * step
    settings.timeIntegration.numberOfSteps = steps
    settings.timeIntegration.verboseMode = 0
    settings.timeIntegration.newton.relativeTolerance = 1e-12
    settings.timeIntegration.newton.absoluteTolerance = 1e-12
    settings.timeIntegration.generalizedAlpha.spectralRadius = 0.5
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = step
    mbs.SolveDynamic(settings)
    data = {name: mbs.GetSensorStoredData(index) for name, index in sensors.items()}
    time = data["drive"][:, 0]
    if case.ramp_time == 0.0:
        turn = (time > period + 0.5 * step) & (time < 2 * period + 0.5 * step)
    else:
        turn = (time > period - 0.5 * step) & (time < period + record + 0.5 * step)
    raw = {name: values[turn, 1:] for name, values in data.items()}
    phi_in = np.array([angle(t) for t in time[turn]])
    beta = np.array([case.bend(t, period)[0] for t in time[turn]])
    return Result(phi_in, step, reactions(case, raw, beta), time[turn])


def reactions(case: Case, raw: dict[str, np.ndarray], beta: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """The FMU's reaction outputs from Exudyn's joint forces (the force on marker 0's body, in
    marker 0's joint frame; the drive's torque as it acts on the shaft) at the bend ``beta`` of
    each sample (default: the case's)."""
    sphere_in, radial_in = raw["sphere_in"], raw["radial_in"]
    # the shaft is marker 1 of both supports
    bearing_in = -(sphere_in + radial_in)
    moment_in = np.cross(np.array([0.0, 0.0, -SUPPORT_SPACING]), -radial_in)
    rotation = raw["tripod_rotation"].reshape(-1, 3, 3)
    U = rotation[:, :, 2]
    beta = np.full(len(U), case.beta) if beta is None else beta
    e_out = np.stack([-np.sin(beta), np.zeros_like(beta), np.cos(beta)], axis=1)
    E1, E2 = _twist_free_frame(e_out, U, beta)
    bearing_out = -raw["sphere_out"]
    values = {
        "Rx_in": bearing_in[:, 0], "Ry_in": bearing_in[:, 1], "Mx_in": moment_in[:, 0], "My_in": moment_in[:, 1],
        "T_in": raw["drive"][:, 2],
        "Rx_out": np.sum(bearing_out * E1, axis=1), "Ry_out": np.sum(bearing_out * E2, axis=1),
        "Rz_out": np.sum(bearing_out * U, axis=1),
    }
    for j in range(3):
        frame = rotation @ _rotation_z(THIRD_TURN * j)  # joint frame of arm j: arm, in-plane normal, shaft axis
        on_tripod = np.einsum("nij,nj->ni", frame, raw[f"arm{j}"])
        values[f"F_arm{j + 1}"] = raw[f"arm{j}"][:, 1]
        values[f"F_plunger{j + 1}"] = -on_tripod[:, 2]
    return values


def _twist_free_frame(e_out: np.ndarray, U: np.ndarray, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Images of the nominal output frame's x and y axes under the smallest rotation taking
    e_out onto U (Rodrigues), one row per sample (nominal axis and bend per sample)."""
    zero, one = np.zeros_like(beta), np.ones_like(beta)
    nominal = (np.stack([np.cos(beta), zero, np.sin(beta)], axis=1), np.stack([zero, one, zero], axis=1))
    axis = np.cross(e_out, U)
    sin_angle = np.linalg.norm(axis, axis=1, keepdims=True)
    cos_angle = np.sum(U * e_out, axis=1)
    unit = axis / np.where(sin_angle > 0, sin_angle, 1.0)
    images = []
    for v in nominal:
        images.append(v * cos_angle[:, None] + np.cross(unit, v) * sin_angle
                      + unit * np.sum(unit * v, axis=1)[:, None] * (1 - cos_angle[:, None]))
    return images[0], images[1]
