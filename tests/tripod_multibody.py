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
* tripod: spherical support at S = l e_out, load torque -T_load about its own axis.

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


@dataclass(frozen=True)
class Result:
    """Reactions over a third of a turn at constant speed, sampled every step (FMU names)."""

    phi_in: np.ndarray
    step: float
    values: dict[str, np.ndarray]


def _rotation_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _tripod_start(case: Case) -> tuple[np.ndarray, np.ndarray]:
    """Tripod centre and rotation matrix (columns: arm 1, in-plane normal, shaft axis) at phi_in = 0."""
    pose = exact.exact_pose(np.zeros(1), case.beta, case.r, case.l)
    spin = _rotation_z(float(pose.phi_out[0]))
    columns = exact._bend_apply(np.full(1, case.beta), exact._swing_apply(pose.swing, spin.T[None]))[0]
    return pose.tripod_centre[0], columns.T


def _run_up(turn_time: float, omega: float) -> tuple:
    """Input angle and speed: a run-up from rest during ``turn_time`` whose speed follows
    ``6 s^5 - 15 s^4 + 10 s^3`` (acceleration and jerk zero at both ends), then ``omega``."""

    def angle(t: float) -> float:
        s = min(t / turn_time, 1.0)
        ramp = turn_time * (s**6 - 3 * s**5 + 2.5 * s**4)
        return omega * (ramp + max(t - turn_time, 0.0))

    def speed(t: float) -> float:
        s = min(t / turn_time, 1.0)
        return omega * (6 * s**5 - 15 * s**4 + 10 * s**3)

    return angle, speed


def simulate(case: Case, steps_per_turn: int = 1500) -> Result:
    """Run the model up to speed over a third of a turn's time, then record a third of a turn:
    the bearing reactions repeat every third of a turn, and the three arms' forces together
    cover each arm's whole turn."""
    period = 2 * math.pi / case.omega / 3
    step = 3 * period / steps_per_turn
    angle, speed = _run_up(period, case.omega)
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
    sphere_out = joint(marker(ground, S), marker(tripod, (0, 0, case.l)), [1, 1, 1, 0, 0, 0])
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
    settings.timeIntegration.endTime = 2 * period
    settings.timeIntegration.numberOfSteps = 2 * steps_per_turn // 3
    settings.timeIntegration.verboseMode = 0
    settings.timeIntegration.newton.relativeTolerance = 1e-12
    settings.timeIntegration.newton.absoluteTolerance = 1e-12
    settings.timeIntegration.generalizedAlpha.spectralRadius = 0.5
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = step
    mbs.SolveDynamic(settings)
    data = {name: mbs.GetSensorStoredData(index) for name, index in sensors.items()}
    time = data["drive"][:, 0]
    turn = (time > period + 0.5 * step) & (time < 2 * period + 0.5 * step)
    raw = {name: values[turn, 1:] for name, values in data.items()}
    phi_in = np.array([angle(t) for t in time[turn]])
    return Result(phi_in, step, reactions(case, raw))


def reactions(case: Case, raw: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The FMU's reaction outputs from Exudyn's joint forces (the force on marker 0's body, in
    marker 0's joint frame; the drive's torque as it acts on the shaft)."""
    sphere_in, radial_in = raw["sphere_in"], raw["radial_in"]
    # the shaft is marker 1 of both supports
    bearing_in = -(sphere_in + radial_in)
    moment_in = np.cross(np.array([0.0, 0.0, -SUPPORT_SPACING]), -radial_in)
    rotation = raw["tripod_rotation"].reshape(-1, 3, 3)
    U = rotation[:, :, 2]
    e_out = np.array([-math.sin(case.beta), 0.0, math.cos(case.beta)])
    E1, E2 = _twist_free_frame(e_out, U, case.beta)
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


def _twist_free_frame(e_out: np.ndarray, U: np.ndarray, beta: float) -> tuple[np.ndarray, np.ndarray]:
    """Images of the nominal output frame's x and y axes under the smallest rotation taking
    e_out onto U (Rodrigues), one row per sample."""
    nominal = (np.array([math.cos(beta), 0.0, math.sin(beta)]), np.array([0.0, 1.0, 0.0]))
    axis = np.cross(e_out, U)
    sin_angle = np.linalg.norm(axis, axis=1, keepdims=True)
    cos_angle = U @ e_out
    unit = axis / np.where(sin_angle > 0, sin_angle, 1.0)
    images = []
    for v in nominal:
        images.append(v * cos_angle[:, None] + np.cross(unit, v) * sin_angle
                      + unit * (unit @ v)[:, None] * (1 - cos_angle[:, None]))
    return images[0], images[1]
