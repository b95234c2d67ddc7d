"""The force-deflection characteristic of a mount along one of its axes: a linear rate and a snubber.

Along axis i of a mount, at the deflection ``d`` from the unloaded mount, the elastic force is

    F(d) = k d + k_s [rho(d - g) - rho(-d - g)],                                    (C1)

``k`` the linear rate (``stiffness``), ``g`` the snubber gap (``gap``, the same in both directions),
``k_s`` the stop rate (``stop_rate``) added beyond it, and ``rho`` a ramp that takes the stop's rate
up from 0 to 1 over the blend length ``w`` (``stop_blend``) with a continuous second derivative:

    rho(x) = 0 (x <= 0),   x^3 / w^2 - x^4 / (2 w^3) (0 < x < w),   x - w / 2 (x >= w),    (C2)
    rho'(x) = 3 x^2 / w^2 - 2 x^3 / w^3 on (0, w) (0 below, 1 above).

F is odd, C2 (Newton's Jacobian, the tangent rate ``F' = k + k_s [rho'(d - g) + rho'(-d - g)]``,
is continuous) and monotonic exactly when ``k >= 0`` and ``k + k_s >= 0``; its energy is
``V(d) = k d^2 / 2 + k_s [P(d - g) + P(-d - g)]`` with ``P`` the integral of rho. Without a stop
(``k_s = 0``) F is the linear ``k d`` to the last bit.

The implicit step needs the mean of F over a step's deflections ``[d0, d1]``, the discrete gradient
``(V(d1) - V(d0)) / (d1 - d0)``: it is integrated by three-point Gauss-Legendre on each piece between
the ramp's breakpoints (exact: rho is a polynomial of degree 4 or less on each), free of the
cancellation of the quotient when d1 is near d0.
"""

from __future__ import annotations

import math

import numpy as np

#: Three-point Gauss-Legendre nodes on [0, 1] and their weights (exact for polynomials of degree 5).
_NODES = (0.5 - math.sqrt(15.0) / 10.0, 0.5, 0.5 + math.sqrt(15.0) / 10.0)
_WEIGHTS = (5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0)


def ramp(x: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``rho(x)`` of equation (C2), elementwise."""
    x, w = np.broadcast_arrays(np.asarray(x, float), np.asarray(w, float))
    u = np.clip(x, 0.0, w)  # the cubic's piece evaluated within its range only (no overflow far out)
    return np.where(x >= w, x - 0.5 * w, u * u * u / (w * w) - u * u * (u * u) / (2.0 * (w * w * w)))


def ramp_slope(x: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``rho'(x)``, elementwise."""
    x, w = np.broadcast_arrays(np.asarray(x, float), np.asarray(w, float))
    u = np.clip(x, 0.0, w) / w
    return u * u * (3.0 - 2.0 * u)


def ramp_integral(x: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``P(x)``, the integral of rho from 0, elementwise."""
    x, w = np.broadcast_arrays(np.asarray(x, float), np.asarray(w, float))
    u, beyond = np.clip(x, 0.0, w), np.maximum(x - w, 0.0)
    fourth = u * u * (u * u)
    return fourth / (4.0 * w * w) - fourth * u / (10.0 * (w * w * w)) + beyond * (0.5 * beyond + 0.5 * w)


def force(d: np.ndarray, rate: np.ndarray, gap: np.ndarray, stop_rate: np.ndarray,
          blend: np.ndarray) -> np.ndarray:
    """``F(d)`` of equation (C1) along each axis (vectors of the axes)."""
    return rate * d + stop_rate * (ramp(d - gap, blend) - ramp(-d - gap, blend))


def tangent(d: np.ndarray, rate: np.ndarray, gap: np.ndarray, stop_rate: np.ndarray,
            blend: np.ndarray) -> np.ndarray:
    """``F'(d)``: the tangent rate along each axis."""
    return rate + stop_rate * (ramp_slope(d - gap, blend) + ramp_slope(-d - gap, blend))


def energy(d: np.ndarray, rate: np.ndarray, gap: np.ndarray, stop_rate: np.ndarray,
           blend: np.ndarray) -> np.ndarray:
    """``V(d)``: the elastic energy along each axis."""
    return 0.5 * rate * d * d + stop_rate * (ramp_integral(d - gap, blend) + ramp_integral(-d - gap, blend))


def _ramp_value(x: float, w: float) -> float:
    """``rho(x)`` of one number."""
    if x <= 0.0:
        return 0.0
    if x >= w:
        return x - 0.5 * w
    return x * x * x / (w * w) - x * x * (x * x) / (2.0 * (w * w * w))


def _mean_ramp(a: float, b: float, w: float) -> float:
    """The mean of rho over [a, b] (a != b), piecewise Gauss-Legendre (exact)."""
    low, high = min(a, b), max(a, b)
    if high <= 0.0:
        return 0.0
    cuts = [low, *(c for c in (0.0, w) if low < c < high), high]
    total = 0.0
    for start, end in zip(cuts[:-1], cuts[1:]):
        length = end - start
        total += length * sum(weight * _ramp_value(start + length * node, w)
                              for node, weight in zip(_NODES, _WEIGHTS))
    return total / (high - low)


def mean_force(d0: np.ndarray, d1: np.ndarray, rate: np.ndarray, gap: np.ndarray, stop_rate: np.ndarray,
               blend: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The mean of F over ``[d0, d1]`` along each axis, ``(V(d1) - V(d0)) / (d1 - d0)`` (F(d0) where
    they are equal), and its derivative by ``d1``, ``(F(d1) - mean) / (d1 - d0)``, or ``F'(d1) / 2``
    when d1 is within a millionth of the blend length of d0 (there the quotient cancels; Newton
    needs the slope only to converge). Axes whose deflections stay within the gap take the linear
    rate's ``k (d0 + d1) / 2`` and ``k / 2``."""
    mean, slope = 0.5 * rate * (d0 + d1), 0.5 * rate
    for i in range(len(mean)):
        if stop_rate[i] == 0.0 or max(abs(d0[i]), abs(d1[i])) <= gap[i]:
            continue
        one = (rate[i:i + 1], gap[i:i + 1], stop_rate[i:i + 1], blend[i:i + 1])
        end_force = force(d1[i:i + 1], *one)[0]
        if d0[i] == d1[i]:
            mean[i] = end_force
        else:
            mean[i] += stop_rate[i] * (_mean_ramp(d0[i] - gap[i], d1[i] - gap[i], blend[i])
                                       - _mean_ramp(-d0[i] - gap[i], -d1[i] - gap[i], blend[i]))
        if abs(d1[i] - d0[i]) <= 1e-6 * blend[i]:
            slope[i] = 0.5 * tangent(d1[i:i + 1], *one)[0]
        else:
            slope[i] = (end_force - mean[i]) / (d1[i] - d0[i])
    return mean, slope
