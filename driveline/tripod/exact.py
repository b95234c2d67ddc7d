"""Exact closed-loop kinematics of the coupling, solved numerically.

The output shaft is a rigid body pivoting about the self-aligning bearing centre
``S = l e_out``; the tripod centre sits on the shaft axis at ``P = S - l u``. The
shaft's orientation is ``M(beta) W(a) Rz(phi_out)``: M is the seed's eq 2 bend
rotation, W the swing (a rotation about the axis ``(a_x, a_y, 0)`` of the nominal
output frame, which tilts the shaft by the cone angle theta = |a| without twisting
it) and Rz the output spin. Arm j points along ``M W (cos, sin, 0)(phi_out + 2 pi j/3)``.

Closure: arm line j meets groove line j. Both lines are known in the input frame and
the grooves are parallel to Z', so the condition is that their projections on the
X'Y' plane meet, i.e. ``(P - g_j) x a_j = 0`` (2-D cross product): three equations in
``(phi_out, a_x, a_y)``, solved with Newton's method, batched over arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .closed_form import angle_deviation
from .geometry import ARM_INDEX, THIRD_TURN, orbit_radius

Array = NDArray[np.float64]

NEWTON_TOLERANCE = 1e-14  # rad; below the float64 resolution of angles of order 1e2
MAX_NEWTON_ITERATIONS = 30


@dataclass(frozen=True)
class ExactPose:
    """Solution of the closure for each sample (arrays of the input's shape)."""

    phi_out: Array  # output spin angle [rad]
    swing: Array  # (..., 2) swing rotation vector (a_x, a_y) in the nominal output frame [rad]
    tripod_centre: Array  # (..., 3) P in the input frame [m]
    arm_lengths: Array  # (..., 3) distance from P to the ball centre along each arm [m]
    plunger_positions: Array  # (..., 3) Z' coordinate of each ball centre (plunger travel) [m]
    speed_ratio: Array  # d(phi_out)/d(phi_in) at constant beta [-]

    @property
    def cone_angle(self) -> Array:
        """theta, the tilt of the output shaft from its nominal axis [rad]."""
        return np.hypot(self.swing[..., 0], self.swing[..., 1])


def _swing_apply(swing: Array, v: Array) -> Array:
    """Rotate vectors ``v`` (..., k, 3) by the rotation vector ``(a_x, a_y, 0)`` (Rodrigues)."""
    a = np.hypot(swing[..., 0], swing[..., 1])[..., None, None]
    axis_vec = np.concatenate([swing, np.zeros(swing.shape[:-1] + (1,))], axis=-1)[..., None, :]
    sin_term = np.sinc(a / np.pi)  # sin(a)/a
    cos_term = 0.5 * np.sinc(a / (2.0 * np.pi)) ** 2  # (1 - cos a)/a^2
    cross = np.cross(np.broadcast_to(axis_vec, v.shape), v)
    dot = np.sum(axis_vec * v, axis=-1, keepdims=True)
    return v * np.cos(a) + cross * sin_term + axis_vec * dot * cos_term


def _bend_apply(beta: Array, v: Array) -> Array:
    """Eq 2: map nominal-output-frame vectors (..., k, 3) to the input frame."""
    c = np.cos(beta)[..., None]
    s = np.sin(beta)[..., None]
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([c * x - s * z, y, s * x + c * z], axis=-1)


def _pose_vectors(phi_out: Array, swing: Array, beta: Array, l: float) -> tuple[Array, Array]:
    """Tripod centre P (..., 3) and arm directions (..., 3, 3) in the input frame."""
    arm_angles = phi_out[..., None] + THIRD_TURN * ARM_INDEX
    local = np.stack([np.cos(arm_angles), np.sin(arm_angles), np.zeros_like(arm_angles)], axis=-1)
    axis = np.zeros(phi_out.shape + (1, 3))
    axis[..., 2] = 1.0
    rotated = _bend_apply(beta, _swing_apply(swing, np.concatenate([local, axis], axis=-2)))
    arms, shaft_axis = rotated[..., :3, :], rotated[..., 3, :]
    nominal_axis = np.stack([-np.sin(beta), np.zeros_like(beta), np.cos(beta)], axis=-1)
    return l * (nominal_axis - shaft_axis), arms


def _groove_points(phi_in: Array, r: float) -> Array:
    angles = phi_in[..., None] + THIRD_TURN * ARM_INDEX
    return np.stack([r * np.cos(angles), r * np.sin(angles)], axis=-1)


def _residual(x: Array, phi_in: Array, beta: Array, r: float, l: float) -> Array:
    centre, arms = _pose_vectors(x[..., 0], x[..., 1:], beta, l)
    offset = centre[..., None, :2] - _groove_points(phi_in, r)
    return offset[..., 0] * arms[..., 1] - offset[..., 1] * arms[..., 0]


def _jacobian(x: Array, phi_in: Array, beta: Array, r: float, l: float) -> Array:
    """Central-difference Jacobian d(residual)/d(phi_out, a_x, a_y), shape (..., 3, 3).

    The step eps^(1/3) balances truncation and round-off (relative error ~1e-10).
    """
    step = 6e-6
    columns = []
    for k in range(3):
        dx = np.zeros(3)
        dx[k] = step
        columns.append((_residual(x + dx, phi_in, beta, r, l) - _residual(x - dx, phi_in, beta, r, l)) / (2 * step))
    return np.stack(columns, axis=-1)


def initial_guess(phi_in: ArrayLike, beta: ArrayLike, r: float, l: float) -> Array:
    """Start values from the small-r/l solution: eq 18 and the planar tripod-centre orbit.

    In the nominal output frame the tripod centre sits at ``-rho (cos 3 phi, sin 3 phi)``,
    so the shaft tilts by the swing ``(-rho sin 3 phi, rho cos 3 phi) / l``.
    """
    phi_in, beta = np.broadcast_arrays(np.asarray(phi_in, dtype=float), np.asarray(beta, dtype=float))
    rho_over_l = orbit_radius(beta, r) / l
    return np.stack(
        [
            phi_in + angle_deviation(phi_in, beta, r, l),
            -rho_over_l * np.sin(3.0 * phi_in),
            rho_over_l * np.cos(3.0 * phi_in),
        ],
        axis=-1,
    )


def solve_closure(
    phi_in: ArrayLike, beta: ArrayLike, r: float, l: float, start: ArrayLike | None = None
) -> Array:
    """Newton solution ``(phi_out, a_x, a_y)`` of the closure, shape (..., 3).

    ``start`` warm-starts the iteration (e.g. the previous time step's solution).
    Raises ``ArithmeticError`` if it does not converge.
    """
    phi_in, beta = np.broadcast_arrays(np.asarray(phi_in, dtype=float), np.asarray(beta, dtype=float))
    x = initial_guess(phi_in, beta, r, l) if start is None else np.array(start, dtype=float)
    for _ in range(MAX_NEWTON_ITERATIONS):
        residual = _residual(x, phi_in, beta, r, l)
        delta = np.linalg.solve(_jacobian(x, phi_in, beta, r, l), residual[..., None])[..., 0]
        x = x - delta
        if np.all(np.abs(delta) <= NEWTON_TOLERANCE * np.maximum(1.0, np.abs(x))):
            return x
    raise ArithmeticError("tripod closure: Newton iteration did not converge")


def exact_pose(
    phi_in: ArrayLike, beta: ArrayLike, r: float, l: float, start: ArrayLike | None = None
) -> ExactPose:
    """Solve the closure and derive the pose quantities at each (phi_in, beta)."""
    phi_in, beta = np.broadcast_arrays(np.asarray(phi_in, dtype=float), np.asarray(beta, dtype=float))
    x = solve_closure(phi_in, beta, r, l, start)
    centre, arms = _pose_vectors(x[..., 0], x[..., 1:], beta, l)
    grooves = _groove_points(phi_in, r)
    arms_xy = arms[..., :2]
    # Distance along arm j from P to the ball centre, where the arm meets groove j.
    along = np.sum((grooves - centre[..., None, :2]) * arms_xy, axis=-1) / np.sum(arms_xy**2, axis=-1)
    plunger_z = centre[..., None, 2] + along * arms[..., 2]
    # Implicit function theorem: dx/dphi_in = -J^-1 dF/dphi_in; only the grooves move with phi_in.
    d_grooves = np.stack([-grooves[..., 1], grooves[..., 0]], axis=-1)
    d_residual = -(d_grooves[..., 0] * arms[..., 1] - d_grooves[..., 1] * arms[..., 0])
    dx = -np.linalg.solve(_jacobian(x, phi_in, beta, r, l), d_residual[..., None])[..., 0]
    return ExactPose(
        phi_out=x[..., 0],
        swing=x[..., 1:],
        tripod_centre=centre,
        arm_lengths=along,
        plunger_positions=plunger_z,
        speed_ratio=dx[..., 0],
    )
