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
With Coulomb friction (``friction`` > 0) step 4 adds a force along each arm and one along each
groove whose sizes follow the normal forces; :func:`_frictional_balance` repeats step 4 with
them until the forces settle, and step 5 then includes the grooves' axial friction.
Input speed and its rate are those at the evaluated instant. A changing bend angle moves the
output bearing along ``S = l e_out(beta)``: ``Sdot = l betadot de_out/dbeta`` joins the tripod's
velocities in step 2 (``Sdot + Omega x d_j - omega e_z x g_j = zdot_j e_z - sigma_j e_j``) and
``Sddot = l (betaddot de_out/dbeta - betadot^2 e_out)`` its accelerations in step 3; the force
balance keeps its form (massless tripod, bearing force through S).

The moving housing (docs/tripod_coupling.md, "The moving housing", eqs M1-M8): everything above is in
the bend-plane frame, X'Y'Z' turned by psi about Z', where ``phi_in`` is the input angle from the bend
plane. That frame turns at psi_dot: the mechanism moves in it as the fixed-plane one with the input speed
``omega - psi_dot`` and its rate ``omega_dot - psi_ddot`` (steps 2-3), the output shaft's angular velocity
is that one's plus ``psi_dot e_z``, the groove points' accelerations (what the plungers' inertia and the
groove forces take) are the circular motion at ``omega``, ``omega_dot`` themselves, and the axial
accelerations ``zddot_j`` are the same in both frames (a turn about Z' has no axial part). The spider
plunging along Z' at ``plunge_dot`` relative to the housing adds it to every plunger's axial speed
``zdot_j`` (the sliding speed in its groove, relative to the housing), nothing else (the grooves are
parallel to Z').
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from ..scalar import Real, lib

HALF_ROOT_3 = 0.5 * math.sqrt(3.0)  # sin(2 pi / 3)


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
    F_plunger: tuple[Real, Real, Real]  # ball joint on plunger j along Z' = m zddot_j
    a_plunger_sum: Real  # zddot_0 + zddot_1 + zddot_2 [m/s^2]
    omega_spin: Real  # Omega . U, the output shaft's angular velocity about its own axis, in the housing [rad/s]
    Rz_in: Real = 0.0  # input bearing force on the input shaft along Z' (friction only)
    P_friction: Real = 0.0  # power dissipated by friction [W]


class Mechanism(NamedTuple):
    """Steps 1-4 of the frictionless balance at one instant, what the friction laws start from
    (:func:`exact_reactions`, :mod:`.rollers`); per arm j the tuples of the module's steps."""

    xp: Any  # math for floats, numpy for arrays
    arms: list  # (gx, gy, bz, ex, ey, ez, dx, dy, dz, |e_xy|^2, k_jx, k_jy, k_jz): pose, arm e_j, d_j, row k_j
    adj: tuple  # adjugate rows of K (Cramer's rule)
    inv_det: Real  # 1 / det K
    known: list  # (ax, ay, hx, hy, hz): the groove point's acceleration (housing) and the tripod's known terms
    zddot: list  # plunger (roller) accelerations along Z'
    slides: list  # (zdot_j, sigma_j): axial speed in the groove (relative to the housing), sliding rate along the arm (sdot_j / |e_j|)
    lams: list  # lambda_j of the frictionless balance
    mus: list  # mu_j of the frictionless balance
    U: tuple  # the output shaft's axis (Ux, Uy, Uz)
    E1: tuple  # its twist-free frame, E1 (bend-plane side)
    E2: tuple  # ... and E2
    Omega: tuple  # the output shaft's angular velocity relative to the housing (Wx, Wy, Wz)


def mechanism(
    phi_in: Real, beta: Real, omega: Real, omega_dot: Real, T_load: Real,
    r: float, l: float, m: float, x: Real, y: Real, beta_dot: Real = 0.0, beta_ddot: Real = 0.0,
    psi_dot: Real = 0.0, psi_ddot: Real = 0.0, plunge_dot: Real = 0.0,
) -> Mechanism:
    """The module's steps 1-4 without friction: pose, velocities, accelerations and the arm forces,
    for the arguments of :func:`exact_reactions`, in the bend-plane frame (M1-M5)."""
    xp = lib(phi_in, beta, x, y)
    cb, sb = xp.cos(beta), xp.sin(beta)
    zn = xp.sqrt(1.0 - x * x - y * y)
    k = 1.0 / (1.0 + zn)
    # twist-free frame (E1, E2, U) of the output shaft, nominal output frame -> input frame (eq 2)
    e1x, e1y = 1.0 - x * x * k, -x * y * k
    e2x, e2y = -x * y * k, 1.0 - y * y * k
    E1x, E1y, E1z = cb * e1x + sb * x, e1y, sb * e1x - cb * x
    E2x, E2y, E2z = cb * e2x + sb * y, e2y, sb * e2x - cb * y
    Ux, Uy, Uz = cb * x - sb * zn, y, sb * x + cb * zn
    Sx, Sz = -l * sb, l * cb
    # the moving bearing: Sdot = l betadot (-cos, 0, -sin), Sddot = l betaddot (-cos, 0, -sin) - l betadot^2 e_out
    Svx, Svz = -l * cb * beta_dot, -l * sb * beta_dot + plunge_dot  # the spider's plunge joins zdot_j (M5)
    Sax, Saz = l * (sb * beta_dot * beta_dot - cb * beta_ddot), -l * (cb * beta_dot * beta_dot + sb * beta_ddot)
    Px, Py, Pz = Sx - l * Ux, -l * Uy, Sz - l * Uz
    p_dot_u = Px * Ux + Py * Uy + Pz * Uz
    # the mechanism in the bend plane's frame, turning at psi_dot: the input speed relative to it (M3)
    spin, spin_dot = omega - psi_dot, omega_dot - psi_ddot
    omega2, spin2 = omega * omega, spin * spin
    c0, s0 = xp.cos(phi_in), xp.sin(phi_in)
    c1, s1 = -0.5 * c0 - HALF_ROOT_3 * s0, -0.5 * s0 + HALF_ROOT_3 * c0
    c2, s2 = -0.5 * c0 + HALF_ROOT_3 * s0, -0.5 * s0 - HALF_ROOT_3 * c0
    arms = []
    for c, s in ((c0, s0), (c1, s1), (c2, s2)):
        gx, gy = r * c, r * s
        # 1. pose: the ball centre b = (gx, gy, bz) on groove j in the tripod plane
        bz = (p_dot_u - gx * Ux - gy * Uy) / Uz
        ex, ey, ez = gx - Px, gy - Py, bz - Pz  # e_j = b_j - P, along the arm
        dx, dy, dz = ex - l * Ux, ey - l * Uy, ez - l * Uz  # d_j = b_j - S
        exy2 = ex * ex + ey * ey  # |n_j|^2
        arms.append((gx, gy, bz, ex, ey, ez, dx, dy, dz, exy2, dz * ex, dz * ey, -(dx * ex + dy * ey)))
    # Cramer's rule: K v = c  <=>  v = sum_j c_j adj_j / det;  K^T w = c  <=>  w_j = c . adj_j / det
    (k0x, k0y, k0z), (k1x, k1y, k1z), (k2x, k2y, k2z) = (a[10:13] for a in arms)
    adj = (
        (k1y * k2z - k1z * k2y, k1z * k2x - k1x * k2z, k1x * k2y - k1y * k2x),
        (k2y * k0z - k2z * k0y, k2z * k0x - k2x * k0z, k2x * k0y - k2y * k0x),
        (k0y * k1z - k0z * k1y, k0z * k1x - k0x * k1z, k0x * k1y - k0y * k1x),
    )
    inv_det = 1.0 / (k0x * adj[0][0] + k0y * adj[0][1] + k0z * adj[0][2])

    # 2. angular velocity of the output shaft: (e_z x g_j) . n_j = -(g_x e_x + g_y e_y), Sdot . n_j = Sdot_x e_y
    rhs = [(-spin * (a[0] * a[3] + a[1] * a[4]) - Svx * a[4]) * inv_det for a in arms]
    Wx = rhs[0] * adj[0][0] + rhs[1] * adj[1][0] + rhs[2] * adj[2][0]
    Wy = rhs[0] * adj[0][1] + rhs[1] * adj[1][1] + rhs[2] * adj[2][1]
    Wz = rhs[0] * adj[0][2] + rhs[1] * adj[1][2] + rhs[2] * adj[2][2]
    W2 = Wx * Wx + Wy * Wy + Wz * Wz

    # 3. accelerations: known terms per arm, then K Omegadot = (known . n_j)
    known, relative, slides = [], [], []
    for gx, gy, bz, ex, ey, ez, dx, dy, dz, exy2, *_ in arms:
        # sliding rate along the arm (sigma e_j = sdot a_j) from the velocity closure
        vx = Wy * dz - Wz * dy + spin * gy + Svx
        vy = Wz * dx - Wx * dz - spin * gx
        sigma = -(vx * ex + vy * ey) / exy2
        wd = Wx * dx + Wy * dy + Wz * dz  # Omega x (Omega x d) = Omega (Omega . d) - d |Omega|^2
        # whirl + 2 sigma Omega x e + the bearing's acceleration
        hx = Wx * wd - dx * W2 + 2.0 * sigma * (Wy * ez - Wz * ey) + Sax
        hy = Wy * wd - dy * W2 + 2.0 * sigma * (Wz * ex - Wx * ez)
        hz = Wz * wd - dz * W2 + 2.0 * sigma * (Wx * ey - Wy * ex) + Saz
        # groove point's acceleration, radial and tangential: in the bend plane's frame, and in the housing (M4)
        relative.append((-spin_dot * gy - spin2 * gx, spin_dot * gx - spin2 * gy))
        known.append((-omega_dot * gy - omega2 * gx, omega_dot * gx - omega2 * gy, hx, hy, hz))
        slides.append((Wx * dy - Wy * dx + sigma * ez + Svz, sigma))  # (zdot_j, sdot_j / |e_j|)
    rhs = [((ar[0] - kn[2]) * a[4] - (ar[1] - kn[3]) * a[3]) * inv_det for ar, kn, a in zip(relative, known, arms)]
    Ax = rhs[0] * adj[0][0] + rhs[1] * adj[1][0] + rhs[2] * adj[2][0]
    Ay = rhs[0] * adj[0][1] + rhs[1] * adj[1][1] + rhs[2] * adj[2][1]
    Az = rhs[0] * adj[0][2] + rhs[1] * adj[1][2] + rhs[2] * adj[2][2]
    # plunger accelerations and 4. the Z' parts of the arm forces, F_j = lambda_j n_j + mu_j (e_j x n_j)
    zddot, mus = [], []
    Mx, My, Mz = T_load * Ux, T_load * Uy, T_load * Uz  # moment balance about S, right-hand side
    for (ax, ay), (_, _, hx, hy, hz), (gx, gy, bz, ex, ey, ez, dx, dy, dz, exy2, *_) in zip(relative, known, arms):
        wx = Ay * dz - Az * dy + hx - ax  # Omegadot x d + known = zddot e_z - tau e_j
        wy = Az * dx - Ax * dz + hy - ay
        wz = Ax * dy - Ay * dx + hz
        acc = wz - (wx * ex + wy * ey) / exy2 * ez
        mu = m * acc / exy2
        qx, qy, qz = ez * ex, ez * ey, -exy2
        Mx -= mu * (dy * qz - dz * qy)
        My -= mu * (dz * qx - dx * qz)
        Mz -= mu * (dx * qy - dy * qx)
        zddot.append(acc)
        mus.append(mu)
    lams = [(Mx * a0 + My * a1 + Mz * a2) * inv_det for a0, a1, a2 in adj]
    return Mechanism(xp, arms, adj, inv_det, known, zddot, slides, lams, mus, (Ux, Uy, Uz),
                     (E1x, E1y, E1z), (E2x, E2y, E2z), (Wx, Wy, Wz + psi_dot))  # (M6)


def exact_reactions(
    phi_in: Real, beta: Real, omega: Real, omega_dot: Real, T_load: Real,
    r: float, l: float, m: float, x: Real, y: Real, friction: float = 0.0, slip_speed: float = 1e-3,
    beta_dot: Real = 0.0, beta_ddot: Real = 0.0, psi_dot: Real = 0.0, psi_ddot: Real = 0.0, plunge_dot: Real = 0.0,
) -> ExactReactions:
    """Reactions at input angle ``phi_in``, bend ``beta``, input speed ``omega`` and its rate
    ``omega_dot``, for the output-shaft axis ``(x, y, sqrt(1 - x^2 - y^2))`` in the nominal
    output frame that solves the closure (:func:`.plane_solver.solve`). Plain arithmetic on
    floats or arrays, written out per component (the module's steps 1-5; with ``n_j``
    horizontal, ``k_j = (d_z e_x, d_z e_y, -(d_x e_x + d_y e_y))`` and
    ``e_j x n_j = (e_z e_x, e_z e_y, -(e_x^2 + e_y^2))``). ``friction`` > 0 adds Coulomb
    friction in both sliding pairs (:func:`_frictional_balance`); 0 is the frictionless balance.
    ``beta_dot``, ``beta_ddot``: the bend angle's rates, which move the output bearing S; ``psi_dot``,
    ``psi_ddot``: the bend plane's (``phi_in`` is then measured from it and the forces are in its frame);
    ``plunge_dot``: the spider's axial speed relative to the housing (M1-M6)."""
    state = mechanism(phi_in, beta, omega, omega_dot, T_load, r, l, m, x, y, beta_dot, beta_ddot, psi_dot, psi_ddot,
                      plunge_dot)
    xp, arms, adj, inv_det, known, zddot, slides, lams, mus = state[:9]
    (Ux, Uy, Uz), (E1x, E1y, E1z), (E2x, E2y, E2z), (Wx, Wy, Wz) = state.U, state.E1, state.E2, state.Omega
    slips = grooves = (0.0, 0.0, 0.0)
    power_loss = 0.0
    if friction:
        lams, mus, slips, grooves, power_loss = _frictional_balance(
            arms, adj, inv_det, known, zddot, slides, (T_load * Ux, T_load * Uy, T_load * Uz), m,
            friction, slip_speed, lams, mus, xp)
    Rx_out = Ry_out = Rz_out = Rx_in = Ry_in = Lx = Ly = Lz = 0.0
    F_arm = []
    for a, lam, mu, slip, groove, (ax, ay, *_) in zip(arms, lams, mus, slips, grooves, known):
        gx, gy, bz, ex, ey, ez, dx, dy, dz, exy2 = a[:10]
        Fx, Fy, Fz = lam * ey + mu * ez * ex + slip * ex, -lam * ex + mu * ez * ey + slip * ey, -mu * exy2 + slip * ez
        Rx_out, Ry_out, Rz_out = Rx_out - Fx, Ry_out - Fy, Rz_out - Fz
        # 5. groove force on the plunger N_j = m bddot_j + F_j (+ friction along Z'), its moment about O
        Nx, Ny = m * ax + Fx, m * ay + Fy
        Rx_in, Ry_in = Rx_in + Nx, Ry_in + Ny
        Lx, Ly, Lz = Lx - bz * Ny + gy * groove, Ly + bz * Nx - gx * groove, Lz + gx * Ny - gy * Nx
        tx, ty, tz = Uy * ez - Uz * ey, Uz * ex - Ux * ez, Ux * ey - Uy * ex  # U x e_j, in the tripod plane
        F_arm.append((Fx * tx + Fy * ty + Fz * tz) / xp.sqrt(tx * tx + ty * ty + tz * tz))
    return ExactReactions(
        Rx_in=Rx_in,
        Ry_in=Ry_in,
        Mx_in=Lx,
        My_in=Ly,
        T_in=Lz,
        Rx_out=Rx_out * E1x + Ry_out * E1y + Rz_out * E1z,
        Ry_out=Rx_out * E2x + Ry_out * E2y + Rz_out * E2z,
        Rz_out=Rx_out * Ux + Ry_out * Uy + Rz_out * Uz,
        F_arm=(F_arm[0], F_arm[1], F_arm[2]),
        F_plunger=(m * zddot[0], m * zddot[1], m * zddot[2]),
        a_plunger_sum=zddot[0] + zddot[1] + zddot[2],
        omega_spin=Wx * Ux + Wy * Uy + Wz * Uz,
        Rz_in=grooves[0] + grooves[1] + grooves[2],
        P_friction=power_loss,
    )


FRICTION_TOLERANCE = 1e-13  # relative change of the arm forces at which the balance has converged
MAX_FRICTION_ITERATIONS = 200


def slip_sign(speed: Real, slip_speed: float) -> Real:
    """Regularised sign of a sliding speed, ``u / sqrt(1 + u^2)`` with ``u = speed / slip_speed``:
    odd, smooth, within 1 % of the sign above 7 slip speeds."""
    u = speed / slip_speed
    return u / lib(u).sqrt(1.0 + u * u)


def _friction_arm(arm, xp):
    """What the friction balance's iterations do not change on one arm: |e|^2, |e|, |n| |e|, |n|, and the
    moment arms of mu_j and of phi_j (the moments' coefficients in :func:`_frictional_balance`)."""
    ex, ey, ez, dx, dy, dz, exy2 = arm[3:10]
    e2 = exy2 + ez * ez
    mu_arm = (dy * -exy2 - dz * ez * ey, dz * ez * ex + dx * exy2, dx * ez * ey - dy * ez * ex)
    slip_arm = (dy * ez - dz * ey, dz * ex - dx * ez, dx * ey - dy * ex)
    return e2, xp.sqrt(e2), xp.sqrt(exy2 * e2), xp.sqrt(exy2), mu_arm, slip_arm


def _frictional_balance(arms, adj, inv_det, known, zddot, slides, load_moment, m, friction, slip_speed,
                        lams, mus, xp):
    """Arm forces with Coulomb friction ``friction`` in both sliding pairs of each arm.

    The ball on arm j adds ``phi_j e_j`` along the arm, ``|phi_j e_j| = friction |F_perp|`` opposing
    the ball's slip along the arm; the groove adds ``g_j e_z`` on plunger j, ``|g_j| = friction
    |N_xy|`` opposing its slip. The normal forces depend on the friction forces: the coupled
    balance is solved by successive substitution (a contraction of rate ~friction) from the
    frictionless forces until the arm forces change by less than FRICTION_TOLERANCE of their
    size. Returns ``lambda_j``, ``mu_j``, ``phi_j``, ``g_j`` and the dissipated power.
    """
    converged = bool if xp is math else np.all
    Tx, Ty, Tz = load_moment
    signs = [(slip_sign(zdot, slip_speed), slip_sign(sigma * xp.sqrt(a[9] + a[5] * a[5]), slip_speed))
             for (zdot, sigma), a in zip(slides, arms)]
    fixed = [_friction_arm(a, xp) for a in arms]  # what the iterations do not change
    for _ in range(MAX_FRICTION_ITERATIONS):
        Mx, My, Mz = Tx, Ty, Tz
        new_mus, slips, grooves = [], [], []
        change = scale = 0.0
        for a, lam, mu, (ax, ay, *_), acc, (groove_sign, arm_sign), arm in zip(arms, lams, mus, known, zddot, signs,
                                                                               fixed):
            gx, gy, bz, ex, ey, ez, dx, dy, dz, exy2 = a[:10]
            e2, e_norm, ne_norm, _, mu_arm, slip_arm = arm
            normal = xp.sqrt(exy2 * (lam * lam + mu * mu * e2))  # |lambda n + mu e x n|
            slip = friction * normal * arm_sign / e_norm  # phi_j, per unit of |e_j|
            Nx = m * ax + lam * ey + mu * ez * ex + slip * ex
            Ny = m * ay - lam * ex + mu * ez * ey + slip * ey
            groove = -friction * xp.sqrt(Nx * Nx + Ny * Ny) * groove_sign
            # plunger along Z': groove - F_z = m zddot with F_z = -mu |n|^2 + phi e_z
            new_mu = (m * acc - groove + slip * ez) / exy2
            Mx = Mx - new_mu * mu_arm[0] - slip * slip_arm[0]
            My = My - new_mu * mu_arm[1] - slip * slip_arm[1]
            Mz = Mz - new_mu * mu_arm[2] - slip * slip_arm[2]
            change = change + abs(new_mu - mu) * ne_norm
            scale = scale + normal
            new_mus.append(new_mu), slips.append(slip), grooves.append(groove)
        new_lams = [(Mx * a0 + My * a1 + Mz * a2) * inv_det for a0, a1, a2 in adj]
        for arm, lam, new_lam in zip(fixed, lams, new_lams):
            change = change + abs(new_lam - lam) * arm[3]
        lams, mus = new_lams, new_mus
        if converged(change <= FRICTION_TOLERANCE * scale):
            break
    else:
        raise ArithmeticError("tripod friction balance did not converge (friction coefficient too large?)")
    power = 0.0
    for (zdot, sigma), slip, groove, a in zip(slides, slips, grooves, arms):
        # dissipation: -g_j zdot_j (groove) + phi_j sdot_j (arm), sdot_j |e_j| = sigma_j |e_j|^2
        power = power - groove * zdot + slip * sigma * (a[9] + a[5] * a[5])
    return lams, mus, slips, grooves, power
