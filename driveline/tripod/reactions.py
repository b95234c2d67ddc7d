"""Exact bearing reactions of the frictionless coupling, from the exact pose (replaces eqs 20-34).

Bodies: the input shaft (speed prescribed), three plungers (point masses m at the ball
centres, sliding along grooves parallel to Z'), three massless balls (spherical joint in the
plunger, sliding along a tripod arm) and the massless tripod with its output shaft, held by
the self-aligning bearing at ``S = l e_out`` and loaded by the moment ``-T_load U`` about its
own axis ``U``. Gravity and friction are left out. Everything is in the input frame X'Y'Z'.

Per arm j the ball centre ``b_j`` lies on groove j (``g_j + z_j e_z``, ``g_j = r (cos, sin,
0)(phi_in + 2 pi j / 3)``) and on the arm through the tripod centre ``P = S - l U``, whose
vector is ``e_j = b_j - P``. With ``d_j = b_j - S``, ``n_j = e_j x e_z`` (normal to arm and
groove) and ``k_j = d_j x n_j``, the algorithm is, step by step:

1. pose: ``z_j`` from ``(b_j - P) . U = 0``;
2. velocities: ``K Omega = omega ((e_z x g_j) . n_j)_j`` with K the matrix of rows k_j
   (the closure differentiated once, projected on n_j, which removes both sliding rates);
   then the sliding rates from ``Omega x d_j - omega e_z x g_j = zdot_j e_z - sigma_j e_j``;
3. accelerations: ``K Omegadot = ((omegadot e_z x g_j - omega^2 g_j - Omega x (Omega x d_j)
   - 2 sigma_j Omega x e_j) . n_j)_j``, then the plunger accelerations ``zddot_j`` from the
   same split as in 2;
4. forces: the ball pushes arm j with ``F_j`` normal to the arm (no sliding friction), whose
   Z' part ``-m zddot_j`` accelerates the plunger (the groove carries no axial force):
   ``F_j = lambda_j n_j + mu_j (e_j x n_j)`` with ``mu_j = m zddot_j / |n_j|^2``; the tripod's
   moment balance about S, ``sum d_j x F_j = T_load U``, is ``K^T lambda = T_load U -
   sum mu_j d_j x (e_j x n_j)``: the transpose of step 2's matrix (virtual power);
5. reactions: output bearing ``R_out = -sum F_j``; groove force on plunger j ``N_j = m bddot_j
   + F_j``; input bearing ``R_in = sum N_j`` and, about the joint centre O,
   ``M_in + T_in e_z = sum b_j x N_j``.

Both 3x3 solves use Cramer's rule with the same three cross products of the rows of K.
Input speed and its rate are those at the evaluated instant; beta is constant (its rate is
not an input).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ..scalar import Real, lib
from .geometry import THIRD_TURN

Vector = tuple[Real, Real, Real]


def _cross(a: Vector, b: Vector) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a: Vector, b: Vector) -> Real:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _combine(weights: tuple[Real, Real, Real], vectors: tuple[Vector, Vector, Vector]) -> Vector:
    """``sum_j weights_j vectors_j``."""
    w0, w1, w2 = weights
    v0, v1, v2 = vectors
    return tuple(w0 * v0[i] + w1 * v1[i] + w2 * v2[i] for i in range(3))  # type: ignore[return-value]


class ExactReactions(NamedTuple):
    """Forces [N] and moments [N.m] that bearings and joints exert, in the input frame X'Y'Z'
    unless named otherwise; arm/plunger quantities per arm j = 0, 1, 2 (groove j at
    ``phi_in + 2 pi j / 3``)."""

    Rx_in: Real  # input bearing force on the input shaft, X' (in the bend plane)
    Ry_in: Real  # ... Y'
    Mx_in: Real  # input bearing moment on the input shaft about the joint centre O, X'
    My_in: Real  # ... Y'
    T_in: Real  # driving torque on the input shaft about Z' (plunger inertia included)
    Rx_out: Real  # output bearing force on the output shaft, radial, along E1 (bend plane side)
    Ry_out: Real  # ... radial, along E2
    Rz_out: Real  # ... axial, along the output shaft's axis U
    F_arm: tuple[Real, Real, Real]  # ball on arm j, in the tripod plane (along U x arm)
    F_arm_axial: tuple[Real, Real, Real]  # ball on arm j, along U
    F_plunger: tuple[Real, Real, Real]  # ball joint on plunger j along Z' = m zddot_j
    a_plunger_sum: Real  # zddot_0 + zddot_1 + zddot_2 [m/s^2]
    omega_spin: Real  # Omega . U, the output shaft's angular velocity about its own axis [rad/s]


def exact_reactions(
    phi_in: Real, beta: Real, omega: Real, omega_dot: Real, T_load: Real,
    r: float, l: float, m: float, x: Real, y: Real,
) -> ExactReactions:
    """Reactions at input angle ``phi_in``, bend ``beta``, input speed ``omega`` and its rate
    ``omega_dot``, for the output-shaft axis ``(x, y, sqrt(1 - x^2 - y^2))`` in the nominal
    output frame that solves the closure (:func:`.plane_solver.solve`). Plain arithmetic on
    floats or arrays; the algorithm is the module's steps 1-5."""
    xp = lib(phi_in, beta, x, y)
    cb, sb = xp.cos(beta), xp.sin(beta)
    zn = xp.sqrt(1.0 - x * x - y * y)
    k = 1.0 / (1.0 + zn)
    # twist-free frame (E1, E2, U) of the output shaft, nominal output frame -> input frame (eq 2)
    e1x, e1y, e1z = 1.0 - x * x * k, -x * y * k, -x
    e2x, e2y, e2z = -x * y * k, 1.0 - y * y * k, -y
    E1 = (cb * e1x - sb * e1z, e1y, sb * e1x + cb * e1z)
    E2 = (cb * e2x - sb * e2z, e2y, sb * e2x + cb * e2z)
    U = (cb * x - sb * zn, y, sb * x + cb * zn)
    S = (-l * sb, 0.0 * x, l * cb)
    P = (S[0] - l * U[0], S[1] - l * U[1], S[2] - l * U[2])
    p_dot_u = _dot(P, U)
    omega2 = omega * omega
    g, b, e, d, n, kk = [], [], [], [], [], []
    for j in range(3):
        angle = phi_in + THIRD_TURN * j
        gj = (r * xp.cos(angle), r * xp.sin(angle), 0.0 * x)
        # 1. pose: the ball centre on groove j in the tripod plane
        zj = (p_dot_u - gj[0] * U[0] - gj[1] * U[1]) / U[2]
        bj = (gj[0], gj[1], zj)
        ej = (bj[0] - P[0], bj[1] - P[1], bj[2] - P[2])
        dj = (bj[0] - S[0], bj[1] - S[1], bj[2] - S[2])
        nj = (ej[1], -ej[0], 0.0 * x)
        g.append(gj), b.append(bj), e.append(ej), d.append(dj), n.append(nj), kk.append(_cross(dj, nj))
    # Cramer's rule: K v = c  <=>  v = sum_j c_j adj_j / det;  K^T w = c  <=>  w_j = c . adj_j / det
    adj = (_cross(kk[1], kk[2]), _cross(kk[2], kk[0]), _cross(kk[0], kk[1]))
    det = _dot(kk[0], adj[0])

    # 2. velocities (e_z x g_j = (-g_y, g_x, 0))
    spin_rhs = tuple(-omega * (g[j][0] * e[j][0] + g[j][1] * e[j][1]) for j in range(3))
    Omega = tuple(c / det for c in _combine(spin_rhs, adj))  # type: ignore[arg-type]
    sigma, zdot = [], []
    for j in range(3):
        v = _cross(Omega, d[j])  # type: ignore[arg-type]
        vx, vy = v[0] + omega * g[j][1], v[1] - omega * g[j][0]
        s = -(vx * e[j][0] + vy * e[j][1]) / (e[j][0] ** 2 + e[j][1] ** 2)
        sigma.append(s)
        zdot.append(v[2] + s * e[j][2])

    # 3. accelerations
    whirl = [_cross(Omega, _cross(Omega, d[j])) for j in range(3)]  # type: ignore[arg-type]
    coriolis = [_cross(Omega, e[j]) for j in range(3)]  # type: ignore[arg-type]
    known = []
    for j in range(3):
        ax = -omega_dot * g[j][1] - omega2 * g[j][0] - whirl[j][0] - 2.0 * sigma[j] * coriolis[j][0]
        ay = omega_dot * g[j][0] - omega2 * g[j][1] - whirl[j][1] - 2.0 * sigma[j] * coriolis[j][1]
        known.append((ax, ay))
    accel_rhs = tuple(known[j][0] * n[j][0] + known[j][1] * n[j][1] for j in range(3))
    Omega_dot = tuple(c / det for c in _combine(accel_rhs, adj))  # type: ignore[arg-type]
    zddot = []
    for j in range(3):
        w = _cross(Omega_dot, d[j])  # type: ignore[arg-type]
        wx, wy = w[0] - known[j][0], w[1] - known[j][1]
        wz = w[2] + whirl[j][2] + 2.0 * sigma[j] * coriolis[j][2]
        tau = -(wx * e[j][0] + wy * e[j][1]) / (e[j][0] ** 2 + e[j][1] ** 2)
        zddot.append(wz + tau * e[j][2])

    # 4. forces on the arms
    q = [_cross(e[j], n[j]) for j in range(3)]
    mu = [m * zddot[j] / (n[j][0] ** 2 + n[j][1] ** 2) for j in range(3)]
    inertia_moment = _combine((mu[0], mu[1], mu[2]), tuple(_cross(d[j], q[j]) for j in range(3)))  # type: ignore[arg-type]
    moment_rhs = tuple(T_load * U[i] - inertia_moment[i] for i in range(3))
    lam = [_dot(moment_rhs, adj[j]) / det for j in range(3)]  # type: ignore[arg-type]
    F = [tuple(lam[j] * n[j][i] + mu[j] * q[j][i] for i in range(3)) for j in range(3)]

    # 5. reactions
    R_out = tuple(-(F[0][i] + F[1][i] + F[2][i]) for i in range(3))
    N = []
    for j in range(3):
        acc = (-omega_dot * g[j][1] - omega2 * g[j][0], omega_dot * g[j][0] - omega2 * g[j][1], zddot[j])
        N.append(tuple(m * acc[i] + F[j][i] for i in range(3)))
    moment_in = _combine((1.0, 1.0, 1.0), tuple(_cross(b[j], N[j]) for j in range(3)))  # type: ignore[arg-type]
    arm_tangent = [_cross(U, e[j]) for j in range(3)]  # type: ignore[arg-type]
    return ExactReactions(
        Rx_in=N[0][0] + N[1][0] + N[2][0],
        Ry_in=N[0][1] + N[1][1] + N[2][1],
        Mx_in=moment_in[0],
        My_in=moment_in[1],
        T_in=moment_in[2],
        Rx_out=_dot(R_out, E1),  # type: ignore[arg-type]
        Ry_out=_dot(R_out, E2),  # type: ignore[arg-type]
        Rz_out=_dot(R_out, U),  # type: ignore[arg-type]
        F_arm=tuple(_dot(F[j], arm_tangent[j]) / xp.sqrt(_dot(arm_tangent[j], arm_tangent[j])) for j in range(3)),  # type: ignore
        F_arm_axial=tuple(_dot(F[j], U) for j in range(3)),  # type: ignore
        F_plunger=tuple(m * zddot[j] for j in range(3)),  # type: ignore
        a_plunger_sum=zddot[0] + zddot[1] + zddot[2],
        omega_spin=_dot(Omega, U),  # type: ignore[arg-type]
    )
