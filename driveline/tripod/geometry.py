"""Geometry of the tripod coupling and the paper's symbols derived from it.

Frames (seed 000, eqs 1-2): the input frame O'X'Y'Z' has Z' along the input shaft;
the nominal output axis is ``e_out = (-sin beta, 0, cos beta)``, so the bend plane is
X'Z' and the output shaft leans towards -X'. Groove j (j = 0, 1, 2) of the input
sleeve runs parallel to Z' at radius r and angle ``phi_in + 2 pi j / 3``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..scalar import Real, lib

THIRD_TURN = 2.0 * np.pi / 3.0
ARM_INDEX = np.arange(3)


def orbit_radius(beta: Real, r: float) -> Real:
    """Radius rho of the tripod centre's orbit, ``rho = r (1 - cos beta) / (2 cos beta)``.

    The paper uses rho without giving it. Cutting the three grooves with the tripod
    plane (normal to the output axis) gives three points at parametric angles 120 deg
    apart on an ellipse with semi-axes r / cos(beta) (bend plane) and r. A 120 deg
    star through three such points has its centre at distance (a - b) / 2 from the
    ellipse centre, ``-rho (cos 3 phi_in, sin 3 phi_in)``: three orbits per turn in the
    shaft's sense of rotation.
    """
    cos_beta = lib(beta).cos(beta)
    return r * (1.0 - cos_beta) / (2.0 * cos_beta)


def arm_lengths(phi: ArrayLike, beta: ArrayLike, r: float) -> NDArray[np.float64]:
    """Distances h_i from the tripod centre to the ball centres, shape (..., 3).

    Corrected eq 21: ``h_i = r + rho + 2 rho cos 2(phi_in + 2 pi i / 3)``. The seed prints
    ``r - rho - 2 rho cos 2(phi + 2 pi i / 3)`` with its phi = phi_in + pi/2, whose
    oscillating part is the same; but the tripod-plane ellipse is longer than r in the
    bend plane, so the mean arm length is r + rho, not r - rho (checked against
    :mod:`.exact`).
    """
    phi = np.asarray(phi, dtype=float)[..., None]
    rho = np.asarray(orbit_radius(np.asarray(beta, dtype=float), r))[..., None]
    return r + rho + 2.0 * rho * np.cos(2.0 * (phi + THIRD_TURN * ARM_INDEX))
