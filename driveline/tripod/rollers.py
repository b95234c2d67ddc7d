"""Roller tripods: the force balance with a roller on each trunnion, rolling along its track.

The pose, velocities and accelerations are the plain tripod's (:func:`.reactions.mechanism`): the
roller's centre ``b_j`` is where the arm meets the track's axis, the ball centre of the plain
tripod, and carries the roller's mass m (``m_plunger``). What changes is each arm's contacts
(docs/tripod_coupling.md, "Roller tripods", eqs R1-R18):

* trunnion: the roller (single roller) or the inner ring (double roller) slides along the arm at
  ``v_t = sigma_j |e_j|^2 / |e_j|`` with Coulomb friction ``mu`` on the normal force ``|F_perp|``
  (eq R5), as the plain tripod's ball;
* track, single roller (type 1): the roller turns about the trunnion's axis ``a_j``, which the joint
  angle tilts against the track; it rolls along ``u = a x k / |a x k|`` (k the contact normal) and
  slips along ``s = k x u`` (the skew): rolling resistance ``mu_roll N`` opposing the rolling speed
  ``v_r`` and Coulomb friction ``mu N`` opposing the skew slip ``v_s`` (eqs R6-R9), both at the
  contact point ``b_j - R k``; what they turn about b_j goes to the trunnion (eq R10);
* track, double roller (type 2): the outer roller stays parallel to its track and rolls along it
  at the axial speed ``zdot_j``: rolling resistance ``mu_roll N`` along the track (eq R11); the needles,
  moving with the inner ring, which turns with the trunnion, slip along its axis ``a_j`` over the outer
  roller's bore (radius ``r_b``) at ``v_n = r_b (zdot_j a_j . e_z / R - w . (k x a_j))`` (R16); the outer
  roller's spin balance passes ``r_b / R`` of their friction's component along the track to the track
  (R17), and the inner ring passes their moment ``-r_b F_n k x a_j`` about b_j to the trunnion (R18).

Every friction force's sign is regularised as the plain tripod's (:func:`.reactions.slip_sign`).
The normal forces depend on the friction forces: the balance is solved by successive substitution
from the frictionless forces, as :func:`.reactions._frictional_balance` does for the plain tripod.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..scalar import Real
from .reactions import FRICTION_TOLERANCE, MAX_FRICTION_ITERATIONS, ExactReactions, Mechanism, slip_sign
from .spec import SINGLE_ROLLER

Array = NDArray[np.float64]
NOT_CONVERGED = "roller tripod friction balance did not converge (friction coefficient too large?)"
E_Z = np.array([0.0, 0.0, 1.0])


class RollerContacts(NamedTuple):
    """Each arm's contacts, shape (..., 3) per arm j = 0, 1, 2 (vectors (..., 3, 3), input frame)."""

    N_track: Array  # normal force of the track on the roller [N]
    normal: Array  # its direction k_j, horizontal, unit
    N_trunnion: Array  # normal force between roller (inner ring) and trunnion, |F_perp| [N]
    v_trunnion: Array  # sliding speed of the roller (inner ring) outwards along the trunnion [m/s]
    v_roll: Array  # rolling speed of the roller on the track [m/s]
    v_skew: Array  # skew slip speed of the roller over the track along s_j (double roller: the needles' slip v_n) [m/s]
    F_trunnion: Array  # friction force of the roller on the arm, along the arm [N]
    F_roll: Array  # rolling resistance of the track on the roller, along u_j [N]
    F_skew: Array  # sliding friction of the track on the roller, along s_j (double roller: the needles', along a_j) [N]
    couple: Array  # moment of the roller on the trunnion about b_j [N.m] (vectors)
    P_trunnion: Array  # power dissipated at the trunnion [W]
    P_roll: Array  # ... by rolling resistance [W]
    P_skew: Array  # ... by the skew slip [W]
    gamma: Array  # tilt of the arm against the track's normal plane, asin(a_j . e_z) [rad]


def _dot(a: Array, b: Array) -> Array:
    """Scalar products along the last axis (written out: numpy's reductions cost more on 3 components)."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def _cross(a: Array, b: Array) -> Array:
    """Vector products along the last axis (numpy's ``cross`` costs ten times more on small arrays)."""
    ax, ay, az = a[..., 0], a[..., 1], a[..., 2]
    bx, by, bz = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx], -1)


def _unit(a: Array) -> tuple[Array, Array]:
    """``a / |a|`` and ``|a|``; a zero vector stays zero."""
    size = np.sqrt(_dot(a, a))
    return a / np.where(size > 0.0, size, 1.0)[..., None], size


