"""A halfshaft between an inboard plunging joint whose housing moves with the powertrain and an
outboard joint fixed at its wheel: the inboard joint's bend angle, bend-plane angle and plunge, with
their first and second time derivatives, from the housing's 6-DOF motion at the joint centre.

The housing carries the joint frame X'Y'Z' (columns of ``frame`` in vehicle axes; Z' its axis towards
the wheel). The inboard joint's centre (the spider's) slides along Z' by the plunge ``p`` from the
housing's reference point O; the outboard joint's centre W is fixed, and the shaft between the two
centres keeps its length L. With ``a = frame^T (W - O)`` the wheel centre in the housing frame,
``rho = |(a_x, a_y)|`` and ``h = sqrt(L^2 - rho^2)``:

    (H1) p = a_z - h                                   the spider's position along Z'
    (H2) sin beta = rho / L,  cos beta = h / L         the bend angle
    (H3) a_x = -rho cos psi,  a_y = -rho sin psi       the bend-plane angle psi about Z'

``psi`` = 0 is TripodCoupling's bend plane: the output shaft leans towards -X'. The rates follow from
those of ``a`` (the housing turns at ``omega`` with angular acceleration ``omega_dot``, its point O
moves at ``v`` with acceleration ``acc``; ``s = W - O``, ``s' = -v``, ``s'' = -acc``):

    (H4) a'  = frame^T (s' - omega x s)
    (H5) a'' = frame^T (s'' - omega_dot x s - 2 omega x s' + omega x (omega x s))

and, by differentiating (H1)-(H3): ``rho' = (a_x a_x' + a_y a_y') / rho``, ``beta' = rho' / h``,
``psi' = (a_x a_y' - a_y a_x') / rho^2``, ``p' = a_z' + rho rho' / h``, and their second derivatives
below. A straight shaft (rho = 0) has no bend plane: psi is 0 there and its rates 0, beta's rates those of
a bend in the plane psi = 0 (the lean along -X').
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class HousingMotion:
    """The housing at the joint centre, vehicle axes: its frame (columns X', Y', Z'), the position of its
    reference point O, that point's velocity and acceleration, the angular velocity and acceleration."""

    frame: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    omega: np.ndarray
    omega_dot: np.ndarray

    @classmethod
    def at_rest(cls, frame: np.ndarray, position: np.ndarray) -> HousingMotion:
        zero = np.zeros(3)
        return cls(np.asarray(frame, float), np.asarray(position, float), zero, zero, zero, zero)


@dataclass(frozen=True)
class ShaftGeometry:
    """The inboard joint's bend angle [rad], bend-plane angle [rad] and plunge [m], each with its first
    and second time derivatives."""

    beta: float
    beta_dot: float
    beta_ddot: float
    psi: float
    psi_dot: float
    psi_ddot: float
    plunge: float
    plunge_dot: float
    plunge_ddot: float


class GeometryError(ValueError):
    """A halfshaft that cannot join its wheel: shorter than the wheel centre's distance from the axis."""


def wheel_in_housing(motion: HousingMotion, wheel: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``a``, ``a'`` and ``a''`` of (H4, H5): the wheel centre in the housing frame and its rates."""
    frame, omega = motion.frame, motion.omega
    s = np.asarray(wheel, float) - motion.position
    s_dot, s_ddot = -motion.velocity, -motion.acceleration
    a = frame.T @ s
    a_dot = frame.T @ (s_dot - np.cross(omega, s))
    a_ddot = frame.T @ (s_ddot - np.cross(motion.omega_dot, s) - 2.0 * np.cross(omega, s_dot)
                        + np.cross(omega, np.cross(omega, s)))
    return a, a_dot, a_ddot


def shaft_geometry(motion: HousingMotion, wheel: np.ndarray, length: float) -> ShaftGeometry:
    """(H1)-(H5) for the shaft of ``length`` L to the wheel centre ``wheel``; GeometryError when the wheel
    centre lies farther than L from the housing's axis."""
    a, a_dot, a_ddot = wheel_in_housing(motion, wheel)
    ax, ay, az = (float(c) for c in a)
    rho2 = ax * ax + ay * ay
    if not rho2 < length * length:
        raise GeometryError(f"the wheel centre lies {math.sqrt(rho2):.6g} m from the housing's axis, beyond the "
                            f"halfshaft's length {length:.6g} m")
    rho = math.sqrt(rho2)
    h = math.sqrt(length * length - rho2)
    # along the radial and tangential directions (the lean direction -(cos psi, sin psi) and its normal)
    if rho > 0.0:
        er = (ax / rho, ay / rho)
    else:
        er = (-1.0, 0.0)
    radial = er[0] * a_dot[0] + er[1] * a_dot[1]           # rho'
    tangential = er[0] * a_dot[1] - er[1] * a_dot[0]       # rho psi'
    radial_acc = er[0] * a_ddot[0] + er[1] * a_ddot[1]     # a'' along e_r
    tangential_acc = er[0] * a_ddot[1] - er[1] * a_ddot[0]  # a'' along e_psi
    psi = math.atan2(-ay, -ax)
    if rho > 0.0:
        psi_dot = tangential / rho
        rho_ddot = radial_acc + rho * psi_dot * psi_dot    # polar coordinates: a''.e_r = rho'' - rho psi'^2
        psi_ddot = (tangential_acc - 2.0 * radial * psi_dot) / rho  # a''.e_psi = rho psi'' + 2 rho' psi'
    else:
        psi_dot = psi_ddot = 0.0
        rho_ddot = radial_acc
    beta = math.atan2(rho, h)
    beta_dot = radial / h
    h_dot = -rho * radial / h
    # beta' = rho' / h  =>  beta'' = (rho'' h - rho' h') / h^2
    beta_ddot = (rho_ddot * h - radial * h_dot) / (h * h)
    plunge = az - h
    plunge_dot = float(a_dot[2]) - h_dot
    # h'' from h^2 + rho^2 = L^2: h h'' + h'^2 + rho rho'' + rho'^2 = 0
    h_ddot = -(h_dot * h_dot + rho * rho_ddot + radial * radial) / h
    plunge_ddot = float(a_ddot[2]) - h_ddot
    return ShaftGeometry(beta, beta_dot, beta_ddot, psi, psi_dot, psi_ddot, plunge, plunge_dot, plunge_ddot)


def design_wheel(frame: np.ndarray, position: np.ndarray, length: float, beta: float, psi: float = 0.0,
                 plunge: float = 0.0) -> np.ndarray:
    """The wheel centre that gives the joint at rest the bend ``beta``, plane ``psi`` and ``plunge``:
    the inverse of (H1)-(H3)."""
    rho, h = length * math.sin(beta), length * math.cos(beta)
    local = np.array([-rho * math.cos(psi), -rho * math.sin(psi), plunge + h])
    return np.asarray(position, float) + np.asarray(frame, float) @ local
