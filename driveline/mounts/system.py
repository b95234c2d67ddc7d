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
from .forces import BranchMap, elastic_forces, elastic_load, equilibrium, tangent_stiffness
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
    """Matrices, input map, the weight's equilibrium and the Maxwell branches of one set of parameters.

    The state is ``(q, q', z)``: q from the weight's equilibrium, z the branches' forces (none without
    rubber damping). Linear characteristics step exactly (``a``, ``b``: :mod:`.exact_step`),
    progressive ones by the implicit scheme of :mod:`.implicit_step`."""

    body: RigidBody
    modes: Modes  # of the linear rates, undamped: what the unrestrained check reads
    a: np.ndarray
    b: np.ndarray
    inputs: np.ndarray
    placement: Placement
    weight_sag: np.ndarray  # Q of the static equilibrium under the weight, from the unloaded mounts
    branches: BranchMap
    weight: np.ndarray  # the weight's generalised force

    @classmethod
    def build(cls, layout: Layout, placement: Placement, g: float, mean_torque: float = 0.0) -> MountSystem:
        """ValueError when the mounts leave a rigid-body motion unrestrained. The branches' rates are
        those at the operating point, the static equilibrium under the weight and ``-mean_torque``
        about the motor axis."""
        body = RigidBody.of(layout)
        found = modes(body)
        reason = unrestrained_error(found)
        if reason is not None:
            raise ValueError(reason)
        weight = body.gravity(g)
        operating = _equilibrium(body, weight + _torque(placement, mean_torque))
        branches = BranchMap(layout, operating)
        a, b = state_matrices(body, branches)
        return cls(body, found, a, b, input_map(body, placement), placement,
                   _equilibrium(body, weight), branches, weight)

    @property
    def progressive(self) -> bool:
        """Whether a mount's characteristic is nonlinear (stepped implicitly)."""
        return any(mount.progressive for mount in self.body.layout.mounts)

    @property
    def size(self) -> int:
        """The state's length: 12 and the branches."""
        return 12 + len(self.branches)

    def equilibrium(self, load: np.ndarray) -> np.ndarray:
        """``Q`` of the static equilibrium under the generalised ``load`` (the weight's included)."""
        return _equilibrium(self.body, load)

    def start_displacement(self, force: np.ndarray) -> np.ndarray:
        """``q`` of the static equilibrium under the generalised ``force`` and the weight, from the weight's: where
        the model starts (``K^-1 force`` on linear mounts, Newton's root of the characteristics on progressive)."""
        if self.progressive:
            return self.equilibrium(self.weight + force) - self.weight_sag
        return self.body.static_displacement(force)

    def static_sag(self, g: float, mean_torque: float) -> np.ndarray:
        """Static displacement from the unloaded mounts under the weight and ``-mean_torque`` about the motor axis."""
        return self.equilibrium(self.body.gravity(g) + _torque(self.placement, mean_torque))

    def wind_up(self, sag: np.ndarray) -> float:
        """The rotation about the motor axis from the weight's equilibrium to ``sag``, positive along the
        drive torque's reaction ``-e`` (so positive for a positive ``T_mean``)."""
        return float(-(sag[3:] - self.weight_sag[3:]) @ self.placement.motor_axis)

    def operating_modes(self, sag: np.ndarray) -> Modes:
        """The modes linearised about the static equilibrium ``sag``: the tangent rates there, the
        branches at each mode's frequency (:func:`.rigid_body.modes`)."""
        stiffness = tangent_stiffness(self.body.layout, sag) if self.progressive else None
        return modes(self.body, stiffness, self.branches.stiffness if len(self.branches) else None)

    def torque_roll_axis(self) -> np.ndarray:
        return torque_roll_axis(self.body.layout.inertia, self.placement.motor_axis)

    def accelerations(self, state: np.ndarray, force: np.ndarray) -> np.ndarray:
        """``q''`` at ``state`` under the generalised force ``force``."""
        if not self.progressive:
            return (self.a @ state + self.b @ force)[6:12]
        q, velocity, z = state[:6], state[6:12], state[12:]
        total = (force + self.weight - elastic_load(self.body.layout, self.weight_sag + q)
                 - self.body.damping @ velocity - self.branches.rows.T @ z)
        return np.linalg.solve(self.body.mass, total)

    def derivatives(self, state: np.ndarray, force: np.ndarray) -> np.ndarray:
        """``s' = (q', q'', z')`` at ``state`` ``(q, q', z)`` under the generalised ``force``: equation (1) with
        the branches' forces, ``q'' = M^-1 (f + W - F(Q) - C q' - R^T z)``, and (R2), ``z' = g (R q') - z / tau``
        (Model Exchange's right-hand side: the ODE whose solution the exact and the implicit steps take)."""
        branches = self.branches
        z_rate = branches.gains * (branches.rows @ state[6:12]) - state[12:] / branches.times
        return np.concatenate([state[6:12], self.accelerations(state, force), z_rate])

    def derivative_jacobian(self, state: np.ndarray) -> np.ndarray:
        """``d s' / d s`` (n x n) at ``state``: ``a``, with ``-M^-1 K_t(Q)`` for the displacements where the
        characteristics are progressive (``d s' / d f`` is ``b`` everywhere)."""
        if not self.progressive:
            return self.a
        found = self.a.copy()
        found[6:12, :6] = -np.linalg.solve(self.body.mass,
                                           tangent_stiffness(self.body.layout, self.weight_sag + state[:6]))
        return found

    def acceleration_scales(self, state: np.ndarray, force: np.ndarray) -> np.ndarray:
        """The sum of the magnitudes of the terms of each ``q''`` (:meth:`accelerations`): zero in
        an equilibrium, the computed ``q''`` is its rounding error, a few eps times this."""
        if not self.progressive:
            return (np.abs(self.a) @ np.abs(state) + np.abs(self.b) @ np.abs(force))[6:12]
        inverse = np.abs(np.linalg.inv(self.body.mass))
        loads = (np.abs(force) + np.abs(self.weight) + _elastic_magnitude(self.body.layout, self.weight_sag + state[:6])
                 + np.abs(self.body.damping) @ np.abs(state[6:12]) + np.abs(self.branches.rows.T) @ np.abs(state[12:]))
        return inverse @ loads

    def mount_forces(self, state: np.ndarray) -> np.ndarray:
        """Each mount's force on the powertrain (rows), the weight's preload included."""
        if not self.progressive and not len(self.branches):
            return self.body.mount_forces(self.weight_sag + state[:6], state[6:12])
        layout = self.body.layout
        elastic = elastic_forces(layout, self.weight_sag + state[:6])
        forces = []
        for mount, to_axes, spring, branch in zip(layout.mounts, layout.maps, elastic,
                                                  self.branches.per_mount(layout, state[12:])):
            local = spring + mount.damping * (to_axes @ state[6:12]) + branch
            forces.append(-(mount.axes.T @ local))
        return np.array(forces)


