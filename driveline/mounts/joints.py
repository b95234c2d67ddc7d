"""The inboard joints' loads on the powertrain, from TripodCoupling's outputs.

TripodCoupling gives, in its input frame X'Y'Z' (Z' along the input shaft, the housing's
axis, pointing to the wheel; the output shaft leans towards -X' in the bend plane X'Z'), the
force ``(Rx_in, Ry_in, Rz_in)`` and the moment ``(Mx_in, My_in, T_in)`` about the joint centre O
that the input bearing and the drive exert **on the input shaft** (the housing). The housing is
held in equilibrium by the joint and by the powertrain, so the joint's action on the housing,
which the housing passes to the powertrain, is the opposite: ``-(Rx_in, Ry_in, Rz_in)`` at O and
``-(Mx_in, My_in, T_in)`` (its axial part ``-Rz_in`` is the generated axial force, its moment
``-T_in`` about Z' the drive torque's reaction).
"""

from __future__ import annotations

import math

import numpy as np

#: The shortest accepted shaft direction and the smallest sine between shaft and bend directions.
MIN_DIRECTION = 1e-6


def joint_frame(shaft: np.ndarray, bend: np.ndarray, name: str) -> np.ndarray:
    """Columns X', Y', Z' in vehicle axes: Z' along ``shaft``, X' the part of ``bend`` normal to
    it, Y' = Z' x X'. ValueError naming the joint ``name`` when the directions do not span a plane or
    a length overflows (a direction of finite components that would otherwise turn into zeros)."""
    length, bend_length = float(np.linalg.norm(shaft)), float(np.linalg.norm(bend))
    for what, size in (("halfshaft", length), ("bend-plane", bend_length)):
        if math.isinf(size):
            raise ValueError(f"the {what} direction of the {name} joint is too long (its length overflows)")
    if not length >= MIN_DIRECTION:
        raise ValueError(f"the halfshaft direction of the {name} joint has no length ({length:.3g})")
    z_axis = shaft / length
    normal = bend - (bend @ z_axis) * z_axis
    sine = float(np.linalg.norm(normal))
    if not sine >= MIN_DIRECTION * max(bend_length, 1.0):
        raise ValueError(f"the bend-plane direction of the {name} joint is parallel to its halfshaft "
                         "direction or zero: it must point across the shaft")
    x_axis = normal / sine
    return np.column_stack([x_axis, np.cross(z_axis, x_axis), z_axis])


def housing_load(frame: np.ndarray, reactions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Force and moment (vehicle axes) of the joint on the powertrain at the joint centre, from
    ``reactions = (Rx_in, Ry_in, Rz_in, Mx_in, My_in, T_in)`` of TripodCoupling."""
    return -(frame @ reactions[:3]), -(frame @ reactions[3:])
