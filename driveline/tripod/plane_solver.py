"""Exact kinematics in the tripod-plane formulation, for one configuration or whole arrays.

A second, independent formulation of the closure solved in :mod:`.exact`, built for
speed: pure ``math`` for one configuration (an FMU step), numpy for arrays (sweeps).
The output shaft's axis ``u`` (components ``x, y`` in the nominal output frame) fixes the
tripod plane (normal to ``u`` through ``P = S - l u``) and its frame ``(e1, e2)``, the
twist-free rotation of the nominal frame onto ``u``. The grooves cut that plane in three
points ``c + A (cos chi_j, sin chi_j)``, an affine image of the groove circle. Writing
``A z = alpha z + beta conj(z)`` for complex z, the 120 deg star through the three points
has its arms at ``chi_j + arg(alpha)`` and its centre at
``c - exp(2i arg alpha) conj(beta) exp(3i chi)`` (checked by substitution). The closure
holds when that centre is P itself: two equations in ``(x, y)``, solved with Newton's
method; the output angle is then ``phi_in + arg(alpha)`` in closed form.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from ..scalar import Real, arcsin, lib

# Newton's method with the analytic Jacobian converges quadratically: after an update below 1e-9
# the remaining error of the axis is of order 1e-18, below the float64 resolution.
LAST_UPDATE = 1e-9
MAX_ITERATIONS = 20
#: Unit tangents of the closure's arguments (x, y, beta, phi_in), for :func:`_star_centre`.
ALONG_X, ALONG_Y, ALONG_BETA, ALONG_PHI = (1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0), (
    0.0, 0.0, 0.0, 1.0)


def _star_centre(
    x: Real, y: Real, turn3: tuple[Real, Real], cb: Real, sb: Real, r: float, l: float, xp: Any,
    tangents: tuple[tuple[float, float, float, float], ...] = (),
) -> tuple[tuple[Real, Real, Real, Real, Real], list[tuple[Real, Real, Real]]]:
    """Star centre relative to P in tripod-plane coordinates (two components) [m], arg(alpha)
    [rad], and the centre's term in ``turn3 = exp(3i chi)`` (two components; its derivative in
    chi is ``-3i`` times that term). Written in real arithmetic, which numpy runs faster.

    With the frame vectors mapped to the input frame by eq 2 (rotations keep dot products):
    ``P.E1 = -l x``, ``P.E2 = -l y``, ``P.U = l (z - 1)``, so ``c = l ((z - 1) f + (x, y))``.

    Second, for each tangent ``(dx, dy, dbeta, dphi_in)`` the directional derivative of the first
    three, exact: the frame's columns turn with beta as ``d(E_x, E_z)/d beta = (-E_z, E_x)``,
    ``arg alpha`` moves by ``Im(d alpha / alpha)``, ``exp(2i arg alpha)`` by ``2i`` times that and
    ``turn3`` by ``3i turn3 dphi_in``.
    """
    z = xp.sqrt(1.0 - x * x - y * y)
    k = 1.0 / (1.0 + z)
    xyk = x * y * k
    # twist-free frame onto u = (x, y, z): e1 = (1 - x^2 k, -x y k, -x), e2 = (-x y k, 1 - y^2 k, -y)
    e1x, e2y = 1.0 - x * x * k, 1.0 - y * y * k
    # x and z components of e1, e2, u in the input frame (eq 2); y components are unchanged
    E1x, E1z = cb * e1x + sb * x, sb * e1x - cb * x
    E2x, E2z = sb * y - cb * xyk, -sb * xyk - cb * y
    Ux, Uz = cb * x - sb * z, sb * x + cb * z
    f1, f2 = E1z / Uz, E2z / Uz
    a11, a12 = r * (E1x - Ux * f1), r * (-xyk - y * f1)
    a21, a22 = r * (E2x - Ux * f2), r * (e2y - y * f2)
    c1, c2 = l * ((z - 1.0) * f1 + x), l * ((z - 1.0) * f2 + y)
    # alpha = ((a11 + a22) + i (a21 - a12)) / 2, beta = ((a11 - a22) + i (a21 + a12)) / 2
    ar, ai = 0.5 * (a11 + a22), 0.5 * (a21 - a12)
    br, bi = 0.5 * (a11 - a22), 0.5 * (a21 + a12)
    norm = ar * ar + ai * ai
    tr, ti = (ar * ar - ai * ai) / norm, 2.0 * ar * ai / norm  # exp(2i arg alpha)
    qr, qi = tr * br + ti * bi, ti * br - tr * bi  # times conj(beta)
    orbit_r, orbit_i = qr * turn3[0] - qi * turn3[1], qr * turn3[1] + qi * turn3[0]
    values = (c1 - orbit_r, c2 - orbit_i, xp.atan2(ai, ar) if xp is math else np.arctan2(ai, ar), orbit_r, orbit_i)
    derivatives = []
    for dx, dy, dbeta, dphi in tangents:
        dz = -(x * dx + y * dy) / z
        dk = -k * k * dz
        dxyk = (dx * y + x * dy) * k + x * y * dk
        de1x, de2y = -(2.0 * x * dx * k + x * x * dk), -(2.0 * y * dy * k + y * y * dk)
        dE1x, dE1z = cb * de1x + sb * dx - E1z * dbeta, sb * de1x - cb * dx + E1x * dbeta
        dE2x, dE2z = sb * dy - cb * dxyk - E2z * dbeta, -sb * dxyk - cb * dy + E2x * dbeta
        dUx, dUz = cb * dx - sb * dz - Uz * dbeta, sb * dx + cb * dz + Ux * dbeta
        df1, df2 = (dE1z - f1 * dUz) / Uz, (dE2z - f2 * dUz) / Uz
        da11, da12 = r * (dE1x - dUx * f1 - Ux * df1), r * (-dxyk - dy * f1 - y * df1)
        da21, da22 = r * (dE2x - dUx * f2 - Ux * df2), r * (de2y - dy * f2 - y * df2)
        dc1, dc2 = l * (dz * f1 + (z - 1.0) * df1 + dx), l * (dz * f2 + (z - 1.0) * df2 + dy)
        dar, dai = 0.5 * (da11 + da22), 0.5 * (da21 - da12)
        dbr, dbi = 0.5 * (da11 - da22), 0.5 * (da21 + da12)
        dtwist = (ar * dai - ai * dar) / norm  # Im(d alpha / alpha)
        dqr, dqi = tr * dbr + ti * dbi - 2.0 * dtwist * qi, ti * dbr - tr * dbi + 2.0 * dtwist * qr
        dorbit_r = dqr * turn3[0] - dqi * turn3[1] - 3.0 * dphi * orbit_i
        dorbit_i = dqr * turn3[1] + dqi * turn3[0] + 3.0 * dphi * orbit_r
        derivatives.append((dc1 - dorbit_r, dc2 - dorbit_i, dtwist))
    return values, derivatives


class Solution(NamedTuple):
    """The closure at one ``phi_in``: axis components and their derivatives in ``phi_in``."""

    phi_in: Real
    x: Real
    y: Real
    dx_dphi: Real
    dy_dphi: Real

    def predict(self, phi_in: Real) -> tuple[Real, Real]:
        """First-order guess of the axis at another input angle (a Newton start value)."""
        step = phi_in - self.phi_in
        return self.x + self.dx_dphi * step, self.y + self.dy_dphi * step

    @property
    def cone_angle(self) -> Real:
        """theta, the tilt of the output shaft [rad]."""
        return arcsin(lib(self.x, self.y).hypot(self.x, self.y))


def solve(phi_in: Real, beta: Real, r: float, l: float, start: Solution | None = None
          ) -> tuple[Real, Real, Solution]:
    """``(phi_out, d phi_out / d phi_in, solution)`` for floats or arrays of (phi_in, beta).

    ``start`` warm-starts the iteration (the previous step's solution, extrapolated to
    ``phi_in``); by default the small-r/l orbit ``rho (cos 3 phi_in, sin 3 phi_in) / l``.
    """
    xp = lib(phi_in, beta)
    converged = bool if xp is math else np.all
    cb, sb = xp.cos(beta), xp.sin(beta)
    if start is None:
        rho_over_l = r * (1.0 - cb) / (2.0 * cb * l)
        x, y = rho_over_l * xp.cos(3.0 * phi_in), rho_over_l * xp.sin(3.0 * phi_in)
    else:
        x, y = start.predict(phi_in)
    turn3 = (xp.cos(3.0 * phi_in), xp.sin(3.0 * phi_in))
    for _ in range(MAX_ITERATIONS):
        (fx, fy, twist, orbit_r, orbit_i), ((jxx, jyx, gradient_x), (jxy, jyy, gradient_y)) = _star_centre(
            x, y, turn3, cb, sb, r, l, xp, (ALONG_X, ALONG_Y))
        det = jxx * jyy - jxy * jyx
        dx = (jyy * fx - jxy * fy) / det
        dy = (jxx * fy - jyx * fx) / det
        x, y = x - dx, y - dy
        if converged(abs(dx) + abs(dy) <= LAST_UPDATE):
            break
    else:
        raise ArithmeticError("tripod closure: plane iteration did not converge")
    # The last update moved (x, y) by (-dx, -dy): carry arg(alpha) along to first order.
    twist = twist - (gradient_x * dx + gradient_y * dy)
    # Implicit function theorem: d(x, y)/d(phi_in) = -J^-1 dF/d(phi_in), dF/d(phi_in) = -3i orbit.
    d_chi_x, d_chi_y = 3.0 * orbit_i, -3.0 * orbit_r
    dx_dphi = -(jyy * d_chi_x - jxy * d_chi_y) / det
    dy_dphi = -(jxx * d_chi_y - jyx * d_chi_x) / det
    ratio = 1.0 + gradient_x * dx_dphi + gradient_y * dy_dphi
    return phi_in + twist, ratio, Solution(phi_in, x, y, dx_dphi, dy_dphi)
