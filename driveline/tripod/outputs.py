"""All outputs of the coupling at once, for one configuration (an FMU step) or whole arrays.

The FMU's model and vectorised sweeps call the same function, so a sweep that needs no
time stepping gives exactly what stepping the FMU would, without a Python loop.
"""

from __future__ import annotations

import math

import numpy as np

from ..scalar import Real, arcsin
from . import closed_form, dynamics, plane_solver
from .geometry import orbit_radius
from .reactions import exact_reactions, mechanism
from .reactions_closed_form import leading_order_reactions
from .rollers import roller_reactions
from .spec import EXACT, PLAIN_TRIPOD

ARMS = ("1", "2", "3")


def efficiency(output_power: Real, loss: Real) -> Real:
    """Delivered over supplied power, whichever side drives. ``output_power = T_load omega_spin``
    is the power the load takes and ``output_power + loss`` the power the input shaft gives:

    * drive (``output_power >= 0``): ``output_power / (output_power + loss)``; 1 where no power flows;
    * coast (the load drives, ``output_power + loss <= 0``): ``(output_power + loss) / output_power``;
    * in between (both shafts supply power, friction takes it all): 0.

    Continuous through the change of direction: 0 from ``output_power = 0`` to ``-loss``."""
    supplied = output_power + loss
    if type(supplied) is float:
        if output_power >= 0.0:
            return output_power / supplied if supplied else 1.0
        coast = supplied / output_power
        return coast if coast > 0.0 else 0.0
    drive = np.divide(output_power, supplied, out=np.ones_like(supplied), where=supplied != 0)
    coast = np.divide(supplied, output_power, out=np.zeros_like(supplied), where=output_power < 0)
    return np.where(output_power >= 0.0, drive, np.where(coast > 0.0, coast, 0.0))


def to_housing(x: Real, y: Real, psi: Real) -> tuple[Real, Real]:
    """Components ``(x, y)`` in the bend plane's frame turned by ``psi`` about Z' into the housing's X'Y'
    (M8); where ``psi`` is 0 they are returned as they are, so that even a zero's sign stays."""
    if type(psi) is float:
        if psi == 0.0:
            return x, y
        c, s = math.cos(psi), math.sin(psi)
        return c * x - s * y, s * x + c * y
    c, s = np.cos(psi), np.sin(psi)
    return np.where(psi == 0.0, x, c * x - s * y), np.where(psi == 0.0, y, s * x + c * y)