def _torque(placement: Placement, mean_torque: float) -> np.ndarray:
    """The generalised force of the reaction ``-mean_torque`` about the motor axis."""
    return np.concatenate([np.zeros(3), -mean_torque * placement.motor_axis])


def _elastic_magnitude(layout: Layout, q: np.ndarray) -> np.ndarray:
    """``sum_i |T_i^T A_i^T| |F_i| + |K_t(q)| max|q|``: the scale of :func:`.forces.elastic_load`'s rounding,
    and of the equilibrium's: Newton's solves leave each coordinate of q within cond(K_t) eps of the largest,
    so a coordinate of the load (a lateral one, nearly zero under the weight) rounds with its row of K_t
    times max|q|."""
    return (sum(np.abs(to_axes.T) @ np.abs(f) for to_axes, f in zip(layout.maps, elastic_forces(layout, q)))
            + np.abs(tangent_stiffness(layout, q)) @ np.full(6, np.max(np.abs(q))))


def _equilibrium(body: RigidBody, load: np.ndarray) -> np.ndarray:
    """``K^-1 load`` for linear mounts (as ever), else Newton's root of the characteristics."""
    if not any(mount.progressive for mount in body.layout.mounts):
        return body.static_displacement(load)
    return equilibrium(body.layout, load, body.stiffness)
