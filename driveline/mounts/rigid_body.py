"""The powertrain as a rigid body on linear mounts: matrices, statics, modes, decoupling.

Coordinates ``q = (x, y, z, roll, pitch, yaw)``: the displacement of the centre of gravity and
the small rotations about the vehicle axes x, y, z (ISO 8855), from the static equilibrium.
A point ``p`` of the body moves by ``u = t + theta x (p - c) = T(p) q`` with
``T(p) = [I, -[p - c]x]`` (c the centre of gravity, ``[a]x`` the cross-product matrix), so

* mass matrix ``M = diag(m I, J)`` (J the inertia tensor about the centre of gravity),
* mount i with axes A_i (rows) adds ``T_i^T A_i^T diag(k_i) A_i T_i`` to the stiffness
  matrix K and the same with ``c_i`` to the damping matrix C,
* a force F at p and a moment N add ``T(p)^T F + (0, N)`` to the generalised force.

Equations of motion ``M q'' + C q' + K q = f(t)``. The modes solve ``K phi = w^2 M phi``
(:func:`scipy.linalg.eigh`); the kinetic-energy share of coordinate k in mode j is
``phi_jk (M phi_j)_k / (phi_j^T M phi_j)``: each mode's shares sum to one (a product of
inertia can make a rotational share slightly negative).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.linalg import eigh

from .layout import Layout, cross_matrix, point_map  # noqa: F401  (the body's point map, used here and by tests)

#: The coordinates in order, as the outputs name them.
COORDINATES = ("x", "y", "z", "roll", "pitch", "yaw")
#: A mode whose frequency lies below this fraction of the highest is a rigid-body motion the
#: mounts leave unrestrained (real layouts span a factor of 3 to 10).
MIN_FREQUENCY_RATIO = 1e-4


@dataclass(frozen=True)
class RigidBody:
    """Mass, stiffness and damping matrices of a layout (6 x 6, in the coordinates above)."""

    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    layout: Layout

    @classmethod
    def of(cls, layout: Layout) -> RigidBody:
        mass = np.zeros((6, 6))
        mass[:3, :3] = layout.mass * np.eye(3)
        mass[3:, 3:] = layout.inertia
        stiffness, damping = np.zeros((6, 6)), np.zeros((6, 6))
        for mount in layout.mounts:
            to_axes = mount.axes @ point_map(mount.position, layout.centre_of_gravity)
            stiffness += to_axes.T @ (mount.stiffness[:, None] * to_axes)
            damping += to_axes.T @ (mount.damping[:, None] * to_axes)
        return cls(mass, stiffness, damping, layout)

    def load(self, point: np.ndarray, force: np.ndarray, moment: np.ndarray) -> np.ndarray:
        """Generalised force of ``force`` at ``point`` and the free ``moment`` (vehicle axes)."""
        return np.concatenate([force, np.cross(np.asarray(point) - self.layout.centre_of_gravity, force) + moment])

    def gravity(self, g: float) -> np.ndarray:
        """Generalised force of the weight (along -z, at the centre of gravity)."""
        return np.array([0.0, 0.0, -self.layout.mass * g, 0.0, 0.0, 0.0])

    def static_displacement(self, load: np.ndarray) -> np.ndarray:
        """``K^-1 load``: the static displacement under a constant generalised force."""
        return np.linalg.solve(self.stiffness, load)

    def mount_forces(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """Force of each mount on the powertrain (vehicle axes, one row per mount) at
        displacement ``q`` and velocity ``qdot`` measured from the unloaded mounts."""
        forces = []
        for mount in self.layout.mounts:
            to_axes = mount.axes @ point_map(mount.position, self.layout.centre_of_gravity)
            local = mount.stiffness * (to_axes @ q) + mount.damping * (to_axes @ qdot)
            forces.append(-(mount.axes.T @ local))
        return np.array(forces)


@dataclass(frozen=True)
class Modes:
    """Undamped modes: ``frequencies`` [Hz] ascending, ``shapes`` (columns, mass-normalised),
    ``shares`` (row j: the kinetic-energy distribution of mode j over the coordinates), and the
    damping ratios of the modal strain energy (equation (4) of docs/powertrain_mounts.md)."""

    frequencies: np.ndarray
    shapes: np.ndarray
    shares: np.ndarray
    damping_ratios: np.ndarray

    @property
    def dominant(self) -> np.ndarray:
        """Index of each mode's largest share."""
        return np.argmax(self.shares, axis=1)


