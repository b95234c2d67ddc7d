"""Kinematics and strength relations of the universal reducer (seed 004), vectorised.

Angle convention: ``alpha`` is the seed's intersection angle (alpha_40 = alpha_14 =
alpha_23) between the input axis a and the output axis d, each taken from their
intersection point O towards its own shaft; ``alpha = 180 deg`` is coaxial shafts
(eq 15's slide vanishes there). ``phi_in`` is the input (carrier) angle about the input
axis in the direction of power flow, zero with the eccentric (axis b) normal to the
bend plane; this is the zero that gives eq 15 its ``sin theta_1``.

Kinematics (eqs 8-17): axes b and c stay parallel to a and d and meet at E, which
lies in the plane through O that bisects the shafts (the homokinetic plane). The axis
of the revolute pair f is normal to both b and c, hence fixed in direction, so the
connecting shafts 2 and 3 only translate (eq 16: theta_2 = -theta_1 relative to shaft 1)
and E turns about d through the same angle phi_in as about a. The planet, fixed to
shaft 3, orbits the centre gear without spinning, so eq 1 with omega_2 = 0 gives eq 17:
``phi_out = phi_in / i`` at any intersection angle, changing or not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]


def transmission_ratio(z1: int, z2: int) -> float:
    """Eqs 4 and 17: ``i = omega_H / omega_1 = z1 / (z1 - z2)`` (centre gear z1, planet z2)."""
    return z1 / (z1 - z2)


def cylinder_slide(phi_in: ArrayLike, alpha: ArrayLike, e: float) -> Array:
    """Eq 15: axial travel of the connecting shaft in the cylindrical pair b [m].

    ``s_1 - s_0 = h_1 (1 + cos alpha) sin theta_1 / sin alpha = e cot(alpha/2) sin phi_in``,
    counted along the input axis towards O (the seed's minus sign belongs to its z_1,
    which the missing figure 4 orients). h_1 is the eccentricity e.
    """
    phi_in = np.asarray(phi_in, dtype=float)
    half = 0.5 * np.asarray(alpha, dtype=float)
    return e * np.cos(half) / np.sin(half) * np.sin(phi_in)


@dataclass(frozen=True)
class ConnectingShaftLoads:
    """Loads on the connecting shafts 2 and 3 at the seed's critical (highest) position."""

    M_out: Array  # output torque, eq 18 [N.m]
    F_B: Array  # eccentric force at B, M_in / r [N]
    M_E: Array  # moment at E, eq 19 [N.m]
    F_t: Array  # tangential gear force, eq 20 [N]
    M_C1: Array  # torque on shaft 3 at C from the planet, eq 20 [N.m]
    M_B: Array  # moment at B, eq 21 [N.m]
    M_C: Array  # bending moment of shaft 3 at C, eq 21 [N.m]


def connecting_shaft_loads(
    M_in: ArrayLike, alpha: ArrayLike, z1: int, z2: int, module: float, e: float, L1: float
) -> ConnectingShaftLoads:
    """Eqs 18-21 for an input torque ``M_in`` [N.m] at intersection angle ``alpha``.

    The shafts 2 and 3 include the angle 2a = alpha. r (eq 19) is the eccentricity e;
    r2 (eq 20) is the planet's pitch radius m z2 / 2, the lever of F_t about the planet
    axis c. Eq 21, ``M_B sin a + M_C sin a - M_C1 cos a - M_E = 0`` and
    ``M_B cos a - M_C cos a - M_C1 sin a = 0``, has determinant ``-sin alpha``; solved:
    ``M_B = M_C1 / sin alpha + M_E / (2 sin a)``, ``M_C = M_C1 cot alpha + M_E / (2 sin a)``.
    It is singular for coaxial shafts (alpha = 180 deg), where a single RCRCR chain
    cannot hold the planet against spinning.
    """
    M_in = np.asarray(M_in, dtype=float)
    alpha = np.asarray(alpha, dtype=float)
    half = 0.5 * alpha
    M_out = transmission_ratio(z1, z2) * M_in
    F_B = M_in / e
    M_E = 2.0 * F_B * L1 * np.sin(half)
    F_t = 2.0 * M_out / (module * z1)
    M_C1 = F_t * 0.5 * module * z2
    shared = M_E / (2.0 * np.sin(half))
    return ConnectingShaftLoads(
        M_out=M_out,
        F_B=F_B,
        M_E=M_E,
        F_t=F_t,
        M_C1=M_C1,
        M_B=M_C1 / np.sin(alpha) + shared,
        M_C=M_C1 * np.cos(alpha) / np.sin(alpha) + shared,
    )


@dataclass(frozen=True)
class ShaftStress:
    """Stresses at the surface of a solid round shaft [Pa]."""

    sigma: Array  # bending stress M / W, W = pi d^3 / 32
    tau: Array  # torsional stress T / W_t, W_t = pi d^3 / 16
    sigma_eq: Array  # third strength theory (Tresca): sqrt(sigma^2 + 4 tau^2)


def shaft_stress(bending: ArrayLike, torsion: ArrayLike, radius: float) -> ShaftStress:
    """Bending, torsion and equivalent stress of a solid shaft of the given radius.

    The seed's check of shaft 3 at C (bent by M_C, twisted by M_C1) breaks off before
    its equation; this is the third strength theory it names, ``sigma_eq <= [sigma]``.
    """
    section_modulus = 0.25 * np.pi * radius**3
    sigma = np.asarray(bending, dtype=float) / section_modulus
    tau = np.asarray(torsion, dtype=float) / (2.0 * section_modulus)
    return ShaftStress(sigma=sigma, tau=tau, sigma_eq=np.sqrt(sigma**2 + 4.0 * tau**2))