def roller_reactions(
    state: Mechanism, omega: Real, T_load: Real, m: float, tripod_type: int, mu: float, mu_roll: float,
    slip_speed: float, roller_radius: float, roller_bore_radius: float,
) -> tuple[ExactReactions, RollerContacts]:
    """Reactions and contacts of the single (``tripod_type`` 1) or double (2) roller tripod at the
    instant ``state`` describes, at input speed ``omega`` [rad/s] and load ``T_load`` [N.m], with the
    rollers' outer radius ``roller_radius`` and bore radius ``roller_bore_radius`` [m]."""
    arms = [np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in a)) for a in state.arms]
    shape = arms[0][0].shape

    def vectors(index: tuple[int, int, int], source: list = arms) -> Array:
        return np.stack([np.stack([np.broadcast_to(np.asarray(a[i], dtype=float), shape) for i in index], -1)
                         for a in source], -2)

    def scalars(values: list) -> Array:
        return np.stack([np.broadcast_to(np.asarray(v, dtype=float), shape) for v in values], -1)

    centre, arm, lever = vectors((0, 1, 2)), vectors((3, 4, 5)), vectors((6, 7, 8))  # b_j, e_j, d_j (R1)
    exy2 = scalars([a[9] for a in arms])
    rows = vectors((10, 11, 12))  # k_j = d_j x n_j
    normal_arm = np.stack([arm[..., 1], -arm[..., 0], np.zeros_like(exy2)], -1)  # n_j = e_j x e_z
    tangent_arm = _cross(arm, normal_arm)  # e_j x n_j
    axis, arm_length = _unit(arm)  # a_j, |e_j|
    zddot = scalars(state.zddot)
    groove_acc = np.stack([scalars([k[0] for k in state.known]), scalars([k[1] for k in state.known]),
                           np.zeros_like(exy2)], -1)
    acceleration = groove_acc + zddot[..., None] * E_Z  # bddot_j (R2)
    zdot = scalars([s[0] for s in state.slides])
    v_trunnion = scalars([s[1] for s in state.slides]) * arm_length  # sdot_j (R3)
    Omega = np.stack([np.broadcast_to(np.asarray(w, dtype=float), shape) for w in state.Omega], -1)[..., None, :]
    U = np.stack([np.broadcast_to(np.asarray(u, dtype=float), shape) for u in state.U], -1)
    spin = Omega - np.asarray(omega, dtype=float)[..., None, None] * E_Z  # w = Omega - omega e_z (R4)
    adj = np.stack([np.stack([np.broadcast_to(np.asarray(v, dtype=float), shape) for v in row], -1)
                    for row in state.adj], -2)
    inv_det = np.broadcast_to(np.asarray(state.inv_det, dtype=float), shape)
    load = np.asarray(T_load, dtype=float)[..., None] * U
    lam, mu_q = scalars(state.lams), scalars(state.mus)
    trunnion_sign = slip_sign(v_trunnion, slip_speed)
    zero = np.zeros_like(exy2)
    friction_h = np.zeros_like(arm)  # horizontal part of the track's friction on the roller
    R = roller_radius
    needle_share = roller_bore_radius / R  # r_b / R
    relax, last_lam, last_mu = np.ones(shape), np.zeros_like(lam), np.zeros_like(mu_q)  # the double roller's damping
    length2 = arm_length * arm_length
    for _ in range(MAX_FRICTION_ITERATIONS):
        N_trunnion = np.sqrt(exy2 * (lam * lam + mu_q * mu_q * arm_length * arm_length))
        phi = mu * N_trunnion * trunnion_sign / arm_length  # F = lam n + mu q + phi e (R5)
        force = lam[..., None] * normal_arm + mu_q[..., None] * tangent_arm + phi[..., None] * arm
        horizontal = m * groove_acc + force * np.array([1.0, 1.0, 0.0])  # H_j
        if tripod_type == SINGLE_ROLLER:
            k, N_track, (u, across, s), (v_roll, v_skew), (F_roll, F_skew) = _skewed_contact(
                horizontal, axis, zdot, spin, R, mu, mu_roll, slip_speed)
            friction = F_roll[..., None] * u + F_skew[..., None] * s
            couple = _cross(-R * k, friction) + (R * F_roll * across)[..., None] * axis  # R10
        else:
            k, N_track = _unit(horizontal)  # N k = H (R11)
            ring = _cross(k, axis)  # k x a
            v_roll, v_skew = zdot, roller_bore_radius * (zdot * axis[..., 2] / R - _dot(spin, ring))  # v_n (R16)
            F_roll = -mu_roll * N_track * slip_sign(v_roll, slip_speed)
            F_skew = -mu * N_track * slip_sign(v_skew, slip_speed)
            friction = (F_roll + needle_share * axis[..., 2] * F_skew)[..., None] * E_Z  # R17
            couple = (-roller_bore_radius * F_skew)[..., None] * ring  # R18
        new_friction_h = friction * np.array([1.0, 1.0, 0.0])
        # the roller along Z': friction_z - F_z = m zddot with F_z = -mu |e_xy|^2 + phi e_z (R12)
        new_mu_q = (m * zddot - friction[..., 2] + phi * arm[..., 2]) / exy2
        moment = (load - np.sum(new_mu_q[..., None] * _cross(lever, tangent_arm), -2)
                  - np.sum(phi[..., None] * _cross(lever, arm), -2) - np.sum(couple, -2))  # R13
        new_lam = _dot(moment[..., None, :], adj) * inv_det[..., None]
        change = np.sum(np.abs(new_lam - lam) * np.sqrt(exy2) + np.abs(new_mu_q - mu_q) * np.sqrt(exy2) * arm_length
                        + np.sqrt(_dot(new_friction_h - friction_h, new_friction_h - friction_h)), -1)
        scale = np.sum(N_trunnion + N_track, -1)
        if tripod_type != SINGLE_ROLLER:
            # the needles' steep regularised sign can make the substitution swing between two states: the
            # steps' ratio rho to the last ones (projected, in forces) estimates the map's gain g = 1 + (rho - 1)
            # / relax, and the steps take the share relax = 1 / (1 - g) that cancels it, at most 1 (Irons-Tuck)
            step_lam, step_mu = new_lam - lam, new_mu_q - mu_q
            last = np.sum(exy2 * (last_lam * last_lam + length2 * last_mu * last_mu), -1)
            ratio = (np.sum(exy2 * (step_lam * last_lam + length2 * step_mu * last_mu), -1)
                     / np.where(last > 0.0, last, 1.0))
            shared = relax / np.where(ratio < 1.0, 1.0 - ratio, 1.0)
            shared = np.where(ratio < 1.0, np.minimum(1.0, shared), 0.5 * relax)
            relax = np.where(last > 0.0, shared, relax)
            last_lam, last_mu = step_lam, step_mu
            new_lam, new_mu_q = lam + relax[..., None] * step_lam, mu_q + relax[..., None] * step_mu
        lam, mu_q, friction_h = new_lam, new_mu_q, new_friction_h
        if np.all(change <= FRICTION_TOLERANCE * scale):
            break
    else:
        raise ArithmeticError(NOT_CONVERGED)
    N_trunnion = np.sqrt(exy2 * (lam * lam + mu_q * mu_q * arm_length * arm_length))
    phi = mu * N_trunnion * trunnion_sign / arm_length
    force = lam[..., None] * normal_arm + mu_q[..., None] * tangent_arm + phi[..., None] * arm
    track = m * acceleration + force  # the track's force on roller j (R2)
    contacts = RollerContacts(
        N_track=N_track, normal=k, N_trunnion=N_trunnion, v_trunnion=v_trunnion, v_roll=v_roll, v_skew=v_skew,
        F_trunnion=phi * arm_length, F_roll=F_roll, F_skew=F_skew, couple=couple,
        P_trunnion=phi * arm_length * v_trunnion, P_roll=-F_roll * v_roll, P_skew=-F_skew * v_skew,
        gamma=np.arcsin(axis[..., 2]),
    )
    return _reactions(state, centre, arm, force, track, couple, zddot, m, U, contacts), contacts


