"""Forces of the coupling as the seed prints them (seed 000, eqs 20-34), neglecting friction and gravity.

Every phi in the seed's formulas is its own angle, ``phi_in + PAPER_PHASE``.
They are wrong (docs/tripod_coupling.md) and reachable only with ``seed_reactions = 1``; the
force balance is in :mod:`.reactions`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..scalar import Real, lib
from .closed_form import paper_angle
from .exact import exact_pose

Array = NDArray[np.float64]


def pin_force(torque: Real, rho: Real, r: float) -> Real:
    """Force F on each tripod arm, normal to the arm in the tripod plane [N].

    Eq 24 with the arm lengths of the corrected eq 21: ``F = T0 / (h1 + h2 + h3)
    = T0 / (3 r + 3 rho)``; the seed prints 3 r - 3 rho. ``rho`` from :func:`.geometry.orbit_radius`.
    """
    return torque / (3.0 * (r + rho))


class Reactions(NamedTuple):
    """The seed's plunger-acceleration sum and bearing reactions at one or more configurations."""

    a_plunger_sum: Real  # eq 20 [m/s^2]
    Rz_out: Real  # eq 30, output self-aligning bearing, axial [N]
    Rx_in: Real  # eq 33, input bearing [N]
    Ry_in: Real  # eq 34, input bearing [N]


def reactions(phi_in: Real, beta: Real, omega: Real, rho: Real, l: float, m: float) -> Reactions:
    """Eqs 20, 30, 33, 34 as printed, with the seed's phi = ``paper_angle(phi_in)`` and ``rho``
    from :func:`.geometry.orbit_radius`:

    * eq 20: ``a1 + a2 + a3 = -6 omega^2 rho sin(beta) cos 3 phi``
    * eq 30: ``R_z'' = -6 m rho omega^2 tan(beta) cos 3 phi``
    * eq 33: ``R_x' = tan(beta) m (a1 + a2 + a3)``
    * eq 34: ``R_y' = -(3 m rho^2 omega^2 tan(beta) sin 6 phi) / l``
    """
    xp = lib(phi_in, beta)
    omega_squared = omega * omega
    tan_beta = xp.tan(beta)
    phi = paper_angle(phi_in)
    cos_3phi = xp.cos(3.0 * phi)
    a_sum = -6.0 * omega_squared * rho * xp.sin(beta) * cos_3phi
    return Reactions(
        a_plunger_sum=a_sum,
        Rz_out=-6.0 * m * rho * omega_squared * tan_beta * cos_3phi,
        Rx_in=tan_beta * m * a_sum,
        Ry_in=-3.0 * m * rho * rho * omega_squared * tan_beta * xp.sin(6.0 * phi) / l,
    )


def input_torque(load_torque: Real, speed_ratio: Real) -> Real:
    """Power balance of the lossless coupling: ``T_in omega_in = T_load omega_out`` [N.m].

    Written with the kinematic ratio d(phi_out)/d(phi_in), so it holds at standstill too.
    """
    return load_torque * speed_ratio


def exact_plunger_accelerations(beta: float, r: float, l: float, omega: float, samples: int = 360) -> tuple[Array, Array]:
    """Plunger accelerations along the grooves from the exact kinematics, at constant omega.

    Returns ``(phi_in, a)`` with ``a`` of shape (samples, 3): the second derivative of each
    ball centre's Z' travel over one turn, by spectral differentiation (the travel is
    smooth and 2 pi periodic, so this is exact to round-off for enough samples).
    """
    phi = np.linspace(0.0, 2.0 * np.pi, samples, endpoint=False)
    travel = exact_pose(phi, beta, r, l).plunger_positions
    harmonic = np.fft.rfftfreq(samples, d=1.0 / samples)[:, None]
    second_derivative = np.fft.irfft(-(harmonic**2) * np.fft.rfft(travel, axis=0), n=samples, axis=0)
    return phi, omega * omega * second_derivative
