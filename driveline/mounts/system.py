"""Everything a step of PowertrainMounts needs, built once from the parameters.

The loads of the inputs ``u`` (:data:`.spec.INPUTS`: the force and moment at the centre of
gravity, the two joints' TripodCoupling reactions, the motor torque) enter the equations of
motion as the generalised force ``f = G u`` (:mod:`.rigid_body`, :mod:`.joints`); ``q`` is
measured from the static equilibrium under the weight, whose mount forces are the preload.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .exact_step import state_matrices
from .joints import housing_load, joint_frame
from .layout import Layout
from .rigid_body import Modes, RigidBody, modes, torque_roll_axis, unrestrained_error
from .spec import INPUTS, SIDES


@dataclass(frozen=True)
class Placement:
    """Where the loads act: joint centres and frames (by side) and the motor axis (vehicle axes)."""

    centres: dict[str, np.ndarray]
    frames: dict[str, np.ndarray]
    motor_axis: np.ndarray

    @classmethod
    def of(cls, centres: dict[str, np.ndarray], shafts: dict[str, np.ndarray], bends: dict[str, np.ndarray],
           motor_axis: np.ndarray) -> Placement:
        """ValueError naming the direction that does not give a frame or an axis."""
        frames = {side: joint_frame(shafts[side], bends[side], side) for side in SIDES}
        length = float(np.linalg.norm(motor_axis))
        if math.isinf(length):
            raise ValueError("the motor axis (motor_axis_x, motor_axis_y, motor_axis_z) is too long (its length "
                             "overflows)")
        if not length > 0.0:
            raise ValueError("the motor axis (motor_axis_x, motor_axis_y, motor_axis_z) has no length")
        return cls(centres, frames, motor_axis / length)


def input_map(body: RigidBody, placement: Placement) -> np.ndarray:
    """``G`` (6 x len(INPUTS)): the generalised force of each input at 1."""
    columns = [np.eye(6)[:, k] for k in range(6)]
    for side in SIDES:
        for k in range(6):
            force, moment = housing_load(placement.frames[side], np.eye(6)[k])
            columns.append(body.load(placement.centres[side], force, moment))
    columns.append(np.concatenate([np.zeros(3), -placement.motor_axis]))
    return np.column_stack(columns)


@dataclass(frozen=True)
class MountSystem:
    """Matrices, modes, input map and the weight's equilibrium of one set of parameters."""

    body: RigidBody
    modes: Modes
    a: np.ndarray
    b: np.ndarray
    inputs: np.ndarray
    placement: Placement
    weight_sag: np.ndarray  # q of the static equilibrium under the weight, from the unloaded mounts

    @classmethod
    def build(cls, layout: Layout, placement: Placement, g: float) -> MountSystem:
        """ValueError when the mounts leave a rigid-body motion unrestrained."""
        body = RigidBody.of(layout)
        found = modes(body)
        reason = unrestrained_error(found)
        if reason is not None:
            raise ValueError(reason)
        a, b = state_matrices(body)
        return cls(body, found, a, b, input_map(body, placement), placement,
                   body.static_displacement(body.gravity(g)))

    def static_sag(self, g: float, mean_torque: float) -> np.ndarray:
        """Static displacement from the unloaded mounts under the weight and ``-mean_torque`` about the motor axis."""
        torque = np.concatenate([np.zeros(3), -mean_torque * self.placement.motor_axis])
        return self.body.static_displacement(self.body.gravity(g) + torque)

    def torque_roll_axis(self) -> np.ndarray:
        return torque_roll_axis(self.body.layout.inertia, self.placement.motor_axis)

    def accelerations(self, state: np.ndarray, force: np.ndarray) -> np.ndarray:
        """``q''`` at ``state`` under the generalised force ``force``."""
        return (self.a @ state + self.b @ force)[6:]

    def acceleration_scales(self, state: np.ndarray, force: np.ndarray) -> np.ndarray:
        """The sum of the magnitudes of the terms of each ``q''`` (:meth:`accelerations`): zero in
        an equilibrium, the computed ``q''`` is its rounding error, a few eps times this."""
        return (np.abs(self.a) @ np.abs(state) + np.abs(self.b) @ np.abs(force))[6:]

    def mount_forces(self, state: np.ndarray) -> np.ndarray:
        """Each mount's force on the powertrain (rows), the weight's preload included."""
        return self.body.mount_forces(self.weight_sag + state[:6], state[6:])
