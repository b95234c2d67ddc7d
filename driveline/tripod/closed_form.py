"""Closed-form kinematics of the coupling for small r/l (seed 000, eqs 18-19).

All angles here follow the project's convention (groove 1 in the bend plane, on the
outer side of the bend, at ``phi_in = 0``). The seed measures its phi a quarter turn
later (see :data:`PAPER_PHASE`); converted, eq 18 reads ``A sin 3 phi_in``.
"""

from __future__ import annotations

import math

from ..scalar import Real, lib

PAPER_PHASE = 0.5 * math.pi
"""The seed's phi equals ``phi_in + PAPER_PHASE``: its phi = 0 has groove 1 normal to the
bend plane. Found by fitting eq 18 and eq 21 to the exact kinematics (docs/tripod_coupling.md)."""


def paper_angle(phi_in: Real) -> Real:
    """The seed's phi for the project's input angle."""
    return phi_in + PAPER_PHASE


def deviation_amplitude(beta: Real, r: float, l: float) -> Real:
    """Amplitude of eq 18, ``r (1 - cos b) / (2 l (1 + cos b)) tan b`` [rad]."""
    xp = lib(beta)
    cos_beta = xp.cos(beta)
    return r * (1.0 - cos_beta) / (2.0 * l * (1.0 + cos_beta)) * xp.tan(beta)


def angle_deviation(phi_in: Real, beta: Real, r: float, l: float) -> Real:
    """Eq 18: ``phi_out - phi_in = A(beta) cos 3 phi`` with the seed's phi, i.e. ``A sin 3 phi_in`` [rad]."""
    return kinematics(phi_in, beta, r, l)[0]


def speed_ratio(phi_in: Real, beta: Real, r: float, l: float) -> Real:
    """d(phi_out)/d(phi_in) at constant beta, the derivative of eq 18.

    ``1 - 3 A sin 3 phi`` with the seed's phi (``1 + 3 A cos 3 phi_in``). The seed's eq 19
    prints ``1 - 3 A cos 3 phi``, which is not the derivative of its own eq 18: it puts
    the speed extremes where the angle deviation peaks.
    """
    return kinematics(phi_in, beta, r, l)[1]


def kinematics(phi_in: Real, beta: Real, r: float, l: float) -> tuple[Real, Real]:
    """``(phi_out - phi_in, d phi_out / d phi_in)`` of eq 18 and its derivative, sharing terms."""
    xp = lib(phi_in, beta)
    amplitude = deviation_amplitude(beta, r, l)
    phase = 3.0 * paper_angle(phi_in)
    return amplitude * xp.cos(phase), 1.0 - 3.0 * amplitude * xp.sin(phase)
