"""Closed forms of the frictionless reactions to leading order in r/l (the closed-form mode).

Same bodies, loads and sign conventions as :mod:`.reactions`. At leading order the output
shaft lies on its nominal axis, the tripod plane passes through O and each plunger travels
``z_j = r tan(beta) cos phi_j`` (``phi_j = phi_in + 2 pi j / 3``), so its axial force is
``m zddot_j = -m r tan(beta) (omega^2 cos phi_j + omegadot sin phi_j)``; a changing bend adds
``m r sec^2(beta) (cos phi_j (betaddot + 2 tan(beta) betadot^2) - 2 omega betadot sin phi_j)``
(the second derivative of ``r tan(beta) cos phi_j``), the only rate term of this mode. The plungers'
radial and tangential inertia forces at these heights and the axial ones give, with
``A = 3/2 m r^2 tan(beta) / cos^2(beta)`` and ``t = tan(beta / 2)``:

* input bearing: ``Rx_in = -A omega^2 / (l cos beta)``,
  ``Ry_in = -(T_load t + A omegadot cos(beta)) / l``;
  about O ``Mx_in = -T_load t - 3/2 m r^2 tan(beta) omegadot``, ``My_in = -A omega^2``;
* output bearing (frame E1, E2, U): ``Rx_out = A omega^2 / l``, ``Ry_out = -Ry_in``,
  ``Rz_out = -A omega^2 tan(beta) / l``;
* input torque: ``T_in = T_load d(phi_out)/d(phi_in) + 3 m r^2 (1 + tan^2(beta) / 2) omegadot``;
* tangential arm force: eq 24 corrected, ``T_load / (3 r + 3 rho)``, on every arm.

The 3rd-order parts of the reactions are one order higher in r/l (except ``T_in``'s, which
the kinematic ratio carries); their size against the exact reactions is in the docs page.
"""

from __future__ import annotations

from typing import NamedTuple

from ..scalar import Real, lib
from .geometry import THIRD_TURN


class LeadingOrderReactions(NamedTuple):
    """Fields as :class:`.reactions.ExactReactions` (without ``omega_spin``)."""

    Rx_in: Real
    Ry_in: Real
    Mx_in: Real
    My_in: Real
    T_in: Real
    Rx_out: Real
    Ry_out: Real
    Rz_out: Real
    F_arm: tuple[Real, Real, Real]
    F_plunger: tuple[Real, Real, Real]
    a_plunger_sum: Real


def leading_order_reactions(
    phi_in: Real, beta: Real, omega: Real, omega_dot: Real, T_load: Real,
    r: float, l: float, m: float, speed_ratio: Real, pin_force: Real,
    beta_dot: Real = 0.0, beta_ddot: Real = 0.0,
) -> LeadingOrderReactions:
    """The closed forms above; ``speed_ratio`` d(phi_out)/d(phi_in) and ``pin_force`` from
    the closed-form kinematics and eq 24; ``beta_dot``, ``beta_ddot`` the bend angle's rates."""
    xp = lib(phi_in, beta)
    cb = xp.cos(beta)
    tb = xp.sin(beta) / cb
    half = xp.sin(beta) / (1.0 + cb)  # tan(beta / 2)
    A = 1.5 * m * r * r * tb / (cb * cb)
    omega2 = omega * omega
    ry_in = -(T_load * half + A * omega_dot * cb) / l
    bend = m * r / (cb * cb)
    bend_rates = beta_ddot + 2.0 * tb * beta_dot * beta_dot
    forces = []
    for j in range(3):
        angle = phi_in + THIRD_TURN * j
        c, s = xp.cos(angle), xp.sin(angle)
        forces.append(-m * r * tb * (omega2 * c + omega_dot * s) + bend * (c * bend_rates - 2.0 * omega * beta_dot * s))
    return LeadingOrderReactions(
        Rx_in=-A * omega2 / (l * cb),
        Ry_in=ry_in,
        Mx_in=-T_load * half - 1.5 * m * r * r * tb * omega_dot,
        My_in=-A * omega2,
        T_in=T_load * speed_ratio + 3.0 * m * r * r * (1.0 + 0.5 * tb * tb) * omega_dot,
        Rx_out=A * omega2 / l,
        Ry_out=-ry_in,
        Rz_out=-A * omega2 * tb / l,
        F_arm=(pin_force, pin_force, pin_force),
        F_plunger=(forces[0], forces[1], forces[2]),
        a_plunger_sum=0.0 * phi_in,
    )