#: The relative change of a mode's frequency at which its fixed point (below) stops, and its iterations at most.
FREQUENCY_TOLERANCE = 1e-13
MAX_FREQUENCY_ITERATIONS = 100

BranchStiffness = Callable[[float], "tuple[np.ndarray, np.ndarray, np.ndarray]"]


def modes(body: RigidBody, stiffness: np.ndarray | None = None, branches: BranchStiffness | None = None) -> Modes:
    """The six modes of ``body`` about an operating point whose tangent stiffness is ``stiffness``
    (default: the mounts' linear rates), with the Maxwell branches' storage and loss stiffness and the
    storage's slope ``w dK_s/dw`` at a frequency, ``branches(f)`` (None: none). Without branches the
    undamped modes of ``K`` and ``M`` (eigenvalues below zero by rounding read as zero); with them each
    mode j is the fixed point of ``(K + K_s(f_j)) phi_j = (2 pi f_j)^2 M phi_j``, the storage stiffness at
    its own frequency. The damping ratio is equation (4) of docs/powertrain_mounts.md,
    ``zeta_j = phi^T K_l phi / (2 phi^T K_s,total phi - phi^T w dK_s/dw phi)`` with the loss stiffness
    ``K_l = 2 pi f C + K_l,branches``: the modal strain energy's ratio, with the first-order correction
    for a storage stiffness that grows with frequency (the pole of ``s^2 m + K(s)``)."""
    stiffness = body.stiffness if stiffness is None else stiffness
    eigenvalues, shapes = eigh(stiffness, body.mass)
    frequencies = np.sqrt(np.maximum(eigenvalues, 0.0)) / (2.0 * math.pi)
    ratios = np.zeros(6)
    for j in range(6):
        storage, loss, slope = stiffness, np.zeros((6, 6)), np.zeros((6, 6))
        if branches is not None:
            frequency = frequencies[j]
            for _ in range(MAX_FREQUENCY_ITERATIONS):
                extra, loss, slope = branches(frequency)
                storage = stiffness + extra
                values, vectors = eigh(storage, body.mass)
                previous, frequency = frequency, math.sqrt(max(values[j], 0.0)) / (2.0 * math.pi)
                if abs(frequency - previous) <= FREQUENCY_TOLERANCE * frequency:
                    break
            frequencies[j], shapes[:, j] = frequency, vectors[:, j]
            extra, loss, slope = branches(frequency)
            storage = stiffness + extra
        shape = shapes[:, j]
        loss = loss + 2.0 * math.pi * frequencies[j] * body.damping
        energy = 2.0 * float(shape @ storage @ shape) - float(shape @ slope @ shape)
        ratios[j] = float(shape @ loss @ shape) / energy if energy > 0.0 else 0.0
    momenta = body.mass @ shapes
    shares = (shapes * momenta).T / np.sum(shapes * momenta, axis=0)[:, None]
    return Modes(frequencies, shapes, shares, ratios)


def unrestrained_error(found: Modes) -> str | None:
    """Why the mounts do not hold the body, or None: a mode below MIN_FREQUENCY_RATIO of the highest."""
    lowest, highest = found.frequencies[0], found.frequencies[-1]
    if lowest >= MIN_FREQUENCY_RATIO * highest:
        return None
    coordinate = COORDINATES[int(found.dominant[0])]
    return (f"the mounts leave a rigid-body motion unrestrained (mode 1, mostly {coordinate}, at {lowest:.3g} Hz, "
            f"below {MIN_FREQUENCY_RATIO:g} of the highest mode, {highest:.6g} Hz): add a mount or move "
            "one off the line or plane of the others")


def torque_roll_axis(inertia: np.ndarray, torque_axis: np.ndarray) -> np.ndarray:
    """Unit direction of the torque roll axis: the free body's angular acceleration ``J^-1 e``
    under a torque about ``torque_axis`` (e.g. the crankshaft), signed to lie along it."""
    axis = np.linalg.solve(inertia, torque_axis)
    axis = axis / np.linalg.norm(axis)
    return axis if axis @ torque_axis >= 0.0 else -axis