def _skewed_slips(k: Array, axis: Array, zdot: Array, spin: Array, R: float):
    """The single roller on its track with contact normal ``k`` (R7-R8): rolling direction
    ``u = a x k / |a x k|``, ``|a x k|`` and the skew direction ``s = k x u``; rolling speed
    ``v_r = v0 . u + R |a x k| (w . a)`` and skew slip ``v_s = v0 . s``, with ``v0 = zdot e_z - R w x k``
    the contact point's velocity over the track before the roller's spin on the trunnion."""
    u, across = _unit(_cross(axis, k))
    s = _cross(k, u)
    v0 = zdot[..., None] * E_Z - R * _cross(spin, k)
    return (u, across, s), (_dot(v0, u) + R * across * _dot(spin, axis), _dot(v0, s))


CONTACT_ITERATIONS = 100  # the contact normal's bracketed root: Illinois steps, far more than it takes
CONTACT_TOLERANCE = 1e-15  # [rad] on the normal's angle or on the miss of H's direction
FRICTION_SHARE_CAP = 0.99  # the largest friction share of the normal force the bracket allows for
BRACKET_MARGIN = 1e-9  # [rad] the bracket's half width beyond asin(mu + mu_roll)


def _skewed_contact(horizontal: Array, axis: Array, zdot: Array, spin: Array, R: float, mu: float,
                    mu_roll: float, slip_speed: float):
    """The single roller's track contact under the horizontal force ``H`` it must carry (R9): the
    friction is ``N g(k)`` with ``g = -mu_roll sgn(v_r) u - mu sgn(v_s) s`` (regularised signs), so
    ``H = N (k + g_h(k))`` fixes the normal's direction k (an angle in the horizontal plane, within
    ``asin(mu + mu_roll)`` of H's, found by the Illinois method on that bracket) and then N."""
    target = np.arctan2(horizontal[..., 1], horizontal[..., 0])
    size = np.sqrt(_dot(horizontal, horizontal))
    spread = np.arcsin(min(mu + mu_roll, FRICTION_SHARE_CAP)) + BRACKET_MARGIN

    def evaluate(angle: Array):
        k = np.stack([np.cos(angle), np.sin(angle), np.zeros_like(angle)], -1)
        directions, speeds = _skewed_slips(k, axis, zdot, spin, R)
        u, _, s = directions
        g = (-mu_roll * slip_sign(speeds[0], slip_speed))[..., None] * u - (mu * slip_sign(speeds[1], slip_speed))[..., None] * s
        pushed = k + g * np.array([1.0, 1.0, 0.0])
        miss = np.arctan2(pushed[..., 1], pushed[..., 0]) - target
        return (miss + np.pi) % (2.0 * np.pi) - np.pi, k, pushed, directions, speeds, g

    low, high = target - spread, target + spread
    f_low, f_high = evaluate(low)[0], evaluate(high)[0]
    side = 0
    for _ in range(CONTACT_ITERATIONS):
        if np.all((np.abs(high - low) <= CONTACT_TOLERANCE) | (np.minimum(np.abs(f_low), np.abs(f_high)) <= CONTACT_TOLERANCE)):
            break
        angle = np.where(f_high != f_low, (low * f_high - high * f_low) / np.where(f_high != f_low, f_high - f_low, 1.0),
                         0.5 * (low + high))
        f_mid = evaluate(angle)[0]
        lower = np.sign(f_mid) == np.sign(f_low)
        low, f_low_new = np.where(lower, angle, low), np.where(lower, f_mid, f_low)
        high, f_high_new = np.where(lower, high, angle), np.where(lower, f_high, f_mid)
        # Illinois: halve the value at the end that stays twice in a row
        f_high_new = np.where(lower & (side == 1), 0.5 * f_high_new, f_high_new)
        f_low_new = np.where(~lower & (side == -1), 0.5 * f_low_new, f_low_new)
        side = np.where(lower, 1, -1)
        f_low, f_high = f_low_new, f_high_new
    angle = np.where(np.abs(f_low) <= np.abs(f_high), low, high)
    _, k, pushed, (u, across, s), (v_roll, v_skew), g = evaluate(angle)
    N = size / np.sqrt(_dot(pushed, pushed))
    return (k, N, (u, across, s), (v_roll, v_skew),
            (-mu_roll * N * slip_sign(v_roll, slip_speed), -mu * N * slip_sign(v_skew, slip_speed)))