def coupling_outputs(
    phi_in: Real, beta: Real, omega_in: Real, T_load: Real, r: float, l: float, m: float,
    kinematics: int, solution: plane_solver.Solution | None = None,
    alpha_in: Real = 0.0, seed_reactions: int = 0, mu: float = 0.0, v_slip: float = 1e-3,
    beta_dot: Real = 0.0, beta_ddot: Real = 0.0, tripod_type: int = PLAIN_TRIPOD, mu_roll: float = 0.0,
    roller_radius: float = 0.0, psi: Real = 0.0, psi_dot: Real = 0.0, psi_ddot: Real = 0.0, plunge_dot: Real = 0.0,
    roller_bore_radius: float = 0.0,
) -> tuple[dict[str, Real], plane_solver.Solution | None]:
    """The ``TripodCoupling`` outputs (names as in the spec) and the exact solver's solution.

    ``solution`` warm-starts the exact solver (kinematics = 1) and is returned updated.
    ``kinematics = 1`` gives the exact reactions (:mod:`.reactions`), 0 their closed forms
    (:mod:`.reactions_closed_form`); ``seed_reactions = 1`` replaces ``a_plunger_sum``,
    ``Rz_out``, ``Rx_in`` and ``Ry_in`` by the seed's eqs 20, 30, 33 and 34 as printed.
    ``mu`` > 0 (exact mode only) adds Coulomb friction regularised over ``v_slip`` [m/s].
    ``beta_dot``, ``beta_ddot``: rates of the bend angle (the output bearing moves with beta).
    ``tripod_type`` 1 (single roller) or 2 (double roller) with the exact kinematics: the roller
    tripods' contacts (:mod:`.rollers`), with rolling resistance ``mu_roll`` and the rollers' outer
    and bore radii ``roller_radius``, ``roller_bore_radius`` [m]; without friction, and in the closed
    form, every type is the plain one.
    The moving housing (docs/tripod_coupling.md, eqs M1-M8): the bend plane at ``psi`` about Z' with its
    rates ``psi_dot``, ``psi_ddot``, and the spider's axial speed ``plunge_dot`` relative to the housing;
    all 0 is the fixed housing, bit for bit.
    """
    rho = orbit_radius(beta, r)
    pin = dynamics.pin_force(T_load, rho, r)
    phi = phi_in - psi  # the input angle from the bend plane (M1)
    spin, spin_dot = omega_in - psi_dot, alpha_in - psi_ddot  # the input speed relative to it (M3)
    if kinematics == EXACT:
        phi_out, ratio, solution = plane_solver.solve(phi, beta, r, l, solution)
        theta = solution.cone_angle
        if tripod_type == PLAIN_TRIPOD:
            forces = exact_reactions(phi, beta, omega_in, alpha_in, T_load, r, l, m, solution.x, solution.y, mu,
                                     v_slip, beta_dot, beta_ddot, psi_dot, psi_ddot, plunge_dot)
        else:
            state = mechanism(phi, beta, omega_in, alpha_in, T_load, r, l, m, solution.x, solution.y, beta_dot,
                              beta_ddot, psi_dot, psi_ddot, plunge_dot)
            forces = roller_reactions(state, omega_in, T_load, m, tripod_type, mu, mu_roll, v_slip, roller_radius,
                                      roller_bore_radius)[0]
        omega_spin, axial_in, loss = forces.omega_spin, forces.Rz_in, forces.P_friction
    else:
        deviation, ratio = closed_form.kinematics(phi, beta, r, l)
        phi_out = phi + deviation
        theta = arcsin(rho / l)
        forces = leading_order_reactions(phi, beta, spin, spin_dot, T_load, r, l, m, ratio, pin,
                                         beta_dot, beta_ddot)
        omega_spin, axial_in, loss = spin * ratio + psi_dot, 0.0 * ratio, 0.0 * ratio
    phi_out = phi_out + psi  # (M2)
    output_power = T_load * omega_spin
    Rx_in, Ry_in = to_housing(forces.Rx_in, forces.Ry_in, psi)
    Mx_in, My_in = to_housing(forces.Mx_in, forces.My_in, psi)
    values = {
        "phi_out": phi_out,
        "delta_phi": phi_out - phi_in,
        "omega_out": spin * ratio + psi_dot,  # (M7)
        "omega_spin": omega_spin,
        "T_in": forces.T_in,
        "F_pin": pin,
        "rho": rho,
        "theta": theta,
        "a_plunger_sum": forces.a_plunger_sum,
        "Rz_out": forces.Rz_out,
        "Rx_out": forces.Rx_out,
        "Ry_out": forces.Ry_out,
        "Rx_in": Rx_in,
        "Ry_in": Ry_in,
        "Mx_in": Mx_in,
        "My_in": My_in,
        "Rz_in": axial_in,
        "P_friction": loss,
        "efficiency": efficiency(output_power, loss),
    }
    for arm, f_arm, f_plunger in zip(ARMS, forces.F_arm, forces.F_plunger):
        values["F_arm" + arm] = f_arm
        values["F_plunger" + arm] = f_plunger
    if seed_reactions:
        seed = dynamics.reactions(phi, beta, spin, rho, l, m)
        Rx_in, Ry_in = to_housing(seed.Rx_in, seed.Ry_in, psi)
        values.update(a_plunger_sum=seed.a_plunger_sum, Rz_out=seed.Rz_out, Rx_in=Rx_in, Ry_in=Ry_in)
    return values, solution
