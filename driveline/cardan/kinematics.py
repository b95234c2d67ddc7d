"""Exact kinematics of a Cardan (Hooke) joint (seed 003), vectorised over numpy arrays.

The seed does not number its equations; (C1)-(C5) are the labels of docs/cardan_joint.md.

Frames (seed 003): axle 1 turns about z and its yoke is ``x1 = (cos g1, sin g1, 0)``;
axle 2's plane of rotation is tilted by the bend angle beta about y, so the bend
plane is xz and ``x2 = (-cos b sin g2, cos g2, sin b sin g2)`` (C1). At ``g1 = 0`` the input
yoke lies in the bend plane. The project measures the shaft angles from a yoke
phase p: ``g1 = phi_in - p`` and ``phi_out = p + g2``, so the input yoke lies in the
bend plane at ``phi_in = p`` (mod pi) and ``phi_out = phi_in`` there and a quarter
turn later. Two joints whose yokes on the intermediate shaft are coplanar have
phases differing by pi/2.

The time derivatives below hold at constant beta: a changing bend angle adds
``d(g2)/d(beta) * d(beta)/dt``, which the seed's relations leave out (docs/cardan_joint.md).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]


def _yoke_terms(phi_in: ArrayLike, beta: ArrayLike, phase: ArrayLike) -> tuple[Array, Array, Array]:
    """``g1 = phi_in - phase``, ``cos beta`` and ``D = 1 - sin^2 beta cos^2 g1``."""
    gamma1 = np.asarray(phi_in, dtype=float) - np.asarray(phase, dtype=float)
    beta = np.asarray(beta, dtype=float)
    return gamma1, np.cos(beta), 1.0 - (np.sin(beta) * np.cos(gamma1)) ** 2


def output_angle(phi_in: ArrayLike, beta: ArrayLike, phase: ArrayLike = 0.0) -> Array:
    """Output angle ``phi_out`` [rad], continuous over any number of turns either way.

    (C2): ``x1 . x2 = 0`` gives ``tan g1 = cos b tan g2``; the seed's ``g2 = atan2(sin g1,
    cos b cos g1)`` holds only for ``-pi < g1 < pi``. Here ``g1 = n pi + r`` with n the
    nearest number of half turns and ``|r| <= pi/2``; since tan has period pi,
    ``g2 = n pi + atan2(sin r, cos b cos r)``, which meets ``g1`` at every multiple of pi/2
    and is therefore continuous (unwrapped).
    """
    gamma1, cos_beta, _ = _yoke_terms(phi_in, beta, phase)
    half_turns = np.round(gamma1 / np.pi)
    rest = gamma1 - half_turns * np.pi
    gamma2 = half_turns * np.pi + np.arctan2(np.sin(rest), cos_beta * np.cos(rest))
    return np.asarray(phase, dtype=float) + gamma2


def speed_ratio(phi_in: ArrayLike, beta: ArrayLike, phase: ArrayLike = 0.0) -> Array:
    """Kinematic ratio ``omega_2 / omega_1 = cos b / (1 - sin^2 b cos^2 g1)`` (C3)."""
    _, cos_beta, denominator = _yoke_terms(phi_in, beta, phase)
    return cos_beta / denominator


def output_speed(phi_in: ArrayLike, beta: ArrayLike, omega_in: ArrayLike, phase: ArrayLike = 0.0) -> Array:
    """Output speed ``omega_2 = omega_1 cos b / (1 - sin^2 b cos^2 g1)`` [rad/s] (C3)."""
    return np.asarray(omega_in, dtype=float) * speed_ratio(phi_in, beta, phase)


def output_acceleration(
    phi_in: ArrayLike,
    beta: ArrayLike,
    omega_in: ArrayLike,
    alpha_in: ArrayLike = 0.0,
    phase: ArrayLike = 0.0,
) -> Array:
    """Output acceleration a2 [rad/s2] (C4), with the input acceleration a1 = ``alpha_in``.

    ``a2 = a1 cos b / D - omega_1^2 cos b sin^2 b sin 2 g1 / D^2`` with ``D = 1 - sin^2 b cos^2 g1``.
    """
    gamma1, cos_beta, denominator = _yoke_terms(phi_in, beta, phase)
    omega_in = np.asarray(omega_in, dtype=float)
    sin2_beta = 1.0 - cos_beta**2
    return (
        np.asarray(alpha_in, dtype=float) * cos_beta / denominator
        - omega_in**2 * cos_beta * sin2_beta * np.sin(2.0 * gamma1) / denominator**2
    )


def speed_fluctuation(beta: ArrayLike) -> Array:
    """Output-speed fluctuation ``(max - min) / mean = tan b sin b`` at constant input speed (C5).

    From (C3): the maximum ``omega_1 / cos b`` at ``cos^2 g1 = 1``, the minimum
    ``omega_1 cos b`` at ``cos g1 = 0``, and the time mean ``omega_1`` (``phi_out - phi_in`` is
    periodic), so ``(1/cos b - cos b) = sin^2 b / cos b``. Taking the mean as (max + min)/2
    instead would give ``2 sin^2 b / (1 + cos^2 b)``.
    """
    beta = np.asarray(beta, dtype=float)
    return np.tan(beta) * np.sin(beta)