def _reactions(state: Mechanism, centre: Array, arm: Array, force: Array, track: Array, couple: Array,
               zddot: Array, m: float, U: Array, contacts: RollerContacts) -> ExactReactions:
    """Step 5 with the rollers: the output bearing takes ``-sum F_j``, the input bearing ``sum T_j``
    and, about O, ``sum b_j x T_j + C_j`` (R14)."""
    R_out = -np.sum(force, -2)
    R_in = np.sum(track, -2)
    L = np.sum(_cross(centre, track) + couple, -2)
    E1 = np.stack([np.asarray(e, dtype=float) * np.ones(U.shape[:-1]) for e in state.E1], -1)
    E2 = np.stack([np.asarray(e, dtype=float) * np.ones(U.shape[:-1]) for e in state.E2], -1)
    t = _cross(U[..., None, :], arm)  # U x e_j, in the tripod plane
    F_arm = _dot(force, t) / np.sqrt(_dot(t, t))
    Omega = np.stack([np.asarray(w, dtype=float) * np.ones(U.shape[:-1]) for w in state.Omega], -1)
    power = np.sum(contacts.P_trunnion + contacts.P_roll + contacts.P_skew, -1)
    scalar = (lambda v: float(v)) if U.ndim == 1 else (lambda v: v)
    return ExactReactions(
        Rx_in=scalar(R_in[..., 0]), Ry_in=scalar(R_in[..., 1]), Mx_in=scalar(L[..., 0]), My_in=scalar(L[..., 1]),
        T_in=scalar(L[..., 2]), Rx_out=scalar(_dot(R_out, E1)), Ry_out=scalar(_dot(R_out, E2)),
        Rz_out=scalar(_dot(R_out, U)),
        F_arm=tuple(scalar(F_arm[..., j]) for j in range(3)),
        F_plunger=tuple(scalar(m * zddot[..., j]) for j in range(3)),
        a_plunger_sum=scalar(np.sum(zddot, -1)), omega_spin=scalar(_dot(Omega, U)),
        Rz_in=scalar(R_in[..., 2]), P_friction=scalar(power),
    )
